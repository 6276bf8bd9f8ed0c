//! The street session: plm-core's [`Concentrator`] driven over a
//! transport with the page's timers, and the fleet of lamps it learns
//! about (discovery, a background sweep, dimming, clocks), with alerts
//! when a lamp fails or stops answering.
//!
//! Like [`crate::session`], it has no browser in it: time comes in as an
//! argument, so its tests run natively against a simulated street.

mod campaign;

pub use campaign::Campaign;

use crate::driver::{self, earliest, AnyEngine, Budget, Driver, Layer};
use crate::throttle::Throttle;
use crate::transport::{LinkState, Transport};
use plm_core::app::discovery::DiscoveryConfig;
use plm_core::app::energy::Meter;
use plm_core::app::hid::{self, Hid, LampState};
use plm_core::app::job::{Begun, Job, Run};
use plm_core::app::service::{Clock, Discovered, Service};
use plm_core::app::sweep::{Known, Reading, Round, RoundConfig};
use plm_core::app::{
    Address, AppEvent, AppFrame, Ballast, Concentrator, Discovery, Happening, Message, Request,
    RequestId, RequesterConfig,
};
use plm_core::decode::{Decoded, Decoder};
use plm_core::link::host;
use plm_core::link::{Dialect, Element, Source};
use plm_core::time::{Duration, Instant, MS};
use std::collections::{BTreeMap, VecDeque};

/// Samples of a lamp's history kept for its plots.
pub const HISTORY: usize = 240;
/// Pause between two sweeps of the street.
pub const SWEEP_PAUSE: Duration = 5_000 * MS;
/// The Street and Firmware update views are drawn again at most five
/// times a second; a change waits at most this and one tick
/// (`stores::IDLE_WAKE_US`).
pub const STREET_DRAW_US: f64 = 200_000.0;
/// Through a bare modem, while the discovery or the sweep has the line,
/// the views are drawn at its quiet moments ([`StreetSession::send_next`]);
/// without one, after this at the latest.
pub const STREET_DRAW_LATE_US: f64 = 1_000_000.0;

/// One reading of a lamp, for its history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// When, on the session's clock.
    pub at: Instant,
    /// Lamp power, W.
    pub power: u16,
    /// Board temperature, °C.
    pub temperature: i16,
    /// SNR, dB, when known.
    pub snr: Option<i8>,
}

/// What the console knows of one lamp.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Lamp {
    /// Its board's address.
    pub address: Address,
    /// What discovery said of it.
    pub discovered: Option<Discovered>,
    /// Its ballast as last read.
    pub ballast: Option<Ballast>,
    /// Dimming last set and acknowledged, %.
    pub dimming: Option<u8>,
    /// Signal quality, dB: the SNR of its last frame (bare modem), or
    /// what the board reports.
    pub snr: Option<i8>,
    /// When that figure was got (a sweep asks the oldest again).
    pub snr_at: Option<Instant>,
    /// Its clock as last read.
    pub clock: Option<Clock>,
    /// When it last answered.
    pub last_seen: Option<Instant>,
    /// Why it does not answer, if it stopped.
    pub unreachable: Option<String>,
    /// Recent readings, oldest first.
    pub history: VecDeque<Sample>,
    /// Its energy, estimated from every power reading taken.
    pub energy: Meter,
}

impl Lamp {
    /// Its lamp state, if read.
    pub fn state(&self) -> Option<LampState> {
        self.ballast.map(|b| b.state())
    }
}

/// Something a technician must see.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Alert {
    /// When.
    pub at: Instant,
    /// Which lamp.
    pub address: Address,
    /// What, in words.
    pub what: String,
}

/// Progress of the background sweep.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Sweep {
    /// Whether the sweep runs.
    pub on: bool,
    /// Lamps read in this round.
    pub done: usize,
    /// Lamps in this round.
    pub total: usize,
    /// Completed rounds.
    pub rounds: u64,
}

/// Called once with the answer to a request made from a view.
pub type StreetReply = Box<dyn FnOnce(Result<Message, String>)>;

enum Purpose {
    /// Read every parameter.
    Read(Address),
    Dim(Address, u8),
    View(StreetReply),
    /// A request of the update campaign (`true`: a broadcast).
    Update(bool),
}

/// The job that has the street's line: a discovery or the sweep's round
/// (never both), its requests and what boards send routed by plm-core's
/// [`Run`], as `plm board`'s and plm-sim's street's jobs are.
enum StreetJob {
    Discovery(Begun<Discovery>),
    Round(Round),
}

impl StreetJob {
    fn get(&self) -> &dyn Job {
        match self {
            StreetJob::Discovery(d) => d,
            StreetJob::Round(r) => r,
        }
    }
    fn get_mut(&mut self) -> &mut dyn Job {
        match self {
            StreetJob::Discovery(d) => d,
            StreetJob::Round(r) => r,
        }
    }
}

impl Job for StreetJob {
    fn poll(&mut self, now: Instant) -> Option<Request> {
        self.get_mut().poll(now)
    }
    fn on_answer(&mut self, now: Instant, answer: Result<&Message, &str>) {
        self.get_mut().on_answer(now, answer)
    }
    fn hear(&mut self, address: Address, message: &Message) -> Option<AppFrame> {
        self.get_mut().hear(address, message)
    }
    fn poll_timeout(&self) -> Option<Instant> {
        self.get().poll_timeout()
    }
    fn is_done(&self) -> bool {
        self.get().is_done()
    }
}

/// What a tick produced.
#[derive(Default)]
pub struct StreetTick {
    /// The fleet changed.
    pub changed: bool,
    /// New alerts.
    pub alerts: Vec<Alert>,
    /// Replies for the views, with their outcomes.
    pub replies: Vec<(StreetReply, Result<Message, String>)>,
    /// Frames on the wire (USART elements, or the modem's link), as
    /// `plm decode` names them, with their times.
    pub traffic: Vec<(Instant, Decoded)>,
    /// Frames the console sent towards the street (in [`StreetSession::hand_out`]'s
    /// ticks: since the views were last drawn).
    pub sent: u64,
    /// The update campaign changed (to save it, and to show it).
    pub campaign: bool,
    /// The street found changed: a lamp heard, a new session, a new
    /// release (to remember it, [`StreetSession::remembered`]; in
    /// [`StreetSession::hand_out`]'s ticks, when the views are drawn).
    pub found: bool,
    /// The street's views are to be drawn now (at most every
    /// [`STREET_DRAW_US`]).
    pub show: bool,
}

/// The street session.
pub struct StreetSession {
    /// The transport, the page's clock on it, the ACK latency, the work.
    drive: Driver,
    conc: Concentrator,
    /// The discovery or the sweep's round under way.
    job: Option<Run<StreetJob>>,
    /// Boards the discovery had found when its current frame began (its
    /// belief of those left is updated at the end of each frame).
    found_before_frame: usize,
    session_no: u8,
    /// A street recalled: once its lamps are read, discovery looks for
    /// new ones.
    look_for_new: bool,
    sweep: Sweep,
    next_sweep: Option<Instant>,
    fleet: BTreeMap<Address, Lamp>,
    /// The views' requests that wait for the round's slots to close.
    held: Vec<(Request, Purpose)>,
    /// What each request under way is for (a few at a time: a list).
    purposes: Vec<(RequestId, Purpose)>,
    /// Names the modem's host-interface traffic (bare modem profile).
    decoder: Decoder,
    out: StreetTick,
    campaign: Option<Campaign>,
    /// When the street's views were last drawn, and whether a change
    /// waits.
    shown: Throttle,
    /// A draw was handed out at a quiet moment of the line: nothing is
    /// sent until the page has painted it.
    hold: crate::wake::Draw,
}

impl StreetSession {
    /// A session over `transport` with `conc` (a board USART or a bare
    /// modem concentrator, as the connection profile says).
    pub fn new(transport: Box<dyn Transport>, conc: Concentrator) -> Self {
        StreetSession {
            drive: Driver::new(Some(transport)),
            conc,
            job: None,
            found_before_frame: 0,
            session_no: 0,
            look_for_new: false,
            sweep: Sweep::default(),
            next_sweep: None,
            fleet: BTreeMap::new(),
            held: Vec::new(),
            purposes: Vec::new(),
            decoder: Decoder::new(Dialect::St7580, Source::Any),
            out: StreetTick::default(),
            campaign: None,
            shown: Throttle::new(STREET_DRAW_US),
            hold: Default::default(),
        }
    }

    /// A session with nothing connected (another profile is in use).
    pub fn idle() -> Self {
        let mut s = Self::new(
            Box::new(crate::transport::sim::SimTransport::new(1, 57_600, 0)),
            Concentrator::usart(RequesterConfig::default()),
        );
        s.drive.transport = None;
        s
    }

    /// A session through a concentrator board's USART.
    pub fn via_board(transport: Box<dyn Transport>) -> Self {
        Self::new(transport, Concentrator::usart(RequesterConfig::default()))
    }

    /// Runs a simulated street `speed` times as fast as the page's clock.
    pub fn set_speed(&mut self, speed: u32) {
        self.drive.pacer.speed = speed;
    }

    /// The transport.
    pub fn transport_mut(&mut self) -> Option<&mut (dyn Transport + 'static)> {
        self.drive.transport.as_deref_mut()
    }

    /// Whether bytes flow.
    pub fn state(&self) -> LinkState {
        self.drive
            .transport
            .as_ref()
            .map_or(LinkState::Disconnected("not connected".into()), |t| {
                t.state()
            })
    }

    /// The transport's clock.
    pub fn now(&self) -> Instant {
        self.drive.now()
    }

    /// Transport time the page's ticks have run (µs), and the page's
    /// time that took (µs, the views' not counted): with a simulated
    /// street, its simulated seconds per wall second.
    pub fn work(&self) -> (Duration, f64) {
        self.drive.work()
    }

    /// Its drive loop: how quickly the console ACKs the bare modem's
    /// frames (none through a board, which ACKs its modem itself).
    pub fn driver(&self) -> &Driver {
        &self.drive
    }

    /// The lamps known so far.
    pub fn fleet(&self) -> &BTreeMap<Address, Lamp> {
        &self.fleet
    }

    /// The sweep's progress.
    pub fn sweep(&self) -> Sweep {
        self.sweep
    }

    /// Whether a discovery is running: the boards found so far and how
    /// many it believes are left (less those heard since its belief was
    /// last updated).
    pub fn discovering(&self) -> Option<(usize, usize)> {
        self.discovery().map(|d| {
            let found = d.found().len();
            let heard = found.saturating_sub(self.found_before_frame);
            (found, (d.left() - heard as f64 + 0.5).max(0.0) as usize)
        })
    }

    /// Requests not yet answered.
    pub fn pending(&self) -> usize {
        self.conc.requester().pending()
    }

    /// Starts a discovery (a new session: every board answers again).
    pub fn discover(&mut self) {
        let now = self.now();
        self.session_no = self.session_no.wrapping_add(1);
        self.look_for_new = false;
        let expected = self.fleet.len().max(12);
        let (d, first) = Discovery::start(now, DiscoveryConfig::new(self.session_no, expected));
        let job = StreetJob::Discovery(Begun::new(d, Some(first)));
        self.job = Some(Run::new(job));
        self.found_before_frame = 0;
        self.out.found = true;
        self.run_discovery(now);
        let now = self.now();
        driver::flush(self, now);
    }

    /// Numbers the sessions of the discoveries to come from `last` on
    /// (the next is `last + 1`).
    pub fn set_session(&mut self, last: u8) {
        self.session_no = last;
    }

    /// Starts from a street found earlier in discovery session `session`
    /// ([`StreetSession::remembered`]): its lamps are in the fleet at
    /// once and read at once; then a discovery of the same session looks
    /// for new ones only (the boards heard in it stay quiet; one that
    /// restarted answers and is heard again).
    /// A street of no lamp is discovered again, in a new session.
    pub fn recall(&mut self, session: u8, known: Vec<(Address, Discovered)>) {
        self.session_no = session;
        if known.is_empty() {
            return self.discover();
        }
        for (a, d) in known {
            let lamp = self.lamp(a);
            lamp.discovered = Some(d);
            lamp.snr = Some(d.snr as i8);
        }
        self.look_for_new = true;
        self.out.changed = true;
        self.set_sweep(true);
        self.sweep.total = self.fleet.len();
    }

    /// What to remember of the street: the discovery session its lamps
    /// were heard in, and each lamp discovery heard with what it said.
    pub fn remembered(&self) -> (u8, Vec<(Address, Discovered)>) {
        let lamps = self
            .fleet
            .values()
            .filter_map(|l| Some((l.address, l.discovered?)))
            .collect();
        (self.session_no, lamps)
    }

    /// Looks for boards not in the fleet, in the session its lamps were
    /// heard in: one new board expected.
    fn look_for_new(&mut self, now: Instant) {
        self.look_for_new = false;
        let (_, known) = self.remembered();
        let config = DiscoveryConfig::new(self.session_no, 1);
        self.found_before_frame = known.len();
        let (d, first) = Discovery::resume(now, config, known);
        let job = StreetJob::Discovery(Begun::new(d, Some(first)));
        self.job = Some(Run::new(job));
        self.out.changed = true;
        // Remembered again: the connection was used last.
        self.out.found = true;
        self.run_discovery(now);
    }

    /// Turns the background sweep on or off.
    pub fn set_sweep(&mut self, on: bool) {
        self.sweep.on = on;
        if on && self.round().is_none() {
            self.next_sweep = Some(self.now());
        }
        if !on && self.round().is_some() {
            self.job = None;
        }
        if !on {
            self.sweep.total = 0;
            self.next_sweep = None;
        }
        self.out.changed = true;
    }

    /// Reads every parameter of one lamp now.
    pub fn read(&mut self, address: Address) {
        self.submit(
            Request::to(address, Message::Hid(Hid::Get(hid::ALL))),
            Purpose::Read(address),
        );
    }

    /// Dims one lamp, or every lamp with `None` (broadcast). Refused
    /// before anything is sent when the value is not 0-100.
    pub fn dim(&mut self, target: Option<Address>, level: u8) -> Result<(), String> {
        let m = Message::Hid(Hid::Dimming(level));
        m.validate()?;
        match target {
            Some(a) => self.submit(Request::to(a, m), Purpose::Dim(a, level)),
            None => {
                self.submit(Request::all(m), Purpose::View(Box::new(|_| {})));
                for lamp in self.fleet.values_mut() {
                    lamp.dimming = Some(level);
                }
                // Read the street again soon to see the power follow.
                self.next_sweep = Some(self.now() + 2_000 * MS);
            }
        }
        Ok(())
    }

    /// Sends any request from a view; `reply` gets the answer. Refused
    /// before anything is sent when the board would refuse it.
    pub fn request(&mut self, request: Request, reply: StreetReply) -> Result<(), String> {
        request.message.validate()?;
        self.submit(request, Purpose::View(reply));
        Ok(())
    }

    fn submit(&mut self, request: Request, purpose: Purpose) {
        if let LinkState::Disconnected(why) = self.state() {
            if let Purpose::View(r) = purpose {
                self.out.replies.push((r, Err(why)));
            }
            return;
        }
        let now = self.now();
        // Lamps answer in their slots: a frame sent now would collide.
        if self.slots_open(now) {
            self.held.push((request, purpose));
            return;
        }
        let id = self.conc.submit(now, request);
        self.purposes.push((id, purpose));
        let now = self.now();
        driver::flush(self, now);
    }

    /// Whether the discovery's or the sweep's next request is to wait for
    /// the street's views to be drawn: through a bare modem, when they are
    /// due, the line is quiet now (the last request's fate known, no
    /// window open), so the draw is handed out at the tick's end and the
    /// request goes once the page has painted it
    /// ([`StreetSession::hold_for_draw`], [`crate::wake::Draw`]). A draw
    /// while the modem's frames may end would hold up their ACKs (T_ACK,
    /// UM0932 3.2.8). Through a board, the board ACKs its modem: nothing
    /// waits.
    fn draw_first(&self) -> bool {
        let changed = self.out.changed || self.out.sent > 0;
        self.via_modem() && self.shown.due(changed, self.drive.tick_at())
    }

    /// The job's request was held back ([`StreetSession::draw_first`]):
    /// the views are drawn at the tick's end, and nothing is sent until
    /// the page has painted them.
    fn hold_for_draw(&mut self) {
        self.out.show = self.shown.show_after(true, self.drive.tick_at(), 0.0);
        self.hold.begin();
    }

    /// Whether the round's lamps (or new boards) may be answering now.
    fn slots_open(&self, now: Instant) -> bool {
        let window = self.round().and_then(|r| r.poll_timeout());
        window.is_some_and(|t| t > now)
    }

    /// Sends what waited for the slots to close or the views' draw.
    fn release_held(&mut self, now: Instant) {
        if !self.slots_open(now) && !self.hold.pending() {
            for (request, purpose) in std::mem::take(&mut self.held) {
                self.submit(request, purpose);
            }
        }
    }

    /// What happened since the last call, without letting time pass.
    pub fn take(&mut self) -> StreetTick {
        std::mem::take(&mut self.out)
    }

    /// What happened since the last call, without letting time pass, and
    /// whether the views are to be drawn at the page's clock `page_us`:
    /// through a bare modem, while the discovery or the sweep has the
    /// line, at its quiet moments ([`StreetSession::send_next`]) or after
    /// [`STREET_DRAW_LATE_US`]; else at most every [`STREET_DRAW_US`].
    pub fn hand_out(&mut self, page_us: f64) -> StreetTick {
        let busy = self.via_modem() && self.job.is_some();
        let after = if busy {
            STREET_DRAW_LATE_US
        } else {
            STREET_DRAW_US
        };
        let changed = self.out.changed || self.out.sent > 0;
        self.out.show |= self.shown.show_after(changed, page_us, after);
        let tick = self.take();
        // Counted on until the views show it; the street found is kept
        // then too (the browser's storage written at a quiet moment).
        if !tick.show {
            self.out.sent = tick.sent;
            self.out.found = tick.found;
        }
        tick
    }

    /// Lets the transport's time catch up with the page's clock.
    pub fn tick(&mut self, page_us: f64, budget: Budget) -> StreetTick {
        self.hold.settle();
        if let LinkState::Disconnected(why) = self.state() {
            if self.conc.requester().pending() > 0 {
                self.conc.abort_all(&why);
                let now = self.now();
                driver::flush(self, now);
            }
        }
        driver::tick(self, page_us, budget);
        self.hand_out(page_us)
    }

    /// Runs the street as fast as possible up to `target` (tests).
    /// The replies wait in [`StreetSession::take`].
    pub fn run_until(&mut self, start: Instant, target: Instant) {
        let mut t = start;
        while t < target && self.drive.transport.is_some() {
            self.hold.settle();
            driver::run_within(self, t, target, Budget::UNLIMITED);
            t = self.now();
        }
    }

    /// The next instant on the transport's clock at which something is
    /// due: the concentrator's, the discovery's, the sweep's and the
    /// update's deadlines, and the transport's next event.
    pub fn next_due(&self) -> Option<Instant> {
        // What a draw holds goes once the page has painted it, which runs
        // the page again ([`crate::wake::Draw`]).
        let drawing = self.hold.pending();
        earliest([
            self.conc.poll_timeout(),
            self.job
                .as_ref()
                .filter(|j| !(drawing && j.is_held()))
                .and_then(|j| j.poll_timeout()),
            self.next_sweep,
            (!self.held.is_empty() && !self.slots_open(self.now()) && !drawing).then(|| self.now()),
            self.update_timeout(),
            self.drive.transport.as_ref().and_then(|t| t.next_event()),
        ])
    }

    /// [`StreetSession::next_due`] on the page's clock (µs).
    pub fn next_wake(&self) -> Option<f64> {
        self.next_due().and_then(|t| self.drive.pacer.page_at(t))
    }

    /// The discovery under way.
    fn discovery(&self) -> Option<&Discovery> {
        match self.job.as_ref()?.job() {
            StreetJob::Discovery(d) => Some(&d.job),
            StreetJob::Round(_) => None,
        }
    }

    /// The sweep's round under way (plm-core's reads of the street).
    fn round(&self) -> Option<&Round> {
        match self.job.as_ref()?.job() {
            StreetJob::Round(r) => Some(r),
            StreetJob::Discovery(_) => None,
        }
    }

    /// Sends the job's next request, unless the views are to be drawn
    /// first ([`StreetSession::draw_first`]); returns whether one was sent,
    /// and the job once it is over.
    fn pump_job(&mut self, now: Instant) -> (bool, Option<StreetJob>) {
        let hold = self.draw_first();
        let Some(run) = self.job.as_mut() else {
            return (false, None);
        };
        let sent = run.pump_unless(&mut self.conc, now, hold).is_some();
        if run.is_held() {
            self.hold_for_draw();
        } else if run.is_done() {
            return (sent, self.job.take().map(Run::into_job));
        }
        (sent, None)
    }

    fn run_discovery(&mut self, now: Instant) {
        let Some(found) = self.discovery().map(|d| d.found().len()) else {
            return;
        };
        if !self.held.is_empty() {
            return;
        }
        let (sent, done) = self.pump_job(now);
        if sent {
            self.found_before_frame = found;
            self.out.changed = true;
        }
        if done.is_some() {
            self.out.changed = true;
            // A street just found is read at once.
            self.next_sweep = Some(now);
            self.sweep.on = true;
        }
    }

    /// The round a sweep starts now: every lamp of the fleet, the SNR
    /// asked through a board only (through a bare modem every frame heard
    /// carries it), and the probe for new boards unless a discovery looks
    /// for them after this round (docs/console.md, "Street").
    fn new_round(&self) -> Round {
        let lamps = self
            .fleet
            .values()
            .map(|l| Known {
                address: l.address,
                discovered: l.discovered,
                snr_at: l.snr_at,
            })
            .collect();
        let mut config = RoundConfig::sweep(self.session_no, !self.via_modem());
        if self.look_for_new {
            config.probe = None;
        }
        Round::new(lamps, config)
    }

    fn via_modem(&self) -> bool {
        matches!(self.conc.carrier(), plm_core::app::Carrier::Modem { .. })
    }

    fn run_sweep(&mut self, now: Instant) {
        // A firmware update has the line to itself.
        let updating = self.campaign.as_ref().is_some_and(|c| !c.update.is_done());
        if !self.sweep.on || self.discovery().is_some() || updating {
            return;
        }
        if self.job.is_none() && self.next_sweep.is_some_and(|t| t <= now) {
            self.next_sweep = None;
            self.job = Some(Run::new(StreetJob::Round(self.new_round())));
            self.sweep.total = self.fleet.len();
            self.sweep.done = 0;
            self.out.changed = true;
        }
        // One request at a time: the requester paces the line.
        if self.conc.requester().pending() > 0 || !self.held.is_empty() {
            return;
        }
        if let (_, Some(StreetJob::Round(round))) = self.pump_job(now) {
            let new = round.found_new();
            self.sweep.rounds += 1;
            self.sweep.total = 0;
            // Sooner when a dimming of every lamp asked for it.
            let pause = now + SWEEP_PAUSE;
            self.next_sweep = Some(self.next_sweep.map_or(pause, |t| t.min(pause)));
            self.out.changed = true;
            // A probe heard a new board: a discovery names it and looks
            // for more.
            if self.look_for_new || new {
                self.look_for_new(now);
            }
        }
    }

    /// What the round learned, into the fleet.
    fn take_readings(&mut self, now: Instant) {
        let modem = self.via_modem();
        let Some(StreetJob::Round(round)) = self.job.as_mut().map(Run::job_mut) else {
            return;
        };
        let readings = round.take_readings();
        self.sweep.done = round.settled();
        for r in readings {
            match r {
                Reading::Value(a, value) => {
                    self.answered(now, a);
                    self.ballast(now, a, &value);
                }
                Reading::Snr(a, v) if !modem => {
                    let lamp = self.lamp(a);
                    lamp.snr = Some(v as i8);
                    lamp.snr_at = Some(now);
                }
                Reading::Heard(a, d) => self.discovered(now, a, d),
                _ => {}
            }
        }
        self.out.changed = true;
    }

    /// A discovery reply: the lamp is in the fleet, with what it said.
    fn discovered(&mut self, now: Instant, address: Address, r: Discovered) {
        let modem = self.via_modem();
        let lamp = self.lamp(address);
        lamp.discovered = Some(r);
        // Through a board it is the board's own figure, the latest; through
        // a bare modem the SNR of each frame heard is better.
        if !modem || lamp.snr.is_none() {
            lamp.snr = Some(r.snr as i8);
            lamp.snr_at = Some(now);
        }
        lamp.last_seen = Some(now);
        self.out.changed = true;
        self.out.found = true;
    }

    fn on_happening(&mut self, now: Instant, h: Happening) {
        // The job's first: it hears a board's frame (its answer is sent)
        // and takes its request's fate.
        let job = (self.job.as_mut()).is_some_and(|run| run.handle(&mut self.conc, now, &h));
        match h {
            Happening::App(e) => self.on_app(now, e, job),
            Happening::Heard { address, snr } => {
                if let Some(l) = self.fleet.get_mut(&address).filter(|_| snr.is_some()) {
                    l.snr = snr;
                    l.snr_at = Some(now);
                }
            }
            Happening::Usart { to_board, element } => {
                let d = plm_core::decode::app::decode_element(&element);
                let from = if to_board { "host" } else { "board" };
                self.out.sent += to_board as u64;
                self.out.traffic.push((now, d.to_decoded(from)));
            }
            Happening::Link(host::Event::Sent(el)) => {
                self.out.sent += matches!(el, Element::Frame { .. }) as u64;
                self.link_traffic(now, &el, "host");
            }
            Happening::Link(host::Event::Received(el)) => self.link_traffic(now, &el, "modem"),
            Happening::Link(_) => {}
        }
    }

    fn link_traffic(&mut self, now: Instant, el: &Element, from: &str) {
        let mut d = self.decoder.decode(el);
        d.from = Some(from.to_string());
        self.out.traffic.push((now, d));
    }

    fn lamp(&mut self, a: Address) -> &mut Lamp {
        self.fleet.entry(a).or_insert_with(|| Lamp {
            address: a,
            ..Lamp::default()
        })
    }

    /// What an application event means for the fleet and the views'
    /// requests; `job`: the discovery's or the round's, which its [`Run`]
    /// has had.
    fn on_app(&mut self, now: Instant, e: AppEvent, job: bool) {
        let sent = matches!(e, AppEvent::Sent { .. });
        match e {
            AppEvent::Unsolicited {
                address,
                message: Message::Service(Service::DiscoverReply(r)),
                ..
            } if job && self.discovery().is_some() => self.discovered(now, address, r),
            AppEvent::Answered {
                id,
                address,
                answer,
                ..
            } => {
                let purpose = self.purpose(id);
                self.answered(now, address);
                if let Some(p) = purpose {
                    self.fulfil(now, p, Ok(answer));
                }
            }
            AppEvent::Failed {
                id,
                address,
                reason,
            } => {
                let p = self.purpose(id);
                let unicast = !matches!(p, Some(Purpose::View(_))) || address != Address::BROADCAST;
                if (job || p.is_some()) && unicast && self.fleet.contains_key(&address) {
                    self.unreachable(now, address, &reason);
                }
                if let Some(p) = p {
                    self.fulfil(now, p, Err(reason));
                }
            }
            AppEvent::Sent { id } => {
                if let Some(p) = self.purpose(id) {
                    self.fulfil(now, p, Ok(Message::Ping));
                }
            }
            _ => {}
        }
        if job && !sent {
            self.take_readings(now);
        }
    }

    /// Takes what request `id` was for.
    fn purpose(&mut self, id: RequestId) -> Option<Purpose> {
        let i = self.purposes.iter().position(|(r, _)| *r == id)?;
        Some(self.purposes.swap_remove(i).1)
    }

    /// Any answer shows the lamp is there.
    fn answered(&mut self, now: Instant, address: Address) {
        let lamp = self.lamp(address);
        lamp.last_seen = Some(now);
        if lamp.unreachable.take().is_some() {
            self.out.alerts.push(Alert {
                at: now,
                address,
                what: "answers again".into(),
            });
        }
        self.out.changed = true;
    }

    fn unreachable(&mut self, now: Instant, address: Address, reason: &str) {
        let lamp = self.lamp(address);
        if lamp.unreachable.is_none() {
            lamp.unreachable = Some(reason.to_string());
            self.out.alerts.push(Alert {
                at: now,
                address,
                what: format!("stopped answering: {reason}"),
            });
        }
        self.out.changed = true;
    }

    /// A lamp's ballast as read: its history, and an alert when it has
    /// just failed.
    fn ballast(&mut self, now: Instant, a: Address, value: &[u8]) {
        let Some(b) = Ballast::decode(value) else {
            return;
        };
        let lamp = self.lamp(a);
        let was = lamp.state();
        lamp.ballast = Some(b);
        lamp.energy.record(now, b.lamp_power);
        let snr = lamp.snr;
        lamp.history.push_back(Sample {
            at: now,
            power: b.lamp_power,
            temperature: b.temperature,
            snr,
        });
        if lamp.history.len() > HISTORY {
            lamp.history.pop_front();
        }
        if b.state() == LampState::Failure && was != Some(LampState::Failure) {
            self.out.alerts.push(Alert {
                at: now,
                address: a,
                what: format!(
                    "lamp failed (was {} before the failure, lamp voltage {} V)",
                    LampState::from_word(b.last_failure.status),
                    b.last_failure.lamp_voltage
                ),
            });
        }
    }

    fn fulfil(&mut self, now: Instant, p: Purpose, r: Result<Message, String>) {
        match (p, r) {
            (Purpose::Read(a), Ok(Message::Hid(Hid::Reply { value, .. }))) => {
                self.ballast(now, a, &value);
            }
            (Purpose::Dim(a, level), Ok(Message::Ack { .. })) => {
                self.lamp(a).dimming = Some(level);
                // Read it again to see its power follow.
                self.read(a);
            }
            (Purpose::View(reply), r) => self.out.replies.push((reply, r)),
            (Purpose::Update(broadcast), r) => self.update_answer(now, broadcast, r),
            _ => {}
        }
        self.out.changed = true;
    }
}

/// The street on the console's one drive loop.
impl Layer for StreetSession {
    /// Through a bare modem the console's host engine ACKs its frames;
    /// through a board, the board does.
    fn acks(&self) -> bool {
        self.via_modem()
    }

    fn parts(&mut self) -> (&mut AnyEngine, &mut Driver) {
        (&mut self.conc, &mut self.drive)
    }

    fn on_event(&mut self, at: Instant, h: Happening) {
        self.on_happening(at, h)
    }

    fn next_due(&self) -> Option<Instant> {
        StreetSession::next_due(self)
    }

    fn at(&mut self, now: Instant) {
        self.run_discovery(now);
        self.release_held(now);
        self.run_sweep(now);
        self.run_update(now);
    }

    /// Replies go to the views at the instant they came: a reply may send
    /// the next request.
    fn stop(&self) -> bool {
        !self.out.replies.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fleet::Look;
    use crate::transport::sim::SimTransport;
    use crate::transport::LampAction;
    use plm_core::st7580::TxParams;
    use plm_sim::board::street_address;
    use plm_sim::{Attach, StreetProfile};

    const S: Duration = 1_000 * MS;
    const LAMPS: usize = 50;

    fn session(via: Attach) -> StreetSession {
        let t = Box::new(SimTransport::street(
            LAMPS,
            via,
            57_600,
            3,
            StreetProfile::Uniform,
        ));
        let conc = match via {
            Attach::Board => Concentrator::usart(RequesterConfig::default()),
            Attach::Modem => Concentrator::modem(
                RequesterConfig::default(),
                57_600,
                street_address(0),
                TxParams::default(),
            ),
        };
        StreetSession::new(t, conc)
    }

    /// Runs `d` of the street's time; calls the replies, as the console
    /// does, and returns the alerts.
    fn run(s: &mut StreetSession, d: Duration) -> Vec<Alert> {
        let start = s.now();
        s.run_until(start, start + d);
        let tick = s.take();
        for (reply, r) in tick.replies {
            reply(r);
        }
        tick.alerts
    }

    /// A street of 50: discovery, the sweep reading every lamp, dimming
    /// one and all (broadcast), every clock set, a failed lamp and an
    /// unreachable one raised as alerts: through the board's USART and
    /// through a bare modem. The discovery and the sweep's rounds are
    /// plm-core's jobs run by plm-core's `job::Run`, the code `plm board
    /// discover` and plm-sim's `StreetDriver` run them with.
    #[test]
    fn a_street_is_found_read_dimmed_and_watched_by_plm_cores_run() {
        for via in [Attach::Board, Attach::Modem] {
            let mut s = session(via);
            s.discover();
            run(&mut s, 90 * S);
            assert_eq!(s.fleet().len(), LAMPS, "{via:?}: every lamp found");
            assert!(s.sweep().on, "a street just found is swept");
            run(&mut s, 60 * S);
            for lamp in s.fleet().values() {
                assert_eq!(
                    lamp.state(),
                    Some(LampState::Run),
                    "{via:?} {}",
                    lamp.address
                );
                assert!(lamp.snr.is_some(), "{via:?} {}: SNR known", lamp.address);
            }
            let a3 = street_address(3);
            let full = s.fleet()[&a3].ballast.unwrap().lamp_power;
            s.dim(Some(a3), 20).unwrap();
            run(&mut s, 10 * S);
            let dimmed = s.fleet()[&a3].ballast.unwrap().lamp_power;
            assert!(
                dimmed < full,
                "{via:?}: {dimmed} W after dimming, {full} W before"
            );
            assert_eq!(s.fleet()[&a3].dimming, Some(20));

            assert!(s.dim(None, 101).is_err(), "refused before anything is sent");
            s.dim(None, 60).unwrap();
            run(&mut s, 60 * S);
            assert!(s.fleet().values().all(|l| l.dimming == Some(60)));
            let full = s.fleet()[&street_address(40)].ballast.unwrap().lamp_power;
            assert_eq!(full, 120, "{via:?}: 150 W × (0.5 + 0.5 × 60 %)");

            let noon = Clock {
                hours: 12,
                minutes: 0,
                seconds: 0,
            };
            let set = Request::all(Message::Service(Service::ClockSet(noon)));
            s.request(set, Box::new(|_| {})).unwrap();
            run(&mut s, 2 * S);
            let clock = std::rc::Rc::new(std::cell::Cell::new(None));
            let got = clock.clone();
            let get = Request::to(street_address(LAMPS), Message::Service(Service::ClockGet));
            s.request(get, Box::new(move |r| got.set(Some(r)))).unwrap();
            run(&mut s, 10 * S);
            match clock.take() {
                Some(Ok(Message::Service(Service::ClockNow(c)))) => {
                    assert!(
                        c.seconds_of_day().abs_diff(noon.seconds_of_day()) < 20,
                        "{via:?}: {c}"
                    )
                }
                other => panic!("{via:?}: {other:?}"),
            }

            let t = s.transport_mut().unwrap().simulator().unwrap();
            t.lamp(street_address(5), LampAction::Fail);
            t.lamp(street_address(8), LampAction::Cut);
            let alerts = run(&mut s, 60 * S);
            let about = |n: usize| {
                alerts
                    .iter()
                    .filter(move |a| a.address == street_address(n))
            };
            assert!(
                about(5).any(|a| a.what.starts_with("lamp failed")),
                "{via:?}: {alerts:?}"
            );
            assert!(
                about(8).any(|a| a.what.starts_with("stopped answering")),
                "{via:?}: {alerts:?}"
            );
            assert!(Look::of(&s.fleet()[&street_address(5)]).in_trouble());
            assert!(Look::of(&s.fleet()[&street_address(8)]).in_trouble());
            assert!(!Look::of(&s.fleet()[&street_address(6)]).in_trouble());
        }
    }

    /// A round of the sweep reads 50 lamps in slots (four requests at most), asks
    /// the SNR of at most five (one in ten) through the board and none
    /// through a bare modem, and ends with one probe frame: about a tenth
    /// of the frames and half the line time of one round trip per lamp.
    #[test]
    fn a_round_reads_the_street_in_slots() {
        for via in [Attach::Board, Attach::Modem] {
            let mut s = session(via);
            s.discover();
            // Past the first minute: every SNR figure is old.
            run(&mut s, 90 * S);
            // 10 ms of the street; the frames sent towards it.
            let step = |s: &mut StreetSession| {
                let start = s.now();
                s.run_until(start, start + 10 * MS);
                s.take().sent
            };
            while s.sweep().total > 0 {
                step(&mut s);
            }
            let rounds = s.sweep().rounds;
            let mut sent = 0;
            while s.sweep().total == 0 {
                sent = step(&mut s);
            }
            let start = s.now();
            while s.sweep().rounds == rounds {
                sent += step(&mut s);
            }
            let took = s.now() - start;
            // At most four requests in slots (15 lamps a request at
            // least) and the probe; through the board, the SNR of five.
            let (snr, slots) = match via {
                Attach::Board => (5, 1..=4),
                Attach::Modem => (0, 1..=4),
            };
            assert!(
                slots.contains(&(sent - snr - 1)),
                "{via:?}: {sent} frames sent in a round"
            );
            assert!(took < 5 * S, "{via:?}: a round took {} ms", took / MS);
            assert!(s.fleet().values().all(|l| l.unreachable.is_none()));
        }
    }

    /// A street remembered after a reload: its lamps in the fleet at once
    /// and read before any discovery frame; then a discovery of the same
    /// session finds the lamp that was off before, while the lamps heard
    /// in that session stay quiet (what was recalled of them is not
    /// overwritten by a new reply). Discover then starts a new session,
    /// which every lamp answers.
    #[test]
    fn a_street_remembered_is_read_at_once_and_only_new_lamps_are_looked_for() {
        let usart = || Concentrator::usart(RequesterConfig::default());
        let t = Box::new(SimTransport::street(
            6,
            Attach::Board,
            57_600,
            5,
            StreetProfile::Uniform,
        ));
        let mut s = StreetSession::new(t, usart());
        let late = street_address(6);
        let sim = s.transport_mut().unwrap().simulator().unwrap();
        sim.lamp(late, LampAction::Cut);
        s.discover();
        run(&mut s, 30 * S);
        let (session, mut known) = s.remembered();
        assert_eq!((session, known.len()), (1, 5));
        // What was kept says stack 9.9: a lamp that answers again says 1.x.
        for (_, d) in known.iter_mut() {
            d.stack = plm_core::app::Release { major: 9, minor: 9 };
        }

        // The page reloads; the boards keep what they were told.
        let mut t = s.drive.transport.take().unwrap();
        t.simulator().unwrap().lamp(late, LampAction::Join);
        let mut s = StreetSession::new(t, usart());
        s.recall(session, known.clone());
        assert_eq!(s.fleet().len(), 5, "the lamps are in the fleet at once");
        assert!(s.take().changed);
        let mut discovery_seen = false;
        for _ in 0..300 {
            run(&mut s, 100 * MS);
            if s.discovering().is_some() {
                discovery_seen = true;
                let unread: Vec<_> = known
                    .iter()
                    .filter(|(a, _)| s.fleet()[a].state().is_none())
                    .collect();
                assert!(unread.is_empty(), "read before any discovery: {unread:?}");
            }
        }
        assert!(discovery_seen, "a discovery looked for new lamps");
        assert!(s.discovering().is_none());
        assert_eq!(s.fleet().len(), 6, "the lamp powered later is found");
        assert!(s.fleet()[&late].discovered.is_some());
        for (a, d) in &known {
            assert_eq!(s.fleet()[a].discovered, Some(*d), "{a} stayed quiet");
        }
        assert_eq!(s.remembered().0, session, "the same session");
        assert_eq!(s.remembered().1.len(), 6);

        s.discover();
        run(&mut s, 30 * S);
        assert_eq!(s.remembered().0, session + 1, "Discover: a new session");
        for (a, _) in &known {
            let stack = s.fleet()[a].discovered.unwrap().stack;
            assert_ne!(stack.major, 9, "{a} answered the new session");
        }
    }

    /// A lamp powered after the discovery is found by a sweep's probe (one
    /// short frame of the same session after each round), without a
    /// discovery the page shows; the lamps already heard stay quiet.
    #[test]
    fn a_lamp_powered_later_is_found_by_the_sweep() {
        let usart = Concentrator::usart(RequesterConfig::default());
        let t = Box::new(SimTransport::street(
            6,
            Attach::Board,
            57_600,
            7,
            StreetProfile::Uniform,
        ));
        let mut s = StreetSession::new(t, usart);
        let late = street_address(4);
        let sim = s.transport_mut().unwrap().simulator().unwrap();
        sim.lamp(late, LampAction::Cut);
        s.discover();
        run(&mut s, 30 * S);
        assert_eq!(s.fleet().len(), 5);
        let sim = s.transport_mut().unwrap().simulator().unwrap();
        sim.lamp(late, LampAction::Join);
        let mut shown = false;
        for _ in 0..400 {
            run(&mut s, 100 * MS);
            shown |= s.discovering().is_some() && s.fleet().len() == 5;
            if s.fleet().contains_key(&late) {
                break;
            }
        }
        assert!(
            s.fleet().contains_key(&late),
            "the lamp powered later is found"
        );
        assert!(!shown, "a sweep's probe is not a discovery the page shows");
        assert_eq!(s.remembered().0, 1, "in the same session");
    }

    /// A street remembered with no lamp is discovered again, in a new
    /// session.
    #[test]
    fn a_street_remembered_empty_is_discovered_again() {
        let t = Box::new(SimTransport::street(
            3,
            Attach::Board,
            57_600,
            6,
            StreetProfile::Uniform,
        ));
        let mut s = StreetSession::new(t, Concentrator::usart(RequesterConfig::default()));
        s.recall(4, Vec::new());
        assert_eq!(s.remembered().0, 5);
        run(&mut s, 30 * S);
        assert_eq!(s.fleet().len(), 3);
    }

    /// Random failures set from the console (the Simulator view's rate)
    /// reach every lamp of the street and come back as alerts; at rate 0
    /// nothing fails.
    #[test]
    fn random_failures_at_the_rate_set_are_raised() {
        let failures_at = |rate: f64| {
            let t = Box::new(SimTransport::street(
                6,
                Attach::Board,
                57_600,
                4,
                StreetProfile::Uniform,
            ));
            let mut s = StreetSession::new(t, Concentrator::usart(RequesterConfig::default()));
            s.discover();
            run(&mut s, 30 * S);
            assert_eq!(s.fleet().len(), 6);
            let sim = s.transport_mut().unwrap().simulator().unwrap();
            sim.set_failure_rate(rate);
            let alerts = run(&mut s, 180 * S);
            alerts
                .iter()
                .filter(|a| a.what.starts_with("lamp failed"))
                .count()
        };
        assert_eq!(failures_at(0.0), 0);
        // 60 per lit hour: each lamp fails about once a minute.
        assert!(failures_at(60.0) >= 2);
    }
}
