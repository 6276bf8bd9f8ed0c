//! The device-side link engine: the modem's half of the host interface,
//! used by the simulated modems. Sans-IO like [`super::host`].
//!
//! Rules implemented (UM0932 3.2.5-3.2.9; ST7570 UM 5.2.2-5.2.3, where
//! the chips differ the [`Dialect`] says how):
//! - on T_REQ low, answer with the status message as soon as not busy;
//!   accept the host's frame only if its STX comes within T_SR of a status
//!   that is not "not now" ([`Dialect::not_now_bits`]); T_REQ
//!   released before that STX ends the wait at once, and a new falling
//!   edge is answered like the first;
//! - send a frame that became ready while the host's frame was awaited as
//!   soon as that wait ends, before the status of a later T_REQ;
//! - ACK a frame with right length and checksum, NAK any other, including
//!   one cut short by T_IC (ST7570: CMD_SyntaxError instead, by its model);
//! - send frames with STX 02h unprompted (the modem is master);
//! - repeat a frame once as [`Dialect::modem_reaction`] says (ST7580: on
//!   NAK, any other frame or no ACK within T_ACK, with STX 03h T_ACK after
//!   the frame; ST7570: only on NAK, with STX 02h T_WBC after the NAK, a
//!   missed or garbled ACK counting as ACK), and count the repeat as
//!   delivered whatever the answer;
//! - drop a frame whose characters are more than T_IC apart (ST7570: T_IC
//!   as MIB 000Bh selects it, [`DeviceEngine::set_tic`]).

use super::dialect::{Answer, Reaction};
use super::host::Transmit;
use super::rx::{is_cut_frame, Receiver};
use super::{Dialect, Element, LocalFrame, Source, StatusMessage, Stx, TicSelector, Timeouts};
use crate::time::{earliest, Instant, TxClock};
use alloc::collections::VecDeque;
use alloc::vec::Vec;

/// What happened, for the device model and the simulator's trace.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DeviceEvent {
    /// An element arrived from the host.
    Received(Element),
    /// An element was sent to the host.
    Sent(Element),
    /// A host frame was accepted and acknowledged: a request to execute.
    Request(LocalFrame),
    /// A host frame the modem took was cut short by T_IC (UM0932 3.2.6):
    /// the ST7580 engine has answered NAK; the ST7570 model answers with
    /// CMD_SyntaxError ([`Dialect::modem_naks_cut_frame`]).
    FrameCut,
    /// A frame the device sent was acknowledged, or counted as such by the
    /// dialect's rule (`repeated`: only after its repeat, which counts as
    /// acknowledged by rule).
    Delivered {
        /// The frame.
        frame: LocalFrame,
        /// Whether it took the repeat.
        repeated: bool,
    },
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum State {
    Idle,
    /// Status message sent: the host's STX must come before `deadline`.
    AwaitHostFrame {
        deadline: Instant,
    },
    /// A frame is out (STX 02h), its last byte leaving the UART at `end`:
    /// waiting for the host's answer until `deadline` (T_ACK).
    AwaitAck {
        frame: LocalFrame,
        end: Instant,
        deadline: Instant,
    },
    /// The frame will be repeated at `at` (ST7570: T_WBC after the NAK).
    AwaitRepeat {
        frame: LocalFrame,
        at: Instant,
    },
}

/// The device-side link engine.
#[derive(Debug, Clone)]
pub struct DeviceEngine {
    dialect: Dialect,
    timeouts: Timeouts,
    /// ST7570: T_IC as MIB 000Bh selects it, kept to follow a baud change;
    /// `None` when T_IC was given as a duration.
    tic: Option<TicSelector>,
    baud: u32,
    state: State,
    rx: Receiver,
    queue: VecDeque<LocalFrame>,
    status: StatusMessage,
    treq: bool,
    /// The current T_REQ assertion has been answered with a status message.
    treq_served: bool,
    /// The host's frame started within T_SR of the status message: the
    /// frame being received is one the modem takes.
    host_frame_open: bool,
    /// Frames at the head of the queue that became ready while the host's
    /// frame was awaited: they go out as soon as that wait ends, before
    /// the status message of a later T_REQ (UM0932 3.2.5: the modem is
    /// master; a confirm held back further is paired by the host with the
    /// wrong request).
    ready_first: usize,
    transmits: VecDeque<Transmit>,
    events: VecDeque<DeviceEvent>,
    /// When the UART will have sent every byte written so far. Timeouts
    /// run from the end of what they time (UM0932 3.2.7, 3.2.8), and a
    /// frame written right behind an ACK or a repeat ends later than its
    /// own length says.
    tx_clock: TxClock,
}

impl DeviceEngine {
    /// A device engine for `dialect` at `baud`, with the reset timeouts
    /// ([`Timeouts::at_reset`]).
    pub fn new(dialect: Dialect, baud: u32) -> Self {
        DeviceEngine {
            dialect,
            timeouts: Timeouts::at_reset(dialect, baud),
            tic: Self::reset_tic(dialect),
            baud,
            state: State::Idle,
            rx: Receiver::new(dialect, Source::Host),
            queue: VecDeque::new(),
            status: StatusMessage::new(dialect, &[0, 0, 0]),
            treq: false,
            treq_served: false,
            host_frame_open: false,
            ready_first: 0,
            transmits: VecDeque::new(),
            events: VecDeque::new(),
            tx_clock: TxClock::default(),
        }
    }

    /// The timeouts in use.
    pub fn timeouts(&self) -> Timeouts {
        self.timeouts
    }

    /// Applies new timeouts (ST7580: a MIB 09h write), T_IC as given.
    pub fn set_timeouts(&mut self, timeouts: Timeouts) {
        self.timeouts = timeouts;
        self.tic = None;
    }

    /// ST7570: applies the T_IC selector of a MIB 000Bh write.
    pub fn set_tic(&mut self, tic: TicSelector) {
        self.tic = Some(tic);
        self.timeouts = self.timeouts.with_tic(tic, self.baud);
    }

    fn reset_tic(dialect: Dialect) -> Option<TicSelector> {
        (dialect == Dialect::St7570).then_some(TicSelector::FACTORY_DEFAULT)
    }

    /// Changes the UART baud rate (the BR0/BR1 pins, read at reset); a T_IC
    /// of 5 characters follows it.
    pub fn set_baud(&mut self, baud: u32) {
        self.baud = baud;
        if let Some(tic) = self.tic {
            self.timeouts = self.timeouts.with_tic(tic, baud);
        }
    }

    /// The bits the next status messages carry.
    pub fn set_status(&mut self, status: StatusMessage) {
        self.status = status;
    }

    /// Whether the engine is idle with nothing queued.
    pub fn is_idle(&self) -> bool {
        self.state == State::Idle && self.queue.is_empty() && !self.rx.busy()
    }

    /// Forgets everything in flight (a modem reset).
    pub fn reset(&mut self) {
        self.state = State::Idle;
        self.queue.clear();
        self.rx = Receiver::new(self.dialect, Source::Host);
        self.timeouts = Timeouts::at_reset(self.dialect, self.baud);
        self.tic = Self::reset_tic(self.dialect);
        self.treq_served = self.treq;
        self.host_frame_open = false;
        self.ready_first = 0;
    }

    /// Queues a frame for the host (confirms, errors, indications). A frame
    /// that cannot be emitted (data longer than the dialect allows) is
    /// dropped: no modem can send it.
    pub fn submit(&mut self, now: Instant, frame: LocalFrame) {
        if frame.emit(self.dialect).is_err() {
            return;
        }
        self.queue.push_back(frame);
        if matches!(self.state, State::AwaitHostFrame { .. }) || self.host_frame_open {
            self.ready_first = self.queue.len();
        }
        self.advance(now);
    }

    /// The host changed T_REQ (`asserted`: pulled low).
    pub fn set_treq(&mut self, now: Instant, asserted: bool) {
        if asserted && !self.treq {
            self.treq_served = false;
            // A new falling edge while the last status message's T_SR runs:
            // the host missed that status and asks again; answer it (the
            // ST7570 within T_POLL, UM 5.2.2).
            if let State::AwaitHostFrame { .. } = self.state {
                self.state = State::Idle;
            }
        }
        if !asserted && self.treq {
            // UM0932 3.2.8: the host keeps T_REQ low until its frame's STX
            // is out. Released before the first byte, the host has given
            // up this frame ("not now" from the status, 3.2.8): the wait
            // ends, and the modem, master again (3.2.5), sends what became
            // ready meanwhile before it answers a later falling edge.
            if let State::AwaitHostFrame { .. } = self.state {
                if !self.rx.busy() {
                    self.state = State::Idle;
                }
            }
        }
        self.treq = asserted;
        self.advance(now);
    }

    /// Bytes received from the host at `now`.
    pub fn handle_rx(&mut self, now: Instant, bytes: &[u8]) {
        let mut out = Vec::new();
        for &b in bytes {
            self.rx.push(now, b, self.timeouts.t_ic, &mut out);
            // Elements this byte completed first: garbage flushed by the
            // host's STX must not close the frame that STX opens.
            for e in out.drain(..) {
                self.on_element(now, e);
            }
            // UM0932 3.2.8: the first byte of the frame must arrive
            // within T_SR of the status message.
            if let State::AwaitHostFrame { deadline } = self.state {
                if self.rx.busy() && now <= deadline {
                    self.state = State::Idle;
                    self.host_frame_open = true;
                }
            }
        }
        self.advance(now);
    }

    /// A deadline from [`DeviceEngine::poll_timeout`] has passed.
    pub fn handle_timeout(&mut self, now: Instant) {
        let mut out = Vec::new();
        self.rx.timeout(now, self.timeouts.t_ic, &mut out);
        for e in out {
            self.on_element(now, e);
        }
        match &self.state {
            State::AwaitHostFrame { deadline } if now > *deadline => self.state = State::Idle,
            State::AwaitAck { deadline, .. } if now >= *deadline => {
                self.on_answer(now, Answer::Silence)
            }
            State::AwaitRepeat { frame, at } if now >= *at => {
                let frame = frame.clone();
                self.repeat(now, frame);
            }
            _ => {}
        }
        self.advance(now);
    }

    /// The next thing to write.
    pub fn poll_transmit(&mut self) -> Option<Transmit> {
        self.transmits.pop_front()
    }

    /// The next event.
    pub fn poll_event(&mut self) -> Option<DeviceEvent> {
        self.events.pop_front()
    }

    /// When [`DeviceEngine::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        let state = match &self.state {
            State::Idle => None,
            State::AwaitHostFrame { deadline } => Some(*deadline + 1),
            State::AwaitAck { deadline, .. } => Some(*deadline),
            State::AwaitRepeat { at, .. } => Some(*at),
        };
        let rx = self.rx.deadline(self.timeouts.t_ic);
        earliest(state, rx)
    }

    /// Accounts for `n` bytes written at `now`; returns when the last one
    /// will have left the UART.
    fn written(&mut self, now: Instant, n: usize) -> Instant {
        self.tx_clock.written(now, n, self.baud)
    }

    /// Sends `e`; returns when its last byte will have left.
    fn send(&mut self, now: Instant, e: Element) -> Instant {
        let bytes = e.to_bytes(self.dialect);
        let end = self.written(now, bytes.len());
        self.transmits.push_back(Transmit::Bytes(bytes));
        self.events.push_back(DeviceEvent::Sent(e));
        end
    }

    /// Sends `frame`; returns when its last byte will have left.
    fn send_frame(&mut self, now: Instant, frame: &LocalFrame) -> Instant {
        let bytes = frame.emit(self.dialect).unwrap_or_default();
        let n = bytes.len();
        let end = self.written(now, n);
        self.events
            .push_back(DeviceEvent::Sent(Element::emitted(frame.clone(), &bytes)));
        self.transmits.push_back(Transmit::Bytes(bytes));
        end
    }

    /// Repeats `frame` once with the dialect's STX (UM0932 3.2.7: 03h;
    /// ST7570 UM 5.2.2: 02h); the repeat counts as delivered.
    fn repeat(&mut self, now: Instant, frame: LocalFrame) {
        let again = LocalFrame {
            stx: self.dialect.repeat_stx(),
            ..frame
        };
        self.send_frame(now, &again);
        self.state = State::Idle;
        self.events.push_back(DeviceEvent::Delivered {
            frame: LocalFrame {
                stx: Stx::First,
                ..again
            },
            repeated: true,
        });
    }

    /// The host answered the frame in flight (or did not, `Silence`).
    fn on_answer(&mut self, now: Instant, answer: Answer) {
        let State::AwaitAck { frame, .. } = &self.state else {
            return;
        };
        let frame = frame.clone();
        match self.dialect.modem_reaction(answer, &self.timeouts) {
            Reaction::Delivered => {
                self.state = State::Idle;
                self.events.push_back(DeviceEvent::Delivered {
                    frame,
                    repeated: false,
                });
            }
            Reaction::Wait => {}
            Reaction::Repeat { after: 0 } => self.repeat(now, frame),
            Reaction::Repeat { after } => {
                self.state = State::AwaitRepeat {
                    frame,
                    at: now + after,
                }
            }
        }
    }

    fn on_element(&mut self, now: Instant, e: Element) {
        self.events.push_back(DeviceEvent::Received(e.clone()));
        match (&self.state, e) {
            // Only what comes after the frame's last byte can be the host's
            // answer to it (UM0932 3.2.3, 3.2.7): an earlier ACK or NAK
            // answers what was sent before, typically the repeat of the
            // previous frame, written right before this one.
            (State::AwaitAck { end, .. }, e) if now > *end => {
                let answer = match e {
                    Element::Ack => Answer::Ack,
                    Element::Nak => Answer::Nak,
                    _ => Answer::Other,
                };
                self.on_answer(now, answer);
            }
            // Nothing the host sends changes a repeat already decided.
            (State::AwaitAck { .. } | State::AwaitRepeat { .. }, _) => {}
            // A frame nobody asked for with T_REQ is ignored (3.2.8).
            (_, Element::Frame { .. }) if !self.host_frame_open => {}
            (
                _,
                Element::Frame {
                    frame, checksum_ok, ..
                },
            ) => {
                self.host_frame_open = false;
                if checksum_ok {
                    self.send(now, Element::Ack);
                    self.events.push_back(DeviceEvent::Request(frame));
                } else {
                    self.send(now, Element::Nak);
                }
            }
            // A frame the modem took, cut short by T_IC: NAK (3.2.8), or
            // the ST7570's CMD_SyntaxError, which its model sends.
            (_, e) if self.host_frame_open && is_cut_frame(self.dialect, &e) => {
                self.host_frame_open = false;
                if self.dialect.modem_naks_cut_frame() {
                    self.send(now, Element::Nak);
                }
                self.events.push_back(DeviceEvent::FrameCut);
            }
            (_, Element::Garbage { .. }) => self.host_frame_open = false,
            _ => {}
        }
    }

    fn advance(&mut self, now: Instant) {
        if self.state != State::Idle || self.rx.busy() {
            return;
        }
        if self.ready_first > 0 {
            self.ready_first -= 1;
            if let Some(frame) = self.queue.pop_front() {
                self.send_queued(now, frame);
                return;
            }
            self.ready_first = 0;
        }
        if self.treq && !self.treq_served {
            self.treq_served = true;
            let status = Element::Status(self.status);
            let end = self.send(now, status);
            // UM0932 3.2.8: only a status confirming the data channel's
            // availability opens the T_SR wait; after a "not now" a host
            // frame is ignored like one outside T_SR, and the modem stays
            // master of the port.
            if !self.dialect.not_now(&self.status) {
                self.state = State::AwaitHostFrame {
                    deadline: end + self.timeouts.t_sr,
                };
                return;
            }
        }
        if let Some(frame) = self.queue.pop_front() {
            self.send_queued(now, frame);
        }
    }

    /// Sends a frame of the queue and waits for its answer.
    fn send_queued(&mut self, now: Instant, frame: LocalFrame) {
        let end = self.send_frame(now, &frame);
        self.state = State::AwaitAck {
            frame,
            end,
            deadline: end + self.timeouts.t_ack,
        };
    }
}
