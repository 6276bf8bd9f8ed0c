//! plm-core's [`Concentrator`] driven over a real port on the wall
//! clock: what `plm_sim::street::StreetDriver` does in virtual time.
//!
//! Concentrator time is microseconds since the driver started. One turn
//! ([`Driver::step`]) reads what the port has (waiting at most
//! [`TICK`]), feeds it in, runs what is due and writes what that
//! produced: bytes, and T_REQ as RTS.

use super::Failure;
use crate::port::Port;
use plm_core::app::discovery::{DiscoveryConfig, Rounds};
use plm_core::app::job::{self, Begun, Router, Run};
use plm_core::app::sweep::Round;
use plm_core::app::{
    Address, AppEvent, AppFrame, Concentrator, Discovered, Discovery, Happening, Message, Request,
    RequestId,
};
use plm_core::drive::{self, Io};
use plm_core::time::Instant;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The longest one turn waits for bytes before it looks at the clock
/// again: well under the 40 ms a modem gives its host to ACK a frame
/// (UM0932 T_ACK).
pub const TICK: Duration = Duration::from_millis(5);

/// Set by the Ctrl-C handler; every turn looks at it.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether Ctrl-C was pressed.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// The requester gives up by itself after its attempts (1.5 + 3 + 4.5 s
/// by default); this only guards against a request that never ends.
const REQUEST_GUARD: Duration = Duration::from_secs(60);

/// No job of `plm board` ends by this limit: each ends by itself, or by
/// Ctrl-C.
const FOREVER: Instant = Instant::MAX / 4;

/// A real port on the wall clock, as plm-core's drive loop sees it.
struct Wall {
    port: Box<dyn Port>,
    /// The port as the user named it, for messages.
    url: String,
    start: std::time::Instant,
}

impl Wall {
    fn lost(&self, e: std::io::Error) -> Failure {
        Failure::port(format!("lost the port {}: {e}", self.url))
    }
}

impl Io for Wall {
    type Error = Failure;

    /// Microseconds since the driver started.
    fn now(&self) -> Instant {
        self.start.elapsed().as_micros() as Instant
    }

    /// Waits for bytes at most until `until` and [`TICK`]; each byte is
    /// stamped with the time it was read. Fails when Ctrl-C was pressed.
    fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), Failure> {
        if interrupted() {
            return Err(Failure::interrupted());
        }
        let wait = Duration::from_micros(until.saturating_sub(self.now())).min(TICK);
        let bytes = self.port.read(wait).map_err(|e| self.lost(e))?;
        let now = self.now();
        rx.extend(bytes.into_iter().map(|b| (now, b)));
        Ok(())
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), Failure> {
        self.port.write(bytes).map_err(|e| self.lost(e))
    }

    fn set_treq(&mut self, asserted: bool) -> Result<(), Failure> {
        self.port.set_rts(asserted).map_err(|e| self.lost(e))
    }
}

/// A concentrator on a port.
pub struct Driver {
    wall: Wall,
    conc: Concentrator,
}

impl Driver {
    /// Drives `conc` over `port` (opened from `url`), time 0 now.
    pub fn new(port: Box<dyn Port>, conc: Concentrator, url: &str) -> Driver {
        Driver {
            wall: Wall {
                port,
                url: url.to_string(),
                start: std::time::Instant::now(),
            },
            conc,
        }
    }

    /// Concentrator time: microseconds since the driver started.
    pub fn now(&self) -> Instant {
        self.wall.now()
    }

    /// One turn of plm-core's drive loop, waiting for bytes at most until
    /// `until` (and [`TICK`]). Fails when the port is lost or Ctrl-C was
    /// pressed.
    pub fn step(&mut self, until: Option<Instant>) -> Result<Vec<Happening>, Failure> {
        let until = until.unwrap_or(FOREVER);
        drive::turn(&mut self.conc, &mut self.wall, until, |_, _| {})?;
        Ok(std::iter::from_fn(|| self.conc.poll_happening()).collect())
    }

    /// Runs turns until `until`.
    pub fn run_until(&mut self, until: Instant) -> Result<(), Failure> {
        while self.now() < until {
            self.step(Some(until))?;
        }
        Ok(())
    }

    /// Queues a request.
    pub fn submit(&mut self, request: Request) -> Result<RequestId, Failure> {
        let id = self.conc.submit(self.now(), request);
        drive::flush(&mut self.conc, &mut self.wall)?;
        Ok(id)
    }

    /// Sends a frame that answers nothing (a discovery ACK).
    pub fn send(&mut self, frame: AppFrame) -> Result<(), Failure> {
        self.conc.send(self.now(), frame);
        drive::flush(&mut self.conc, &mut self.wall)
    }

    /// Sends a request and waits for its fate: answered, failed, or (for
    /// a request that expects no answer) sent.
    pub fn request(&mut self, request: Request) -> Result<AppEvent, Failure> {
        let address = request.address;
        let guard = REQUEST_GUARD.as_micros() as Instant;
        let (id, fate) = job::fate(&mut self.conc, &mut self.wall, request, guard, |_, _| {})?;
        Ok(fate.unwrap_or_else(|| AppEvent::Failed {
            id,
            address,
            reason: format!(
                "no answer within {} s (the requester never gave up: a bug)",
                REQUEST_GUARD.as_secs()
            ),
        }))
    }

    /// The answer of one board, or why there is none, in words.
    pub fn ask(
        &mut self,
        to: Address,
        message: Message,
    ) -> Result<Result<Message, String>, Failure> {
        Ok(match self.request(Request::to(to, message))? {
            AppEvent::Answered { answer, .. } => Ok(answer),
            AppEvent::Failed { reason, .. } => Err(reason),
            other => Err(format!("no answer ({other:?})")),
        })
    }

    /// The concentrator.
    pub fn concentrator(&self) -> &Concentrator {
        &self.conc
    }

    /// Runs `run` (a job's [`Run`], or plm-core's street) to its end
    /// (plm-core's loop, [`job::drive`]); `each` is called after every
    /// turn with the happenings it brought.
    pub fn run<T: Router>(
        &mut self,
        run: &mut T,
        each: impl FnMut(&mut T, Instant, &[Happening]) -> Result<(), Failure>,
    ) -> Result<(), Failure> {
        job::drive(run, &mut self.conc, &mut self.wall, FOREVER, each).map(|_| ())
    }

    /// Discovery (plm-core's rule), then with `older_rule` a round of the
    /// older rule: each board is handed to `found` the first time it is
    /// heard.
    pub fn discover(
        &mut self,
        config: DiscoveryConfig,
        older_rule: bool,
        mut found: impl FnMut(Address, Discovered),
    ) -> Result<Discovery, Failure> {
        let (d, first) = Discovery::start(self.now(), config);
        let mut run = Run::new(Begun::new(d, Some(first)));
        let mut told = 0;
        self.run(&mut run, |run, _, _| {
            let heard = run.job().job.found();
            for (a, info) in &heard[told..] {
                found(*a, *info);
            }
            told = heard.len();
            Ok(())
        })?;
        let mut d = run.into_job().job;
        if older_rule {
            // A round of rule 1 for boards still on it (protocol notes,
            // "Discovery").
            let (r, first) = Rounds::start(self.now(), config.session, 1, 3);
            let mut run = Run::new(Begun::new(r, Some(first)));
            self.run(&mut run, |_, _, _| Ok(()))?;
            for (a, info) in run.job().job.found() {
                if d.record_found(*a, *info) {
                    found(*a, *info);
                }
            }
        }
        Ok(d)
    }

    /// Runs a round of reads (plm-core's [`Round`]) to its end: each
    /// request it gives sent, the fate of each unicast one and what boards
    /// send unasked handed back; what was read stays in it.
    pub fn run_round(&mut self, round: &mut Round) -> Result<(), Failure> {
        self.run(&mut Run::new(round), |_, _, _| Ok(()))
    }
}
