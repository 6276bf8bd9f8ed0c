//! plm-core's host engine driving node 0 of a [`Sim`] in virtual time:
//! what the console does with browser timers, done as fast as possible.
//! Tests and `cargo xtask bench` use it.

use crate::sim::Sim;
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Ticket, Transmit};
use plm_core::link::Dialect;
use plm_core::st7580::{code, Command};
use plm_core::time::{earliest, Duration, Instant};

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
            self.push_transmits();
            while seen < self.events.len() {
                seen += 1;
                if done(&self.events[seen - 1].1) {
                    return true;
                }
            }
            let next = earliest(self.host.poll_timeout(), self.sim.next_deadline());
            match next {
                Some(t) if t <= end => self.sim.advance_to(t),
                _ => {
                    self.sim.advance_to(end);
                    return false;
                }
            }
            let now = self.sim.now();
            for (at, b) in self.sim.host_read() {
                self.host.handle_rx(at, &[b]);
            }
            if self.host.poll_timeout().is_some_and(|t| t <= now) {
                self.host.handle_timeout(now);
            }
            while let Some(e) = self.host.poll_event() {
                self.events.push((now, e));
            }
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

    fn push_transmits(&mut self) {
        while let Some(t) = self.host.poll_transmit() {
            match t {
                Transmit::Bytes(b) => self.sim.write(&b),
                Transmit::TReq { asserted } => self.sim.set_treq(asserted),
            }
        }
    }
}
