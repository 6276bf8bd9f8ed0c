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

/// A USB-UART adapter between node 0's UART and the host, as an FTDI
/// chip hands received bytes to USB: held until its latency timer runs
/// out (16 ms by default, counted from the first byte held) or a packet
/// is full ([`UsbUart::PACKET`] bytes), then delivered at once, each
/// stamped with the time the host gets it. What the host writes goes
/// straight to the modem. It keeps, for every ACK the host writes, how
/// long after the acknowledged frame's last byte reached the adapter the
/// ACK left the host: what the modem waits, against T_ACK (UM0932 3.2.8).
#[derive(Debug, Clone)]
pub struct UsbUart {
    /// The simulation behind the adapter.
    pub sim: Sim,
    /// The latency timer.
    pub latency: Duration,
    held: Vec<(Instant, u8)>,
    /// When the last byte handed to the host reached the adapter.
    last_in: Option<Instant>,
    /// Each ACK's wait as the modem sees it.
    pub acks: Vec<Duration>,
}

impl UsbUart {
    /// Bytes of data in one USB packet of an FTDI chip (64 less its 2
    /// status bytes).
    pub const PACKET: usize = 62;

    /// `sim` behind an adapter with latency timer `latency`.
    pub fn new(sim: Sim, latency: Duration) -> Self {
        UsbUart {
            sim,
            latency,
            held: Vec::new(),
            last_in: None,
            acks: Vec::new(),
        }
    }

    /// When the held bytes go to the host.
    fn release_at(&self) -> Option<Instant> {
        self.held.first().map(|(t, _)| t + self.latency)
    }
}

impl Io for UsbUart {
    type Error = Infallible;
    fn now(&self) -> Instant {
        self.sim.now()
    }
    fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), Infallible> {
        let now = self.sim.now();
        let until = self.release_at().map_or(until, |t| t.min(until));
        let next = self
            .sim
            .next_deadline()
            .unwrap_or(until)
            .clamp(now, until.max(now));
        self.sim.advance_to(next);
        self.held.extend(self.sim.host_read());
        let now = self.sim.now();
        let full = self.held.len() >= Self::PACKET;
        if full || self.release_at().is_some_and(|t| t <= now) {
            self.last_in = self.held.last().map(|(t, _)| *t);
            rx.extend(self.held.drain(..).map(|(_, b)| (now, b)));
        }
        Ok(())
    }
    fn write(&mut self, bytes: &[u8]) -> Result<(), Infallible> {
        if bytes == [plm_core::link::ACK] {
            if let Some(t) = self.last_in {
                self.acks.push(self.sim.now() - t);
            }
        }
        self.sim.write(bytes);
        Ok(())
    }
    fn set_treq(&mut self, asserted: bool) -> Result<(), Infallible> {
        self.sim.set_treq(asserted);
        Ok(())
    }
}

/// A host engine joined to a simulation (through `P`: node 0's UART
/// itself, or a [`UsbUart`]).
#[derive(Debug, Clone)]
pub struct HostDriver<P = Sim> {
    /// The simulation, or the adapter in front of it.
    pub sim: P,
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

    /// The same host behind a [`UsbUart`] with latency timer `latency`:
    /// its waits for the modem (T_ACK, T_IC) lengthened by it, as the
    /// console does for a real adapter.
    pub fn behind_usb(self, latency: Duration) -> HostDriver<UsbUart> {
        let mut config = self.host.config();
        config.timeouts.t_ack += latency;
        config.timeouts.t_ic += latency;
        config.timeouts.t_poll += latency;
        HostDriver {
            sim: UsbUart::new(self.sim, latency),
            host: HostEngine::new(Dialect::St7580, config),
            events: self.events,
        }
    }
}

impl<P: Io<Error = Infallible>> HostDriver<P> {
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
