//! plm-core's host engine driving one simulated ST7570 over a byte-level
//! UART in virtual time (ST7570 UM 5.1-5.2), as [`crate::drive`] does for
//! the ST7580 world: one node of the S-FSK network ([`super::net`]), or a
//! modem alone in tests.

use super::St7570;
use crate::rng::Rng;
use crate::sim::Dir;
use crate::uart::Wire;
use plm_core::link::host::{Event, HostConfig, HostEngine, LinkError, Ticket, Transmit};
use plm_core::link::Dialect;
use plm_core::st7570::{code, Command, Layer};
use plm_core::time::{earliest, Duration, Instant};
use std::collections::VecDeque;

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

/// A host engine joined to one ST7570 by a UART in each direction.
#[derive(Debug, Clone)]
pub struct ModemDriver {
    /// The modem.
    pub modem: St7570,
    /// The host's link engine (ST7570 dialect).
    pub host: HostEngine,
    /// Every host event so far, with its time.
    pub events: Vec<(Instant, Event)>,
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
    /// The host is outside ([`ModemDriver::serve_outside`]): the modem's
    /// bytes wait here, with their arrival times, instead of going to
    /// [`ModemDriver::host`].
    outside: Option<Vec<(Instant, u8)>>,
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
            modem: St7570::new(baud, 0),
            host: HostEngine::new(Dialect::St7570, HostConfig::at_reset(Dialect::St7570, baud)),
            events: Vec::new(),
            now: 0,
            to_modem: Wire::new(baud),
            to_host: Wire::new(baud),
            rng: Rng::new(seed),
            at_modem: VecDeque::new(),
            at_host: VecDeque::new(),
            treq: VecDeque::new(),
            outside: None,
        }
    }

    /// From now on the host is outside (`plm sim`'s client, the console):
    /// it writes bytes and T_REQ levels ([`ModemDriver::write`],
    /// [`ModemDriver::set_treq`]) and reads the modem's bytes
    /// ([`ModemDriver::host_read`]); [`ModemDriver::host`] stays idle.
    pub fn serve_outside(&mut self) {
        self.outside.get_or_insert_with(Vec::new);
    }

    /// Whether the host is outside.
    pub fn is_outside(&self) -> bool {
        self.outside.is_some()
    }

    /// The outside host writes `bytes` on the UART now.
    pub fn write(&mut self, bytes: &[u8]) {
        let arrivals = self.to_modem.write(self.now, bytes, &mut self.rng);
        self.at_modem.extend(arrivals);
    }

    /// The outside host sets T_REQ (`asserted`: low), once the bytes it
    /// wrote before have left the UART.
    pub fn set_treq(&mut self, asserted: bool) {
        let at = self.to_modem.drained_at(self.now);
        self.treq.push_back((at, asserted));
    }

    /// How long until the bytes the outside host wrote so far have all
    /// reached the modem.
    pub fn backlog_to_modem(&self) -> Duration {
        self.to_modem.drained_at(self.now) - self.now
    }

    /// Purges the outside host's transmit side (its serial driver dropping
    /// its buffer): the bytes it wrote that have not yet reached the modem
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

    /// Purges the outside host's receive side: the modem's bytes that
    /// reached it and are not yet read, and those on their way to it.
    pub fn purge_to_host(&mut self) {
        self.at_host.clear();
        if let Some(out) = self.outside.as_mut() {
            out.clear();
        }
    }

    /// The modem's bytes that reached the outside host by now.
    pub fn host_read(&mut self) -> Vec<(Instant, u8)> {
        self.outside
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
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

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// Queues a command for the modem.
    pub fn submit(&mut self, cmd: &Command) -> Ticket {
        self.host.submit(self.now, cmd.to_frame())
    }

    /// Runs until `done` holds for a host event or `limit` µs have passed;
    /// returns whether `done` held.
    pub fn run_until(&mut self, limit: Duration, mut done: impl FnMut(&Event) -> bool) -> bool {
        let end = self.now + limit;
        let mut seen = self.events.len();
        loop {
            self.move_bytes();
            while seen < self.events.len() {
                seen += 1;
                if done(&self.events[seen - 1].1) {
                    return true;
                }
            }
            match self.next_due() {
                Some(t) if t <= end => self.now = self.now.max(t),
                _ => {
                    self.now = end;
                    return false;
                }
            }
            self.step();
        }
    }

    /// The next moment something is due on either side or on a wire.
    pub fn next_due(&self) -> Option<Instant> {
        [
            self.host.poll_timeout(),
            self.modem.poll_timeout(),
            self.at_modem.front().map(|b| b.0),
            self.at_host.front().map(|b| b.0),
            self.treq.front().map(|t| t.0),
        ]
        .into_iter()
        .fold(None, earliest)
    }

    /// Moves virtual time to `t` (never back), runs what is due and hands
    /// the outputs on: a network steps its nodes with this.
    pub fn advance(&mut self, t: Instant) {
        self.now = self.now.max(t);
        self.step();
        self.move_bytes();
    }

    /// Hands on what either side has to say after something outside (the
    /// line, a host program) acted at `now` (never back).
    pub fn flush(&mut self, now: Instant) {
        self.now = self.now.max(now);
        self.move_bytes();
    }

    /// Runs for `d` µs.
    pub fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_| false);
    }

    /// Sends `cmd` and waits up to `limit` µs for the answer that closes
    /// it in the modem's current access layer (`code::answers`).
    pub fn request(&mut self, cmd: &Command, limit: Duration) -> Outcome {
        let layer = self.modem.layer();
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

    /// Delivers what is due at `now` to both sides.
    fn step(&mut self) {
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
        while let Some(&(at, b)) = self.at_host.front().filter(|(at, _)| *at <= now) {
            self.at_host.pop_front();
            match self.outside.as_mut() {
                Some(out) => out.push((at, b)),
                None => self.host.handle_rx(at, &[b]),
            }
        }
        if self.modem.poll_timeout().is_some_and(|t| t <= now) {
            self.modem.handle_timeout(now);
        }
        if self.host.poll_timeout().is_some_and(|t| t <= now) {
            self.host.handle_timeout(now);
        }
    }

    /// Hands each side's output to its wire, and T_REQ to the modem.
    fn move_bytes(&mut self) {
        let now = self.now;
        while let Some(t) = self.host.poll_transmit() {
            match t {
                Transmit::Bytes(b) => {
                    let arrivals = self.to_modem.write(now, &b, &mut self.rng);
                    self.at_modem.extend(arrivals);
                }
                Transmit::TReq { asserted } => {
                    let at = self.to_modem.drained_at(now);
                    self.treq.push_back((at, asserted));
                }
            }
        }
        while let Some(b) = self.modem.poll_transmit() {
            let arrivals = self.to_host.write(now, &b, &mut self.rng);
            self.at_host.extend(arrivals);
        }
        while let Some(e) = self.host.poll_event() {
            self.events.push((now, e));
        }
    }
}
