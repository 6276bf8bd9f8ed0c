//! The street-light controller board (STEVAL-IHP007V1): an ST7580 whose
//! host is the board's firmware, the application engine of UM 4.4.
//!
//! The firmware drives its modem with plm-core's host link engine over
//! the simulated UART, exactly as the console drives a modem, and speaks
//! plm-core's application layer: line frames in DL frames
//! ([`plm_core::app::LineFrame`]), service commands, HID ballast commands
//! forwarded to the board's [`HidBallast`] over the ballast's USART frames
//! (Appendix A). It keeps what the seed gives a board: an RTC, 8 GPIO
//! pins, three parameter groups, firmware and stack releases, the SNR of
//! the last frame heard.
//!
//! A concentrator board (the one at the street's end, whose USART the
//! console or `plm sim --board` talks to) also bridges (4.4, "the user
//! program"): USART frames for other boards go out on the power line,
//! line frames for it come back on the USART with the sender's address.

use crate::ballast::{BallastConfig, HidBallast, Reply};
use crate::breach::Breach;
use crate::rfu::{self, RfuManager};
use crate::rng::Rng;
use plm_core::app::concentrator::USART_IDLE;
use plm_core::app::discovery::Responder;
use plm_core::app::hid::{self, Hid};
use plm_core::app::service::{Discovered, Release, Service, SlotRead, PARAM_LEN, SNR_MAX};
use plm_core::app::{
    Address, AppFrame, Clock, ErrorCode, FrameType, LineFrame, Message, UsartDecoder, UsartElement,
};
use plm_core::link::host::{Event, HostConfig, HostEngine, Ticket, Transmit};
use plm_core::link::Dialect;
use plm_core::st7580::{Command, DataRequest, TxParams};
use plm_core::time::{earliest, Instant};
use std::collections::VecDeque;

/// The first board address of a simulated street: ST's OUI 00-80-E1, then
/// the node number (the concentrator is node 0).
pub const ADDRESS_BASE: u64 = 0x0080_E100_0000;
/// Firmware release of the simulated boards' application as they leave
/// the factory (a remote firmware update changes it, [`crate::rfu`]).
pub const FIRMWARE: Release = Release { major: 1, minor: 4 };
/// Release of their ST7580 data link stack.
pub const STACK: Release = Release { major: 2, minor: 0 };
/// GPIO pins an input reads when nothing drives it: a photocell on IO0
/// reporting night, the cabinet door switch on IO1 closed (model).
pub const INPUT_LEVELS: u8 = 0b0000_0011;

/// How long a board waits for its ballast before it reports HID error
/// 12h, "HID board response timeout" (model).
pub const HID_TIMEOUT: plm_core::time::Duration = 100 * plm_core::time::MS;

/// The firmware hands each line frame it makes to its modem after a delay
/// drawn uniformly from 0 to this, never before the frame it made before
/// (its main loop, its interrupts; the seed gives no figure): a model
/// decision, so that nothing above the line is tuned to a perfect clock.
pub const FIRMWARE_JITTER: plm_core::time::Duration = 4 * plm_core::time::MS;

/// The address of a street's node.
pub fn street_address(node: usize) -> Address {
    Address::from_u64(ADDRESS_BASE + node as u64)
}

/// How a board starts.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardConfig {
    /// Its address.
    pub address: Address,
    /// Its lamp (`None`: a concentrator in a cabinet, no ballast).
    pub ballast: Option<BallastConfig>,
    /// UART baud rate between the STM32 and its ST7580.
    pub baud: u32,
    /// Seconds the RTC is ahead of virtual midnight at power-on (drift).
    pub clock_offset: u64,
    /// The modulation its frames go out with.
    pub modulation: plm_core::st7580::Modulation,
}

/// A line frame the firmware made: when, when it goes to the modem
/// (drawn with [`FIRMWARE_JITTER`] before the board's turn ends), and
/// when it is given up if it has not left by then (a discovery reply at
/// the end of its frame's slots, [`Responder::on_request`]).
#[derive(Debug, Clone)]
struct LineOut {
    made: Instant,
    due: Option<Instant>,
    until: Option<Instant>,
    frame: LineFrame,
}

/// A discovery reply to send: when, given up when, to whom.
#[derive(Debug, Clone, Copy)]
struct DiscoveryReply {
    at: Instant,
    until: Option<Instant>,
    to: Address,
}

/// A pending MIB frame: who asked, and whether it was a write.
#[derive(Debug, Clone, Copy)]
struct MibAsk {
    from: Address,
    index: u8,
    write: bool,
}

/// A simulated controller board.
#[derive(Debug, Clone)]
pub struct Board {
    address: Address,
    engine: HostEngine,
    params: TxParams,
    /// Seconds of day at virtual time 0.
    clock_offset: u64,
    io_config: u8,
    outputs: u8,
    groups: [[u8; PARAM_LEN]; 3],
    snr_threshold: u8,
    last_snr: u8,
    ballast: Option<HidBallast>,
    /// Discovery: the session of the last request, the session this
    /// board was acknowledged in, and when its reply is due (to whom).
    discovery_session: Option<u8>,
    discovery_acked: Option<u8>,
    discovery_reply: Option<DiscoveryReply>,
    /// The modem's frame withdrawn at this instant if none of it has
    /// left ([`LineOut::until`]).
    withdraw: Option<(Ticket, Instant)>,
    /// Discovery rule 2: quiet once named in a session.
    responder: Responder,
    /// Broadcasts it could not read: left unanswered (hundreds of error
    /// frames at once would jam the line), counted here.
    pub unread_broadcasts: u64,
    mib_asks: VecDeque<MibAsk>,
    /// Answers from the ballast on their way: when, to whom, what.
    hid_answers: VecDeque<(Instant, Address, Message)>,
    /// The USART to the outside host, for a concentrator.
    usart: Option<UsartDecoder>,
    /// When the last USART byte of an incomplete frame came.
    usart_last: Option<Instant>,
    usart_out: VecDeque<Vec<u8>>,
    /// Remote firmware update, with the board's flash.
    rfu: RfuManager,
    /// The board protocol rule it breaks, if any (`plm sim --break`).
    breach: Option<Breach>,
    /// Line frames made and not yet handed to the modem, oldest first.
    line_out: VecDeque<LineOut>,
    /// Frames handled (for tests and views).
    pub handled: u64,
}

impl Board {
    /// A board powered on at `now`.
    pub fn new(now: Instant, config: BoardConfig) -> Self {
        Board {
            address: config.address,
            engine: HostEngine::new(
                Dialect::St7580,
                HostConfig {
                    baud: config.baud,
                    ..HostConfig::default()
                },
            ),
            params: TxParams {
                modulation: config.modulation,
                ..TxParams::default()
            },
            clock_offset: config.clock_offset,
            io_config: 0,
            outputs: 0,
            groups: [[0; PARAM_LEN]; 3],
            snr_threshold: 0,
            last_snr: 0,
            ballast: config.ballast.map(|b| HidBallast::new(now, b)),
            discovery_session: None,
            discovery_acked: None,
            discovery_reply: None,
            withdraw: None,
            responder: Responder::default(),
            unread_broadcasts: 0,
            mib_asks: VecDeque::new(),
            hid_answers: VecDeque::new(),
            usart: None,
            usart_last: None,
            usart_out: VecDeque::new(),
            rfu: RfuManager::factory(now, FIRMWARE),
            breach: None,
            line_out: VecDeque::new(),
            handled: 0,
        }
    }

    /// The release of the firmware that runs (service 06h).
    pub fn firmware(&self) -> Release {
        self.rfu.version()
    }

    /// Its RFU manager and flash (tests, faults).
    pub fn rfu_mut(&mut self) -> &mut RfuManager {
        &mut self.rfu
    }

    /// Its supply came back at `now`: the bootloader starts an image
    /// (the flash's power went with the supply: a write under way was
    /// torn), and the firmware starts with nothing in RAM.
    pub fn power_cycle(&mut self, now: Instant) {
        self.rfu.power_cycle(now);
        self.restarted();
    }

    /// The board restarted (after a swap, or its watchdog): what its RAM
    /// held is gone; its modem, a separate chip, keeps going.
    fn restarted(&mut self) {
        self.io_config = 0;
        self.outputs = 0;
        self.discovery_session = None;
        self.discovery_acked = None;
        self.discovery_reply = None;
        self.withdraw = None;
        self.responder = Responder::default();
        self.mib_asks.clear();
        self.hid_answers.clear();
        self.line_out.clear();
    }

    /// The same board with a USART to the outside host (a concentrator).
    pub fn with_usart(mut self) -> Self {
        self.usart = Some(UsartDecoder::new());
        self
    }

    /// The same board breaking one rule of the board protocol.
    pub fn with_breach(mut self, breach: Option<Breach>) -> Self {
        self.breach = breach;
        self
    }

    /// Its address.
    pub fn address(&self) -> Address {
        self.address
    }

    /// Its lamp.
    pub fn ballast(&self) -> Option<&HidBallast> {
        self.ballast.as_ref()
    }

    /// Its lamp, to fail or repair it on demand.
    pub fn ballast_mut(&mut self) -> Option<&mut HidBallast> {
        self.ballast.as_mut()
    }

    /// The RTC at `now`.
    pub fn clock(&self, now: Instant) -> Clock {
        Clock::from_seconds(self.clock_offset + now / 1_000_000)
    }

    /// GPIO pins configured as outputs (bit x = IOx).
    pub fn io_config(&self) -> u8 {
        self.io_config
    }

    /// Output pin levels.
    pub fn outputs(&self) -> u8 {
        self.outputs
    }

    /// Bytes from its modem, each with its arrival time, oldest first.
    /// The firmware acts once on what they completed, at the last one's
    /// time: a run of one write of the modem completes at most its last
    /// byte's element (UM0932 3.2: one frame, ACK or status message).
    pub fn handle_rx(&mut self, bytes: impl IntoIterator<Item = (Instant, u8)>, rng: &mut Rng) {
        let mut last = None;
        for (at, b) in bytes {
            self.engine.handle_rx(at, &[b]);
            last = Some(at);
        }
        if let Some(at) = last {
            self.pump(at, rng);
        }
    }

    /// Bytes from the outside host on the USART (a concentrator).
    pub fn usart_rx(&mut self, now: Instant, bytes: &[u8], rng: &mut Rng) {
        let Some(d) = self.usart.as_mut() else { return };
        d.push(bytes);
        self.usart_last = d.is_partial().then_some(now);
        self.pump(now, rng);
    }

    /// When [`Board::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        let t = earliest(
            self.engine.poll_timeout(),
            self.discovery_reply.map(|r| r.at),
        );
        let t = earliest(t, self.withdraw.map(|w| w.1));
        let t = earliest(t, self.hid_answers.front().map(|a| a.0));
        let t = earliest(t, self.rfu.poll_timeout());
        let t = earliest(t, self.line_out.front().and_then(|o| o.due));
        earliest(t, self.usart_last.map(|t| t + USART_IDLE))
    }

    /// Runs what is due.
    pub fn handle_timeout(&mut self, now: Instant, rng: &mut Rng) {
        if self.rfu.poll_timeout().is_some_and(|t| t <= now) && self.rfu.handle_timeout(now) {
            self.restarted();
        }
        if self.engine.poll_timeout().is_some_and(|t| t <= now) {
            self.engine.handle_timeout(now);
        }
        if self.usart_last.is_some_and(|t| t + USART_IDLE <= now) {
            // The USART went quiet: a frame begun is given up.
            self.usart_last = None;
            if let Some(d) = self.usart.as_mut() {
                d.idle();
            }
        }
        while self.hid_answers.front().is_some_and(|a| a.0 <= now) {
            let (_, to, m) = self.hid_answers.pop_front().expect("front exists");
            self.answer(now, to, m);
        }
        if let Some(r) = self.discovery_reply.filter(|r| r.at <= now) {
            self.discovery_reply = None;
            let reply = Service::DiscoverReply(Discovered {
                firmware: self.rfu.version(),
                stack: STACK,
                snr: self.last_snr,
            });
            let line = LineFrame::from_app(&Message::Service(reply).to(r.to), self.address);
            self.submit_line(now, &line, r.until);
        }
        if let Some((ticket, _)) = self.withdraw.filter(|w| w.1 <= now) {
            self.withdraw = None;
            self.engine.withdraw(now, ticket);
        }
        self.pump(now, rng);
    }

    /// The next bytes or T_REQ change for its modem.
    pub fn poll_transmit(&mut self) -> Option<Transmit> {
        self.engine.poll_transmit()
    }

    /// The next bytes for the outside host on the USART.
    pub fn poll_usart(&mut self) -> Option<Vec<u8>> {
        self.usart_out.pop_front()
    }

    fn pump(&mut self, now: Instant, rng: &mut Rng) {
        while let Some(el) = self.usart.as_mut().and_then(|d| d.next()) {
            if let UsartElement::Frame { frame, .. } = el {
                self.on_usart_frame(now, frame, rng);
            }
        }
        while let Some(ev) = self.engine.poll_event() {
            let Event::Frame(f) = ev else { continue };
            match Command::from_frame(&f) {
                Ok(Command::DlDataIndication(ind)) => {
                    let Some(line) = LineFrame::parse(&ind.payload) else {
                        continue;
                    };
                    if !line.is_for(self.address) || line.source == self.address {
                        continue;
                    }
                    let snr = if ind.info.snr == 0xFF {
                        0
                    } else {
                        ind.info.snr as i8
                    };
                    self.last_snr = snr.clamp(0, SNR_MAX as i8) as u8;
                    if self.last_snr < self.snr_threshold {
                        continue; // below the SN_SET threshold: not acted on
                    }
                    self.on_line_frame(now, line, rng);
                }
                Ok(Command::MibReadConfirm { data }) => self.mib_answer(now, Some(data)),
                Ok(Command::MibWriteConfirm) => self.mib_answer(now, None),
                Ok(Command::MibReadError(_) | Command::MibWriteError(_)) => {
                    if let Some(ask) = self.mib_asks.pop_front() {
                        self.answer(now, ask.from, Message::Error(ErrorCode::SERVICE_CMD_ERROR));
                    }
                }
                _ => {}
            }
        }
        self.release_line(now, rng);
    }

    /// Draws when each new line frame goes ([`FIRMWARE_JITTER`]), and
    /// hands those due to the modem.
    fn release_line(&mut self, now: Instant, rng: &mut Rng) {
        let mut after = now;
        for o in self.line_out.iter_mut() {
            let due = *o
                .due
                .get_or_insert_with(|| (o.made + rng.below(FIRMWARE_JITTER + 1)).max(after));
            after = due;
        }
        while self
            .line_out
            .front()
            .is_some_and(|o| o.due.is_some_and(|d| d <= now))
        {
            let o = self.line_out.pop_front().expect("front exists");
            let cmd = Command::DlDataRequest(DataRequest {
                params: self.params,
                payload: o.frame.emit(),
            });
            let ticket = self.engine.submit(now, cmd.to_frame());
            if let Some(u) = o.until {
                self.withdraw = Some((ticket, u));
            }
        }
    }

    /// A frame from the outside host: for this board, or for the line.
    fn on_usart_frame(&mut self, now: Instant, frame: AppFrame, rng: &mut Rng) {
        if !frame.broadcast && frame.address == self.address {
            let me = self.address;
            if let Some(reply) = self.handle(now, me, false, &frame, rng) {
                self.usart_send(reply.to(me));
            }
            return;
        }
        let line = LineFrame::from_app(&frame, self.address);
        self.submit_line(now, &line, None);
    }

    /// A line frame for this board.
    fn on_line_frame(&mut self, now: Instant, line: LineFrame, rng: &mut Rng) {
        self.handled += 1;
        if self.usart.is_some() {
            // A concentrator hands what comes for it to its host (4.4).
            self.usart_send(line.to_app());
            return;
        }
        let frame = line.to_app();
        if let Some(reply) = self.handle(now, line.source, line.broadcast, &frame, rng) {
            if !line.broadcast {
                self.send_line(now, line.source, &reply);
            }
        }
    }

    /// The application engine: what this board answers `frame` from
    /// `from`; broadcasts are carried out and not answered.
    fn handle(
        &mut self,
        now: Instant,
        from: Address,
        broadcast: bool,
        frame: &AppFrame,
        rng: &mut Rng,
    ) -> Option<Message> {
        let Some(breach) = self.breach else {
            return self.respond(now, from, broadcast, frame, rng);
        };
        let m = Message::of(frame).ok();
        if m.as_ref().is_some_and(|m| breach.ignores(m)) {
            return None;
        }
        let answer = self.respond(now, from, broadcast, frame, rng);
        breach.answer(m.as_ref(), answer)
    }

    /// What a board that keeps every rule answers.
    fn respond(
        &mut self,
        now: Instant,
        from: Address,
        broadcast: bool,
        frame: &AppFrame,
        rng: &mut Rng,
    ) -> Option<Message> {
        let m = match Message::of(frame) {
            Ok(m) => m,
            Err(_) if broadcast => {
                self.unread_broadcasts += 1;
                return None;
            }
            Err(_) if frame.frame_type == FrameType::Service => {
                return Some(Message::Error(ErrorCode::SERVICE_CMD_ERROR))
            }
            Err(_) => return None,
        };
        match &m {
            Message::Ping => Some(m.ack()),
            Message::Service(s) => self.service(now, from, broadcast, s, rng),
            Message::Hid(h) => {
                self.hid(now, from, broadcast, h, &m);
                None
            }
            Message::Ack {
                frame_type: FrameType::Service,
                echo: 0x0b,
            } => {
                self.discovery_acked = self.discovery_session;
                None
            }
            Message::Programming { group, data } => Some(self.program(*group, data, &m)),
            Message::Mib { index, data } => {
                let cmd = if data.is_empty() {
                    Command::MibReadRequest { index: *index }
                } else {
                    Command::MibWriteRequest {
                        index: *index,
                        data: data.clone(),
                    }
                };
                self.mib_asks.push_back(MibAsk {
                    from,
                    index: *index,
                    write: !data.is_empty(),
                });
                self.engine.submit(now, cmd.to_frame());
                None
            }
            _ => None,
        }
    }

    fn program(&mut self, group: u8, data: &[u8], m: &Message) -> Message {
        match self.groups.get_mut(group as usize) {
            Some(g) if data.len() == PARAM_LEN => {
                g.copy_from_slice(data);
                m.ack()
            }
            Some(_) => Message::Error(ErrorCode(0x08)),
            None => Message::Error(ErrorCode::WRONG_PROG_GROUP),
        }
    }

    fn service(
        &mut self,
        now: Instant,
        from: Address,
        broadcast: bool,
        s: &Service,
        rng: &mut Rng,
    ) -> Option<Message> {
        // Remote firmware update: the manager checks its own requests and
        // keeps why it refused one for RFU_STATUS_GET.
        if let Some(a) = self.rfu.handle(now, s, rng) {
            return match a {
                _ if broadcast => None,
                rfu::Answer::Ack => Some(Message::ack_of(s)),
                rfu::Answer::Refused => Some(Message::Error(ErrorCode::SERVICE_CMD_ERROR)),
                rfu::Answer::Reply(r) => Some(Message::Service(r)),
                rfu::Answer::Nothing => None,
            };
        }
        if s.validate().is_err() {
            let code = match s {
                Service::ClockSet(_) => ErrorCode::RTC_ERROR,
                Service::ParamSet { group, .. } | Service::ParamGet { group } if *group > 2 => {
                    ErrorCode::WRONG_PROG_GROUP
                }
                _ => ErrorCode::SERVICE_CMD_ERROR,
            };
            return Some(Message::Error(code));
        }
        let ack = Some(Message::ack_of(s));
        let reply = |s: Service| Some(Message::Service(s));
        match s {
            Service::SoftwareReset => {
                self.discovery_reply = None;
                None
            }
            Service::HardwareReset => {
                self.io_config = 0;
                self.outputs = 0;
                self.discovery_reply = None;
                None
            }
            Service::ParamSet { group, data } => {
                self.groups[*group as usize].copy_from_slice(data);
                ack
            }
            Service::ParamGet { group } => reply(Service::Params {
                group: *group,
                data: self.groups[*group as usize].to_vec(),
            }),
            Service::InputsGet => reply(Service::Inputs(self.inputs())),
            Service::OutputsSet(v) => {
                self.outputs = *v & self.io_config;
                ack
            }
            Service::FwRelGet => reply(Service::FwRel {
                firmware: self.rfu.version(),
                stack: STACK,
            }),
            Service::ClockSet(c) => {
                let since_boot = now / 1_000_000;
                self.clock_offset =
                    (c.seconds_of_day() as u64 + 86_400 - since_boot % 86_400) % 86_400;
                ack
            }
            Service::ClockGet => reply(Service::ClockNow(self.clock(now))),
            Service::IoConfigSet(v) => {
                self.io_config = *v;
                self.outputs &= *v;
                ack
            }
            Service::IoConfigGet => reply(Service::IoConfig(self.io_config)),
            Service::DiscoverAny | Service::DiscoverFrame(_) => {
                if let Some(slot) = self.responder.on_request(&self.address, s) {
                    self.discovery_reply = Some(DiscoveryReply {
                        at: now + slot.start,
                        until: Some(now + slot.end),
                        to: from,
                    });
                }
                None
            }
            Service::Discover { session, window } => {
                self.discovery_session = Some(*session);
                if self.discovery_acked != Some(*session) {
                    let delay = rng.below(*window as u64 * 1_000_000);
                    self.discovery_reply = Some(DiscoveryReply {
                        at: now + delay,
                        until: None,
                        to: from,
                    });
                }
                None
            }
            Service::SnSet(v) => {
                self.snr_threshold = *v;
                ack
            }
            Service::SnGet => reply(Service::Sn(self.last_snr)),
            Service::ReadInSlots(r) => {
                self.read_in_slot(now, from, r);
                None
            }
            _ if broadcast => None,
            // Replies, and user commands this firmware does not know.
            _ => Some(Message::Error(ErrorCode::SERVICE_CMD_ERROR)),
        }
    }

    /// GPIO inputs: input pins read [`INPUT_LEVELS`], output pins their
    /// own level.
    fn inputs(&self) -> u8 {
        (INPUT_LEVELS & !self.io_config) | (self.outputs & self.io_config)
    }

    /// A HID command goes to the ballast on its USART (Appendix A); its
    /// answer goes back to `from` once the ballast gave it (nothing for a
    /// broadcast).
    fn hid(&mut self, now: Instant, from: Address, broadcast: bool, h: &Hid, m: &Message) {
        if matches!(h, Hid::Reply { .. }) {
            return;
        }
        let (at, answer) = match self.ballast.as_mut() {
            // No ballast on this board: "HID packet delivery impossible".
            None => (now, Message::Error(ErrorCode(0x13))),
            Some(b) => match b.handle(now, &hid::ballast_frame(&h.payload())) {
                None => (now + HID_TIMEOUT, Message::Error(ErrorCode::HID_TIMEOUT)),
                Some(a) => (
                    a.at,
                    match a.reply {
                        Reply::Frame(f) => match hid::ballast_payload(&f).and_then(Hid::parse) {
                            Some(r @ Hid::Reply { .. }) => Message::Hid(r),
                            _ => m.ack(),
                        },
                        r => Message::Error(r.error().unwrap_or(ErrorCode(0x10))),
                    },
                ),
            },
        };
        if !broadcast {
            self.queue_answer(at, from, answer);
        }
    }

    /// SERVICE_READ_IN_SLOTS (docs/protocol-notes.md, "Reads in slots"):
    /// named at index i, the board asks its ballast for the parameter now
    /// and sends its HID reply `first_ms + i × slot_ms` after hearing the
    /// request, or nothing if the ballast is late or answers otherwise.
    fn read_in_slot(&mut self, now: Instant, from: Address, r: &SlotRead) {
        let (Some(after), Some(b)) = (r.reply_after(&self.address), self.ballast.as_mut()) else {
            return;
        };
        let Some(a) = b.handle(now, &hid::ballast_frame(&Hid::Get(r.param).payload())) else {
            return;
        };
        let due = now + after;
        let Reply::Frame(f) = a.reply else {
            return;
        };
        if let Some(h @ Hid::Reply { .. }) = hid::ballast_payload(&f).and_then(Hid::parse) {
            if a.at <= due {
                self.queue_answer(due, from, Message::Hid(h));
            }
        }
    }

    /// An answer due at `at`, kept in time order.
    fn queue_answer(&mut self, at: Instant, to: Address, m: Message) {
        let i = self.hid_answers.partition_point(|a| a.0 <= at);
        self.hid_answers.insert(i, (at, to, m));
    }

    fn mib_answer(&mut self, now: Instant, data: Option<Vec<u8>>) {
        let Some(ask) = self.mib_asks.pop_front() else {
            return;
        };
        let msg = match data {
            Some(d) if !ask.write => Message::Mib {
                index: ask.index,
                data: d,
            },
            _ => Message::Mib {
                index: ask.index,
                data: vec![0],
            }
            .ack(),
        };
        self.answer(now, ask.from, msg);
    }

    /// Sends an answer back where the question came from.
    fn answer(&mut self, now: Instant, to: Address, m: Message) {
        if to == self.address {
            self.usart_send(m.to(to));
        } else {
            self.send_line(now, to, &m);
        }
    }

    fn send_line(&mut self, now: Instant, to: Address, m: &Message) {
        let line = LineFrame::from_app(&m.to(to), self.address);
        self.submit_line(now, &line, None);
    }

    /// A line frame made now: it goes to the modem when
    /// [`Board::release_line`] says, unless `until` has passed.
    fn submit_line(&mut self, now: Instant, line: &LineFrame, until: Option<Instant>) {
        self.line_out.push_back(LineOut {
            made: now,
            due: None,
            until,
            frame: line.clone(),
        });
    }

    fn usart_send(&mut self, frame: AppFrame) {
        if let Ok(bytes) = frame.emit() {
            self.usart_out.push_back(bytes);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The host's default address as a bare-modem concentrator is the
    /// simulated street's node 0: the console and `plm board` need no
    /// fact of the simulator to reach it.
    #[test]
    fn node_0_is_the_concentrators_default_address() {
        assert_eq!(street_address(0), plm_core::app::Concentrator::ADDRESS);
    }
}
