//! A host program that behaves as the ST7580 reference host driver does
//! (issue 15), for the point-to-point demo: plm-core's host engine, driven
//! the way that driver drives its port.
//!
//! - After a status message with bit 1 or 2 set (transmission or
//!   reception in progress) T_REQ is released and pulled low again at
//!   once (`HostEngine::set_not_now`).
//! - T_REQ is released right after the STX (the engine's rule).
//! - Modem frames are ACKed late: after a frame the program is busy for
//!   `late` (more than T_ACK), reads nothing, and only then writes its ACK,
//!   so the modem repeats every frame with STX 03h (UM0932 3.2.7).
//! - Each confirm is paired with the request before it (the last one the
//!   modem ACKed): a confirm that comes after a later request's ACK is
//!   paired with the wrong request, and counted so.
//!
//! The demo: the master sends a 21-byte DL trigger, the slave answers with
//! a 17-byte DL message. Right after each data request is ACKed, the
//! program reads a MIB object (while its modem transmits), which makes it
//! meet "not now" statuses and the data confirm arriving during them.
//!
//! Sans-IO: bytes and time in, T_REQ levels and bytes out, so that one
//! program runs against the simulator in virtual time and over real
//! RFC 2217 ports in wall time.

#![allow(dead_code)]

use plm_core::link::host::{Event, HostConfig, HostEngine, Transmit};
use plm_core::link::{Dialect, Element, ACK};
use plm_core::st7580::mib::{index, MibObject, ModemConfig};
use plm_core::st7580::{code, Command, DataRequest, FrequencySet, Modulation, TxParams};
use plm_core::time::{Duration, Instant, MS};
use std::collections::VecDeque;

/// UM0932 Table 9: T_ACK.
pub const T_ACK: Duration = 40 * MS;
/// How late the program ACKs a modem frame.
pub const LATE: Duration = T_ACK + 5 * MS;
/// The demo's trigger and answer lengths.
pub const TRIGGER_LEN: usize = 21;
pub const ANSWER_LEN: usize = 17;
/// The master's wait for an answer before the next trigger.
pub const ANSWER_WAIT: Duration = 1_000 * MS;
/// Status bits 1-2 (Table 8): transmission, reception in progress.
const NOT_NOW: u8 = 0b0000_0110;
/// The demo's carrier.
pub const FREQUENCY: u32 = 117_000;

/// Which end of the demo.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Master,
    Slave,
}

/// What happened, counted.
#[derive(Debug, Clone, Default)]
pub struct Stats {
    /// Requests submitted, ACKed by the modem, given up by the link.
    pub requests: usize,
    pub acked: usize,
    pub failed: usize,
    /// Confirms (or errors) paired with their own request, with another.
    pub paired: usize,
    pub mispaired: usize,
    /// Data requests refused by the modem (DL_DataError).
    pub refused: usize,
    /// T_REQ falling edges; status messages; the longest wait for a
    /// status from its edge (or from the end of the modem's own frame
    /// exchange that went first, UM0932 3.2.5), µs; how many took more
    /// than 20 ms; the longest raw edge-to-status time.
    pub edges: usize,
    pub statuses: usize,
    pub not_now: usize,
    pub max_status_wait: Duration,
    pub late_statuses: usize,
    pub max_raw_status_wait: Duration,
    /// The late ones: (edge, end of the modem's last frame, status).
    pub late: Vec<(Instant, Instant, Instant)>,
    /// Modem frames, and their repeats (STX 03h) caused by our late ACKs.
    pub frames: usize,
    pub repeats: usize,
    /// Master: triggers sent (confirmed), answers heard. Slave: triggers
    /// heard, answers sent (confirmed).
    pub triggers: usize,
    pub answers: usize,
}

/// The host program of one modem.
pub struct VendorHost {
    pub role: Role,
    engine: HostEngine,
    /// Writes waiting for the program to be free, in order.
    out: VecDeque<Transmit>,
    /// Busy (ACKing late) until then: nothing read, nothing written.
    busy_until: Option<Instant>,
    /// Bytes that came while busy, read afterwards, with their arrival.
    inbox: VecDeque<(Instant, u8)>,
    /// When the byte being read arrived.
    arrived: Instant,
    /// Requests the program still has to submit, in order.
    todo: VecDeque<Command>,
    /// The request the modem ACKed last, and whether its confirm came.
    last_acked: Option<(u8, bool)>,
    /// Tickets in flight with their request codes.
    tickets: VecDeque<(plm_core::link::host::Ticket, u8)>,
    /// The last T_REQ falling edge not yet answered with a status.
    edge: Option<Instant>,
    /// When the modem's last frame ended (its own exchange first).
    modem_frame_end: Instant,
    /// Master: the trigger number and when the next one is due.
    seq: u8,
    next_trigger: Option<Instant>,
    configured: bool,
    /// No new trigger after this (the demo winds down).
    stopped: bool,
    /// The data request whose ACK is awaited (to read a MIB object then).
    pub stats: Stats,
}

impl VendorHost {
    /// A program for `role` at `baud`, starting at `now` (its modem just
    /// reset): configure the modem for the demo, then run it.
    pub fn new(role: Role, baud: u32, now: Instant) -> VendorHost {
        let mut engine =
            HostEngine::new(Dialect::St7580, HostConfig::at_reset(Dialect::St7580, baud));
        engine.set_not_now(NOT_NOW, 0);
        let _ = now;
        // The demo's configuration: DL layer with CRC-32, B-PSK coded at
        // 117 kHz, high channel only.
        let mc = ModemConfig {
            access_mode: 1,
            sniffer_mode: false,
            crc_length: 2,
            dl_crc_on_phy_length: false,
        };
        let Some(MibObject::PhyConfig(mut phy)) = MibObject::factory_default(index::PHY_CONFIG)
        else {
            unreachable!("PHY_Config has a factory default")
        };
        phy.high_frequency = FREQUENCY;
        phy.rx_mode_dual = false;
        phy.rx_high_psk = true;
        let todo = VecDeque::from([
            Command::MibWriteRequest {
                index: index::MODEM_CONFIG,
                data: mc.encode(),
            },
            Command::MibWriteRequest {
                index: index::PHY_CONFIG,
                data: phy.encode(),
            },
        ]);
        VendorHost {
            role,
            engine,
            out: VecDeque::new(),
            busy_until: None,
            inbox: VecDeque::new(),
            arrived: 0,
            todo,
            last_acked: None,
            tickets: VecDeque::new(),
            edge: None,
            modem_frame_end: 0,
            seq: 0,
            next_trigger: None,
            configured: false,
            stopped: false,
            stats: Stats::default(),
        }
    }

    /// Bytes from the modem that arrived at `at`, seen at `now`.
    pub fn handle_rx(&mut self, at: Instant, now: Instant, bytes: &[u8]) {
        self.inbox.extend(bytes.iter().map(|&b| (at, b)));
        self.run(now);
    }

    /// Time passed: call at [`VendorHost::poll_timeout`].
    pub fn handle_timeout(&mut self, now: Instant) {
        self.run(now);
    }

    /// When [`VendorHost::handle_timeout`] is due.
    pub fn poll_timeout(&self) -> Option<Instant> {
        if let Some(t) = self.busy_until {
            return Some(t);
        }
        [self.engine.poll_timeout(), self.next_trigger]
            .into_iter()
            .flatten()
            .min()
    }

    /// The next write or T_REQ change, once the program is free.
    pub fn poll_transmit(&mut self, now: Instant) -> Option<Transmit> {
        if self.busy_until.is_some() {
            return None;
        }
        let t = self.out.pop_front()?;
        if std::env::var_os("VENDOR_TRACE").is_some() {
            eprintln!("{:?} {now} out {t:?}", self.role);
        }
        if let Transmit::TReq { asserted: true } = t {
            self.stats.edges += 1;
            self.edge = Some(now);
        }
        Some(t)
    }

    fn run(&mut self, now: Instant) {
        loop {
            if let Some(t) = self.busy_until {
                if now < t {
                    return;
                }
                self.busy_until = None;
            }
            // Read what came, byte by byte: an ACK to write makes the
            // program busy, and the rest waits.
            while self.busy_until.is_none() {
                let Some((at, b)) = self.inbox.pop_front() else {
                    break;
                };
                self.arrived = at;
                self.engine.handle_rx(now, &[b]);
                self.collect(now);
            }
            if self.busy_until.is_some() {
                continue;
            }
            if self.engine.poll_timeout().is_some_and(|t| t <= now) {
                self.engine.handle_timeout(now);
                self.collect(now);
            }
            self.app(now);
            self.collect(now);
            return;
        }
    }

    /// Takes the engine's output and events.
    fn collect(&mut self, now: Instant) {
        while let Some(t) = self.engine.poll_transmit() {
            if t == Transmit::Bytes(vec![ACK]) {
                // The ACK waits: the program is busy with the frame.
                self.busy_until = Some(now + LATE);
            }
            self.out.push_back(t);
        }
        while let Some(e) = self.engine.poll_event() {
            self.on_event(now, e);
        }
    }

    fn on_event(&mut self, now: Instant, e: Event) {
        if std::env::var_os("VENDOR_TRACE").is_some() {
            eprintln!("{:?} {now} arrived {} {e:?}", self.role, self.arrived);
        }
        match e {
            Event::Received(Element::Status(s)) => {
                self.stats.statuses += 1;
                if s.data().first().is_some_and(|b| b & NOT_NOW != 0) {
                    self.stats.not_now += 1;
                }
                // Timed on the wire: when its last byte arrived.
                let at = self.arrived;
                if let Some(edge) = self.edge.take() {
                    let raw = at - edge.min(at);
                    let wait = at - edge.max(self.modem_frame_end).min(at);
                    self.stats.max_raw_status_wait = self.stats.max_raw_status_wait.max(raw);
                    self.stats.max_status_wait = self.stats.max_status_wait.max(wait);
                    if wait > 20 * MS {
                        self.stats.late.push((edge, self.modem_frame_end, at));
                        self.stats.late_statuses += 1;
                    }
                }
            }
            Event::Received(Element::Frame { .. }) => self.modem_frame_end = self.arrived,
            Event::Repeat(_) => self.stats.repeats += 1,
            Event::Delivered(t) => {
                self.stats.acked += 1;
                let Some(pos) = self.tickets.iter().position(|(k, _)| *k == t) else {
                    return;
                };
                let (_, req) = self.tickets.remove(pos).unwrap();
                self.last_acked = Some((req, false));
                if req == code::DL_DATA_REQUEST {
                    // While the modem transmits: read a counter.
                    self.todo.push_back(Command::MibReadRequest {
                        index: index::DL_DATA,
                    });
                }
            }
            Event::Failed(t, _) => {
                self.stats.failed += 1;
                self.tickets.retain(|(k, _)| *k != t);
            }
            Event::Frame(f) => {
                self.stats.frames += 1;
                let Ok(cmd) = Command::from_frame(&f) else {
                    return;
                };
                if code::command_type(f.code) == Some(code::CommandType::Indication) {
                    self.indication(now, cmd);
                    return;
                }
                // A confirm or error: the request before it.
                match &mut self.last_acked {
                    Some((req, done @ false)) if code::answers(*req, f.code) => {
                        *done = true;
                        self.stats.paired += 1;
                        let req = *req;
                        self.confirmed(now, req, &cmd);
                    }
                    _ => self.stats.mispaired += 1,
                }
            }
            _ => {}
        }
    }

    fn confirmed(&mut self, now: Instant, req: u8, cmd: &Command) {
        match cmd {
            Command::DlDataError(_) => self.stats.refused += 1,
            Command::DlDataConfirm(_) => match self.role {
                Role::Master => self.stats.triggers += 1,
                Role::Slave => self.stats.answers += 1,
            },
            Command::MibWriteConfirm
                if req == code::MIB_WRITE_REQUEST && self.todo.is_empty() && !self.configured =>
            {
                self.configured = true;
                if self.role == Role::Master {
                    self.next_trigger = Some(now + 100 * MS);
                }
            }
            _ => {}
        }
    }

    fn indication(&mut self, now: Instant, cmd: Command) {
        let Command::DlDataIndication(ind) = cmd else {
            return;
        };
        match self.role {
            Role::Slave if ind.payload.len() == TRIGGER_LEN => {
                self.stats.triggers += 1;
                let mut answer = vec![0xA5; ANSWER_LEN];
                answer[0] = ind.payload[0];
                self.todo.push_back(data_request(answer));
            }
            Role::Master if ind.payload.len() == ANSWER_LEN && ind.payload[0] == self.seq => {
                self.stats.answers += 1;
                // The next trigger a little later.
                self.next_trigger = Some(now + 50 * MS);
            }
            _ => {}
        }
    }

    /// The program's own work: the next request, one at a time (each
    /// waits for the ACK of the one before, as a blocking driver does).
    fn app(&mut self, now: Instant) {
        if self.stopped {
            self.next_trigger = None;
        }
        if self.role == Role::Master && self.next_trigger.is_some_and(|t| t <= now) {
            self.seq = self.seq.wrapping_add(1);
            let mut trigger = vec![0x5A; TRIGGER_LEN];
            trigger[0] = self.seq;
            self.todo.push_back(data_request(trigger));
            self.next_trigger = Some(now + ANSWER_WAIT);
        }
        if self.engine.pending() == 0 {
            if let Some(cmd) = self.todo.pop_front() {
                self.stats.requests += 1;
                let t = self.engine.submit(now, cmd.to_frame());
                self.tickets.push_back((t, cmd.code()));
            }
        }
    }

    /// Receives with a more lenient T_IC (a host behind a TCP bridge, whose
    /// bytes come in bursts as the processes on both ends are scheduled).
    pub fn set_receive_tic(&mut self, t_ic: Duration) {
        let mut c = self.engine.config();
        c.timeouts.t_ic = t_ic;
        self.engine.set_config(c);
    }

    /// Whether the modem is configured for the demo.
    pub fn configured(&self) -> bool {
        self.configured
    }

    /// Sends no new trigger from now on: what is under way finishes.
    pub fn stop(&mut self) {
        self.stopped = true;
        self.next_trigger = None;
    }

    /// Requests submitted and not yet ACKed or given up.
    pub fn in_flight(&self) -> usize {
        self.tickets.len()
    }

    /// Master: triggers sent so far (submitted).
    pub fn triggers_sent(&self) -> u8 {
        self.seq
    }
}

fn data_request(payload: Vec<u8>) -> Command {
    Command::DlDataRequest(DataRequest {
        params: TxParams {
            modulation: Modulation::BPskCoded,
            frequency_set: FrequencySet::High,
            ..TxParams::default()
        },
        payload,
    })
}
