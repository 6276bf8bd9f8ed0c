//! A virtual-time bench for the link engines: a [`HostEngine`] and a
//! [`DeviceEngine`] of one [`Dialect`] joined by a simulated UART, byte by
//! byte.
//!
//! Model:
//! - each direction is a UART transmitter at `baud`, 10 bit times per byte
//!   (UM0932 3.1); bytes written while the line is busy queue behind the
//!   ones before, so a byte written at `t` on an idle line arrives at
//!   `t + wire_time(1)` and a run of back-to-back bytes started at `s`
//!   has its `k`-th byte arrive at `s + wire_time(k)`, the same arithmetic
//!   the engines use;
//! - T_REQ is a wire of its own with no delay, but a level change the host
//!   asks for after some bytes takes effect once those bytes have left its
//!   UART (a driver drains its FIFO before touching RTS). So "release
//!   T_REQ once STX is out" (UM0932 3.2.8) is observable at the device;
//! - faults are applied per byte at the transmitter: drop (the time still
//!   passes, the receiver gets nothing), corrupt (XOR), or delay (the line
//!   stalls before the byte, and the bytes after it wait too);
//! - the test plays the modem application: an optional responder sees each
//!   [`DeviceEvent::Request`] and may answer with a frame, submitted to the
//!   device at that very instant.
//!
//! The loop advances time to the earliest of the next byte arrival and the
//! two engines' `poll_timeout()`, delivers arrivals (before deadlines of
//! the same instant: a byte exactly T_IC after the previous one is still
//! in time), calls `handle_timeout` where due, and drains both engines'
//! transmits and events, recording everything with timestamps.

#![allow(dead_code)]

pub mod chip;

use plm_core::link::device::{DeviceEngine, DeviceEvent};
use plm_core::link::host::{Event, HostConfig, HostEngine, Ticket, Transmit};
use plm_core::link::{Dialect, Element, LocalFrame, ACK, NAK, STATUS_FIRST};
use plm_core::time::{wire_time, Duration, Instant, MS};
use std::collections::VecDeque;

/// A direction on the UART.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    /// Host TX, modem RX.
    HostToDev,
    /// Modem TX, host RX.
    DevToHost,
}

/// What a byte is part of, as its sender wrote it (known at the
/// transmitter, so it is right even when the receiver is confused).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Byte `offset` (0 = STX) of the `n`-th frame sent this way (0-based).
    Frame {
        /// Frame number in this direction.
        n: usize,
        /// Offset in the frame.
        offset: usize,
    },
    /// Byte `offset` of the `n`-th status message.
    Status {
        /// Status message number.
        n: usize,
        /// Offset in the message.
        offset: usize,
    },
    /// An ACK character.
    Ack,
    /// A NAK character.
    Nak,
    /// Anything else.
    Other,
}

impl Part {
    /// Whether this is byte `offset` of frame `n`.
    pub fn is_frame_byte(self, n: usize, offset: usize) -> bool {
        self == Part::Frame { n, offset }
    }

    /// Whether this is a byte of a status message.
    pub fn is_status(self) -> bool {
        matches!(self, Part::Status { .. })
    }
}

/// A byte about to be transmitted, shown to the fault injectors.
#[derive(Debug, Clone, Copy)]
pub struct ByteCtx {
    /// Direction.
    pub dir: Dir,
    /// Index of the byte among all bytes sent this way.
    pub index: usize,
    /// The byte as written.
    pub byte: u8,
    /// What it is part of.
    pub part: Part,
    /// When it would start on the wire without a fault.
    pub start: Instant,
}

/// What happens to a byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// Lost: the line time passes, the receiver gets nothing.
    Drop,
    /// Received XORed with the mask.
    Corrupt(u8),
    /// The line stalls this long before the byte.
    Delay(Duration),
}

type Pred = Box<dyn FnMut(&ByteCtx) -> Option<Fault>>;

struct Injector {
    pred: Pred,
    /// How many more times it may fire (`None`: always).
    remaining: Option<usize>,
}

/// One byte on the wire, for assertions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WireByte {
    /// Direction.
    pub dir: Dir,
    /// Index among all bytes sent this way.
    pub index: usize,
    /// What it is part of.
    pub part: Part,
    /// The byte as written.
    pub sent: u8,
    /// The byte as received, `None` if dropped.
    pub got: Option<u8>,
    /// Start bit on the wire.
    pub start: Instant,
    /// Stop bit done: when the receiver has it.
    pub at: Instant,
}

#[derive(Debug, Clone, Copy)]
enum Item {
    Byte { at: Instant, byte: u8 },
    TReq { at: Instant, asserted: bool },
}

impl Item {
    fn at(&self) -> Instant {
        match *self {
            Item::Byte { at, .. } | Item::TReq { at, .. } => at,
        }
    }
}

/// Tracks which element each written byte belongs to.
#[derive(Debug)]
struct Framer {
    dialect: Dialect,
    frames: usize,
    statuses: usize,
    /// (is_frame, number, next offset, total length if known)
    cur: Option<(bool, usize, usize, Option<usize>)>,
}

impl Framer {
    fn new(dialect: Dialect) -> Self {
        Framer {
            dialect,
            frames: 0,
            statuses: 0,
            cur: None,
        }
    }

    fn classify(&mut self, dir: Dir, byte: u8, write_start: bool) -> Part {
        if let Some((is_frame, n, offset, total)) = self.cur {
            let total = if is_frame && offset == 1 {
                Some(Dialect::frame_len(self.dialect.data_len(byte).unwrap_or(0)))
            } else {
                total
            };
            let done = total.is_some_and(|t| offset + 1 >= t);
            self.cur = (!done).then_some((is_frame, n, offset + 1, total));
            return if is_frame {
                Part::Frame { n, offset }
            } else {
                Part::Status { n, offset }
            };
        }
        if write_start && self.dialect.is_stx(byte) {
            let n = self.frames;
            self.frames += 1;
            self.cur = Some((true, n, 1, None));
            return Part::Frame { n, offset: 0 };
        }
        if write_start && byte == STATUS_FIRST && dir == Dir::DevToHost {
            let n = self.statuses;
            self.statuses += 1;
            self.cur = Some((false, n, 1, Some(self.dialect.status_len())));
            return Part::Status { n, offset: 0 };
        }
        match byte {
            ACK => Part::Ack,
            NAK => Part::Nak,
            _ => Part::Other,
        }
    }
}

struct Line {
    dir: Dir,
    baud: u32,
    inflight: VecDeque<Item>,
    /// When the last byte written so far has left.
    free_at: Instant,
    run_start: Instant,
    run_len: usize,
    index: usize,
    framer: Framer,
    injectors: Vec<Injector>,
}

impl Line {
    fn new(dialect: Dialect, dir: Dir, baud: u32) -> Self {
        Line {
            dir,
            baud,
            inflight: VecDeque::new(),
            free_at: 0,
            run_start: 0,
            run_len: 0,
            index: 0,
            framer: Framer::new(dialect),
            injectors: Vec::new(),
        }
    }

    fn fault(&mut self, ctx: &ByteCtx) -> Option<Fault> {
        for inj in &mut self.injectors {
            if inj.remaining == Some(0) {
                continue;
            }
            if let Some(f) = (inj.pred)(ctx) {
                if let Some(r) = &mut inj.remaining {
                    *r -= 1;
                }
                return Some(f);
            }
        }
        None
    }

    fn write(&mut self, now: Instant, bytes: &[u8], log: &mut Vec<WireByte>) {
        for (i, &byte) in bytes.iter().enumerate() {
            let part = self.framer.classify(self.dir, byte, i == 0);
            let mut start = now.max(self.free_at);
            let ctx = ByteCtx {
                dir: self.dir,
                index: self.index,
                byte,
                part,
                start,
            };
            let fault = self.fault(&ctx);
            if let Some(Fault::Delay(d)) = fault {
                start += d;
            }
            if start > self.free_at || self.run_len == 0 {
                self.run_start = start;
                self.run_len = 0;
            }
            self.run_len += 1;
            let at = self.run_start + wire_time(self.run_len, self.baud);
            self.free_at = at;
            let got = match fault {
                Some(Fault::Drop) => None,
                Some(Fault::Corrupt(mask)) => Some(byte ^ mask),
                _ => Some(byte),
            };
            log.push(WireByte {
                dir: self.dir,
                index: self.index,
                part,
                sent: byte,
                got,
                start,
                at,
            });
            if let Some(b) = got {
                self.inflight.push_back(Item::Byte { at, byte: b });
            }
            self.index += 1;
        }
    }

    fn treq(&mut self, now: Instant, asserted: bool) -> Instant {
        let at = now.max(self.free_at);
        self.inflight.push_back(Item::TReq { at, asserted });
        at
    }

    fn next_at(&self) -> Option<Instant> {
        self.inflight.front().map(Item::at)
    }

    fn pop_due(&mut self, now: Instant) -> Option<Item> {
        if self.next_at()? <= now {
            self.inflight.pop_front()
        } else {
            None
        }
    }
}

/// The modem application of a bench: answers a request with a frame, or not.
pub type Responder = Box<dyn FnMut(Instant, &LocalFrame) -> Option<LocalFrame>>;

/// The bench.
pub struct Sim {
    /// Virtual time (µs).
    pub now: Instant,
    /// Baud rate of both directions.
    pub baud: u32,
    /// The host engine under test.
    pub host: HostEngine,
    /// The device engine under test.
    pub dev: DeviceEngine,
    h2d: Line,
    d2h: Line,
    responder: Option<Responder>,
    /// Host events with the time they were polled.
    pub host_events: Vec<(Instant, Event)>,
    /// Device events with the time they were polled.
    pub dev_events: Vec<(Instant, DeviceEvent)>,
    /// Host transmits, in the order the host asked for them.
    pub host_tx: Vec<(Instant, Transmit)>,
    /// Every byte put on the wire, both ways, in write order per direction.
    pub wire: Vec<WireByte>,
    /// T_REQ levels as the device saw them (`true`: asserted).
    pub treq: Vec<(Instant, bool)>,
    /// Safety net: the loop stops (and panics) after this virtual time.
    pub horizon: Instant,
}

impl Sim {
    /// An ST7580 bench at `baud`; the host gets `config` (its baud is
    /// overwritten).
    pub fn new(baud: u32, config: HostConfig) -> Self {
        Sim::new_in(Dialect::St7580, baud, config)
    }

    /// A bench of `dialect` at `baud`; the host gets `config` (its baud is
    /// overwritten), the device its reset timeouts.
    pub fn new_in(dialect: Dialect, baud: u32, config: HostConfig) -> Self {
        let config = HostConfig { baud, ..config };
        Sim {
            now: 0,
            baud,
            host: HostEngine::new(dialect, config),
            dev: DeviceEngine::new(dialect, baud),
            h2d: Line::new(dialect, Dir::HostToDev, baud),
            d2h: Line::new(dialect, Dir::DevToHost, baud),
            responder: None,
            host_events: Vec::new(),
            dev_events: Vec::new(),
            host_tx: Vec::new(),
            wire: Vec::new(),
            treq: Vec::new(),
            horizon: 3_600_000_000,
        }
    }

    /// A bench at `baud` with the default host settings.
    pub fn with_baud(baud: u32) -> Self {
        Sim::new(baud, HostConfig::default())
    }

    /// Lets `responder` answer the device's requests.
    pub fn responder(mut self, responder: Responder) -> Self {
        self.responder = Some(responder);
        self
    }

    /// Applies `fault` to the bytes going `dir` that match `pred`, at most
    /// `times` times (`None`: every time).
    pub fn inject(
        &mut self,
        dir: Dir,
        times: Option<usize>,
        fault: Fault,
        mut pred: impl FnMut(&ByteCtx) -> bool + 'static,
    ) {
        self.inject_with(dir, times, move |c| pred(c).then_some(fault));
    }

    /// Like [`Sim::inject`] with the fault chosen per byte.
    pub fn inject_with(
        &mut self,
        dir: Dir,
        times: Option<usize>,
        pred: impl FnMut(&ByteCtx) -> Option<Fault> + 'static,
    ) {
        let line = match dir {
            Dir::HostToDev => &mut self.h2d,
            Dir::DevToHost => &mut self.d2h,
        };
        line.injectors.push(Injector {
            pred: Box::new(pred),
            remaining: times,
        });
    }

    /// Submits a frame to the host now.
    pub fn submit(&mut self, frame: LocalFrame) -> Ticket {
        let t = self.host.submit(self.now, frame);
        self.pump();
        t
    }

    /// Submits a frame to the device now (an unsolicited indication).
    pub fn dev_submit(&mut self, frame: LocalFrame) {
        self.dev.submit(self.now, frame);
        self.pump();
    }

    /// Drains both engines until neither has anything to say.
    fn pump(&mut self) {
        loop {
            let mut progress = false;
            while let Some(tx) = self.host.poll_transmit() {
                progress = true;
                self.host_tx.push((self.now, tx.clone()));
                match tx {
                    Transmit::Bytes(b) => self.h2d.write(self.now, &b, &mut self.wire),
                    Transmit::TReq { asserted } => {
                        self.h2d.treq(self.now, asserted);
                    }
                }
            }
            while let Some(tx) = self.dev.poll_transmit() {
                progress = true;
                match tx {
                    Transmit::Bytes(b) => self.d2h.write(self.now, &b, &mut self.wire),
                    Transmit::TReq { .. } => panic!("the device has no T_REQ output"),
                }
            }
            while let Some(e) = self.host.poll_event() {
                progress = true;
                self.host_events.push((self.now, e));
            }
            let mut replies = Vec::new();
            while let Some(e) = self.dev.poll_event() {
                progress = true;
                if let (DeviceEvent::Request(f), Some(r)) = (&e, &mut self.responder) {
                    replies.extend(r(self.now, f));
                }
                self.dev_events.push((self.now, e));
            }
            for r in replies {
                self.dev.submit(self.now, r);
            }
            if !progress {
                break;
            }
        }
    }

    fn next_time(&self) -> Option<Instant> {
        [
            self.d2h.next_at(),
            self.h2d.next_at(),
            self.host.poll_timeout(),
            self.dev.poll_timeout(),
        ]
        .into_iter()
        .flatten()
        .min()
    }

    /// Runs everything due up to and including `end`, then sets the clock
    /// to `end`.
    pub fn run_until(&mut self, end: Instant) {
        self.run(end);
        self.now = self.now.max(end);
    }

    /// Runs everything due up to and including `end`; the clock stays at
    /// the last thing done.
    fn run(&mut self, end: Instant) {
        let mut same_instant = 0u32;
        self.pump();
        while let Some(next) = self.next_time() {
            if next > end {
                break;
            }
            assert!(
                next <= self.horizon,
                "still busy at the horizon ({} µs)",
                self.horizon
            );
            // A deadline already past is due now.
            let t = next.max(self.now);
            if t == self.now {
                same_instant += 1;
                assert!(
                    same_instant < 10_000,
                    "no progress at {t} µs: an engine keeps asking for the same instant"
                );
            } else {
                same_instant = 0;
            }
            self.now = t;
            while let Some(item) = self.d2h.pop_due(t) {
                if let Item::Byte { byte, .. } = item {
                    self.host.handle_rx(t, &[byte]);
                }
                self.pump();
            }
            while let Some(item) = self.h2d.pop_due(t) {
                match item {
                    Item::Byte { byte, .. } => self.dev.handle_rx(t, &[byte]),
                    Item::TReq { asserted, .. } => {
                        self.treq.push((t, asserted));
                        self.dev.set_treq(t, asserted);
                    }
                }
                self.pump();
            }
            if self.host.poll_timeout().is_some_and(|d| d <= t) {
                self.host.handle_timeout(t);
                self.pump();
            }
            if self.dev.poll_timeout().is_some_and(|d| d <= t) {
                self.dev.handle_timeout(t);
                self.pump();
            }
        }
    }

    /// Runs until nothing is in flight and no engine waits for a deadline;
    /// the clock stays at the last thing done.
    pub fn run_to_idle(&mut self) {
        self.run(Instant::MAX);
        assert_eq!(self.next_time(), None);
    }

    // ---- queries -------------------------------------------------------

    /// The bytes that went `dir`, in order, with their fate.
    pub fn wire(&self, dir: Dir) -> impl Iterator<Item = &WireByte> {
        self.wire.iter().filter(move |w| w.dir == dir)
    }

    /// The bytes received going `dir` (after faults).
    pub fn received(&self, dir: Dir) -> Vec<u8> {
        self.wire(dir).filter_map(|w| w.got).collect()
    }

    /// The bytes of the `n`-th frame sent `dir`.
    pub fn frame_bytes(&self, dir: Dir, n: usize) -> Vec<WireByte> {
        self.wire(dir)
            .filter(|w| matches!(w.part, Part::Frame { n: m, .. } if m == n))
            .copied()
            .collect()
    }

    /// When the last byte of the `n`-th frame sent `dir` was through.
    pub fn frame_end(&self, dir: Dir, n: usize) -> Instant {
        self.frame_bytes(dir, n).last().expect("no such frame").at
    }

    /// When the first byte of the `n`-th frame sent `dir` started.
    pub fn frame_start(&self, dir: Dir, n: usize) -> Instant {
        self.frame_bytes(dir, n)
            .first()
            .expect("no such frame")
            .start
    }

    /// Host events matching `f`, with their times.
    pub fn host_events_where(&self, f: impl Fn(&Event) -> bool) -> Vec<(Instant, Event)> {
        self.host_events
            .iter()
            .filter(|(_, e)| f(e))
            .cloned()
            .collect()
    }

    /// Device events matching `f`, with their times.
    pub fn dev_events_where(
        &self,
        f: impl Fn(&DeviceEvent) -> bool,
    ) -> Vec<(Instant, DeviceEvent)> {
        self.dev_events
            .iter()
            .filter(|(_, e)| f(e))
            .cloned()
            .collect()
    }

    /// The frames the device accepted as requests.
    pub fn requests(&self) -> Vec<LocalFrame> {
        self.dev_events
            .iter()
            .filter_map(|(_, e)| match e {
                DeviceEvent::Request(f) => Some(f.clone()),
                _ => None,
            })
            .collect()
    }

    /// The frames the host reported as [`Event::Frame`].
    pub fn host_frames(&self) -> Vec<LocalFrame> {
        self.host_events
            .iter()
            .filter_map(|(_, e)| match e {
                Event::Frame(f) => Some(f.clone()),
                _ => None,
            })
            .collect()
    }

    /// The elements the device sent, in order.
    pub fn dev_sent(&self) -> Vec<(Instant, Element)> {
        self.dev_events
            .iter()
            .filter_map(|(t, e)| match e {
                DeviceEvent::Sent(el) => Some((*t, el.clone())),
                _ => None,
            })
            .collect()
    }

    /// The elements the device received, in order.
    pub fn dev_received(&self) -> Vec<(Instant, Element)> {
        self.dev_events
            .iter()
            .filter_map(|(t, e)| match e {
                DeviceEvent::Received(el) => Some((*t, el.clone())),
                _ => None,
            })
            .collect()
    }
}

/// A small deterministic generator for the fault injector.
pub struct XorShift(pub u64);

impl XorShift {
    /// The next number.
    pub fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
}

/// Random faults: per byte, `drop_pm`/1000 of a loss or (half as often)
/// a stall of up to 30 ms, `corrupt_pm`/1000 of a damaged byte; at most
/// one fault per frame transmission. The limit is the checksum's, not the
/// engines': UM0932's checksum is a 16-bit sum, which two compensating
/// errors in one frame pass (see
/// `additive_checksum_misses_compensating_errors`), while it always sees a
/// single changed byte.
pub fn faults(seed: u64, drop_pm: u64, corrupt_pm: u64) -> impl FnMut(&ByteCtx) -> Option<Fault> {
    let mut rng = XorShift(seed | 1);
    let mut faulted_frame = None;
    move |c| {
        let r = rng.next() % 1000;
        if let Part::Frame { n, .. } = c.part {
            if faulted_frame == Some(n) {
                return None;
            }
            if r < drop_pm + corrupt_pm {
                faulted_frame = Some(n);
            }
        }
        if r < drop_pm / 2 {
            Some(Fault::Delay(rng.next() % (30 * MS)))
        } else if r < drop_pm {
            Some(Fault::Drop)
        } else if r < drop_pm + corrupt_pm {
            Some(Fault::Corrupt((rng.next() % 255 + 1) as u8))
        } else {
            None
        }
    }
}

/// The host's events by kind.
/// When the device sent each status message.
pub fn statuses_sent(sim: &Sim) -> Vec<Instant> {
    sim.dev_sent()
        .into_iter()
        .filter(|(_, e)| matches!(e, Element::Status(_)))
        .map(|(t, _)| t)
        .collect()
}

/// The first byte of `part` that went `dir`.
pub fn first_wire(sim: &Sim, dir: Dir, part: Part) -> WireByte {
    *sim.wire(dir)
        .find(|w| w.part == part)
        .expect("no such byte on the wire")
}

pub fn is_retry(e: &Event) -> bool {
    matches!(e, Event::Retry { .. })
}

/// See [`is_retry`].
pub fn is_failed(e: &Event) -> bool {
    matches!(e, Event::Failed(..))
}

/// See [`is_retry`].
pub fn is_delivered(e: &Event) -> bool {
    matches!(e, Event::Delivered(_))
}

/// See [`is_retry`].
pub fn is_repeat(e: &Event) -> bool {
    matches!(e, Event::Repeat(_))
}

/// Requests of `code` through a line with the [`faults`] of `seed`,
/// `drop_pm` and `corrupt_pm` both ways: each `(gap, data)` waits `gap` µs,
/// then goes with its number first (so every payload differs); runs to
/// idle. The payloads sent and their tickets.
pub fn lossy_requests(
    sim: &mut Sim,
    (seed, drop_pm, corrupt_pm): (u64, u64, u64),
    code: u8,
    reqs: Vec<(u32, Vec<u8>)>,
) -> (Vec<Vec<u8>>, Vec<Ticket>) {
    sim.horizon = 120_000_000;
    sim.inject_with(Dir::HostToDev, None, faults(seed, drop_pm, corrupt_pm));
    sim.inject_with(
        Dir::DevToHost,
        None,
        faults(seed.rotate_left(32), drop_pm, corrupt_pm),
    );
    let mut payloads = Vec::new();
    let mut tickets = Vec::new();
    for (i, (gap, data)) in reqs.into_iter().enumerate() {
        sim.run_until(sim.now + gap as u64);
        let mut d = vec![i as u8];
        d.extend(data);
        tickets.push(sim.submit(LocalFrame::new(code, d.clone())));
        payloads.push(d);
    }
    sim.run_to_idle();
    (payloads, tickets)
}

/// What every run of [`lossy_requests`] must show, whatever the line did:
/// each ticket ended exactly once, nothing is pending, and the device
/// accepted only requests of `code` that were submitted, in order (a
/// later one goes only once the earlier one is over).
pub fn check_lossy(
    sim: &Sim,
    code: u8,
    payloads: &[Vec<u8>],
    tickets: &[Ticket],
) -> Result<(), proptest::test_runner::TestCaseError> {
    use proptest::{prop_assert, prop_assert_eq};
    for t in tickets {
        let ends = sim.host_events_where(
            |e| matches!(e, Event::Delivered(x) | Event::Failed(x, _) if x == t),
        );
        prop_assert_eq!(ends.len(), 1, "{:?}: {:?}", t, ends);
    }
    prop_assert_eq!(sim.host.pending(), 0);
    let mut last = 0usize;
    for r in sim.requests() {
        prop_assert_eq!(r.code, code);
        let i = payloads.iter().position(|p| *p == r.data);
        prop_assert!(
            i.is_some(),
            "accepted a payload never submitted: {:02x?}",
            r.data
        );
        let i = i.unwrap();
        prop_assert!(i >= last, "request {} accepted after {}", i, last);
        last = i;
    }
    Ok(())
}
