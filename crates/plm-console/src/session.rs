//! The session: plm-core's host link engine driven over a transport with
//! the page's timers, requests matched with their answers, and everything
//! that happened handed to the console's stores as [`Note`]s.
//!
//! The session has no browser in it (time comes in as an argument, after
//! quinn-proto), so its tests run natively against the simulated modem.
//!
//! - Each tick lets the transport's time run up to the page's clock in
//!   slices of at most [`SLICE`], feeding the engine every received byte
//!   with its arrival time and calling `handle_timeout` at its deadlines.
//! - The session knows the chip only through plm-core's description of
//!   its host interface ([`plm_core::chip::Chip`]): request frames, which
//!   answer closes which request, what an answer says, the decoder.
//! - Requests go to the modem one at a time: neither chip's host interface
//!   has sequence numbers, so an answer is matched by [`Chip::answers`] to
//!   the one request outstanding. After a request that had to be repeated
//!   for want of an ACK the modem may have executed it twice (protocol notes, "Known
//!   limits"); a second answer of the same kind within [`DUPLICATE_GRACE`]
//!   is reported as such and never taken for the next request's.
//! - Every modem frame the engine ACKs adds a sample to the ACK latency
//!   ([`AckLatency`]): from the arrival of the frame's last byte to the
//!   ACK written, against T_ACK (UM0932 3.2.8).

use crate::driver::ack::AckLatency;
use crate::driver::{self, earliest, AnyEngine, Budget, Driver, HostLink, Layer};
use crate::transport::{LinkState, Transport};
use plm_core::app::Happening;
use plm_core::chip::{self, Chip};
use plm_core::decode::Decoded;
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Ticket};
use plm_core::link::{Dialect, Element, LocalFrame, Source, StatusMessage, Timeouts};
use plm_core::time::{Duration, Instant, MS};
use std::collections::VecDeque;

/// How often the notes of what happened are handed out, µs of the page's
/// clock: about one screen refresh.
pub const SHOW_EVERY: f64 = 16_000.0;
/// How often while the line is busy: five times a second. Each hand-out
/// redraws the views, one block of the page's main thread that a frame
/// ending meanwhile waits behind for its ACK (issue 13: at 60 redraws a
/// second, ACK latency p99 1.5-2.7 ms with the Diagnostics view on screen,
/// 9-10 ms with the Traffic view). Nobody reads 300 exchanges a second as
/// they come; the replies of requests still come at once.
pub const BUSY_SHOW_EVERY: f64 = 200_000.0;
/// Elements on the wire in one exchange (status message, request, ACK,
/// confirm, ACK): more waiting than this is a busy line.
pub const EXCHANGE_ELEMENTS: usize = 5;
/// How long after its answer a request repeated for want of an ACK may
/// still see a second answer.
pub const DUPLICATE_GRACE: Duration = 200 * MS;
/// What became of a request: in the session the answer's frame (`None`
/// for a request the modem acknowledges and does not answer, [`Chip::
/// expects_answer`]); views of one chip read it as that chip's command
/// ([`Outcome::read`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome<A = Option<LocalFrame>> {
    /// The modem's answer (confirm, error or CMD_SyntaxError) and the time
    /// from handing the request to the link to the answer's last byte (or
    /// to its acknowledgement, when no answer comes).
    Answer {
        /// The answer.
        command: A,
        /// Round-trip time, µs.
        rtt: Duration,
    },
    /// The request was not answered; why, in words, with what to do.
    Failed(String),
}

impl Outcome {
    /// The answer as `read` makes it; a request left unanswered, or an
    /// answer `read` refuses, fails with the reason.
    pub fn read<A>(self, read: impl FnOnce(&LocalFrame) -> Result<A, String>) -> Outcome<A> {
        match self {
            Outcome::Answer {
                command: Some(frame),
                rtt,
            } => match read(&frame) {
                Ok(command) => Outcome::Answer { command, rtt },
                Err(why) => Outcome::Failed(why),
            },
            Outcome::Answer { command: None, .. } => {
                Outcome::Failed("the modem acknowledged the request and sent no answer".into())
            }
            Outcome::Failed(why) => Outcome::Failed(why),
        }
    }
}

/// Called once with the outcome of a request.
pub type Reply = Box<dyn FnOnce(Outcome)>;

/// Something that happened, for the stores.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// An element on the wire, either way, decoded by plm-core.
    Traffic {
        /// When, µs on the transport's clock.
        at: Instant,
        /// The element, named as `plm decode` names it.
        decoded: Box<Decoded>,
    },
    /// A status message arrived.
    Status {
        /// When.
        at: Instant,
        /// The bytes after `?` (UM0932 Table 8, ST7570 UM Table 11).
        message: StatusMessage,
    },
    /// T_REQ changed; `true` is asserted (low).
    TReq(bool),
    /// A frame from the modem that answers no request (indications,
    /// duplicates).
    Unsolicited {
        /// When.
        at: Instant,
        /// The frame.
        frame: LocalFrame,
        /// Whether it says the modem reset ([`Chip::is_reset`]).
        reset: bool,
        /// Whether it is a second answer to a request already answered.
        duplicate: bool,
    },
    /// An attempt to deliver a request failed and is being repeated.
    Retry {
        /// When.
        at: Instant,
        /// Attempts so far.
        attempt: u8,
        /// Why, in words.
        cause: String,
    },
    /// The host engine's timeouts changed (MIB 09h written, or reset).
    Timeouts(Timeouts),
    /// This many requests in a row had a T_REQ assertion answered by no
    /// status message (UM0932 3.2.8): the T_REQ line does not reach the
    /// modem, or reaches it late.
    TReqUnanswered(u8),
}

/// What a tick produced: notes for the stores and replies to call, both to
/// be handled once the session is no longer borrowed.
#[derive(Default)]
pub struct Tick {
    /// In order of occurrence.
    pub notes: Vec<Note>,
    /// Replies with their outcomes.
    pub replies: Vec<(Reply, Outcome)>,
}

struct Queued {
    frame: LocalFrame,
    reply: Reply,
}

struct Active {
    ticket: Ticket,
    /// The request.
    request: LocalFrame,
    reply: Reply,
    submitted: Instant,
    /// Set once the modem acknowledged the request.
    deadline: Option<Instant>,
    /// Whether an attempt went unacknowledged (the modem may have run it).
    repeated: bool,
    /// Whether an attempt's T_REQ got no status message.
    unanswered: bool,
}

/// The host side of one connection.
pub struct Session {
    /// The transport, the page's clock on it, the ACK latency.
    drive: Driver,
    host: HostLink,
    /// The chip's host interface, with its decoding context.
    chip: Box<dyn Chip>,
    queue: VecDeque<Queued>,
    active: Option<Active>,
    /// A request code whose second answer is expected until the instant.
    duplicate_of: Option<(u8, Instant)>,
    /// Added to the transport's clock in every [`Note`]: the times of one
    /// connection carry on from where the last one stopped, so the log
    /// never runs backwards when the transport changes (the simulator's
    /// clock starts at 0, WebSerial's is the page's).
    log_offset: i64,
    /// Requests in a row whose T_REQ went unanswered at least once.
    unanswered: u8,
    /// When notes were last handed out, or painted when the line waited
    /// for that, µs of the page's clock.
    shown: f64,
    /// Elements on the wire among the notes not handed out yet.
    held: usize,
    /// Notes were handed out: the next request waits until the page has
    /// painted them ([`Session::holds_line`]).
    hold: crate::wake::Draw,
    /// The modem's timeouts (MIB 09h, 000Bh, the chip's at reset); the
    /// host engine waits them plus the transport's latency.
    timeouts: Timeouts,
    out: Tick,
}

impl Session {
    /// A session with a chip of `dialect` over `transport` (or none yet).
    pub fn new(transport: Option<Box<dyn Transport>>, dialect: Dialect) -> Self {
        let baud = transport.as_ref().map_or(57_600, |t| t.baud());
        let mut s = Session {
            drive: Driver::new(transport),
            host: HostLink(HostEngine::new(
                dialect,
                HostConfig::at_reset(dialect, baud),
            )),
            chip: chip::for_dialect(dialect),
            queue: VecDeque::new(),
            active: None,
            duplicate_of: None,
            log_offset: 0,
            unanswered: 0,
            shown: 0.0,
            held: 0,
            hold: Default::default(),
            timeouts: Timeouts::at_reset(dialect, baud),
            out: Tick::default(),
        };
        s.configure();
        s
    }

    /// Gives the host engine the modem's timeouts, each of its waits for
    /// the modem (T_POLL, T_ACK, and T_IC between received bytes)
    /// lengthened by the transport's latency ([`Transport::latency`]: a
    /// USB adapter holds received bytes and queues the host's), and tells
    /// the transport the modem's T_IC.
    fn configure(&mut self) {
        let t = self.timeouts;
        let slack = self.drive.transport.as_ref().map_or(0, |t| t.latency());
        let config = HostConfig {
            timeouts: Timeouts {
                t_poll: t.t_poll + slack,
                t_ack: t.t_ack + slack,
                t_ic: t.t_ic + slack,
                ..t
            },
            ..self.host.config()
        };
        self.host.set_config(config);
        if let Some(tr) = self.drive.transport.as_mut() {
            tr.set_byte_gap_limit(t.t_ic);
        }
    }

    /// The transport, if connected to one.
    pub fn transport(&self) -> Option<&dyn Transport> {
        self.drive.transport.as_deref()
    }

    /// The transport, to change it (fault injection, baud).
    pub fn transport_mut(&mut self) -> Option<&mut (dyn Transport + 'static)> {
        self.drive.transport.as_deref_mut()
    }

    /// Whether bytes can flow, and if not why.
    pub fn state(&self) -> LinkState {
        match &self.drive.transport {
            Some(t) => t.state(),
            None => LinkState::Disconnected(
                "not connected: connect to the simulated modem (connection bar)".to_string(),
            ),
        }
    }

    /// The chip's host interface.
    pub fn chip(&self) -> &dyn Chip {
        &*self.chip
    }

    /// Replaces the transport (or disconnects with `None`) and the chip
    /// behind it; every request not yet answered fails, with the reason
    /// the old transport was lost if it was, else a message saying it was
    /// closed.
    pub fn replace_transport(&mut self, transport: Option<Box<dyn Transport>>, dialect: Dialect) {
        let why = match self.state() {
            LinkState::Disconnected(why) if self.drive.transport.is_some() => why,
            _ => "the connection was closed before the modem answered".to_string(),
        };
        self.fail_requests(&why);
        let ended = self.log_time(self.now());
        let baud = transport.as_ref().map_or(57_600, |t| t.baud());
        self.log_offset = ended as i64 - transport.as_ref().map_or(0, |t| t.now()) as i64;
        self.host = HostLink(HostEngine::new(
            dialect,
            HostConfig::at_reset(dialect, baud),
        ));
        self.chip = chip::for_dialect(dialect);
        self.drive = Driver::new(transport);
        self.timeouts = Timeouts::at_reset(dialect, baud);
        self.configure();
        self.duplicate_of = None;
        self.out.notes.push(Note::TReq(false));
        self.out.notes.push(Note::Timeouts(self.timeouts));
    }

    /// Changes the UART baud rate of the transport and the engine.
    pub fn set_baud(&mut self, baud: u32) {
        if let Some(t) = self.drive.transport.as_mut() {
            t.set_baud(baud);
        }
        let config = HostConfig {
            baud,
            ..self.host.config()
        };
        self.host.set_config(config);
    }

    /// The host-interface timeouts in use.
    pub fn timeouts(&self) -> Timeouts {
        self.timeouts
    }

    /// How quickly the host has ACKed the modem's frames since connecting.
    pub fn ack_latency(&self) -> AckLatency {
        self.drive.ack_latency()
    }

    /// The most recent ACK latencies one by one, oldest first: when the
    /// tick that wrote the ACK began (µs of the page's clock), the latency
    /// on the transport's clock and on the page's (for the bench, to find
    /// what held up the late ones).
    pub fn ack_samples(&self) -> Vec<(f64, Duration, Duration)> {
        self.drive.ack_samples()
    }

    /// Its drive loop.
    pub fn driver(&self) -> &Driver {
        &self.drive
    }

    /// Requests not yet answered (the one outstanding and those queued).
    pub fn outstanding(&self) -> usize {
        self.queue.len() + self.active.is_some() as usize
    }

    /// Sends the request `frame` to the modem; `reply` is called once with
    /// its fate.
    pub fn request(&mut self, frame: LocalFrame, reply: Reply) {
        if let LinkState::Disconnected(why) = self.state() {
            self.out.replies.push((reply, Outcome::Failed(why)));
            return;
        }
        self.queue.push_back(Queued { frame, reply });
        let now = self.now();
        self.start_next(now);
        driver::flush(self, now);
    }

    /// The transport's clock (0 when there is none).
    pub fn now(&self) -> Instant {
        self.drive.now()
    }

    /// Lets the transport's time catch up with the page's clock `page_us`
    /// (µs, any origin) and returns what happened. While the transport is
    /// down, requests fail at once with its reason instead of waiting for
    /// the link's timeouts.
    pub fn tick(&mut self, page_us: f64, budget: Budget) -> Tick {
        if self.hold.pending() {
            self.hold.settle();
            // The pace of the hand-outs counts from the paint, when the
            // line goes on: else each wait for a frame would let the next
            // hand-out fall due, one exchange later, and the line would
            // wait for every frame.
            if !self.hold.pending() {
                self.shown = page_us;
            }
        }
        if self.outstanding() > 0 {
            if let LinkState::Disconnected(why) = self.state() {
                self.fail_requests(&why);
            }
        }
        driver::tick(self, page_us, budget);
        self.take_due(page_us)
    }

    /// What happened since the last call, without letting time pass:
    /// replies at once, notes when [`Session::show_at`] says, on the
    /// page's clock `page_us` (a redraw per frame on the line would hold
    /// up the next ACK: chained requests, each sent from the previous
    /// one's reply, used to hand the notes out and redraw once per
    /// exchange).
    pub fn take_due(&mut self, page_us: f64) -> Tick {
        // Notes wait for the answer of the request on the line, so that
        // the page redraws between two requests ([`Session::holds_line`]);
        // a busy line's hand-out longer at most.
        let mid_request = self.active.is_some() && page_us < self.show_at() + BUSY_SHOW_EVERY;
        if page_us < self.show_at() || mid_request {
            return Tick {
                notes: Vec::new(),
                replies: std::mem::take(&mut self.out.replies),
            };
        }
        self.shown = page_us;
        if !self.out.notes.is_empty() {
            self.hold.begin();
        }
        self.take()
    }

    /// What happened since the last call, without letting time pass.
    pub fn take(&mut self) -> Tick {
        self.held = 0;
        std::mem::take(&mut self.out)
    }

    /// Whether the next request waits: notes are due (they wait for the
    /// answer on the line, [`Session::take_due`]), or were handed out and
    /// the page has not painted them yet ([`Session::drawing`]). The page
    /// redraws then while no frame of the modem can end: the modem answers
    /// requests, and the next has not left (issue 13: a redraw of the
    /// Traffic table, 5-8 ms, held up the ACKs of the frames that ended
    /// under it: p99 9-10 ms, then 1-2 ms; its paint at the next frame,
    /// 2-4 ms, did too). Frames the modem sends of its own accord still
    /// come when they come. It costs the line up to a frame (16.7 ms at
    /// 60 Hz) once per hand-out.
    pub fn holds_line(&self) -> bool {
        self.hold.pending()
            || (!self.out.notes.is_empty() && self.drive.tick_at() >= self.show_at())
    }

    /// Whether notes handed out wait to be painted: the line is quiet
    /// until the page's next frame ([`crate::wake::Draw`]).
    pub fn drawing(&self) -> bool {
        self.hold.pending()
    }

    /// When the notes held back are handed out, µs of the page's clock:
    /// [`SHOW_EVERY`] after the last time, or [`BUSY_SHOW_EVERY`] when more
    /// than one exchange's elements wait.
    fn show_at(&self) -> f64 {
        let pace = if self.held > EXCHANGE_ELEMENTS {
            BUSY_SHOW_EVERY
        } else {
            SHOW_EVERY
        };
        self.shown + pace
    }

    /// The next instant on the transport's clock at which something is
    /// due: an engine deadline, a request's answer timeout, the end of a
    /// duplicate's grace, the transport's next event (a simulated byte
    /// arriving), or now if a request waits to be sent.
    pub fn next_due(&self) -> Option<Instant> {
        let now = self.now();
        // A request held for a draw goes once the page has painted it,
        // which runs the page again ([`crate::wake::Draw`]).
        let waiting = (self.active.is_none() && !self.queue.is_empty() && !self.hold.pending())
            .then_some(now);
        earliest([waiting, self.world_due()])
    }

    /// [`Session::next_due`] but a request waiting to be sent: the next
    /// instant the link or the world behind the transport does something
    /// of its own.
    fn world_due(&self) -> Option<Instant> {
        earliest([
            self.host.poll_timeout(),
            self.drive.transport.as_ref().and_then(|t| t.next_event()),
            self.active.as_ref().and_then(|a| a.deadline),
            self.duplicate_of.map(|d| d.1),
        ])
    }

    /// [`Session::next_due`] on the page's clock (µs), or when notes held
    /// back are due ([`Session::notes_due`]).
    pub fn next_wake(&self) -> Option<f64> {
        let due = self.next_due().and_then(|t| self.drive.pacer.page_at(t));
        [self.notes_due(), due]
            .into_iter()
            .flatten()
            .reduce(f64::min)
    }

    /// When the notes held back are handed out (µs of the page's clock):
    /// while a request is on the line they wait for its answer, which
    /// wakes the page ([`Session::take_due`]), or for a busy line's
    /// hand-out at the latest; the page is not woken for them at once,
    /// tick after tick, until then.
    fn notes_due(&self) -> Option<f64> {
        let busy = if self.active.is_some() {
            BUSY_SHOW_EVERY
        } else {
            0.0
        };
        (!self.out.notes.is_empty()).then_some(self.show_at() + busy)
    }

    /// Hands the next queued request to the engine when none is
    /// outstanding and no duplicate answer is expected.
    fn start_next(&mut self, now: Instant) {
        if self.active.is_some() || self.holds_line() {
            return;
        }
        if let Some((_, until)) = self.duplicate_of {
            if now < until {
                return;
            }
            self.duplicate_of = None;
        }
        let Some(q) = self.queue.pop_front() else {
            return;
        };
        let ticket = self.host.submit(now, q.frame.clone());
        self.active = Some(Active {
            ticket,
            request: q.frame,
            reply: q.reply,
            submitted: now,
            deadline: None,
            repeated: false,
            unanswered: false,
        });
    }

    fn expire(&mut self, now: Instant) {
        let late = self
            .active
            .as_ref()
            .and_then(|a| a.deadline)
            .is_some_and(|d| now >= d);
        if late {
            if let Some(a) = self.active.take() {
                let secs = self.chip.answer_timeout(a.request.code) / 1_000_000;
                let msg = format!(
                    "the modem acknowledged {} but sent no answer within {secs} s: reset the modem (Diagnostics) and try again",
                    self.chip.code_name(a.request.code).unwrap_or("the request")
                );
                self.out.replies.push((a.reply, Outcome::Failed(msg)));
            }
        }
    }

    fn traffic(&mut self, at: Instant, element: &Element, from: Source) {
        let decoded = self.chip.decode(from, element);
        self.held += 1;
        self.out.notes.push(Note::Traffic {
            at: self.log_time(at),
            decoded: Box::new(decoded),
        });
    }

    fn on_event(&mut self, now: Instant, e: Event) {
        match e {
            Event::Received(el) => {
                if let Element::Status(message) = el {
                    let at = self.log_time(now);
                    self.out.notes.push(Note::Status { at, message });
                }
                self.traffic(now, &el, Source::Modem);
            }
            Event::Sent(el) => self.traffic(now, &el, Source::Host),
            Event::Frame(f) => self.on_frame(now, f),
            Event::Repeat(_) => {}
            Event::Delivered(t) => {
                if let Some(a) = self.active.as_mut().filter(|a| a.ticket == t) {
                    if !a.unanswered {
                        self.unanswered = 0;
                    }
                    a.deadline = Some(now + self.chip.answer_timeout(a.request.code));
                }
                let done = self
                    .active
                    .as_ref()
                    .is_some_and(|a| a.ticket == t && !self.chip.expects_answer(a.request.code));
                if let Some(a) = self.active.take_if(|_| done) {
                    let rtt = now.saturating_sub(a.submitted);
                    let outcome = Outcome::Answer { command: None, rtt };
                    self.out.replies.push((a.reply, outcome));
                }
            }
            Event::Failed(t, cause) => {
                self.count_unanswered(cause);
                if self.active.as_ref().is_some_and(|a| a.ticket == t) {
                    if let Some(a) = self.active.take() {
                        self.out
                            .replies
                            .push((a.reply, Outcome::Failed(cause.to_string())));
                    }
                }
            }
            Event::Retry {
                ticket,
                attempt,
                cause,
            } => {
                self.count_unanswered(cause);
                if let Some(a) = self.active.as_mut().filter(|a| a.ticket == ticket) {
                    a.repeated |= cause == LinkError::NoAck;
                }
                self.out.notes.push(Note::Retry {
                    at: self.log_time(now),
                    attempt,
                    cause: cause.to_string(),
                });
            }
        }
    }

    /// Counts the requests in a row whose T_REQ got no status message at
    /// least once: an adapter that applies RTS one call late (Windows'
    /// usbser) makes every request lose one attempt that way, while the
    /// modem answers the "release" that comes next.
    fn count_unanswered(&mut self, cause: LinkError) {
        let Some(a) = self.active.as_mut() else {
            return;
        };
        if cause == LinkError::NoStatus && !a.unanswered {
            a.unanswered = true;
            self.unanswered = self.unanswered.saturating_add(1);
            self.out.notes.push(Note::TReqUnanswered(self.unanswered));
        }
    }

    fn on_frame(&mut self, now: Instant, f: LocalFrame) {
        let answers_active = self
            .active
            .as_ref()
            .is_some_and(|a| self.chip.answers(a.request.code, f.code));
        if answers_active {
            let Some(a) = self.active.take() else {
                return;
            };
            if a.repeated {
                self.duplicate_of = Some((a.request.code, now + DUPLICATE_GRACE));
            }
            if let Some(t) = self
                .chip
                .timeouts_after(&a.request, &f, self.host.config().baud)
            {
                self.set_timeouts(t);
            }
            let outcome = Outcome::Answer {
                command: Some(f),
                rtt: now.saturating_sub(a.submitted),
            };
            self.out.replies.push((a.reply, outcome));
            return;
        }
        let duplicate = self
            .duplicate_of
            .is_some_and(|(req, until)| now < until && self.chip.answers(req, f.code));
        let reset = self.chip.is_reset(&f);
        if reset {
            // UM0932 4.2.9, ST7570 UM 5.3.4 / protocol notes: a reset
            // restores the objects that set the host's timeouts.
            let config = self.host.config();
            self.set_timeouts(Timeouts::at_reset(self.chip.dialect(), config.baud));
        }
        self.out.notes.push(Note::Unsolicited {
            at: self.log_time(now),
            frame: f,
            reset,
            duplicate,
        });
    }

    fn set_timeouts(&mut self, timeouts: Timeouts) {
        self.timeouts = timeouts;
        self.configure();
        self.out.notes.push(Note::Timeouts(timeouts));
    }

    /// A time on the transport's clock on the traffic log's (which goes
    /// on across connections).
    pub fn log_time(&self, t: Instant) -> Instant {
        (t as i64).saturating_add(self.log_offset).max(0) as Instant
    }

    /// Fails every request not yet answered with `why`, and starts the
    /// link engine afresh so that nothing of theirs is repeated later.
    fn fail_requests(&mut self, why: &str) {
        if let Some(a) = self.active.take() {
            self.out
                .replies
                .push((a.reply, Outcome::Failed(why.to_string())));
            self.host = HostLink(HostEngine::new(self.chip.dialect(), self.host.config()));
            if let Some(t) = self.drive.transport.as_mut() {
                t.set_treq(false);
            }
            self.out.notes.push(Note::TReq(false));
        }
        for q in self.queue.drain(..) {
            self.out
                .replies
                .push((q.reply, Outcome::Failed(why.to_string())));
        }
        self.duplicate_of = None;
    }
}

/// The modem session on the console's one drive loop.
impl Layer for Session {
    fn acks(&self) -> bool {
        true
    }

    fn parts(&mut self) -> (&mut AnyEngine, &mut Driver) {
        (&mut self.host, &mut self.drive)
    }

    fn on_event(&mut self, at: Instant, event: Happening) {
        if let Happening::Link(e) = event {
            self.on_event(at, e)
        }
    }

    fn on_treq(&mut self, asserted: bool) {
        self.out.notes.push(Note::TReq(asserted));
    }

    fn next_due(&self) -> Option<Instant> {
        Session::next_due(self)
    }

    fn world_due(&self) -> Option<Instant> {
        Session::world_due(self)
    }

    /// Nothing in flight and nothing due before the target: the time
    /// passes at once, and a waiting request leaves at the target, when
    /// the page asked for it.
    fn idle_until(&self, target: Instant) -> bool {
        self.active.is_none() && !matches!(self.world_due(), Some(d) if d < target)
    }

    fn at(&mut self, now: Instant) {
        self.expire(now);
        self.start_next(now);
    }

    /// Answers go to their replies at the instant they came.
    fn stop(&self) -> bool {
        !self.out.replies.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::{SIM_CATCH_UP, SLICE};
    use crate::transport::sim::SimTransport;
    use plm_sim::Fault;
    use std::cell::RefCell;
    use std::rc::Rc;

    use plm_core::st7580::mib::index;
    use plm_core::st7580::Command;

    type Seen = Rc<RefCell<Vec<Outcome<Command>>>>;

    fn session(nodes: usize) -> Session {
        let t = SimTransport::new(nodes, 57_600, 7);
        Session::new(Some(Box::new(t)), Dialect::St7580)
    }

    /// Keeps the outcome, the answer read as an ST7580 command.
    fn reply(seen: &Seen) -> Reply {
        let seen = seen.clone();
        Box::new(move |o: Outcome| {
            let o = o.read(|f| Command::from_frame(f).map_err(|e| e.to_string()));
            seen.borrow_mut().push(o)
        })
    }

    impl Session {
        /// Sends an ST7580 command.
        fn ask(&mut self, command: Command, reply: Reply) {
            self.request(command.to_frame(), reply);
        }
    }

    /// Ticks every 4 ms of page time (as setInterval does) for `ms`,
    /// calling the replies and keeping the notes.
    fn run(s: &mut Session, page: &mut f64, ms: u32, notes: &mut Vec<Note>) {
        for _ in 0..ms / 4 {
            *page += 4_000.0;
            let t = s.tick(*page, Budget::UNLIMITED);
            notes.extend(t.notes);
            for (r, o) in t.replies {
                r(o);
            }
        }
    }

    /// Only the end of a run of bytes on the UART is waited exactly (a
    /// frame may end there, to be ACKed or answered): through a ping and
    /// its answer, the exact wake is a handful of instants, never in the
    /// past, and no earlier than the next ordinary deadline (each byte of
    /// a frame), not one per byte.
    #[test]
    fn the_exact_wake_is_the_end_of_a_run_of_bytes() {
        let mut s = session(1);
        let (mut page, mut notes) = (1_000_000.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        assert_eq!(s.drive.exact_wake(), None, "idle wires");
        let seen = Seen::default();
        s.ask(Command::PingRequest { data: vec![7; 8] }, reply(&seen));
        let (mut ends, mut looks) = (Vec::new(), 0);
        while seen.borrow().is_empty() {
            page += 100.0;
            let t = s.tick(page, Budget::UNLIMITED);
            t.replies.into_iter().for_each(|(r, o)| r(o));
            if let Some(end) = s.drive.exact_wake() {
                assert!(end >= page, "{end} before {page}");
                assert!(s.next_wake().is_some_and(|w| w <= end));
                ends.push(end);
                looks += 1;
            }
            assert!(page < 2e6, "the ping answered");
        }
        ends.dedup();
        assert!(looks > 20, "bytes on the wire at {looks} looks");
        assert!((2..=6).contains(&ends.len()), "{ends:?}");
    }

    /// Issue 13, "event-driven link": the session steps to what is due,
    /// so a modem frame is ACKed at the instant its last byte arrives, and
    /// a request sent from the reply of another leaves at the instant of
    /// that reply: chained requests go as fast as queued ones, however
    /// coarse the page's ticks (here 8 ms).
    #[test]
    fn frames_are_acked_and_chained_requests_sent_at_the_instant_they_are_due() {
        let mut s = session(1);
        let (mut page, mut notes) = (1_000_000.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        let ping = || Command::PingRequest { data: vec![7; 8] };
        let elapsed = |s: &mut Session, page: &mut f64, chained: bool| {
            let seen = Seen::default();
            let start = s.now();
            let n = 20;
            for _ in 0..if chained { 1 } else { n } {
                s.ask(ping(), reply(&seen));
            }
            let mut last = start;
            while seen.borrow().len() < n {
                *page += 8_000.0;
                let t = s.tick(*page, Budget::UNLIMITED);
                for (r, o) in t.replies {
                    r(o);
                    last = s.now();
                    if chained && seen.borrow().len() < n {
                        s.ask(ping(), reply(&seen));
                    }
                }
                assert!(*page < 2e7, "20 pings answered");
            }
            last - start
        };
        let queued = elapsed(&mut s, &mut page, false);
        let chained = elapsed(&mut s, &mut page, true);
        assert!(
            chained * 100 <= queued * 105,
            "chained {chained} µs vs queued {queued} µs"
        );
        let l = s.ack_latency();
        assert!(l.count >= 40, "{l:?}");
        assert_eq!(l.link.max, 0, "ACKed at the byte's arrival: {l:?}");
    }

    /// Issue 13: the notes of one exchange come at the next screen
    /// refresh; those of a busy line five times a second, between two
    /// requests, so that the page's redraws hold up no ACK. Replies come
    /// at once either way.
    #[test]
    fn notes_come_at_the_next_refresh_or_five_times_a_second_on_a_busy_line() {
        let mut s = session(1);
        let (mut page, mut notes) = (1_000_000.0, Vec::new());
        run(&mut s, &mut page, 400, &mut notes);
        // Ticks of 1 ms; when each reply and each batch of notes came.
        let tick = |s: &mut Session, page: &mut f64, replied: &mut Vec<f64>| {
            *page += 1_000.0;
            let t = s.tick(*page, Budget::UNLIMITED);
            // Notes come between two requests, and the next waits for the
            // next tick: the page draws while the line is quiet.
            if !t.notes.is_empty() {
                assert!(s.active.is_none() && s.drawing(), "notes mid-request");
            }
            for (r, o) in t.replies {
                r(o);
                replied.push(*page);
            }
            assert!(s.active.is_none() || !s.drawing());
            // Notes held for the answer on the line do not wake the page
            // at once, tick after tick, until it comes.
            if s.active.is_some() {
                let due = s.notes_due().unwrap_or(f64::INFINITY);
                assert!(
                    due > *page,
                    "notes due at once ({due}) mid-request at {page}"
                );
            }
            (!t.notes.is_empty()).then_some((*page, t.notes.len()))
        };
        let seen = Seen::default();
        let (mut replied, mut batches) = (Vec::new(), Vec::new());
        s.ask(Command::PingRequest { data: vec![1] }, reply(&seen));
        for _ in 0..100 {
            batches.extend(tick(&mut s, &mut page, &mut replied));
        }
        let (answered, first) = (replied[0], batches[0].0);
        assert!(
            first - answered <= SHOW_EVERY,
            "one exchange: {batches:?} after {answered}"
        );
        // Pings queued: the line is busy for over half a second.
        let (mut replied, mut batches) = (Vec::new(), Vec::new());
        let start = page;
        for _ in 0..300 {
            s.ask(Command::PingRequest { data: vec![1] }, reply(&seen));
        }
        while replied.len() < 300 {
            batches.extend(tick(&mut s, &mut page, &mut replied));
            assert!(page < start + 1e7, "300 pings answered");
        }
        assert!(page - start > 700_000.0, "{} µs", page - start);
        assert!(
            replied.windows(2).all(|w| w[1] - w[0] < 20_000.0),
            "replies at once: {replied:?}"
        );
        let gaps: Vec<f64> = batches.windows(2).map(|w| w[1].0 - w[0].0).collect();
        assert!(!gaps.is_empty(), "{batches:?}");
        assert!(
            gaps.iter().all(|g| *g >= BUSY_SHOW_EVERY),
            "batches {batches:?}"
        );
    }

    #[test]
    fn ping_is_answered_with_its_payload_and_a_round_trip_time() {
        let mut s = session(1);
        let (mut page, mut notes) = (1_000_000.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes); // the modem boots in 20 ms
        let seen = Seen::default();
        s.ask(
            Command::PingRequest {
                data: vec![1, 2, 3],
            },
            reply(&seen),
        );
        run(&mut s, &mut page, 100, &mut notes);
        let seen = seen.borrow();
        match &seen[..] {
            [Outcome::Answer { command, rtt }] => {
                assert_eq!(
                    command,
                    &Command::PingConfirm {
                        data: vec![1, 2, 3]
                    }
                );
                assert!(*rtt > 0 && *rtt < 20 * MS, "rtt {rtt}");
            }
            other => panic!("{other:?}"),
        }
        let kinds: Vec<_> = notes
            .iter()
            .filter_map(|n| match n {
                Note::Traffic { decoded, .. } => decoded
                    .command
                    .as_ref()
                    .and_then(|c| c.as_str())
                    .map(str::to_string),
                _ => None,
            })
            .collect();
        assert_eq!(
            kinds,
            ["BIO_ResetIndication", "PingRequest", "PingConfirm"],
            "traffic of both directions, decoded"
        );
        assert!(notes.iter().any(|n| matches!(n, Note::Status { .. })));
        assert!(notes.iter().any(|n| matches!(n, Note::TReq(true))));
    }

    #[test]
    fn requests_queue_and_each_gets_its_own_answer() {
        let mut s = session(1);
        let (mut page, mut notes) = (0.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        let seen = Seen::default();
        for i in [index::FIRMWARE_VERSION, index::HOST_INTERFACE_TIMEOUT] {
            s.ask(Command::MibReadRequest { index: i }, reply(&seen));
        }
        assert_eq!(s.outstanding(), 2);
        run(&mut s, &mut page, 200, &mut notes);
        let data: Vec<_> = seen
            .borrow()
            .iter()
            .map(|o| match o {
                Outcome::Answer {
                    command: Command::MibReadConfirm { data },
                    ..
                } => data.clone(),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(data, [vec![0x00, 0x42, 0x00, 0x97], vec![0xC8, 0x28, 0x0A]]);
        assert_eq!(s.outstanding(), 0);
    }

    #[test]
    fn an_unplugged_cable_fails_the_request_in_words() {
        let mut s = session(1);
        let (mut page, mut notes) = (0.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        s.transport_mut()
            .and_then(|t| t.simulator())
            .expect("simulated")
            .inject(Fault::Unplug);
        let seen = Seen::default();
        s.ask(Command::PingRequest { data: vec![] }, reply(&seen));
        run(&mut s, &mut page, 2_000, &mut notes);
        assert_eq!(
            *seen.borrow(),
            [Outcome::Failed(
                "the simulated cable is unplugged: plug it back in (Simulator view)".into()
            )]
        );
        // Unplugged while the request is in flight: it fails at the next
        // tick with the reason, not seconds later at the link's timeouts.
        fn inject(s: &mut Session, fault: Fault) {
            let t = s.transport_mut().expect("a transport");
            t.simulator().expect("simulated").inject(fault);
        }
        inject(&mut s, Fault::Plug);
        s.ask(Command::PingRequest { data: vec![] }, reply(&seen));
        inject(&mut s, Fault::Unplug);
        run(&mut s, &mut page, 4, &mut notes);
        assert_eq!(seen.borrow().len(), 2);
        assert_eq!(seen.borrow()[1], seen.borrow()[0]);
        assert_eq!(s.outstanding(), 0);
        // Plugged back in, the next request goes through from scratch.
        inject(&mut s, Fault::Plug);
        s.ask(Command::PingRequest { data: vec![5] }, reply(&seen));
        run(&mut s, &mut page, 200, &mut notes);
        assert!(
            matches!(&seen.borrow()[2], Outcome::Answer { command: Command::PingConfirm { data }, .. } if data == &[5]),
            "{:?}",
            seen.borrow()[2]
        );
    }

    #[test]
    fn the_log_time_carries_on_across_a_change_of_transport() {
        let mut s = session(1);
        let (mut page, mut notes) = (0.0, Vec::new());
        run(&mut s, &mut page, 400, &mut notes);
        let last = |notes: &[Note]| {
            notes.iter().rev().find_map(|n| match n {
                Note::Traffic { at, .. } => Some(*at),
                _ => None,
            })
        };
        let first_run = last(&notes).expect("the reset indication");
        // A new simulated modem: its clock starts at 0 again.
        s.replace_transport(
            Some(Box::new(SimTransport::new(1, 57_600, 8))),
            Dialect::St7580,
        );
        let mut after = Vec::new();
        run(&mut s, &mut page, 40, &mut after);
        let second = last(&after).expect("its reset indication");
        assert!(
            second > 400 * MS && second > first_run,
            "{second} after {first_run}"
        );
    }

    #[test]
    fn a_confirmed_timeout_write_retunes_the_engine_and_a_reset_restores_it() {
        let mut s = session(1);
        let (mut page, mut notes) = (0.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        let seen = Seen::default();
        s.ask(
            Command::MibWriteRequest {
                index: index::HOST_INTERFACE_TIMEOUT,
                data: vec![150, 30, 8],
            },
            reply(&seen),
        );
        run(&mut s, &mut page, 100, &mut notes);
        assert_eq!(s.timeouts(), Timeouts::from_ms(150, 30, 8));
        s.ask(Command::BioResetRequest, reply(&seen));
        run(&mut s, &mut page, 200, &mut notes);
        assert_eq!(s.timeouts(), Timeouts::default());
        assert!(notes.iter().any(|n| matches!(
            n,
            Note::Unsolicited {
                frame: LocalFrame {
                    code: plm_core::st7580::code::BIO_RESET_INDICATION,
                    ..
                },
                reset: true,
                ..
            }
        )));
    }

    #[test]
    fn every_frame_acked_is_timed_on_both_clocks() {
        let mut s = session(1);
        let (mut page, mut notes) = (0.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        let seen = Seen::default();
        s.ask(Command::PingRequest { data: vec![9] }, reply(&seen));
        run(&mut s, &mut page, 100, &mut notes);
        let acks = notes
            .iter()
            .filter(|n| matches!(n, Note::Traffic { decoded, .. } if decoded.from.as_deref() == Some("host") && decoded.kind == "ack"))
            .count();
        let l = s.ack_latency();
        // The BIO_ResetIndication at boot and the PingConfirm.
        assert_eq!((l.count, acks), (2, 2), "{l:?}");
        assert!(l.link.max <= SLICE, "{l:?}");
        // Ticks every 4 ms: the page got to each byte within a tick.
        assert!(l.page.max <= 4 * MS && l.page.p50 >= l.link.p50, "{l:?}");
        // A page stalled for 30 ms shows on the page's clock only.
        s.ask(Command::PingRequest { data: vec![9] }, reply(&seen));
        page += 30_000.0;
        let _ = s.tick(page, Budget::UNLIMITED);
        let l = s.ack_latency();
        assert_eq!(l.count, 3);
        assert!(l.link.max <= SLICE, "{l:?}");
        assert!(l.page.max > 10 * MS && l.page.max < 30 * MS, "{l:?}");
        s.replace_transport(None, Dialect::St7580);
        assert_eq!(s.ack_latency(), AckLatency::default());
    }

    /// Issue 13: after the page stalled, the simulated modem carries on
    /// from where it was; its time does not replay the stall frame by
    /// frame, each ACK of the replay counting the page's lag again.
    #[test]
    fn a_stall_of_the_page_makes_one_late_ack_not_a_replay_of_them() {
        let mut s = session(1);
        let (mut page, mut notes) = (1_000_000.0, Vec::new());
        run(&mut s, &mut page, 40, &mut notes);
        let seen = Seen::default();
        for _ in 0..30 {
            s.ask(Command::PingRequest { data: vec![5; 8] }, reply(&seen));
        }
        let mut late = Vec::new();
        for i in 0..20_000 {
            // Every 100 µs, as the page wakes for bytes; once, 35 ms late.
            page += if i == 100 { 35_000.0 } else { 100.0 };
            let before = s.ack_latency().count;
            for (r, o) in s.tick(page, Budget::UNLIMITED).replies {
                r(o);
            }
            let n = (s.ack_latency().count - before) as usize;
            let new = s.ack_samples().into_iter().rev().take(n);
            late.extend(new.map(|(_, _, p)| p).filter(|&p| p > 2 * MS));
            if seen.borrow().len() == 30 {
                break;
            }
        }
        assert_eq!(seen.borrow().len(), 30, "30 pings answered");
        assert_eq!(late.len(), 1, "ACKs later than 2 ms: {late:?}");
        assert!(late[0] > 30 * MS, "{late:?}");
    }

    /// A stall of the page while something is due behind the transport
    /// (here the simulated modem's boot indication) is given up past
    /// SIM_CATCH_UP: the world slows down rather than racing.
    #[test]
    fn a_stalled_page_slows_the_simulation_instead_of_racing_it() {
        let mut s = session(1);
        s.tick(0.0, Budget::UNLIMITED);
        let due = s.world_due().expect("the modem's boot is due");
        s.tick(5_000_000.0, Budget::UNLIMITED);
        assert_eq!(s.now(), due + SIM_CATCH_UP);
    }

    /// The simulated ST7570 is paced by the same rule: idle, its time
    /// follows the page's whole (two reads of one object a user asks for
    /// a second apart are a second apart on the modem's clock too, not a
    /// catch-up limit), and a stall with a request in flight is given up
    /// as the ST7580's.
    #[test]
    fn a_simulated_st7570_idles_in_real_time_and_a_stall_is_given_up() {
        use crate::transport::sfsk::SfskTransport;
        use plm_core::st7570::mib::index::PLC_CONFIGURATION;
        let t = SfskTransport::new(2, 57_600, 7);
        let mut s = Session::new(Some(Box::new(t)), Dialect::St7570);
        s.tick(0.0, Budget::UNLIMITED);
        s.tick(5_000_000.0, Budget::UNLIMITED);
        assert_eq!(s.now(), 5_000_000, "an idle world's time passes whole");
        let seen: Rc<RefCell<Vec<Outcome>>> = Rc::default();
        let mut page = 5_000_000.0;
        for n in 1..=2 {
            let keep = seen.clone();
            let read = s.chip().mib_read(PLC_CONFIGURATION);
            s.request(read, Box::new(move |o| keep.borrow_mut().push(o)));
            while seen.borrow().len() < n && page < 10_000_000.0 {
                for (r, o) in s.tick(page, Budget::UNLIMITED).replies {
                    r(o);
                }
                page += 4_000.0;
            }
            let last = seen.borrow().last().cloned();
            assert!(
                matches!(
                    last,
                    Some(Outcome::Answer {
                        command: Some(_),
                        ..
                    })
                ),
                "read {n}: {last:?}"
            );
            // The page wakes when something is due (the ACK reaching the
            // modem), then sleeps until the user clicks again.
            while let Some(w) = s.next_wake().filter(|&w| w < page + 1_000_000.0) {
                page = page.max(w);
                s.tick(page, Budget::UNLIMITED);
            }
            assert_eq!(s.world_due(), None, "idle");
            page += 1_000_000.0;
        }
        let keep = seen.clone();
        let read = s.chip().mib_read(PLC_CONFIGURATION);
        s.request(read, Box::new(move |o| keep.borrow_mut().push(o)));
        s.tick(page, Budget::UNLIMITED);
        let due = s.world_due().expect("the read is in flight");
        s.tick(page + 5_000_000.0, Budget::UNLIMITED);
        assert!(s.now() <= due + SIM_CATCH_UP, "{} {due}", s.now());
    }

    /// Issue 12, item 1: the same session drives a simulated ST7570
    /// through plm-core's description of its host interface: a MIB read
    /// and write with 16-bit indexes, the access layer followed from
    /// 00A1h, a refusal in words, and a request the modem acknowledges
    /// and does not answer (Table 21: a PHY CMD_DesynchroRequest) done at
    /// its ACK.
    #[test]
    fn the_same_session_drives_an_st7570_through_its_description() {
        use crate::transport::sfsk::SfskTransport;
        use plm_core::st7570::mib::{index as i7570, PlcConfiguration};
        use plm_core::st7570::Command as C7570;
        let t = SfskTransport::new(2, 57_600, 7);
        let mut s = Session::new(Some(Box::new(t)), Dialect::St7570);
        let (mut page, mut notes) = (1_000_000.0, Vec::new());
        run(&mut s, &mut page, 200, &mut notes);
        let seen: Rc<RefCell<Vec<Outcome>>> = Rc::default();
        let keep = |seen: &Rc<RefCell<Vec<Outcome>>>| -> Reply {
            let seen = seen.clone();
            Box::new(move |o| seen.borrow_mut().push(o))
        };
        let verdict = |s: &Session, o: &Outcome| match o {
            Outcome::Answer {
                command: Some(f), ..
            } => s.chip().verdict(f),
            other => panic!("{other:?}"),
        };
        let plc = i7570::PLC_CONFIGURATION;
        s.request(s.chip().mib_read(plc), keep(&seen));
        run(&mut s, &mut page, 200, &mut notes);
        let value = verdict(&s, &seen.borrow()[0]).expect("00A1h read");
        let mut p = PlcConfiguration::decode(&value);
        assert_eq!(p.access_layer_mode, 1, "PHY at the factory");
        // PHY: CMD_DesynchroRequest draws no answer (Table 21).
        let desync = C7570::DesynchroRequest { reset: 0 }.to_frame();
        s.request(desync.clone(), keep(&seen));
        run(&mut s, &mut page, 200, &mut notes);
        assert!(
            matches!(seen.borrow()[1], Outcome::Answer { command: None, .. }),
            "{:?}",
            seen.borrow()[1]
        );
        // MAC Client.
        (p.operating_mode, p.access_layer_mode) = (1, 2);
        s.request(s.chip().mib_write(plc, &p.encode()), keep(&seen));
        s.request(s.chip().mib_read(plc), keep(&seen));
        run(&mut s, &mut page, 400, &mut notes);
        assert_eq!(verdict(&s, &seen.borrow()[2]), Ok(p.encode()));
        assert_eq!(verdict(&s, &seen.borrow()[3]), Ok(p.encode()));
        // A value the chip refuses comes back in words.
        s.request(s.chip().mib_write(plc, &[0; 3]), keep(&seen));
        run(&mut s, &mut page, 200, &mut notes);
        let why = verdict(&s, &seen.borrow()[4]).unwrap_err();
        assert!(
            why.starts_with("the modem refused it with CMD_WriteDBError: ERR_"),
            "{why}"
        );
        assert!(notes.iter().any(|n| matches!(n, Note::Traffic { decoded, .. } if decoded.layer.as_deref() == Some("MAC"))));
    }
}
