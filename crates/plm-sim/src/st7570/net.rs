//! A simulated S-FSK network: ST7570 modems, each with its host on a
//! byte-level UART ([`ModemDriver`]), sharing one [`SfskLine`] in virtual
//! time. Node 0's host is the outside world (a test, `plm sim`); the
//! other nodes' hosts are the outside world too or a [`Responder`] (a
//! Server that configures itself and echoes what is sent to it).
//!
//! Slots are delivered at two moments: the end of the frame part (PRE,
//! SSD, P_SDU: 42 of the 45 bytes) and just before the slot's end (the
//! 3-byte window: alarms). All slot boundaries are the Client's, which a
//! Server takes on when it synchronizes (4.6): one grid from virtual time
//! 0, every node's phase only changing the delta-phase it measures.

use super::drive::{ModemDriver, Outcome};
use super::line::{self, SfskLine, Signal};
use super::responder::{PhySettings, Responder};
use super::slots::{SlotUse, Transmission, FRAME_BITS};
use super::St7570;
use crate::ports::Ports;
use crate::rng::Rng;
use plm_core::link::host::{Event, LinkError};
use plm_core::st7570::{code, Command, Layer};
use plm_core::time::{earliest, Duration, Instant};

/// One node: a modem, its host's link engine, and where it sits.
#[derive(Debug, Clone)]
pub struct Node {
    /// The modem and its host's engine.
    pub driver: ModemDriver,
    /// A simulated host answering for it, or `None` for the outside.
    pub responder: Option<Responder>,
    /// Its mains phase in 60° steps (0, 2, 4: L1, L2, L3; +3: reversed).
    pub phase: u8,
    /// Extra noise at this node, dBµV (power-added to the line's).
    pub extra_noise_dbuv: Option<f64>,
    /// The zero crossing of its phase is missing.
    pub mains_lost: bool,
    seen: usize,
}

/// A transmission on the line, and from whom.
#[derive(Debug, Clone)]
struct OnAir {
    node: usize,
    tx: Transmission,
}

/// What the line does at a moment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Due {
    /// The frame part of slots starting at `start` is over.
    Frame { start: Instant, slot: Duration },
    /// The window of slots starting at `start` is over.
    Window { start: Instant, slot: Duration },
}

/// How a network is made.
#[derive(Debug, Clone)]
pub struct NetConfig {
    /// Number of nodes (node 0 is the outside host's).
    pub nodes: usize,
    /// Seed of every random draw.
    pub seed: u64,
    /// UART baud rate of every node.
    pub baud: u32,
    /// The line.
    pub line: SfskLine,
    /// Nodes 1.. whose host is a [`Responder`] (the others are driven from
    /// outside), and which of those are repeaters.
    pub responders: Vec<(usize, bool)>,
    /// MAC timeouts (0002h-0004h, 0009h) run this many times faster.
    pub timeout_scale: u64,
    /// Nodes 0..served have their host outside at byte level
    /// ([`ModemDriver::serve_outside`]: `plm sim`'s clients, through
    /// [`Ports`]); the others' hosts are a [`Responder`] or plm-core's
    /// host engine driven by a test.
    pub served: usize,
    /// The [`Responder`] Servers take on node 0's bit rate, f0 and f1
    /// (00A1h) whenever they change ([`Responder::follow`]); otherwise
    /// they keep the factory ones.
    pub servers_follow: bool,
}

/// Nodes of a served network unless told otherwise: the host's modem and
/// three Servers, the third a repeater.
pub const SERVED_LINE_NODES: usize = 4;

/// In a served network ([`NetConfig::served_line`]) every this-many-th
/// node is a repeater (000Bh REPEAT).
pub const REPEATER_EVERY: usize = 3;

impl NetConfig {
    /// The network `plm sim --chip st7570` and the console's simulated
    /// ST7570 serve: nodes 0..`served` driven from outside, the others
    /// Servers at their node number that answer what is sent to them
    /// ([`Responder`]), every [`REPEATER_EVERY`]-th a repeater, taking on
    /// node 0's bit rate, f0 and f1 ([`NetConfig::servers_follow`]).
    pub fn served_line(nodes: usize, served: usize, seed: u64) -> Self {
        NetConfig {
            seed,
            served,
            servers_follow: true,
            responders: (served..nodes)
                .map(|i| (i, i % REPEATER_EVERY == 0))
                .collect(),
            ..NetConfig::new(nodes)
        }
    }

    /// The repeaters of a [`NetConfig::served_line`].
    pub fn repeaters(&self) -> Vec<usize> {
        self.responders
            .iter()
            .filter(|(_, rep)| *rep)
            .map(|(n, _)| *n)
            .collect()
    }

    /// `nodes` nodes, all driven from outside, on a default line.
    pub fn new(nodes: usize) -> Self {
        NetConfig {
            nodes,
            seed: 0x57_7570,
            baud: 57_600,
            line: SfskLine::default(),
            responders: Vec::new(),
            timeout_scale: 1,
            served: 0,
            servers_follow: false,
        }
    }
}

/// ST7570 nodes on one S-FSK line.
#[derive(Debug, Clone)]
pub struct Network {
    /// The nodes, by number.
    pub nodes: Vec<Node>,
    /// The line's conditions (may be changed between steps).
    pub line: SfskLine,
    rng: Rng,
    now: Instant,
    on_air: Vec<OnAir>,
    due: Vec<Due>,
    /// Subframe slots sent with differing contents heard by someone.
    pub collisions: u64,
    servers_follow: bool,
    /// Node 0's PHY settings as last given to the Servers.
    followed: Option<PhySettings>,
}

impl Network {
    /// Powers every node on at virtual time 0.
    pub fn new(config: NetConfig) -> Self {
        let mut rng = Rng::new(config.seed);
        let nodes = (0..config.nodes)
            .map(|i| {
                let mut driver = ModemDriver::with_seed(config.baud, rng.next_u64());
                driver.port.modem.set_timeout_scale(config.timeout_scale);
                if i < config.served {
                    driver.serve_outside();
                }
                let responder = config
                    .responders
                    .iter()
                    .find(|(n, _)| *n == i)
                    .map(|&(n, rep)| Responder::new(n as u16, rep));
                Node {
                    driver,
                    responder,
                    phase: (i % 3) as u8 * 2,
                    extra_noise_dbuv: None,
                    mains_lost: false,
                    seen: 0,
                }
            })
            .collect();
        let mut net = Network {
            nodes,
            line: config.line,
            rng,
            now: 0,
            on_air: Vec::new(),
            due: Vec::new(),
            collisions: 0,
            servers_follow: config.servers_follow,
            followed: None,
        };
        for i in 0..net.nodes.len() {
            net.refresh_node(i);
        }
        net
    }

    /// Virtual time now.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// Node `i`'s modem.
    pub fn modem(&self, i: usize) -> &St7570 {
        &self.nodes[i].driver.port.modem
    }

    /// Node `i`'s driver (modem and host engine).
    pub fn node(&mut self, i: usize) -> &mut ModemDriver {
        &mut self.nodes[i].driver
    }

    /// The zero crossing of node `i`'s phase disappears (`true`) or comes
    /// back: ZC_FAIL (3.6.8, Table 11).
    pub fn set_mains_lost(&mut self, i: usize, lost: bool) {
        self.nodes[i].mains_lost = lost;
        self.refresh_node(i);
    }

    /// Every modem's MAC timeouts (0002h-0004h, 0009h) run `scale` times
    /// faster from now on, so that a demo sees a timeout of minutes.
    pub fn set_timeout_scale(&mut self, scale: u64) {
        for n in &mut self.nodes {
            n.driver.port.modem.set_timeout_scale(scale);
        }
    }

    /// Node `i`'s frames received so far, decoded in `layer`.
    pub fn frames(&self, i: usize, layer: Layer) -> Vec<Command> {
        self.nodes[i].driver.frames(layer)
    }

    /// Queues `cmd` at node `i`'s host.
    pub fn submit(&mut self, i: usize, cmd: &Command) -> plm_core::link::host::Ticket {
        self.nodes[i].driver.flush(self.now);
        self.nodes[i].driver.submit(cmd)
    }

    /// Sends `cmd` from node `i`'s host and runs the network until the
    /// answer that closes it, or `limit` µs.
    pub fn request(&mut self, i: usize, cmd: &Command, limit: Duration) -> Outcome {
        let layer = self.modem(i).layer();
        let ticket = self.submit(i, cmd);
        let request = cmd.code();
        let mut out = Outcome::TimedOut;
        self.run_until(limit, |n, e| {
            if n != i {
                return false;
            }
            match e {
                Event::Frame(f) if code::answers(request, f.code, layer) => {
                    out = Command::from_frame(f, layer).map_or(Outcome::TimedOut, Outcome::Answer);
                    true
                }
                Event::Failed(t, why) if *t == ticket => {
                    out = Outcome::Failed(*why as LinkError);
                    true
                }
                _ => false,
            }
        });
        out
    }

    /// Runs for `d` µs.
    pub fn run_for(&mut self, d: Duration) {
        self.run_until(d, |_, _| false);
    }

    /// Runs until `done` holds for a host event of a node driven from
    /// outside, or `limit` µs have passed; returns whether it held.
    pub fn run_until(
        &mut self,
        limit: Duration,
        mut done: impl FnMut(usize, &Event) -> bool,
    ) -> bool {
        let end = self.now + limit;
        loop {
            self.follow_node_0();
            for i in 0..self.nodes.len() {
                self.after_step(i);
                let n = &mut self.nodes[i];
                if n.responder.is_some() {
                    continue;
                }
                while n.seen < n.driver.events.len() {
                    n.seen += 1;
                    if done(i, &n.driver.events[n.seen - 1].1) {
                        return true;
                    }
                }
            }
            match self.next_due() {
                Some(t) if t <= end => self.now = self.now.max(t),
                _ => {
                    self.now = end;
                    return false;
                }
            }
            let now = self.now;
            for i in 0..self.nodes.len() {
                if self.nodes[i].driver.next_due().is_some_and(|t| t <= now) {
                    self.nodes[i].driver.advance(now);
                }
            }
            self.run_line(now);
        }
    }

    /// The next moment a node, a wire or the line has something to do.
    fn next_due(&self) -> Option<Instant> {
        self.nodes
            .iter()
            .map(|n| n.driver.next_due())
            .chain(self.due.iter().map(|d| Some(due_at(d))))
            .fold(None, earliest)
    }

    /// [`NetConfig::servers_follow`]: node 0's bit rate, f0 and f1, when
    /// they changed (its host wrote 00A1h, or a reset brought the factory
    /// values back), given to every Responder Server, whose host then
    /// writes them to its modem.
    fn follow_node_0(&mut self) {
        if !self.servers_follow || self.nodes.is_empty() {
            return;
        }
        let phy = PhySettings::of(&self.modem(0).mib().plc());
        if self.followed == Some(phy) {
            return;
        }
        self.followed = Some(phy);
        for n in &mut self.nodes[1..] {
            if let Some(r) = n.responder.as_mut() {
                r.follow(phy);
            }
        }
    }

    /// Node `i`'s RESETn held low (`true`) or released: as a host wiring
    /// DTR to it ([`St7570::set_resetn`]).
    pub fn set_resetn(&mut self, i: usize, low: bool) {
        let now = self.now;
        let d = &mut self.nodes[i].driver;
        d.flush(now);
        d.port.modem.set_resetn(now, low);
        d.flush(now);
    }

    /// After node `i` acted: its responder, its mains, its transmissions.
    fn after_step(&mut self, i: usize) {
        let now = self.now;
        let node = &mut self.nodes[i];
        // What a host queued since (a request, T_REQ) leaves now.
        node.driver.flush(now);
        if let Some(r) = node.responder.as_mut() {
            r.step(&mut node.driver);
            node.driver.flush(now);
        }
        self.refresh_node(i);
        while let Some(tx) = self.nodes[i].driver.port.modem.poll_line() {
            self.schedule(&tx);
            self.on_air.push(OnAir { node: i, tx });
        }
    }

    /// ZC_FAIL when the node's phase has no zero crossing or its 00A1h
    /// expects another mains frequency (its PLL cannot lock); the noise
    /// it measures when nothing is sent (A0h, E0h).
    fn refresh_node(&mut self, i: usize) {
        let now = self.now;
        let line = &self.line;
        let node = &mut self.nodes[i];
        let m = &mut node.driver.port.modem;
        let fail = node.mains_lost || m.mib().plc().mains_60_hz != line.mains_60_hz;
        if fail != m.zc_fail() {
            m.set_zc_fail(now, fail);
            node.driver.flush(now);
        }
        let noise = self.noise_at(i);
        self.nodes[i]
            .driver
            .port
            .modem
            .set_line_noise(line::signal_noise(noise, 0.0, noise));
    }

    fn noise_at(&self, i: usize) -> f64 {
        let base = self.line.noise_dbuv;
        self.nodes[i]
            .extra_noise_dbuv
            .map_or(base, |x| line::power_sum([base, x]))
    }

    fn schedule(&mut self, tx: &Transmission) {
        for k in 0..tx.slots.len() as u64 {
            let start = tx.start + k * tx.slot;
            for d in [
                Due::Frame {
                    start,
                    slot: tx.slot,
                },
                Due::Window {
                    start,
                    slot: tx.slot,
                },
            ] {
                if !self.due.contains(&d) {
                    self.due.push(d);
                }
            }
        }
    }

    /// Delivers every slot part that ends at `now`.
    fn run_line(&mut self, now: Instant) {
        // In order as they are taken (a handful at a time), not `sort()`:
        // std's sort brings its own copy of its algorithms for each element
        // type into the console's page (docs/console.md, "Size").
        let mut due: Vec<Due> = Vec::new();
        self.due.retain(|d| {
            if due_at(d) <= now {
                let at = due.iter().position(|e| e > d).unwrap_or(due.len());
                due.insert(at, *d);
                false
            } else {
                true
            }
        });
        for d in due {
            self.deliver(now, d);
        }
        self.on_air.retain(|a| a.tx.end() > now);
    }

    /// What every node hears of the slots starting at `start`.
    fn deliver(&mut self, now: Instant, d: Due) {
        let (start, slot, window) = match d {
            Due::Frame { start, slot } => (start, slot, false),
            Due::Window { start, slot } => (start, slot, true),
        };
        // Who sends what in this slot.
        let sent: Vec<(usize, SlotUse, bool, u32, u32, u8)> = self
            .on_air
            .iter()
            .filter(|a| a.tx.slot == slot && a.tx.start <= start && start < a.tx.end())
            .filter(|a| self.nodes[a.node].driver.port.modem.is_on())
            .map(|a| {
                let k = ((start - a.tx.start) / slot) as usize;
                (
                    a.node,
                    a.tx.slots[k],
                    a.tx.bit_rate_2400,
                    a.tx.f0,
                    a.tx.f1,
                    a.tx.gain,
                )
            })
            .collect();
        if sent.is_empty() {
            return;
        }
        let slot_number = start / slot;
        for r in 0..self.nodes.len() {
            let plc = self.nodes[r].driver.port.modem.mib().plc();
            let rx_slot = self.nodes[r].driver.port.modem.slots().slot;
            if rx_slot != slot {
                continue;
            }
            let rphase = self.nodes[r].phase;
            let signals: Vec<Signal<'_>> = sent
                .iter()
                .filter(|s| s.0 != r)
                .filter(|s| {
                    s.3.abs_diff(plc.f0) <= line::TONE_TOLERANCE
                        && s.4.abs_diff(plc.f1) <= line::TONE_TOLERANCE
                })
                .map(|s| {
                    let loss = self.line.attenuation(s.0, r, self.nodes[s.0].phase, rphase);
                    Signal {
                        level: self.line.tx_level(s.5) - loss,
                        tilt: self.line.tilt_db * loss / 10.0
                            * (s.3.abs_diff(s.4) as f64 / 10_000.0),
                        slot: &s.1,
                        phase: line::delta_phase(self.nodes[s.0].phase, rphase, s.2, slot_number),
                    }
                })
                .collect();
            if signals.is_empty() {
                continue;
            }
            let noise = self.noise_at(r);
            let max_pga = self.nodes[r].driver.port.modem.mib().byte(0x00AB, 0).min(8);
            let modem = &mut self.nodes[r].driver.port.modem;
            if window {
                if let Some(sn) = line::receive_alarm(&signals, noise) {
                    modem.hear_alarm(now, sn);
                }
            } else {
                let subframes: Vec<&Signal<'_>> = signals
                    .iter()
                    .filter(|s| matches!(s.slot, SlotUse::Subframe(_)))
                    .collect();
                if subframes.len() > 1 && subframes.iter().any(|s| s.slot != subframes[0].slot) {
                    self.collisions += 1;
                }
                if let Some(heard) =
                    line::receive(&self.line, &signals, noise, max_pga, &mut self.rng)
                {
                    modem.hear(now, &heard);
                }
                let rc = line::receive_rc(&signals, noise);
                if !rc.is_empty() {
                    modem.hear_rc(now, &rc);
                }
            }
            self.nodes[r].driver.flush(now);
        }
    }
}

fn due_at(d: &Due) -> Instant {
    match *d {
        Due::Frame { start, slot } => start + slot * FRAME_BITS / super::slots::SLOT_BITS,
        // The window's pattern is known at its end; a hair before the
        // boundary, so that it belongs to the slot it ends.
        Due::Window { start, slot } => start + slot - 1,
    }
}

/// `plm sim --chip st7570`: nodes 0..[`NetConfig::served`] reached from
/// outside at byte level.
impl Ports for Network {
    fn served(&self) -> usize {
        self.nodes
            .iter()
            .take_while(|n| n.driver.is_outside())
            .count()
    }

    fn write_to(&mut self, node: usize, bytes: &[u8]) {
        let now = self.now;
        if let Some(n) = self.nodes.get_mut(node).filter(|n| n.driver.is_outside()) {
            n.driver.flush(now);
            n.driver.port.write(bytes);
        }
    }

    fn set_treq_of(&mut self, node: usize, asserted: bool) {
        let now = self.now;
        if let Some(n) = self.nodes.get_mut(node).filter(|n| n.driver.is_outside()) {
            n.driver.flush(now);
            n.driver.port.set_treq(asserted);
        }
    }

    fn set_resetn_of(&mut self, node: usize, low: bool) {
        if node < Ports::served(self) {
            self.set_resetn(node, low);
        }
    }

    fn baud_of(&self, node: usize) -> u32 {
        self.nodes[node].driver.port.baud()
    }

    fn set_baud_of(&mut self, node: usize, baud: u32) {
        if node < Ports::served(self) {
            let now = self.now;
            let d = &mut self.nodes[node].driver;
            d.flush(now);
            d.port.set_baud(baud);
        }
    }

    fn backlog_to_modem(&self, node: usize) -> Duration {
        // The driver's clock lags the network's until it is flushed.
        self.nodes
            .get(node)
            .filter(|n| n.driver.is_outside())
            .map_or(0, |n| {
                let left = n.driver.port.backlog_to_modem() + n.driver.now();
                left.saturating_sub(self.now)
            })
    }

    fn purge_to_modem(&mut self, node: usize) {
        let now = self.now;
        if let Some(n) = self.nodes.get_mut(node).filter(|n| n.driver.is_outside()) {
            n.driver.flush(now);
            n.driver.port.purge_to_modem();
        }
    }

    fn purge_to_host(&mut self, node: usize) {
        let now = self.now;
        if let Some(n) = self.nodes.get_mut(node).filter(|n| n.driver.is_outside()) {
            n.driver.flush(now);
            n.driver.port.purge_to_host();
        }
    }

    fn host_read_of(&mut self, node: usize) -> Vec<(Instant, u8)> {
        self.nodes
            .get_mut(node)
            .map_or_else(Vec::new, |n| n.driver.port.host_read())
    }

    fn uart_due_of(&self, node: usize) -> Option<Instant> {
        let n = self.nodes.get(node).filter(|n| n.driver.is_outside())?;
        n.driver.port.uart_due()
    }

    fn next_deadline(&self) -> Option<Instant> {
        self.next_due()
    }

    fn advance_to(&mut self, t: Instant) {
        self.run_for(t.saturating_sub(self.now));
    }
}
