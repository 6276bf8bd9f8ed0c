//! plm-core's host engine driving one simulated ST7570 over a byte-level
//! UART in virtual time (ST7570 UM 5.1-5.2), on plm-core's one drive loop
//! ([`turn`]) as [`crate::drive`] does for the ST7580 world: the modem
//! and its UART are the host's port ([`ModemPort`]); one node of the
//! S-FSK network ([`super::net`]), or a modem alone in tests.

use super::St7570;
use crate::rng::Rng;
use crate::sim::Dir;
use crate::uart::Wire;
use plm_core::drive::{turn, Io};
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Ticket};
use plm_core::link::Dialect;
use plm_core::st7570::{code, Command, Layer};
use plm_core::time::{earliest, Duration, Instant};
use std::collections::VecDeque;
use std::convert::Infallible;

/// What became of a request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// The modem's answer (a confirm, an error, CMD_SyntaxError).
    Answer(Command),
    /// The link gave up on the request.
    Failed(LinkError),
    /// No answer within the time allowed.
    TimedOut,
}

/// One ST7570 and the UART to it, as its host's serial port sees them:
/// the host writes bytes and T_REQ levels and reads the modem's bytes
/// ([`ModemPort::host_read`], or plm-core's [`Io`]).
#[derive(Debug, Clone)]
pub struct ModemPort {
    /// The modem.
    pub modem: St7570,
    now: Instant,
    to_modem: Wire,
    to_host: Wire,
    rng: Rng,
    /// Bytes on the wires, with their arrival times.
    at_modem: VecDeque<(Instant, u8)>,
    at_host: VecDeque<(Instant, u8)>,
    /// T_REQ levels, each taking effect once the bytes written before it
    /// have left the UART (a driver drains its FIFO before touching RTS).
    treq: VecDeque<(Instant, bool)>,
    /// The modem's bytes that reached the host, not yet read, with their
    /// arrival times.
    rx: Vec<(Instant, u8)>,
}

impl ModemPort {
    /// A modem powered on at 0 at `baud`, the UART faults (none by
    /// default) drawing on an RNG seeded with `seed`.
    pub fn new(baud: u32, seed: u64) -> Self {
        ModemPort {
            modem: St7570::new(baud, 0),
            now: 0,
            to_modem: Wire::new(baud),
            to_host: Wire::new(baud),
            rng: Rng::new(seed),
            at_modem: VecDeque::new(),
            at_host: VecDeque::new(),
            treq: VecDeque::new(),
            rx: Vec::new(),
        }
    }

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// The host writes `bytes` on the UART now.
    pub fn write(&mut self, bytes: &[u8]) {
        let arrivals = self.to_modem.write(self.now, bytes, &mut self.rng);
        self.at_modem.extend(arrivals);
    }

    /// The host sets T_REQ (`asserted`: low), once the bytes it wrote
    /// before have left the UART.
    pub fn set_treq(&mut self, asserted: bool) {
        let at = self.to_modem.drained_at(self.now);
        self.treq.push_back((at, asserted));
    }

    /// How long until the bytes the host wrote so far have all reached
    /// the modem.
    pub fn backlog_to_modem(&self) -> Duration {
        self.to_modem.drained_at(self.now) - self.now
    }

    /// Purges the host's transmit side (its serial driver dropping its
    /// buffer): the bytes it wrote that have not yet reached the modem
    /// are lost, and a T_REQ change waiting behind them takes effect now,
    /// at the level the host set last. The modem runs on.
    pub fn purge_to_modem(&mut self) {
        self.to_modem.purge(self.now);
        self.at_modem.clear();
        if let Some(&(_, asserted)) = self.treq.back() {
            self.treq.clear();
            self.treq.push_back((self.now, asserted));
        }
    }

    /// Purges the host's receive side: the modem's bytes that reached it
    /// and are not yet read, and those on their way to it.
    pub fn purge_to_host(&mut self) {
        self.at_host.clear();
        self.rx.clear();
    }

    /// The modem's bytes that reached the host by now.
    pub fn host_read(&mut self) -> Vec<(Instant, u8)> {
        std::mem::take(&mut self.rx)
    }

    /// The UART baud rate (both ways; the modem's BR0/BR1 strapped to it).
    pub fn baud(&self) -> u32 {
        self.to_modem.baud()
    }

    /// Sets the UART baud rate both ways and at the modem (Table 9: its
    /// BR0/BR1 pins strapped to match the host), for bytes written from
    /// now on.
    pub fn set_baud(&mut self, baud: u32) {
        self.to_modem.set_baud(baud);
        self.to_host.set_baud(baud);
        self.modem.set_baud(baud);
    }

    /// One direction of the UART, for fault injection ([`Wire::faults`],
    /// [`Wire::inject`]).
    pub fn wire(&mut self, dir: Dir) -> &mut Wire {
        match dir {
            Dir::HostToModem => &mut self.to_modem,
            Dir::ModemToHost => &mut self.to_host,
        }
    }

    /// When the bytes now on the UART have arrived, the earliest of the
    /// two ways (`None`: none are on the way).
    pub fn uart_due(&self) -> Option<Instant> {
        earliest(
            self.at_modem.back().map(|b| b.0),
            self.at_host.back().map(|b| b.0),
        )
    }

    /// The next moment something is due at the modem or on a wire.
    pub fn next_due(&self) -> Option<Instant> {
        let wires = earliest(
            self.at_modem.front().map(|b| b.0),
            self.at_host.front().map(|b| b.0),
        );
        let modem = earliest(self.modem.poll_timeout(), self.treq.front().map(|t| t.0));
        earliest(wires, modem)
    }

    /// Moves virtual time to `t` (never back), delivers what is due and
    /// hands the modem's output to its wire.
    pub fn advance(&mut self, t: Instant) {
        self.now = self.now.max(t);
        let now = self.now;
        while let Some(&(at, b)) = self.at_modem.front().filter(|(at, _)| *at <= now) {
            self.at_modem.pop_front();
            self.modem.handle_rx(at, &[b]);
        }
        // A level change and a byte at the same instant: the byte left
        // first (the host touches RTS once its FIFO is drained).
        while let Some(&(at, asserted)) = self.treq.front().filter(|(at, _)| *at <= now) {
            self.treq.pop_front();
            self.modem.set_treq(at, asserted);
        }
        while let Some(&b) = self.at_host.front().filter(|(at, _)| *at <= now) {
            self.at_host.pop_front();
            self.rx.push(b);
        }
        if self.modem.poll_timeout().is_some_and(|t| t <= now) {
            self.modem.handle_timeout(now);
        }
        self.flush(now);
    }

    /// Hands the modem's output to its wire after something outside (the
    /// line, the host) acted at `now` (never back).
    pub fn flush(&mut self, now: Instant) {
        self.now = self.now.max(now);
        while let Some(b) = self.modem.poll_transmit() {
            let arrivals = self.to_host.write(self.now, &b, &mut self.rng);
            self.at_host.extend(arrivals);
        }
    }
}

/// The port as plm-core's drive loop sees it: time passes as fast as the
/// loop asks, to the next thing that happens at the modem or on a wire.
impl Io for ModemPort {
    type Error = Infallible;
    fn now(&self) -> Instant {
        self.now
    }
    fn wait(&mut self, until: Instant, rx: &mut Vec<(Instant, u8)>) -> Result<(), Infallible> {
        let next = self
            .next_due()
            .unwrap_or(until)
            .clamp(self.now, until.max(self.now));
        self.advance(next);
        rx.extend(self.host_read());
        Ok(())
    }
    fn write(&mut self, bytes: &[u8]) -> Result<(), Infallible> {
        ModemPort::write(self, bytes);
        Ok(())
    }
    fn set_treq(&mut self, asserted: bool) -> Result<(), Infallible> {
        ModemPort::set_treq(self, asserted);
        Ok(())
    }
}

/// A host engine joined to one ST7570 by a UART in each direction.
#[derive(Debug, Clone)]
pub struct ModemDriver {
    /// The modem and its UART.
    pub port: ModemPort,
    /// The host's link engine (ST7570 dialect).
    pub host: HostEngine,
    /// Every host event so far, with its time.
    pub events: Vec<(Instant, Event)>,
    /// The host is outside ([`ModemDriver::serve_outside`]).
    outside: bool,
}

impl ModemDriver {
    /// A modem powered on at 0 and a host with the reset timeouts, both at
    /// `baud`.
    pub fn new(baud: u32) -> Self {
        Self::with_seed(baud, 0x7570)
    }

    /// As [`ModemDriver::new`], the UART faults (none by default) drawing
    /// on an RNG seeded with `seed`.
    pub fn with_seed(baud: u32, seed: u64) -> Self {
        ModemDriver {
            port: ModemPort::new(baud, seed),
            host: HostEngine::new(Dialect::St7570, HostConfig::at_reset(Dialect::St7570, baud)),
            events: Vec::new(),
            outside: false,
        }
    }

    /// From now on the host is outside (`plm sim`'s client, the console):
    /// it drives [`ModemDriver::port`] itself, and [`ModemDriver::host`]
    /// stays idle.
    pub fn serve_outside(&mut self) {
        self.outside = true;
    }

    /// Whether the host is outside.
    pub fn is_outside(&self) -> bool {
        self.outside
    }

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.port.now
    }

    /// One direction of the UART, for fault injection.
    pub fn wire(&mut self, dir: Dir) -> &mut Wire {
        self.port.wire(dir)
    }

    /// Queues a command for the modem.
    pub fn submit(&mut self, cmd: &Command) -> Ticket {
        self.host.submit(self.port.now, cmd.to_frame())
    }

    /// Runs until `done` holds for a host event or `limit` µs have passed;
    /// returns whether `done` held.
    pub fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Event) -> bool) -> bool {
        let end = self.port.now + limit;
        let mut seen = self.events.len();
        loop {
            while seen < self.events.len() {
                seen += 1;
                if done(&self.events[seen - 1].1) {
                    return true;
                }
            }
            if self.port.now >= end {
                return false;
            }
            self.turn(end);
        }
    }

    /// One turn of plm-core's drive loop: time runs to `until` at most, to
    /// the next thing due at the host, the modem or a wire. The port stops
    /// at each byte's arrival, so every event of the turn is at its end.
    fn turn(&mut self, until: Instant) {
        let Ok(now) = turn(&mut self.host, &mut self.port, until, |_, _| {});
        self.events
            .extend(std::iter::from_fn(|| self.host.poll_event()).map(|e| (now, e)));
    }

    /// The next moment something is due at the host (unless it is
    /// outside), the modem or a wire.
    pub fn next_due(&self) -> Option<Instant> {
        let host = self.host.poll_timeout().filter(|_| !self.outside);
        earliest(self.port.next_due(), host)
    }

    /// Moves virtual time to `t` (never back) and runs what is due: a
    /// network steps its nodes with this.
    pub fn advance(&mut self, t: Instant) {
        match self.outside {
            true => self.port.advance(t),
            false => self.turn(t),
        }
    }

    /// Hands on what either side has to say after something outside (the
    /// line, a host program) acted at `now` (never back).
    pub fn flush(&mut self, now: Instant) {
        self.port.flush(now);
        if !self.outside {
            self.turn(self.port.now);
        }
    }

    /// Runs for `d` µs.
    pub fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_| false);
    }

    /// Sends `cmd` and waits up to `limit` µs for the answer that closes
    /// it in the modem's current access layer (`code::answers`).
    pub fn request(&mut self, cmd: &Command, limit: Duration) -> Outcome {
        let layer = self.port.modem.layer();
        let ticket = self.submit(cmd);
        let request = cmd.code();
        let mut out = Outcome::TimedOut;
        self.run_until(limit, |e| match e {
            Event::Frame(f) if code::answers(request, f.code, layer) => {
                out = Command::from_frame(f, layer).map_or(Outcome::TimedOut, Outcome::Answer);
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

    /// The modem's frames received so far, decoded in `layer`.
    pub fn frames(&self, layer: Layer) -> Vec<Command> {
        self.events
            .iter()
            .filter_map(|(_, e)| match e {
                Event::Frame(f) => Command::from_frame(f, layer).ok(),
                _ => None,
            })
            .collect()
    }
}
