//! The host-side link engine (the console is the host), sans-IO after
//! quinn-proto: no port, no clock. The driver feeds bytes and time in and
//! takes bytes, T_REQ levels and events out.
//!
//! Rules implemented (UM0932 3.2.5-3.2.9; ST7570 UM 5.2.2-5.2.3, where
//! the chips differ the [`Dialect`] says how):
//! - to send, pull T_REQ low and wait for the status message (ST7580:
//!   T_SR, 3.2.8; ST7570: T_POLL, 5.2.2);
//! - send the frame with STX 02h, release T_REQ once STX is out;
//! - expect ACK within T_ACK of the frame's last byte; on NAK or silence
//!   restart the whole sequence, at most `max_attempts` times;
//! - ACK every modem frame with a right length and checksum, NAK the
//!   others (one cut short by T_IC too); the modem's repeat of a frame just accepted (ST7580: STX 03h;
//!   ST7570: the same frame T_WBC after the ACK, which it took for a NAK)
//!   is acknowledged but not reported again;
//! - drop a frame whose characters are more than T_IC apart.
//!
//! Decisions where the seeds are silent are in docs/protocol-notes.md
//! ("Host link engine", "ST7570: link").

use super::rx::{is_cut_frame, Receiver};
use super::{Answer, Dialect, Element, LocalFrame, Reaction, Source, StatusMessage, Stx, Timeouts};
use crate::time::{earliest, wire_time, Duration, Instant, TxClock, MS};
use alloc::collections::VecDeque;
use alloc::vec::Vec;

pub use crate::drive::Transmit;

crate::drive::engine!(HostEngine, Event, poll_event);

/// Identifies a submitted frame in later events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Ticket(pub u32);

/// Why a submitted frame was not delivered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkError {
    /// No status message came after T_REQ, on every attempt.
    NoStatus,
    /// The modem answered NAK on the last attempt.
    Nak,
    /// No ACK or NAK within T_ACK on the last attempt.
    NoAck,
    /// The frame cannot be emitted (too long for the dialect).
    Unencodable,
    /// Every status said "not now" for [`BUSY_LIMIT`].
    Busy,
}

/// How long a frame waits for a status that is not "not now" before it
/// fails with [`LinkError::Busy`]: longer than the longest power line
/// frame the ST7580 sends or receives (255 bytes of B-FSK at 1200 bps,
/// about 1.8 s), so that only a modem stuck busy makes a frame fail.
pub const BUSY_LIMIT: Duration = 2_000 * MS;

impl core::fmt::Display for LinkError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            LinkError::NoStatus => "the modem did not answer T_REQ with a status message: check the cable, the T_REQ wiring (RTS) and its polarity",
            LinkError::Nak => "the modem refused the frame (NAK) on every attempt: check the baud rate",
            LinkError::NoAck => "the modem did not acknowledge the frame within T_ACK: check the baud rate and the cable",
            LinkError::Unencodable => "the frame is too long for a local frame",
            LinkError::Busy => "the modem said it was transmitting or receiving on the power line on every status message for 2 s",
        })
    }
}

/// What happened, for the layers above and the traffic inspector.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// An element arrived from the modem (every one, for the inspector).
    Received(Element),
    /// An element was sent to the modem.
    Sent(Element),
    /// A modem frame was accepted and acknowledged.
    Frame(LocalFrame),
    /// The modem repeated a frame already accepted (see
    /// [`Dialect::repeat_window`]); it was acknowledged and is not reported
    /// again as [`Event::Frame`].
    Repeat(LocalFrame),
    /// The modem acknowledged a submitted frame.
    Delivered(Ticket),
    /// A submitted frame was given up after every attempt.
    Failed(Ticket, LinkError),
    /// An attempt failed and the whole sequence restarts.
    Retry {
        /// The frame concerned.
        ticket: Ticket,
        /// Attempts made so far.
        attempt: u8,
        /// Why the attempt failed.
        cause: LinkError,
    },
}

/// Settings of the host engine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HostConfig {
    /// Host-interface timeouts (keep in step with MIB 09h).
    pub timeouts: Timeouts,
    /// UART baud rate, to know when written bytes have left.
    pub baud: u32,
    /// Attempts per frame before [`Event::Failed`].
    pub max_attempts: u8,
}

impl Default for HostConfig {
    /// The ST7580's reset timeouts at 57 600 baud, three attempts.
    fn default() -> Self {
        HostConfig {
            timeouts: Timeouts::default(),
            baud: 57_600,
            max_attempts: 3,
        }
    }
}

impl HostConfig {
    /// The settings for a chip of `dialect` just reset, its UART at `baud`
    /// ([`Timeouts::at_reset`]), three attempts.
    pub fn at_reset(dialect: Dialect, baud: u32) -> Self {
        HostConfig {
            timeouts: Timeouts::at_reset(dialect, baud),
            baud,
            ..HostConfig::default()
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Nothing in flight; `not_before` spaces a retry from the last attempt.
    Idle { not_before: Instant },
    /// T_REQ is low, waiting for the status message.
    AwaitStatus { deadline: Instant },
    /// The frame is out, waiting for ACK/NAK.
    AwaitAck { deadline: Instant },
}

/// A modem frame accepted (and ACKed) that the modem may still repeat.
#[derive(Debug, Clone)]
struct Accepted {
    frame: LocalFrame,
    /// When its last byte arrived.
    end: Instant,
    /// When the host's ACK had left the UART.
    answered: Instant,
}

#[derive(Debug, Clone)]
struct Pending {
    ticket: Ticket,
    bytes: Vec<u8>,
    frame: LocalFrame,
    attempts: u8,
    /// The first "not now" status for this frame.
    busy_since: Option<Instant>,
}

/// The host-side link engine.
#[derive(Debug, Clone)]
pub struct HostEngine {
    dialect: Dialect,
    config: HostConfig,
    state: State,
    rx: Receiver,
    /// Frames waiting, oldest first (a few at most).
    queue: Vec<Pending>,
    current: Option<Pending>,
    next_ticket: u32,
    transmits: VecDeque<Transmit>,
    events: VecDeque<Event>,
    /// The last frame accepted that the modem may repeat, to recognise
    /// the repeat (UM0932 3.2.7, ST7570 UM 5.2.2).
    last_accepted: Option<Accepted>,
    last_status: Option<StatusMessage>,
    /// Bits of the status message's first data byte that mean "not now",
    /// and how long T_REQ stays released after one (see
    /// [`HostEngine::set_not_now`]).
    not_now: u8,
    again_after: Duration,
    /// When the UART will have sent every byte written so far: T_ACK runs
    /// from the frame's last byte on the wire (UM0932 3.2.8), which is later
    /// than its own length says when an ACK was written just before it.
    tx_clock: TxClock,
    /// The NAK of a modem frame cut short, held until the frame's
    /// announced length would have ended on the wire (see
    /// [`HostEngine::nak_broken`]).
    nak_at: Option<Instant>,
    /// Garbage that ends before this is the tail of a cut frame already
    /// NAKed: it draws no second NAK.
    tail_until: Instant,
}

impl HostEngine {
    /// A host engine for `dialect`.
    pub fn new(dialect: Dialect, config: HostConfig) -> Self {
        HostEngine {
            dialect,
            config,
            state: State::Idle { not_before: 0 },
            rx: Receiver::new(dialect, Source::Modem),
            queue: Vec::new(),
            current: None,
            next_ticket: 0,
            transmits: VecDeque::new(),
            events: VecDeque::new(),
            last_accepted: None,
            last_status: None,
            not_now: dialect.not_now_bits(),
            again_after: config.timeouts.t_ic,
            tx_clock: TxClock::default(),
            nak_at: None,
            tail_until: 0,
        }
    }

    /// The settings in use.
    pub fn config(&self) -> HostConfig {
        self.config
    }

    /// Changes the timeouts (after a MIB 09h write was confirmed) or baud.
    pub fn set_config(&mut self, config: HostConfig) {
        self.config = config;
    }

    /// Takes a status message whose first data byte has one of the `mask`
    /// bits set as "not now" (UM0932 3.2.8: the status "confirms or not"
    /// the data channel availability): T_REQ is released before any byte
    /// of the frame, which ends the modem's wait, and pulled low again
    /// `again_after` later, a new falling edge the modem answers like the
    /// first. A frame the modem sends meanwhile is taken as any other. Not
    /// an attempt: the frame was not sent; after [`BUSY_LIMIT`] of "not
    /// now" it fails with [`LinkError::Busy`]. Default:
    /// [`Dialect::not_now_bits`] and T_IC, see docs/protocol-notes.md
    /// "Status message availability".
    pub fn set_not_now(&mut self, mask: u8, again_after: Duration) {
        self.not_now = mask;
        self.again_after = again_after;
    }

    /// The last status message received.
    pub fn last_status(&self) -> Option<StatusMessage> {
        self.last_status
    }

    /// Frames queued or in flight.
    pub fn pending(&self) -> usize {
        self.queue.len() + self.current.is_some() as usize
    }

    /// Queues a frame for the modem; its fate comes as
    /// [`Event::Delivered`] or [`Event::Failed`] with the returned ticket.
    pub fn submit(&mut self, now: Instant, frame: LocalFrame) -> Ticket {
        let ticket = Ticket(self.next_ticket);
        self.next_ticket = self.next_ticket.wrapping_add(1);
        match frame.emit(self.dialect) {
            Ok(bytes) => self.queue.push(Pending {
                ticket,
                bytes,
                frame,
                attempts: 0,
                busy_since: None,
            }),
            Err(_) => self
                .events
                .push_back(Event::Failed(ticket, LinkError::Unencodable)),
        }
        self.advance(now);
        ticket
    }

    /// Drops a frame none of whose bytes has left: queued, or waiting for
    /// the modem's leave (a "not now" status, UM0932 3.2.5). False once
    /// it has begun: its fate then comes as an event. A frame withdrawn
    /// gets none.
    pub fn withdraw(&mut self, now: Instant, ticket: Ticket) -> bool {
        if let Some(i) = self.queue.iter().position(|p| p.ticket == ticket) {
            self.queue.remove(i);
            return true;
        }
        let Some(p) = self.current.as_ref().filter(|p| p.ticket == ticket) else {
            return false;
        };
        match self.state {
            State::Idle { .. } if p.attempts == 0 => {}
            State::AwaitStatus { .. } if p.attempts == 1 => {
                self.transmits.push_back(Transmit::TReq { asserted: false });
                self.state = State::Idle {
                    not_before: now + self.again_after,
                };
            }
            _ => return false,
        }
        self.current = None;
        self.advance(now);
        true
    }

    /// Drops every queued frame and any exchange in flight (the port was
    /// lost or closed); each gets [`Event::Failed`] with `cause`.
    pub fn abort(&mut self, cause: LinkError) {
        for p in self.current.take().into_iter().chain(self.queue.drain(..)) {
            self.events.push_back(Event::Failed(p.ticket, cause));
        }
        if !matches!(self.state, State::Idle { .. }) {
            self.transmits.push_back(Transmit::TReq { asserted: false });
        }
        self.state = State::Idle { not_before: 0 };
    }

    /// Bytes received from the modem at `now`.
    pub fn handle_rx(&mut self, now: Instant, bytes: &[u8]) {
        self.send_held_nak(now);
        let mut out = Vec::new();
        for &b in bytes {
            self.rx.push(now, b, self.config.timeouts.t_ic, &mut out);
            // Any modem activity while waiting for the status message means
            // the modem is busy with its own frame: keep waiting.
            let wait = self.dialect.status_wait(&self.config.timeouts);
            if let State::AwaitStatus { deadline } = &mut self.state {
                *deadline = (*deadline).max(now + wait);
            }
            // Each element as its last byte completes it: a repeat is told
            // from a new frame by when its first byte came.
            if !out.is_empty() {
                for e in out.drain(..) {
                    self.on_element(now, e);
                }
            }
        }
        self.advance(now);
    }

    /// A deadline from [`HostEngine::poll_timeout`] has passed.
    pub fn handle_timeout(&mut self, now: Instant) {
        self.send_held_nak(now);
        let mut out = Vec::new();
        self.rx.timeout(now, self.config.timeouts.t_ic, &mut out);
        for e in out {
            self.on_element(now, e);
        }
        self.send_held_nak(now);
        match self.state {
            State::AwaitStatus { deadline } if now >= deadline => {
                self.transmits.push_back(Transmit::TReq { asserted: false });
                self.attempt_failed(now, LinkError::NoStatus);
            }
            State::AwaitAck { deadline } if now >= deadline => {
                self.attempt_failed(now, LinkError::NoAck)
            }
            _ => {}
        }
        self.advance(now);
    }

    /// The next thing to write or signal.
    pub fn poll_transmit(&mut self) -> Option<Transmit> {
        self.transmits.pop_front()
    }

    /// The next event.
    pub fn poll_event(&mut self) -> Option<Event> {
        self.events.pop_front()
    }

    /// When [`HostEngine::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        let state = match self.state {
            State::Idle { not_before } if self.current.is_some() || !self.queue.is_empty() => {
                Some(not_before)
            }
            State::Idle { .. } => None,
            State::AwaitStatus { deadline } | State::AwaitAck { deadline } => Some(deadline),
        };
        let rx = self.rx.deadline(self.config.timeouts.t_ic);
        earliest(earliest(state, rx), self.nak_at)
    }

    /// Accounts for `n` bytes written at `now`; returns when the last one
    /// will have left the UART.
    fn written(&mut self, now: Instant, n: usize) -> Instant {
        self.tx_clock.written(now, n, self.config.baud)
    }

    /// Sends `e`; returns when its last byte will have left.
    fn send(&mut self, now: Instant, e: Element) -> Instant {
        let bytes = e.to_bytes(self.dialect);
        let end = self.written(now, bytes.len());
        self.transmits.push_back(Transmit::Bytes(bytes));
        self.events.push_back(Event::Sent(e));
        end
    }

    fn on_element(&mut self, now: Instant, e: Element) {
        self.events.push_back(Event::Received(e.clone()));
        match e {
            Element::Frame {
                frame, checksum_ok, ..
            } => {
                if !checksum_ok {
                    self.last_accepted = None;
                    self.send(now, Element::Nak);
                    return;
                }
                // The modem has finished what was cut: nothing to hold.
                self.nak_at = None;
                // The ACK is sent at once, well within T_ACK.
                let answered = self.send(now, Element::Ack);
                let started = self.rx.started_at();
                let repeat = frame.stx == self.dialect.repeat_stx()
                    && self.last_accepted.as_ref().is_some_and(|a| {
                        let (from, to) = self.dialect.repeat_window(
                            &self.config.timeouts,
                            a.end,
                            a.answered,
                            self.config.baud,
                        );
                        a.frame.code == frame.code
                            && a.frame.data == frame.data
                            && (from..=to).contains(&started)
                    });
                if repeat {
                    // A repeat is sent once only: the next copy is new.
                    self.last_accepted = None;
                    self.events.push_back(Event::Repeat(frame));
                } else {
                    // UM0932 3.2.7: a frame with STX 03h is itself a repeat.
                    self.last_accepted = (frame.stx == Stx::First).then(|| Accepted {
                        frame: frame.clone(),
                        end: now,
                        answered,
                    });
                    self.events.push_back(Event::Frame(frame));
                }
            }
            Element::Status(s) => {
                self.nak_at = None;
                self.last_status = Some(s);
                if let State::AwaitStatus { .. } = self.state {
                    let not_now = s.data().first().is_some_and(|b| b & self.not_now != 0);
                    match &mut self.current {
                        Some(p) if not_now => {
                            self.transmits.push_back(Transmit::TReq { asserted: false });
                            let since = *p.busy_since.get_or_insert(now);
                            if now - since >= BUSY_LIMIT {
                                p.attempts = self.config.max_attempts;
                                self.attempt_failed(now, LinkError::Busy);
                                return;
                            }
                            // Not an attempt: `advance` counts it again.
                            p.attempts -= 1;
                            self.state = State::Idle {
                                not_before: now + self.again_after,
                            };
                        }
                        _ => self.send_current(now),
                    }
                }
            }
            Element::Ack => {
                if let State::AwaitAck { .. } = self.state {
                    // A modem that waits to repeat a frame takes no host
                    // frame (device engine, AwaitRepeat): having ACKed
                    // this one, it repeats nothing, and a frame equal to
                    // the one accepted before is new (the answer to the
                    // same request asked again).
                    self.last_accepted = None;
                    if let Some(p) = self.current.take() {
                        self.events.push_back(Event::Delivered(p.ticket));
                    }
                    self.state = State::Idle { not_before: now };
                }
            }
            Element::Nak => {
                if let State::AwaitAck { .. } = self.state {
                    self.attempt_failed(now, LinkError::Nak);
                }
            }
            e => {
                self.last_accepted = None;
                self.nak_broken(now, &e);
            }
        }
    }

    /// A broken frame from the modem (garbage): the modem will repeat it
    /// if a NAK reaches it after the frame's last byte left (ST7570 UM
    /// 5.2.2; the ST7580 repeats it after T_ACK anyway, UM0932 3.2.7). A
    /// frame cut short by T_IC (3.2.6, 5.2.2) is NAKed ("In other cases,
    /// it answers with a NAK"), but no earlier than its announced length
    /// would have ended on the wire: the cut may be a stall of the line
    /// (a USB adapter holding bytes back) while the modem is still
    /// sending, and the ST7570 ignores an answer that comes during its
    /// frame. Where a missed answer counts as ACK (ST7570), bytes that are
    /// no element (a frame whose STX or length byte was lost or damaged,
    /// the stalled tail of a frame cut before its length came) are NAKed
    /// too, as T_IC ends them, unless they are the tail of a cut frame
    /// already NAKed. docs/protocol-notes.md "ST7570: link".
    fn nak_broken(&mut self, now: Instant, e: &Element) {
        let Element::Garbage { bytes, .. } = e else {
            return;
        };
        let baud = self.config.baud;
        if is_cut_frame(self.dialect, e) {
            let announced = bytes
                .get(1)
                .and_then(|&len| self.dialect.data_len(len))
                .map(|n| self.rx.started_at() + wire_time(Dialect::frame_len(n) - 1, baud));
            match announced {
                Some(end) => {
                    self.nak_at = Some(end.max(now));
                    self.tail_until = end + self.config.timeouts.t_ack;
                }
                None => {
                    self.send(now, Element::Nak);
                }
            }
            return;
        }
        let silence_is_ack = matches!(
            self.dialect
                .modem_reaction(Answer::Silence, &self.config.timeouts),
            Reaction::Delivered
        );
        if silence_is_ack && now >= self.tail_until && self.nak_at.is_none() {
            self.send(now, Element::Nak);
        }
    }

    /// Sends the NAK held by [`HostEngine::nak_broken`] once it is due.
    fn send_held_nak(&mut self, now: Instant) {
        if self.nak_at.is_some_and(|t| t <= now) {
            self.nak_at = None;
            self.send(now, Element::Nak);
        }
    }

    /// Status received: send STX, release T_REQ, send the rest (3.2.8).
    fn send_current(&mut self, now: Instant) {
        let Some(p) = &self.current else { return };
        let bytes = p.bytes.clone();
        let frame = p.frame.clone();
        self.transmits
            .push_back(Transmit::Bytes(bytes[..1].to_vec()));
        self.transmits.push_back(Transmit::TReq { asserted: false });
        self.transmits
            .push_back(Transmit::Bytes(bytes[1..].to_vec()));
        self.events
            .push_back(Event::Sent(Element::emitted(frame, &bytes)));
        let end = self.written(now, bytes.len());
        self.state = State::AwaitAck {
            deadline: end + self.config.timeouts.t_ack,
        };
    }

    fn attempt_failed(&mut self, now: Instant, cause: LinkError) {
        // A restart is a new T_REQ falling edge: leave T_REQ high for T_IC
        // so that the modem sees the edge.
        self.state = State::Idle {
            not_before: now + self.config.timeouts.t_ic,
        };
        let Some(p) = self.current.take() else { return };
        if p.attempts >= self.config.max_attempts {
            self.events.push_back(Event::Failed(p.ticket, cause));
        } else {
            self.events.push_back(Event::Retry {
                ticket: p.ticket,
                attempt: p.attempts,
                cause,
            });
            self.current = Some(p);
        }
    }

    fn advance(&mut self, now: Instant) {
        let State::Idle { not_before } = self.state else {
            return;
        };
        if now < not_before {
            return;
        }
        if self.current.is_none() {
            self.current = (!self.queue.is_empty()).then(|| self.queue.remove(0));
        }
        let Some(p) = &mut self.current else { return };
        p.attempts += 1;
        self.transmits.push_back(Transmit::TReq { asserted: true });
        self.state = State::AwaitStatus {
            deadline: now + self.dialect.status_wait(&self.config.timeouts),
        };
    }
}
