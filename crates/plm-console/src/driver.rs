//! The loop every console session runs, written once (docs/architecture.md,
//! "One drive loop"): the modem session ([`crate::session`]) and the street
//! ([`crate::street`]) are layers ([`Layer`]) over it. The page's clock is
//! mapped onto the transport's ([`Pacer`], with a catch-up limit), the
//! transport's time runs in slices of at most [`SLICE`] straight to
//! whatever is due, within the tick's [`Budget`]; each step is plm-core's
//! [`plm_core::drive::turn`]; every ACK the host engine writes is timed
//! ([`ack`]).

pub mod ack;

use crate::transport::Transport;
use ack::{AckLatency, AckTimes};
use plm_core::app::Happening;
use plm_core::drive::{self, Engine, Io};
use plm_core::link::host::{Event, HostEngine};
use plm_core::link::Element;
use plm_core::time::{Duration, Instant, MS};
use std::convert::Infallible;

/// Longest step of the transport's time between two looks at the engine:
/// the host answers a modem frame at most this late (T_ACK is 40 ms).
pub const SLICE: Duration = MS;
/// How far the transport's time may be behind the page's clock before the
/// difference is given up: after the page was busy or hidden the
/// simulated world slows down rather than fast-forwarding.
pub const MAX_CATCH_UP: Duration = 100 * MS;
/// The same for the simulated modem (less than one exchange), whose time
/// otherwise replays a stall of the page frame by frame with a host that
/// answers at once: every frame of the replay counted the page's lag as
/// ACK latency again (issue 13: after a 35 ms stall, seven ACKs from 35
/// ms down by 5 ms). A real modem sees one late ACK and carries on from
/// there, as this does.
pub const SIM_CATCH_UP: Duration = 4 * MS;
/// How far `transport`'s time may trail the page's clock: a simulated
/// modem whose frames the host ACKs, of either chip ([`SIM_CATCH_UP`]);
/// a real port, or a simulated concentrator board that ACKs its modem
/// itself ([`MAX_CATCH_UP`]).
pub fn catch_up(transport: &dyn Transport, acks: bool) -> Duration {
    match transport.kind() {
        "Simulated" if acks => SIM_CATCH_UP,
        _ => MAX_CATCH_UP,
    }
}
/// How soon after an ACK the line counts as just quiet, µs of the page's
/// clock ([`Driver::just_acked`]): a tick or two.
pub const JUST_ACKED_US: f64 = 2_000.0;
/// How long one tick may keep the page busy, µs of the page's clock: past
/// it the transport's time stops short of the page's and catches up at the
/// next tick, so a simulated world the page cannot run in real time (a long
/// street during discovery) slows down instead of freezing the page.
pub const TICK_BUDGET_US: f64 = 12_000.0;

/// Maps the page's clock onto a transport's clock: the transport's time
/// follows the page's (`speed` times as fast, for a simulated world; 1
/// when 0), but never more than [`MAX_CATCH_UP`] at once.
#[derive(Debug, Clone, Copy, Default)]
pub struct Pacer {
    /// Page time (µs) at which the transport's clock read 0.
    origin: Option<f64>,
    /// The page's clock on the transport's clock at the last call.
    page_now: Instant,
    /// How much faster than the page's clock (0: as fast).
    pub speed: u32,
}

impl Pacer {
    /// Where the transport's time, now at `start`, should run to when the
    /// page's clock reads `page_us`.
    pub fn target(&mut self, page_us: f64, start: Instant) -> Instant {
        self.target_within(page_us, start, MAX_CATCH_UP, Some(start))
    }

    /// [`Pacer::target`], giving up a lag past `catch_up` behind `busy`,
    /// the transport's next event (a byte due, a timeout; `None`: none).
    /// Until then nothing happens behind the transport, so that time
    /// passes whole: an idle world is not late, and a request made after
    /// an idle while leaves when the page asked for it, not a catch-up
    /// limit after the world's last event.
    pub fn target_within(
        &mut self,
        page_us: f64,
        start: Instant,
        catch_up: Duration,
        busy: Option<Instant>,
    ) -> Instant {
        let speed = self.speed.max(1) as f64;
        let origin = *self.origin.get_or_insert(page_us - start as f64 / speed);
        let target = ((page_us - origin) * speed).max(0.0) as Instant;
        self.page_now = target;
        let Some(limit) = busy.map(|b| b.max(start) + catch_up) else {
            return target;
        };
        if target > limit {
            self.origin = Some(page_us - limit as f64 / speed);
            return limit;
        }
        target
    }

    /// The page's clock on the transport's clock at the last call (before
    /// any catch-up limit).
    pub fn page_now(&self) -> Instant {
        self.page_now
    }

    /// When the page's clock reaches the transport's instant `t` (µs of
    /// the page's clock), as the last call mapped them.
    pub fn page_at(&self, t: Instant) -> Option<f64> {
        let speed = self.speed.max(1) as f64;
        self.origin.map(|o| o + t as f64 / speed)
    }
}

/// The earliest of some instants.
pub fn earliest(times: impl IntoIterator<Item = Option<Instant>>) -> Option<Instant> {
    times.into_iter().flatten().min()
}

/// When a tick must hand the page back (see [`TICK_BUDGET_US`]).
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    clock: Option<fn() -> f64>,
    until: f64,
}

impl Budget {
    /// No limit: tests, and time that must pass whole.
    pub const UNLIMITED: Budget = Budget {
        clock: None,
        until: f64::INFINITY,
    };

    /// `us` from now on `clock` (µs).
    pub fn wall(clock: fn() -> f64, us: f64) -> Budget {
        Budget {
            clock: Some(clock),
            until: clock() + us,
        }
    }

    /// The budget's clock now (µs), if it has one.
    pub fn now(&self) -> Option<f64> {
        self.clock.map(|c| c())
    }

    /// Whether the time is up.
    pub fn spent(&self) -> bool {
        self.clock.is_some_and(|c| c() > self.until)
    }
}

/// What every session has: the transport, the page's clock mapped onto
/// it, the ACK latency and the work done.
#[derive(Default)]
pub struct Driver {
    /// The transport (none: nothing runs).
    pub transport: Option<Box<dyn Transport>>,
    /// The page's clock mapped onto the transport's.
    pub pacer: Pacer,
    /// The page's clock at the current tick, on the transport's clock.
    page_now: Instant,
    /// The page's clock (µs) at the tick running now.
    tick_at: f64,
    /// Whether the session's engine ACKs a modem's frames ([`Layer::acks`]).
    acks: bool,
    ack_times: AckTimes,
    /// Transport time run by the ticks, and the page's time that took.
    work: (Duration, f64),
}

impl Driver {
    /// A driver over `transport`.
    pub fn new(transport: Option<Box<dyn Transport>>) -> Driver {
        Driver {
            transport,
            ..Driver::default()
        }
    }

    /// The transport's clock (0 when there is none).
    pub fn now(&self) -> Instant {
        self.transport.as_ref().map_or(0, |t| t.now())
    }

    /// The page's clock (µs) at the tick running now.
    pub fn tick_at(&self) -> f64 {
        self.tick_at
    }

    /// The ACK latency so far.
    pub fn ack_latency(&self) -> AckLatency {
        self.ack_times.stats()
    }

    /// Each ACK timed: when it was written (the page's clock, µs) and its
    /// latency on the transport's clock and on the page's.
    pub fn ack_samples(&self) -> Vec<(f64, Duration, Duration)> {
        self.ack_times.samples()
    }

    /// Whether the host engine ACKed a frame of the modem within
    /// [`JUST_ACKED_US`] of the page's clock `page_us`: the line is quiet
    /// for a while then (the modem's next frame is the next power line
    /// frame it hears, a slot or more later).
    pub fn just_acked(&self, page_us: f64) -> bool {
        self.ack_times
            .last_written()
            .is_some_and(|w| page_us - w <= JUST_ACKED_US)
    }

    /// Transport time the ticks have run (µs), and the page's time that
    /// took (µs): a simulated world's speed.
    pub fn work(&self) -> (Duration, f64) {
        self.work
    }

    /// When the page must run to its clock's resolution (µs of the
    /// page's clock), for a host that ACKs the modem's frames: the bytes
    /// on the UART have arrived one way, and a frame may end there
    /// ([`Transport::uart_due`]).
    pub fn exact_wake(&self) -> Option<f64> {
        let due = self.transport.as_ref()?.uart_due().filter(|_| self.acks)?;
        self.pacer.page_at(due)
    }

    /// The host engine wrote an ACK for the frame whose last byte came at
    /// `at`: one sample, on both clocks.
    fn acked(&mut self, at: Instant) {
        let written = self.now();
        self.ack_times.record(
            written.saturating_sub(at),
            self.page_now.max(written).saturating_sub(at),
            self.tick_at,
        );
    }
}

/// The engine of any session, as the driver sees it: its events are the
/// concentrator's [`Happening`]s, a host link engine's being
/// [`Happening::Link`] ([`HostLink`]). One type, so that the loop below
/// is compiled once for every session.
pub type AnyEngine = dyn Engine<Event = Happening>;

/// A host link engine whose events are [`Happening::Link`].
pub struct HostLink(pub HostEngine);

impl Engine for HostLink {
    type Event = Happening;
    fn handle_rx(&mut self, at: Instant, bytes: &[u8]) {
        self.0.handle_rx(at, bytes)
    }
    fn handle_timeout(&mut self, now: Instant) {
        self.0.handle_timeout(now)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        self.0.poll_timeout()
    }
    fn poll_transmit(&mut self) -> Option<plm_core::drive::Transmit> {
        self.0.poll_transmit()
    }
    fn poll_event(&mut self) -> Option<Happening> {
        self.0.poll_event().map(Happening::Link)
    }
}

impl std::ops::Deref for HostLink {
    type Target = HostEngine;
    fn deref(&self) -> &HostEngine {
        &self.0
    }
}

impl std::ops::DerefMut for HostLink {
    fn deref_mut(&mut self) -> &mut HostEngine {
        &mut self.0
    }
}

/// Whether `event` is an ACK the host engine wrote to a modem's frame.
fn is_ack(event: &Happening) -> bool {
    matches!(event, Happening::Link(Event::Sent(Element::Ack)))
}

/// A session on the driver: an engine and what the session does with it.
pub trait Layer {
    /// Whether the engine ACKs a modem's frames (a host link engine):
    /// its ACKs are timed, and a simulated modem's time trails the page
    /// little ([`catch_up`]).
    fn acks(&self) -> bool;
    /// The engine and the driver, borrowed together.
    fn parts(&mut self) -> (&mut AnyEngine, &mut Driver);
    /// An event of the engine, at the instant it happened.
    fn on_event(&mut self, at: Instant, event: Happening);
    /// T_REQ was set on the transport.
    fn on_treq(&mut self, _asserted: bool) {}
    /// The next instant the engine, the world behind the transport or the
    /// session's own work has something due.
    fn next_due(&self) -> Option<Instant>;
    /// The next instant the link or the world behind the transport does
    /// something of its own (a request waiting to be sent left out):
    /// until then time passes whole ([`Pacer::target_within`]).
    fn world_due(&self) -> Option<Instant> {
        self.next_due()
    }
    /// Whether time may run straight to `target`: nothing in flight and
    /// nothing due before it.
    fn idle_until(&self, _target: Instant) -> bool {
        false
    }
    /// The session's own work at `now`, after each turn (requests started,
    /// answers timed out, discovery, sweeps).
    fn at(&mut self, now: Instant);
    /// Whether the tick stops here: replies are to be handed out at once
    /// (a reply may send the next request, which then leaves at once
    /// rather than when the page next catches up).
    fn stop(&self) -> bool {
        false
    }
}

/// The transport as plm-core's drive loop sees it; T_REQ levels set are
/// kept for the session.
struct Port<'a> {
    transport: &'a mut dyn Transport,
    treq: &'a mut Vec<bool>,
}

impl Io for Port<'_> {
    type Error = Infallible;
    fn now(&self) -> Instant {
        self.transport.now()
    }
    fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), Infallible> {
        rx.extend(self.transport.poll(until));
        Ok(())
    }
    fn write(&mut self, bytes: &[u8]) -> Result<(), Infallible> {
        self.transport.write(bytes);
        Ok(())
    }
    fn set_treq(&mut self, asserted: bool) -> Result<(), Infallible> {
        self.transport.set_treq(asserted);
        self.treq.push(asserted);
        Ok(())
    }
}

/// Lets the transport's time catch up with the page's clock `page_us`
/// (µs, any origin), within `budget`.
pub fn tick(layer: &mut dyn Layer, page_us: f64, budget: Budget) {
    let acks = layer.acks();
    let busy = layer.world_due();
    let (_, d) = layer.parts();
    let Some((start, catch_up)) = d
        .transport
        .as_ref()
        .map(|t| (t.now(), catch_up(t.as_ref(), acks)))
    else {
        return;
    };
    let target = d.pacer.target_within(page_us, start, catch_up, busy);
    d.page_now = d.pacer.page_now();
    d.tick_at = page_us;
    d.acks = acks;
    let began = budget.now();
    run_within(layer, start, target, budget);
    let (_, d) = layer.parts();
    d.work.0 += d.now().saturating_sub(start);
    d.work.1 += budget
        .now()
        .zip(began)
        .map_or(0.0, |(end, began)| end - began);
}

/// Runs the transport's time from `start` to `target`, as fast as the
/// budget allows: in steps of at most [`SLICE`], straight to whatever is
/// due next, so that a byte is taken, and ACKed, at the instant it
/// arrives (UM0932 3.2.8, T_ACK).
pub fn run_within(layer: &mut dyn Layer, start: Instant, target: Instant, budget: Budget) {
    let mut t = start;
    while t < target && !budget.spent() {
        let mut next = (t + SLICE).min(target);
        if let Some(d) = layer.next_due().filter(|d| *d > t && *d < next) {
            next = d;
        }
        if layer.idle_until(target) {
            next = target;
        }
        let (mut events, mut treq) = (Vec::new(), Vec::new());
        let (engine, d) = layer.parts();
        let Some(transport) = d.transport.as_deref_mut() else {
            return;
        };
        let mut port = Port {
            transport,
            treq: &mut treq,
        };
        let Ok(now) = drive::turn(engine, &mut port, next, |e, at| {
            events.extend(std::iter::from_fn(|| e.poll_event()).map(|ev| (at, ev)));
        });
        hand_over(layer, events, treq, now);
        layer.at(now);
        flush(layer, now);
        t = if now > t { now } else { next };
        if layer.stop() {
            break;
        }
    }
}

/// Writes now what the session gave the engine, and hands the events it
/// caused to the session.
pub fn flush(layer: &mut dyn Layer, now: Instant) {
    let mut treq = Vec::new();
    let (engine, d) = layer.parts();
    if let Some(transport) = d.transport.as_deref_mut() {
        let Ok(()) = drive::flush(
            engine,
            &mut Port {
                transport,
                treq: &mut treq,
            },
        );
    }
    hand_over(layer, Vec::new(), treq, now);
}

/// T_REQ levels set and the engine's events (`events`, each at its byte's
/// arrival, then the rest at `now`) to the session, in order, each ACK
/// timed.
fn hand_over(
    layer: &mut dyn Layer,
    mut events: Vec<(Instant, Happening)>,
    treq: Vec<bool>,
    now: Instant,
) {
    let (engine, _) = layer.parts();
    events.extend(std::iter::from_fn(|| engine.poll_event()).map(|ev| (now, ev)));
    for asserted in treq {
        layer.on_treq(asserted);
    }
    let acks = layer.acks();
    for (at, e) in events {
        if acks && is_ack(&e) {
            layer.parts().1.acked(at);
        }
        layer.on_event(at, e);
    }
}
