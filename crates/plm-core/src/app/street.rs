//! The street, orchestrated (sans-IO): what a concentrator's driver does
//! with a street of lamps, written once for the console, `plm board` and
//! plm-sim's tests (docs/console.md, "Street"; docs/board-protocol.md).
//!
//! - a discovery, then a background sweep of rounds of reads
//!   ([`super::sweep::Round`]) that also probes for boards powered later;
//! - dimming and clocks for one lamp, a selection or all ([`Lamps`]), and
//!   any request;
//! - a firmware update campaign ([`Campaign`]) that has the line to
//!   itself;
//! - the fleet: what is known of each lamp, and alerts when one fails or
//!   stops answering.
//!
//! Like [`Run`], it drives a [`Concentrator`] it is lent: the driver calls
//! [`Street::pump`] after each turn and hands it every happening
//! ([`Street::handle`]); [`super::job::drive`] is such a driver. What a
//! view asked carries the caller's `R` (the console: the reply to call),
//! handed back with its outcome ([`Changes::replies`]).

mod campaign;
mod fleet;

pub use campaign::Campaign;
pub use fleet::{Alert, Lamp, Sample, HISTORY};

use super::concentrator::{Carrier, Concentrator, Happening};
use super::discovery::{Discovery, DiscoveryConfig};
use super::frame::{Address, AppFrame};
use super::hid::{self, Hid};
use super::job::{Begun, Job, Router, Run};
use super::message::Message;
use super::requester::{AppEvent, Request, RequestId};
use super::service::{Clock, Discovered, Service};
use super::sweep::{Known, Round, RoundConfig};
use crate::time::{Duration, Instant, MS};
use alloc::collections::BTreeMap;
use alloc::string::String;
use alloc::vec::Vec;

/// Pause between two sweeps of the street.
pub const SWEEP_PAUSE: Duration = 5_000 * MS;

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

/// Which lamps a command goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lamps<'a> {
    /// Every lamp at once: one broadcast, which has no answer.
    All,
    /// These (one, or a selection): a request each, each acknowledged.
    These(&'a [Address]),
}

/// What changed since [`Street::take`] was last called.
#[derive(Debug)]
pub struct Changes<R> {
    /// The fleet, the discovery or the sweep changed.
    pub changed: bool,
    /// New alerts.
    pub alerts: Vec<Alert>,
    /// The outcome of each request asked with [`Street::request`].
    pub replies: Vec<(R, Result<Message, String>)>,
    /// The update campaign changed (to save it, and to show it).
    pub campaign: bool,
    /// The street found changed: a lamp heard, a new session, a new
    /// release (to remember it, [`Street::remembered`]).
    pub found: bool,
}

impl<R> Default for Changes<R> {
    fn default() -> Self {
        Changes {
            changed: false,
            alerts: Vec::new(),
            replies: Vec::new(),
            campaign: false,
            found: false,
        }
    }
}

/// What a request of the street's is for.
enum Purpose<R> {
    /// Read every parameter.
    Read(Address),
    Dim(Address, u8),
    /// Its fate matters to nobody but the fleet (dimming every lamp,
    /// setting clocks).
    None,
    /// Asked by the caller: its outcome goes back with `R`.
    View(R),
}

/// The job that has the street's line: a discovery or the sweep's round
/// (never both; the update runs beside them, in its own [`Run`]).
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

/// The street.
pub struct Street<R> {
    /// Through a bare modem (this side is the concentrator), not a
    /// board's USART.
    modem: bool,
    /// The discovery or the sweep's round under way.
    job: Option<Run<StreetJob>>,
    /// Boards the discovery had found when its current frame began (its
    /// belief of those left is updated at the end of each frame).
    found_before_frame: usize,
    session_no: u8,
    /// A street recalled: once its lamps are read, discovery looks for
    /// new ones.
    look_for_new: bool,
    /// A discovery has just ended: the next round needs no probe.
    just_found: bool,
    sweep: Sweep,
    /// Lamps heard in their slot in the last round.
    in_slots: usize,
    next_sweep: Option<Instant>,
    fleet: BTreeMap<Address, Lamp>,
    /// Requests that wait for the round's slots to close or the page's
    /// draw.
    held: Vec<(Request, Purpose<R>)>,
    /// What each request under way is for (a few at a time: a list).
    purposes: Vec<(RequestId, Purpose<R>)>,
    campaign: Option<Campaign>,
    /// Why nothing can be sent (the cable is out), if so.
    down: Option<String>,
    out: Changes<R>,
}

impl<R> Street<R> {
    /// The street on `conc` (a board's USART or a bare modem).
    pub fn new(conc: &Concentrator) -> Self {
        Street {
            modem: matches!(conc.carrier(), Carrier::Modem { .. }),
            job: None,
            found_before_frame: 0,
            session_no: 0,
            look_for_new: false,
            just_found: false,
            sweep: Sweep::default(),
            in_slots: 0,
            next_sweep: None,
            fleet: BTreeMap::new(),
            held: Vec::new(),
            purposes: Vec::new(),
            campaign: None,
            down: None,
            out: Changes::default(),
        }
    }

    /// The cable is out (`why`), or back (`None`): until it is back, what
    /// is asked is not sent (a caller's request fails with `why` at once,
    /// a read or a dimming is dropped) and the update waits, its state
    /// kept.
    pub fn set_down(&mut self, why: Option<String>) {
        self.down = why;
    }

    /// Whether it runs through a bare modem.
    pub fn via_modem(&self) -> bool {
        self.modem
    }

    /// The lamps known so far.
    pub fn fleet(&self) -> &BTreeMap<Address, Lamp> {
        &self.fleet
    }

    /// The sweep's progress.
    pub fn sweep(&self) -> Sweep {
        self.sweep
    }

    /// Lamps heard in their slot in the sweep's last round (the others
    /// were asked alone).
    pub fn in_slots(&self) -> usize {
        self.in_slots
    }

    /// What changed and is not taken yet.
    pub fn changes(&self) -> &Changes<R> {
        &self.out
    }

    /// What changed since the last call.
    pub fn take(&mut self) -> Changes<R> {
        core::mem::take(&mut self.out)
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

    /// Whether the discovery's or the sweep's next request is held back
    /// ([`Street::pump`]'s `hold`).
    pub fn is_held(&self) -> bool {
        self.job.as_ref().is_some_and(Run::is_held)
    }

    /// Whether a discovery or the sweep's round has the line now (the
    /// work its driver's page may hold for a draw; the update is not
    /// held).
    pub fn is_busy(&self) -> bool {
        self.job.is_some()
    }

    /// Starts a discovery (a new session: every board answers again).
    pub fn discover(&mut self, now: Instant) {
        let session = self.session_no.wrapping_add(1);
        let guess = self.fleet.len().max(12);
        self.discover_with(now, DiscoveryConfig::new(session, guess));
    }

    /// Starts a discovery as `config` says (its session the street's from
    /// now on).
    pub fn discover_with(&mut self, now: Instant, config: DiscoveryConfig) {
        self.session_no = config.session;
        self.look_for_new = false;
        let (d, first) = Discovery::start(now, config);
        self.job = Some(Run::new(StreetJob::Discovery(Begun::new(d, Some(first)))));
        self.found_before_frame = 0;
        self.out.found = true;
    }

    /// Numbers the sessions of the discoveries to come from `last` on
    /// (the next is `last + 1`).
    pub fn set_session(&mut self, last: u8) {
        self.session_no = last;
    }

    /// Starts from a street found earlier in discovery session `session`
    /// ([`Street::remembered`]): its lamps are in the fleet at once and
    /// read at once; then a discovery of the same session looks for new
    /// ones only (the boards heard in it stay quiet; one that restarted
    /// answers and is heard again). A street of no lamp is discovered
    /// again, in a new session.
    pub fn recall(&mut self, now: Instant, session: u8, known: Vec<(Address, Discovered)>) {
        self.session_no = session;
        if known.is_empty() {
            return self.discover(now);
        }
        for (a, d) in known {
            let lamp = self.lamp(a);
            lamp.discovered = Some(d);
            lamp.snr = Some(d.snr as i8);
        }
        self.look_for_new = true;
        self.out.changed = true;
        self.set_sweep(now, true);
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

    /// Turns the background sweep on or off.
    pub fn set_sweep(&mut self, now: Instant, on: bool) {
        self.sweep.on = on;
        if on && self.round().is_none() {
            self.next_sweep = Some(now);
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
    pub fn read(&mut self, conc: &mut Concentrator, now: Instant, address: Address) {
        let request = Request::to(address, Message::Hid(Hid::Get(hid::ALL)));
        self.submit(conc, now, request, Purpose::Read(address));
    }

    /// Dims `lamps` (each read again once it has acknowledged, to see its
    /// power follow; all: the street is swept again in 2 s). Refused
    /// before anything is sent when the value is not 0-100.
    pub fn dim(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        lamps: Lamps<'_>,
        level: u8,
    ) -> Result<(), String> {
        let m = || Message::Hid(Hid::Dimming(level));
        m().validate()?;
        if self.down.is_some() {
            return Ok(());
        }
        self.send_to(conc, now, lamps, m, |a| Purpose::Dim(a, level));
        if lamps == Lamps::All {
            for lamp in self.fleet.values_mut() {
                lamp.dimming = Some(level);
            }
            self.next_sweep = Some(now + 2_000 * MS);
        }
        Ok(())
    }

    /// Sets the clocks of `lamps` to `clock`.
    pub fn set_clock(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        lamps: Lamps<'_>,
        clock: Clock,
    ) -> Result<(), String> {
        let m = || Message::Service(Service::ClockSet(clock));
        m().validate()?;
        self.send_to(conc, now, lamps, m, |_| Purpose::None);
        Ok(())
    }

    /// Sends what `m` makes to `lamps`: a request each, for `p` of its
    /// lamp, or one broadcast.
    fn send_to(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        lamps: Lamps<'_>,
        m: impl Fn() -> Message,
        p: impl Fn(Address) -> Purpose<R>,
    ) {
        match lamps {
            Lamps::These(list) => {
                for &a in list {
                    self.submit(conc, now, Request::to(a, m()), p(a));
                }
            }
            Lamps::All => self.submit(conc, now, Request::all(m()), Purpose::None),
        }
    }

    /// Sends any request; its outcome comes back with `reply`
    /// ([`Changes::replies`]). Refused before anything is sent when the
    /// board would refuse it.
    pub fn request(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        request: Request,
        reply: R,
    ) -> Result<(), String> {
        request.message.validate()?;
        self.submit(conc, now, request, Purpose::View(reply));
        Ok(())
    }

    fn submit(&mut self, conc: &mut Concentrator, now: Instant, request: Request, p: Purpose<R>) {
        if let Some(why) = &self.down {
            if let Purpose::View(reply) = p {
                self.out.replies.push((reply, Err(why.clone())));
            }
            return;
        }
        // Lamps answer in their slots: a frame sent now would collide.
        if self.slots_open(now) {
            self.held.push((request, p));
            return;
        }
        let id = conc.submit(now, request);
        self.purposes.push((id, p));
    }

    /// Whether the round's lamps (or new boards) may be answering now.
    fn slots_open(&self, now: Instant) -> bool {
        let window = self.round().and_then(|r| r.poll_timeout());
        window.is_some_and(|t| t > now)
    }

    /// The street's work at `now`, after each turn of its driver: the
    /// discovery's, the sweep's and the update's next requests, and the
    /// callers' requests that waited. With `hold` (its driver's page
    /// draws), the discovery's or the sweep's next request and the
    /// callers' wait; the update goes on.
    pub fn pump(&mut self, conc: &mut Concentrator, now: Instant, hold: bool) {
        self.run_discovery(conc, now, hold);
        if !hold && !self.slots_open(now) {
            for (request, p) in core::mem::take(&mut self.held) {
                self.submit(conc, now, request, p);
            }
        }
        self.run_sweep(conc, now, hold);
        if self.down.is_none() {
            self.run_update(conc, now);
        }
    }

    /// The next instant [`Street::pump`] has something to do, with its
    /// `hold` (what it holds goes once it is released, which its driver
    /// knows).
    pub fn poll_timeout(&self, now: Instant, hold: bool) -> Option<Instant> {
        let job = self.job.as_ref().filter(|j| !(hold && j.is_held()));
        let held = !self.held.is_empty() && !self.slots_open(now) && !hold;
        let mut t = job.and_then(|j| j.poll_timeout());
        for u in [
            self.next_sweep,
            held.then_some(now),
            self.campaign.as_ref().and_then(Campaign::poll_timeout),
        ] {
            t = match (t, u) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
        }
        t
    }

    /// Whether nothing is under way: no job, no update sending, no
    /// request awaited or waiting (a driver that runs the street for one
    /// task stops here; the next sweep may be due later).
    pub fn is_idle(&self) -> bool {
        self.job.is_none() && !self.updating() && self.held.is_empty() && self.purposes.is_empty()
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

    /// Sends the job's next request, unless `hold`; returns whether one
    /// was sent, and the job once it is over.
    fn pump_job(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        hold: bool,
    ) -> (bool, Option<StreetJob>) {
        let Some(run) = self.job.as_mut() else {
            return (false, None);
        };
        let sent = run.pump_unless(conc, now, hold).is_some();
        if run.is_done() {
            return (sent, self.job.take().map(Run::into_job));
        }
        (sent, None)
    }

    fn run_discovery(&mut self, conc: &mut Concentrator, now: Instant, hold: bool) {
        let Some(found) = self.discovery().map(|d| d.found().len()) else {
            return;
        };
        if !self.held.is_empty() {
            return;
        }
        let (sent, done) = self.pump_job(conc, now, hold);
        if sent {
            self.found_before_frame = found;
            self.out.changed = true;
        }
        if done.is_some() {
            self.out.changed = true;
            // A street just found is read at once.
            self.next_sweep = Some(now);
            self.sweep.on = true;
            self.just_found = true;
        }
    }

    /// The round a sweep starts now: every lamp of the fleet, the SNR
    /// asked through a board only (through a bare modem every frame heard
    /// carries it), and the probe for new boards unless a discovery has
    /// just looked for them or looks after this round (docs/console.md,
    /// "Street").
    fn new_round(&mut self) -> Round {
        let lamps = self
            .fleet
            .values()
            .map(|l| Known {
                address: l.address,
                discovered: l.discovered,
                snr_at: l.snr_at,
            })
            .collect();
        let mut config = RoundConfig::sweep(self.session_no, !self.modem);
        if self.look_for_new || core::mem::take(&mut self.just_found) {
            config.probe = None;
        }
        Round::new(lamps, config)
    }

    fn run_sweep(&mut self, conc: &mut Concentrator, now: Instant, hold: bool) {
        // A firmware update has the line to itself.
        if !self.sweep.on || self.discovery().is_some() || self.updating() {
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
        if conc.requester().pending() > 0 || !self.held.is_empty() {
            return;
        }
        if let (_, Some(StreetJob::Round(round))) = self.pump_job(conc, now, hold) {
            self.sweep.rounds += 1;
            self.sweep.total = 0;
            self.in_slots = round.in_slots();
            // Sooner when a dimming of every lamp asked for it.
            let pause = now + SWEEP_PAUSE;
            self.next_sweep = Some(self.next_sweep.map_or(pause, |t| t.min(pause)));
            self.out.changed = true;
            // A probe heard a new board: a discovery names it and looks
            // for more.
            if self.look_for_new || round.found_new() {
                self.look_for_new(conc, now);
            }
        }
    }

    /// Looks for boards not in the fleet, in the session its lamps were
    /// heard in: one new board expected.
    fn look_for_new(&mut self, conc: &mut Concentrator, now: Instant) {
        self.look_for_new = false;
        let (_, known) = self.remembered();
        let config = DiscoveryConfig::new(self.session_no, 1);
        self.found_before_frame = known.len();
        let (d, first) = Discovery::resume(now, config, known);
        self.job = Some(Run::new(StreetJob::Discovery(Begun::new(d, Some(first)))));
        self.out.changed = true;
        // Remembered again: the connection was used last.
        self.out.found = true;
        self.run_discovery(conc, now, false);
    }

    /// A happening of the concentrator: the fate of a request, or what a
    /// board sent unasked (the job hears it first, and its answer is
    /// sent).
    pub fn handle(&mut self, conc: &mut Concentrator, now: Instant, h: Happening) {
        let job = (self.job.as_mut()).is_some_and(|run| run.handle(conc, now, &h));
        let update = !job && self.campaign_handle(conc, now, &h);
        match h {
            Happening::App(e) => self.on_app(conc, now, e, job, update),
            Happening::Heard { address, snr } => {
                if let Some(l) = self.fleet.get_mut(&address).filter(|_| snr.is_some()) {
                    l.snr = snr;
                    l.snr_at = Some(now);
                }
            }
            _ => {}
        }
    }

    /// What an application event means for the fleet and the callers'
    /// requests; `job`, `update`: the discovery's or the round's, or the
    /// update's, which its [`Run`] has had.
    fn on_app(
        &mut self,
        conc: &mut Concentrator,
        now: Instant,
        e: AppEvent,
        job: bool,
        update: bool,
    ) {
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
                    self.fulfil(conc, now, p, Ok(answer));
                }
            }
            AppEvent::Failed {
                id,
                address,
                reason,
            } => {
                let p = self.purpose(id);
                let ours = job || update || p.is_some();
                if ours && address != Address::BROADCAST && self.fleet.contains_key(&address) {
                    self.unreachable(now, address, &reason);
                }
                if let Some(p) = p {
                    self.fulfil(conc, now, p, Err(reason));
                }
            }
            AppEvent::Sent { id } => {
                if let Some(p) = self.purpose(id) {
                    self.fulfil(conc, now, p, Ok(Message::Ping));
                }
                return;
            }
            _ => {}
        }
        if job {
            self.take_readings(now);
        }
    }

    /// Takes what request `id` was for.
    fn purpose(&mut self, id: RequestId) -> Option<Purpose<R>> {
        let i = self.purposes.iter().position(|(r, _)| *r == id)?;
        Some(self.purposes.swap_remove(i).1)
    }
}

/// [`Router`]: the street driven by [`super::job::drive`] (the line
/// always free), until it is idle.
impl<R> Router for Street<R> {
    fn pump(&mut self, conc: &mut Concentrator, now: Instant) {
        Street::pump(self, conc, now, false)
    }
    fn handle(&mut self, conc: &mut Concentrator, now: Instant, h: &Happening) {
        Street::handle(self, conc, now, h.clone())
    }
    fn poll_timeout(&self, now: Instant) -> Option<Instant> {
        // The next sweep is not waited for: the street is idle until then.
        let next = Street::poll_timeout(self, now, false);
        next.filter(|_| !self.is_idle())
    }
    fn is_done(&self) -> bool {
        self.is_idle()
    }
}
