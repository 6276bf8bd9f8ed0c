//! plm-core's host engine driving node 0 of a [`Sim`] in virtual time:
//! what the console does with browser timers, done as fast as possible.
//! Tests and `cargo xtask bench` use it.

use crate::sim::Sim;
use plm_core::drive::{turn, Io};
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Ticket};
use plm_core::link::Dialect;
use plm_core::st7580::{code, Command};
use plm_core::time::{Duration, Instant};
use std::convert::Infallible;

/// Node 0's host UART as plm-core's drive loop sees it: time passes as
/// fast as the loop asks, to the next thing that happens in the world.
impl Io for Sim {
    type Error = Infallible;
    fn now(&self) -> Instant {
        Sim::now(self)
    }
    fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), Infallible> {
        let next = self
            .next_deadline()
            .unwrap_or(until)
            .clamp(Sim::now(self), until);
        self.advance_to(next);
        rx.extend(self.host_read());
        Ok(())
    }
    fn write(&mut self, bytes: &[u8]) -> Result<(), Infallible> {
        Sim::write(self, bytes);
        Ok(())
    }
    fn set_treq(&mut self, asserted: bool) -> Result<(), Infallible> {
        Sim::set_treq(self, asserted);
        Ok(())
    }
}

/// A host engine joined to a simulation.
#[derive(Debug, Clone)]
pub struct HostDriver {
    /// The simulation.
    pub sim: Sim,
    /// The host's link engine.
    pub host: HostEngine,
    /// Every host event so far, with its time.
    pub events: Vec<(Instant, Event)>,
}

/// What became of a request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// The modem's answer: confirm, error or CMD_SyntaxError.
    Answer(Command),
    /// The link gave up on the request.
    Failed(LinkError),
    /// No answer within the time allowed.
    TimedOut,
}

impl HostDriver {
    /// A host at the simulation's baud rate with the reset timeouts.
    pub fn new(sim: Sim) -> Self {
        let config = HostConfig {
            baud: sim.baud(),
            ..HostConfig::default()
        };
        HostDriver {
            sim,
            host: HostEngine::new(Dialect::St7580, config),
            events: Vec::new(),
        }
    }

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.sim.now()
    }

    /// Queues a command for the modem.
    pub fn submit(&mut self, cmd: &Command) -> Ticket {
        let now = self.sim.now();
        self.host.submit(now, cmd.to_frame())
    }

    /// Runs until `done` holds for an event or `limit` µs have passed;
    /// returns whether `done` held.
    pub fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Event) -> bool) -> bool {
        let end = self.sim.now() + limit;
        let mut seen = self.events.len();
        loop {
            while seen < self.events.len() {
                seen += 1;
                if done(&self.events[seen - 1].1) {
                    return true;
                }
            }
            if self.sim.now() >= end {
                return false;
            }
            let events = &mut self.events;
            let Ok(now) = turn(&mut self.host, &mut self.sim, end, |host, at| {
                events.extend(std::iter::from_fn(|| host.poll_event()).map(|e| (at, e)))
            });
            self.events
                .extend(std::iter::from_fn(|| self.host.poll_event()).map(|e| (now, e)));
        }
    }

    /// Runs for `d` µs.
    pub fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_| false);
    }

    /// Sends `cmd` and waits up to `limit` µs for the modem's answer.
    pub fn request(&mut self, cmd: &Command, limit: Duration) -> Outcome {
        let ticket = self.submit(cmd);
        let request = cmd.code();
        let mut out = Outcome::TimedOut;
        self.run_until(limit, |e| match e {
            Event::Frame(f) if code::answers(request, f.code) => {
                out = Command::from_frame(f).map_or(Outcome::TimedOut, Outcome::Answer);
                true
            }
            Event::Failed(t, why) if *t == ticket => {
                out = Outcome::Failed(*why);
                true
            }
            _ => false,
        });
        out
    }

    /// The modem's frames received so far, decoded, in order.
    pub fn frames(&self) -> Vec<Command> {
        self.events
            .iter()
            .filter_map(|(_, e)| match e {
                Event::Frame(f) => Command::from_frame(f).ok(),
                _ => None,
            })
            .collect()
    }
}
