//! A concentrator (plm-core's [`Concentrator`]) joined to a [`Sim`] in
//! virtual time: what the console does with the page's timers and
//! `plm board` with a serial port, done as fast as possible, over either
//! way in ([`Attach`]). Tests and `cargo xtask bench` use it.

use crate::sim::{Attach, Sim};
use plm_core::app::job::{self, Begun, Job, Router, Run};
use plm_core::app::read_all::ReadAll;
use plm_core::app::{
    Address, AppEvent, Concentrator, Discovery, Happening, Message, Request, RequestId,
    RequesterConfig,
};
use plm_core::drive;
use plm_core::st7580::TxParams;
use plm_core::time::{Duration, Instant};
use std::collections::BTreeMap;

/// A limit no job of a test reaches (a job always has a deadline).
const FOREVER: Duration = Duration::MAX / 4;

/// A concentrator driving a simulated street.
#[derive(Debug, Clone)]
pub struct StreetDriver {
    /// The simulation.
    pub sim: Sim,
    /// The host's concentrator.
    pub conc: Concentrator,
    /// Every happening so far, with its time.
    pub log: Vec<(Instant, Happening)>,
}

impl StreetDriver {
    /// A concentrator for `sim`, of the kind its node 0 needs: over the
    /// board's USART, or speaking the board protocol through the bare
    /// modem from node 0's street address.
    pub fn new(sim: Sim, config: RequesterConfig) -> Self {
        let conc = Self::concentrator(&sim, config);
        StreetDriver {
            sim,
            conc,
            log: Vec::new(),
        }
    }

    fn concentrator(sim: &Sim, config: RequesterConfig) -> Concentrator {
        match sim.attach() {
            Attach::Board => Concentrator::usart(config),
            Attach::Modem => Concentrator::modem(
                config,
                sim.baud(),
                Concentrator::ADDRESS,
                TxParams::default(),
            ),
        }
    }

    /// The host's cable pulled for `gone` µs, then plugged in again: every
    /// request under way is lost, the world goes on without a host (what
    /// it sends the host is lost), and a new concentrator starts.
    pub fn pull_cable(&mut self, gone: Duration) {
        let config = self.conc.requester().config();
        self.conc.abort_all("the cable was pulled");
        while self.conc.poll_happening().is_some() {}
        self.sim.set_treq(false);
        self.sim.advance_to(self.sim.now() + gone);
        self.sim.host_read();
        self.conc = Self::concentrator(&self.sim, config);
    }

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.sim.now()
    }

    /// Queues a request.
    pub fn submit(&mut self, request: Request) -> RequestId {
        let now = self.sim.now();
        let id = self.conc.submit(now, request);
        self.flush();
        id
    }

    /// The simulated world, to act on it (cut a board's supply, ...).
    pub fn sim_mut(&mut self) -> &mut Sim {
        &mut self.sim
    }

    /// Sends a frame without waiting for anything.
    pub fn send(&mut self, frame: plm_core::app::AppFrame) {
        let now = self.sim.now();
        self.conc.send(now, frame);
        self.flush();
    }

    fn flush(&mut self) {
        let Ok(()) = drive::flush(&mut self.conc, &mut self.sim);
    }

    /// Runs one turn of plm-core's drive loop: to the next deadline of the
    /// world or the concentrator, at most `until`. Returns the happenings
    /// of the turn.
    pub fn step(&mut self, until: Instant) -> Vec<Happening> {
        let Ok(now) = drive::turn(&mut self.conc, &mut self.sim, until, |_, _| {});
        let out: Vec<Happening> = std::iter::from_fn(|| self.conc.poll_happening()).collect();
        self.log.extend(out.iter().map(|h| (now, h.clone())));
        out
    }

    /// Runs until `done` holds for a happening or `limit` µs have passed;
    /// returns whether `done` held.
    pub fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Happening) -> bool) -> bool {
        let until = self.sim.now() + limit;
        while self.sim.now() < until {
            if self.step(until).iter().any(&mut done) {
                return true;
            }
        }
        false
    }

    /// Runs for `d` µs.
    pub fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_| false);
    }

    /// Sends a request and waits for its fate (answer, failure, or sent).
    pub fn request(&mut self, request: Request, limit: Duration) -> Option<AppEvent> {
        let log = &mut self.log;
        let Ok((_, fate)) = job::fate(&mut self.conc, &mut self.sim, request, limit, |at, h| {
            log.push((at, h.clone()))
        });
        fate
    }

    /// The answer to a request to one board, or why there is none.
    pub fn ask(
        &mut self,
        to: Address,
        message: Message,
        limit: Duration,
    ) -> Result<Message, String> {
        match self.request(Request::to(to, message), limit) {
            Some(AppEvent::Answered { answer, .. }) => Ok(answer),
            Some(AppEvent::Failed { reason, .. }) => Err(reason),
            other => Err(format!("no answer within the time allowed ({other:?})")),
        }
    }

    /// Runs `job` to its end on the concentrator (plm-core's loop,
    /// [`job::drive`]), for at most `limit`; returns the job and whether
    /// it ended.
    pub fn run_job<J: Job>(&mut self, job: J, limit: Duration) -> (J, bool) {
        let mut run = Run::new(job);
        let done = self.drive(&mut run, limit);
        (run.into_job(), done)
    }

    /// Drives `router` (a job's [`Run`], or plm-core's whole
    /// [`plm_core::app::street::Street`]) with plm-core's loop
    /// ([`job::drive`]) until it is over (a street: idle) or `limit` has
    /// passed; returns whether it is over.
    pub fn drive<T: Router>(&mut self, router: &mut T, limit: Duration) -> bool {
        let until = self.sim.now().saturating_add(limit);
        let log = &mut self.log;
        let Ok(done) = job::drive(router, &mut self.conc, &mut self.sim, until, |_, at, hs| {
            log.extend(hs.iter().map(|h| (at, h.clone())));
            Ok(())
        });
        done
    }

    /// Runs a firmware update campaign to its end.
    pub fn update(&mut self, u: &mut plm_core::app::update::Update) {
        self.run_job(u, FOREVER);
    }

    /// Reads `boards` in slots (plm-core's [`ReadAll`]): every request
    /// it hands out is broadcast, every HID reply handed back to it.
    /// Returns the finished read: what was heard, and the stragglers for
    /// the caller to ask one by one.
    pub fn read_in_slots(
        &mut self,
        boards: &[Address],
        config: plm_core::app::read_all::ReadConfig,
    ) -> ReadAll {
        let (r, first) = ReadAll::start(self.sim.now(), boards, config);
        self.run_job(Begun::new(r, first), FOREVER).0.job
    }

    /// Discovers the boards on the line (plm-core's rule); returns what
    /// was found.
    pub fn discover(
        &mut self,
        config: plm_core::app::discovery::DiscoveryConfig,
    ) -> BTreeMap<Address, plm_core::app::Discovered> {
        let (d, first) = Discovery::start(self.sim.now(), config);
        let d = self.run_job(Begun::new(d, Some(first)), FOREVER).0.job;
        d.found().iter().copied().collect()
    }
}
