//! The simulation: modems, their UARTs and hosts, and the power line that
//! joins them, run in virtual time from one event queue and one seeded RNG.
//!
//! Node 0's host is outside: the test, the console or `plm sim` writes
//! bytes and T_REQ through [`Sim::write`] and [`Sim::set_treq`] and reads
//! what came back with [`Sim::host_read`]. With [`SimConfig::served`]
//! above 1, nodes 1.. up to it have outside hosts too, each its own UART,
//! T_REQ, baud rate and faults ([`Sim::write_to`], [`Sim::set_treq_of`],
//! [`Sim::host_read_of`], [`Sim::inject_on`], [`Sim::set_baud_of`]). What those bytes reach is
//! [`Attach`]: node 0's modem (its host interface), or a concentrator
//! [`Board`] (its USART). Every other node's host is an [`EchoHost`] that
//! sends back what its modem hears, or, on a street ([`Peers::Street`]),
//! a street-light [`Board`] with its lamp.
//!
//! Nothing is ticked. The event queue holds what crosses a wire or the
//! line, at its time; each modem and host says when it next has something
//! to do (its `poll_timeout`), filed among the timers by node, and runs
//! only then or when an event reaches it (only that node is looked at
//! afterwards). A modem's write to its board (or echoing host) is one
//! event, at the arrival of the write's last byte: the host still takes
//! each byte at its own arrival time, so its UART timing rules (T_IC
//! between characters, UM0932 3.2.6, and the timing of repeats) hold, and
//! when a deadline of the host falls inside a write the bytes before it
//! are taken first. A frame's end at its receivers is one event too, run
//! at each receiver in node order. A board hearing a frame that is not
//! for it costs about four events (the frame's end, the modem's
//! indication, the board's ACK back, the modem's deadline); a quiet
//! street costs none ([`Sim::events_run`]).

use crate::ballast::BallastConfig;
use crate::board::{street_address, Board, BoardConfig};
use crate::breach::Breach;
use crate::echo::EchoHost;
use crate::line::{self, LineConfig, Transmission};
use crate::modem::{Reception, St7580};
use crate::profile::StreetProfile;
use crate::rng::Rng;
use crate::st7570::line::power_sum;
use crate::uart::{ByteFaults, OneShot, Wire};
use plm_core::link::host::Transmit;
use plm_core::mib::MibError;
use plm_core::st7580::{Channel, Command, Modulation, ResetCause, Temperature};
use plm_core::time::{earliest, Duration, Instant};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};
use std::sync::Arc;

/// How a simulation starts.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Seed of the one RNG: the same seed gives the same run.
    pub seed: u64,
    /// Modems on the line (at least 1): node 0 is the host's, the others
    /// echo.
    pub nodes: usize,
    /// UART baud rate of every node (UM0932 Table 5).
    pub baud: u32,
    /// Conditions on the power line.
    pub line: LineConfig,
    /// What the outside host is wired to.
    pub attach: Attach,
    /// Who the other nodes' hosts are.
    pub peers: Peers,
    /// Nodes whose host is outside, 0 up to this (at least 1; more than 1
    /// only with [`Attach::Modem`] and echoing peers).
    pub served: usize,
    /// The lamps of a street's boards, before [`SimConfig::profile`]
    /// shapes each.
    pub ballast: BallastConfig,
    /// How a street's lamps differ, from [`SimConfig::seed`].
    pub profile: StreetProfile,
    /// The modulation the street's boards (and a concentrator board)
    /// send with (their firmware's TxParams; B-PSK by default).
    pub modulation: Modulation,
    /// A rule of the board protocol every street board breaks (to show
    /// `plm board conformance` catching it); `None` for a street that
    /// keeps them all.
    pub breach: Option<Breach>,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            nodes: 1,
            baud: 57_600,
            line: LineConfig::default(),
            attach: Attach::Modem,
            peers: Peers::Echo,
            served: 1,
            ballast: BallastConfig::default(),
            profile: StreetProfile::Uniform,
            modulation: Modulation::BPsk,
            breach: None,
        }
    }
}

impl SimConfig {
    /// A street of `lamps` boards along the line behind node 0, reached
    /// `via` a concentrator board's USART or a bare modem.
    pub fn street(lamps: usize, via: Attach) -> SimConfig {
        SimConfig {
            nodes: lamps + 1,
            line: LineConfig::street(lamps),
            attach: via,
            peers: Peers::Street,
            // The lamps were lit before the simulation began, so that a
            // newcomer sees a street at work at once.
            ballast: BallastConfig {
                warm_start: true,
                ..BallastConfig::default()
            },
            ..SimConfig::default()
        }
    }
}

/// What the outside host's bytes reach on node 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Attach {
    /// The ST7580's host interface (UM0932 3), with T_REQ.
    Modem,
    /// A concentrator board's USART (STEVAL UM 4.6): application frames,
    /// no T_REQ; the board's firmware drives the modem.
    Board,
}

/// Who the hosts of nodes 1.. are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Peers {
    /// Echoing hosts (modem demos and tests), configured at the factory
    /// defaults.
    Echo,
    /// Echoing hosts that apply node 0's MIB 00h and 01h values whenever
    /// they change (as if their host wrote the same), so that they hear
    /// what node 0 sends whatever its host configured.
    EchoFollowing,
    /// Street-light controller boards with their lamps.
    Street,
}

/// Who drives a node's modem.
#[derive(Debug, Clone)]
enum Host {
    /// The outside world (node 0 with [`Attach::Modem`]).
    Outside,
    Echo(Box<EchoHost>),
    Board(Box<Board>),
}

impl Host {
    fn poll_timeout(&self) -> Option<Instant> {
        match self {
            Host::Outside => None,
            Host::Echo(e) => e.poll_timeout(),
            Host::Board(b) => b.poll_timeout(),
        }
    }

    fn poll_transmit(&mut self) -> Option<Transmit> {
        match self {
            Host::Outside => None,
            Host::Echo(e) => e.poll_transmit(),
            Host::Board(b) => b.poll_transmit(),
        }
    }
}

/// A direction on node 0's UART.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    /// Host TX to modem RX.
    HostToModem,
    /// Modem TX to host RX.
    ModemToHost,
}

/// A fault to inject on node 0, at the current time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// Lose the next byte written this way.
    DropByte(Dir),
    /// Flip bits (the mask) of the next byte written this way.
    CorruptByte(Dir, u8),
    /// Stall the line before the next byte written this way.
    DelayByte(Dir, Duration),
    /// Pull RESETN: the modem restarts with its factory MIB (Table 19
    /// cause 0).
    ModemReset,
    /// Hold RESETN low (`true`: the modem off, its MIB lost) or release it
    /// (`false`: it boots with its factory MIB and sends
    /// BIO_ResetIndication, Table 19 cause 0), as a host that wires DTR
    /// to RESETN does.
    Resetn(bool),
    /// The watchdog fires: the modem restarts and keeps the MIB objects
    /// 00h-02h the host wrote (Table 19 cause 1).
    Watchdog,
    /// Pull the cable: nothing crosses the UART, T_REQ floats high.
    Unplug,
    /// Plug it back in.
    Plug,
    /// Set the modem's temperature class (Table 8).
    Temperature(Temperature),
}

/// Something that happened on the power line, for traces and views.
#[derive(Debug, Clone, PartialEq)]
pub enum LineEvent {
    /// A modem started a frame.
    Sent {
        /// When the preamble started.
        at: Instant,
        /// Sender.
        from: usize,
        /// Modulation.
        modulation: Modulation,
        /// Carrier, Hz.
        frequency: u32,
        /// PSDU bytes (length byte included).
        bytes: usize,
        /// Airtime.
        airtime: Duration,
    },
    /// A modem received it.
    Heard {
        /// End of the frame.
        at: Instant,
        /// Sender.
        from: usize,
        /// Receiver.
        to: usize,
        /// Signal to noise ratio, dB.
        snr_db: f64,
        /// Whether a byte was corrupted on the way.
        corrupted: bool,
    },
    /// A modem that could have heard it did not.
    Missed {
        /// When it was lost.
        at: Instant,
        /// Sender.
        from: usize,
        /// Receiver.
        to: usize,
        /// Why.
        why: &'static str,
    },
}

/// Line events kept for [`Sim::poll_line_event`].
const LINE_LOG: usize = 4_096;

#[derive(Debug, Clone)]
enum Ev {
    ToModem {
        node: usize,
        byte: u8,
    },
    /// A byte for an outside host.
    ToHost {
        node: usize,
        byte: u8,
    },
    /// The last byte of a write of `node`'s modem has reached its inside
    /// host: the host takes what its inbox holds by now.
    HostBytes {
        node: usize,
    },
    Treq {
        node: usize,
        asserted: bool,
    },
    /// Outside host to the concentrator board's USART.
    ToUsart {
        byte: u8,
    },
    /// The concentrator board's USART to the outside host.
    FromUsart {
        byte: u8,
    },
    TxStart(Box<Transmission>),
    /// Frame `id` ends at the modems that were receiving it, in node
    /// order.
    RxEnd {
        id: u64,
        nodes: Vec<usize>,
    },
}

#[derive(Debug, Clone)]
struct Scheduled {
    at: Instant,
    seq: u64,
    ev: Ev,
}

impl PartialEq for Scheduled {
    fn eq(&self, o: &Self) -> bool {
        (self.at, self.seq) == (o.at, o.seq)
    }
}
impl Eq for Scheduled {}
impl PartialOrd for Scheduled {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Scheduled {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        (self.at, self.seq).cmp(&(o.at, o.seq))
    }
}

/// A frame being received by one modem.
#[derive(Debug, Clone)]
struct ActiveRx {
    id: u64,
    tx: Arc<Transmission>,
    channel: Channel,
    level: f64,
    /// The other frames that overlapped it on its channel: their powers
    /// summed and the strongest, dBµV (`-inf` while none did).
    others: f64,
    strongest: f64,
    /// Why it is lost whatever the others were (its receiver started
    /// sending).
    dropped: Option<&'static str>,
}

#[derive(Debug, Clone)]
struct Node {
    modem: St7580,
    /// Host to modem.
    down: Wire,
    /// Modem to host.
    up: Wire,
    host: Host,
    /// What the modem wrote to an inside host ([`Host::Echo`],
    /// [`Host::Board`]), with each byte's arrival time, not yet taken.
    inbox: VecDeque<(Instant, u8)>,
    rx: Vec<ActiveRx>,
    /// Cut off the line (the board's supply off, its cable cut): it
    /// neither hears nor is heard.
    cut: bool,
}

/// The simulated modems and their power line.
#[derive(Debug, Clone)]
pub struct Sim {
    now: Instant,
    seq: u64,
    rng: Rng,
    line: LineConfig,
    nodes: Vec<Node>,
    queue: BinaryHeap<Reverse<Scheduled>>,
    /// Per outside host (index = node): bytes that reached it, whether its
    /// cable is in, its T_REQ level.
    host_rx: Vec<VecDeque<(Instant, u8)>>,
    plugged: Vec<bool>,
    treq: Vec<bool>,
    /// Node 0's MIB 00h and 01h as last applied to following peers.
    followed: [Vec<u8>; 2],
    peers: Peers,
    log: VecDeque<LineEvent>,
    attach: Attach,
    /// Outside host to the concentrator board's USART ([`Attach::Board`]).
    usart_down: Wire,
    /// The concentrator board's USART to the outside host.
    usart_up: Wire,
    /// Nodes whose components may have output or a new deadline: only
    /// they are looked at after an event, so that a street of 500 costs
    /// what its busy nodes do.
    dirty: Vec<usize>,
    is_dirty: Vec<bool>,
    /// Each node's earliest component deadline, and all of them ordered.
    deadlines: Vec<Option<Instant>>,
    /// Earliest first; an entry is current while `deadlines` holds it
    /// (older ones are dropped when they come to the top): a heap, so
    /// that the console's wasm carries no B-tree code for it.
    timers: BinaryHeap<Reverse<(Instant, usize)>>,
    /// Events run so far ([`Sim::events_run`]).
    events_run: u64,
}

impl Sim {
    /// Powers every modem on at virtual time 0: the BIO_ResetIndications
    /// follow after the boot time. A real-time driver maps its own clock
    /// onto virtual time from the moment it creates the simulation (or
    /// from when its host is there to hear them).
    pub fn new(config: SimConfig) -> Sim {
        let mut rng = Rng::new(config.seed);
        // The far lamp's poor connection, on a realistic street.
        let lamps = config.nodes.max(1) - 1;
        let mut line = config.line.clone();
        if config.peers == Peers::Street {
            line.node_loss_db
                .extend(config.profile.weak_lamp(lamps, &config.line));
        }
        let nodes: Vec<Node> = (0..config.nodes.max(1))
            .map(|i| {
                let board = |ballast, clock_offset| {
                    Board::new(
                        0,
                        BoardConfig {
                            address: street_address(i),
                            ballast,
                            baud: config.baud,
                            clock_offset,
                            modulation: config.modulation,
                        },
                    )
                };
                let host = match (i, config.attach, config.peers) {
                    (0, Attach::Modem, _) => Host::Outside,
                    (_, Attach::Modem, Peers::Echo | Peers::EchoFollowing) if i < config.served => {
                        Host::Outside
                    }
                    (0, Attach::Board, _) => Host::Board(Box::new(board(None, 0).with_usart())),
                    (_, _, Peers::Echo | Peers::EchoFollowing) => {
                        Host::Echo(Box::new(EchoHost::new(config.baud)))
                    }
                    (_, _, Peers::Street) => {
                        // Each board's RTC drifted up to 10 minutes; each
                        // ballast has its own stream of chance.
                        let offset = rng.below(600);
                        let mut ballast = BallastConfig {
                            seed: rng.next_u64(),
                            ..config.ballast.clone()
                        };
                        // A street at work has lamps of every age: up to
                        // two years of nights, a start about each night.
                        if ballast.warm_start {
                            ballast.lifetime_hours = rng.below(8_000) as u16;
                            ballast.power_ons = ballast.lifetime_hours / 11 + 1;
                        }
                        config.profile.shape(config.seed, i, lamps, &mut ballast);
                        Host::Board(Box::new(
                            board(Some(ballast), offset).with_breach(config.breach),
                        ))
                    }
                };
                Node {
                    modem: St7580::new(i, config.baud, 0, config.seed),
                    down: Wire::new(config.baud),
                    up: Wire::new(config.baud),
                    host,
                    inbox: VecDeque::new(),
                    rx: Vec::new(),
                    cut: false,
                }
            })
            .collect();
        let served = nodes
            .iter()
            .take_while(|n| matches!(n.host, Host::Outside))
            .count()
            .max(1);
        let mut sim = Sim {
            now: 0,
            seq: 0,
            rng,
            line,
            nodes,
            queue: BinaryHeap::new(),
            host_rx: vec![VecDeque::new(); served],
            plugged: vec![true; served],
            treq: vec![false; served],
            followed: Default::default(),
            peers: config.peers,
            log: VecDeque::new(),
            attach: config.attach,
            usart_down: Wire::new(config.baud),
            usart_up: Wire::new(config.baud),
            dirty: Vec::new(),
            is_dirty: Vec::new(),
            deadlines: Vec::new(),
            timers: BinaryHeap::new(),
            events_run: 0,
        };
        let n = sim.nodes.len();
        sim.is_dirty = vec![false; n];
        sim.deadlines = vec![None; n];
        for i in 0..n {
            sim.touch(i);
        }
        sim.flush();
        sim
    }

    /// Marks `node` for the next [`Sim::flush`].
    fn touch(&mut self, node: usize) {
        if let Some(d) = self.is_dirty.get_mut(node) {
            if !*d {
                *d = true;
                self.dirty.push(node);
            }
        }
    }

    /// Files `node`'s earliest deadline among the timers.
    fn refresh_deadline(&mut self, node: usize) {
        let n = &self.nodes[node];
        let d = earliest(n.modem.poll_timeout(), n.host.poll_timeout());
        if d != self.deadlines[node] {
            if let Some(new) = d {
                self.timers.push(Reverse((new, node)));
            }
            self.deadlines[node] = d;
            self.drop_stale_timers();
        }
    }

    /// Keeps the heap's top current: entries a node's new deadline
    /// replaced go.
    fn drop_stale_timers(&mut self) {
        while let Some(Reverse((t, node))) = self.timers.peek() {
            if self.deadlines[*node] == Some(*t) {
                break;
            }
            self.timers.pop();
        }
    }

    /// What the outside host is wired to.
    pub fn attach(&self) -> Attach {
        self.attach
    }

    /// The board of `node`, if a board drives that node's modem.
    pub fn board(&self, node: usize) -> Option<&Board> {
        match &self.nodes.get(node)?.host {
            Host::Board(b) => Some(b),
            _ => None,
        }
    }

    /// Acts on the board of `node` now (fail or repair its lamp, ...).
    pub fn with_board<R>(
        &mut self,
        node: usize,
        f: impl FnOnce(&mut Board, Instant) -> R,
    ) -> Option<R> {
        let now = self.now;
        if node < self.nodes.len() {
            self.take_inbox(node);
        }
        let r = match &mut self.nodes.get_mut(node)?.host {
            Host::Board(b) => Some(f(b, now)),
            _ => None,
        };
        self.touch(node);
        self.flush();
        r
    }

    /// Cuts `node` off the line, or joins it again: a board whose supply
    /// is off neither hears nor answers (an unreachable node), and when it
    /// comes back its firmware starts again (RAM lost, the bootloader
    /// choosing the image, `Board::power_cycle`).
    pub fn set_cut(&mut self, node: usize, cut: bool) {
        let Some(n) = self.nodes.get_mut(node) else {
            return;
        };
        let restored = n.cut && !cut;
        n.cut = cut;
        if restored {
            self.with_board(node, |b, now| b.power_cycle(now));
        }
    }

    /// Whether `node` is cut off the line.
    pub fn is_cut(&self, node: usize) -> bool {
        self.nodes.get(node).is_some_and(|n| n.cut)
    }

    /// Virtual time now, µs.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// Number of modems.
    pub fn nodes(&self) -> usize {
        self.nodes.len()
    }

    /// The modem of `node`.
    pub fn modem(&self, node: usize) -> &St7580 {
        &self.nodes[node].modem
    }

    /// Data indications the host of `node` has echoed (0 for node 0).
    pub fn echoed(&self, node: usize) -> u64 {
        match &self.nodes[node].host {
            Host::Echo(e) => e.echoed,
            _ => 0,
        }
    }

    /// Configures a MIB object of `node` directly, as its host would have
    /// (peers come up configured this way). Checked like a write.
    pub fn configure(&mut self, node: usize, index: u8, data: &[u8]) -> Result<(), MibError> {
        let r = self.nodes[node].modem.configure(index, data);
        self.touch(node);
        self.flush();
        r
    }

    /// Makes the host of peer `node` (not 0) send `cmd` to its modem now,
    /// e.g. a data request: peers can talk first, not only echo.
    pub fn peer_request(&mut self, node: usize, cmd: &Command) {
        let now = self.now;
        if node < self.nodes.len() {
            self.take_inbox(node);
        }
        if let Some(Host::Echo(app)) = self.nodes.get_mut(node).map(|n| &mut n.host) {
            app.submit(now, cmd);
        }
        self.touch(node);
        self.flush();
    }

    /// Line conditions.
    pub fn line(&self) -> &LineConfig {
        &self.line
    }

    /// Changes the line conditions from now on.
    pub fn set_line(&mut self, line: LineConfig) {
        self.line = line;
    }

    /// Random byte faults on one direction of node 0's UART.
    pub fn set_byte_faults(&mut self, dir: Dir, faults: ByteFaults) {
        self.wire(0, dir).faults = faults;
    }

    /// Injects a fault now.
    pub fn inject(&mut self, fault: Fault) {
        self.inject_on(0, fault);
    }

    /// Injects a fault on served node `node` now (nothing for another
    /// node).
    pub fn inject_on(&mut self, node: usize, fault: Fault) {
        if node >= self.served() {
            return;
        }
        let now = self.now;
        match fault {
            Fault::DropByte(d) => self.wire(node, d).inject(OneShot::Drop),
            Fault::CorruptByte(d, m) => self.wire(node, d).inject(OneShot::Corrupt(m)),
            Fault::DelayByte(d, by) => self.wire(node, d).inject(OneShot::Delay(by)),
            Fault::ModemReset => self.nodes[node].modem.reset(now, ResetCause::PowerOn),
            // A concentrator board's USART has no line to RESETN.
            Fault::Resetn(low) if self.attach == Attach::Modem => {
                self.nodes[node].modem.set_resetn(now, low)
            }
            Fault::Resetn(_) => {}
            Fault::Watchdog => self.nodes[node].modem.reset(now, ResetCause::Watchdog),
            Fault::Unplug => {
                self.plugged[node] = false;
                self.nodes[node].modem.set_treq(now, false);
            }
            Fault::Plug => {
                self.plugged[node] = true;
                let treq = self.treq[node];
                self.nodes[node].modem.set_treq(now, treq);
            }
            Fault::Temperature(t) => self.nodes[node].modem.temperature = t,
        }
        self.touch(node);
        self.flush();
    }

    /// Nodes whose host is outside (0 up to this).
    pub fn served(&self) -> usize {
        self.plugged.len()
    }

    /// Whether node 0's cable is plugged in.
    pub fn plugged(&self) -> bool {
        self.plugged[0]
    }

    /// The outside host's UART baud rate.
    pub fn baud(&self) -> u32 {
        self.baud_of(0)
    }

    /// The UART baud rate of served node `node`'s host.
    pub fn baud_of(&self, node: usize) -> u32 {
        match (self.attach, node) {
            (Attach::Board, 0) => self.usart_down.baud(),
            _ => self.nodes[node].down.baud(),
        }
    }

    /// Sets node 0's UART baud rate, both ways and at the modem (its
    /// BR0/BR1 pins strapped to match the host, see protocol notes); with
    /// a concentrator board, its USART's.
    pub fn set_baud(&mut self, baud: u32) {
        self.set_baud_of(0, baud);
    }

    /// Sets served node `node`'s UART baud rate, as [`Sim::set_baud`] does
    /// node 0's.
    pub fn set_baud_of(&mut self, node: usize, baud: u32) {
        if node >= self.served() {
            return;
        }
        if self.attach == Attach::Board && node == 0 {
            self.usart_down.set_baud(baud);
            self.usart_up.set_baud(baud);
            return;
        }
        let n = &mut self.nodes[node];
        n.down.set_baud(baud);
        n.up.set_baud(baud);
        n.modem.set_baud(baud);
        self.touch(node);
        self.flush();
    }

    /// The host writes `bytes` to node 0's UART (or the concentrator
    /// board's USART) now.
    pub fn write(&mut self, bytes: &[u8]) {
        self.write_to(0, bytes);
    }

    /// The host of served node `node` writes `bytes` to its UART now.
    pub fn write_to(&mut self, node: usize, bytes: &[u8]) {
        if !self.plugged.get(node).copied().unwrap_or(false) {
            return;
        }
        if self.attach == Attach::Board && node == 0 {
            let arrivals = self.usart_down.write(self.now, bytes, &mut self.rng);
            for (at, byte) in arrivals {
                self.schedule(at, Ev::ToUsart { byte });
            }
            return;
        }
        let arrivals = self.nodes[node].down.write(self.now, bytes, &mut self.rng);
        for (at, byte) in arrivals {
            self.schedule(at, Ev::ToModem { node, byte });
        }
    }

    /// The host sets node 0's T_REQ (`asserted`: low). It changes once the
    /// bytes written before have left the UART, as a driver drains its
    /// FIFO before touching RTS.
    pub fn set_treq(&mut self, asserted: bool) {
        self.set_treq_of(0, asserted);
    }

    /// The host of served node `node` sets its T_REQ, as
    /// [`Sim::set_treq`].
    pub fn set_treq_of(&mut self, node: usize, asserted: bool) {
        if self.attach == Attach::Board || node >= self.served() {
            return; // a board's USART has no T_REQ (STEVAL UM 4.6)
        }
        self.treq[node] = asserted;
        let at = self.nodes[node].down.drained_at(self.now);
        self.schedule(at, Ev::Treq { node, asserted });
    }

    /// How long until the bytes served node `node`'s host wrote so far
    /// have all reached its modem (or the concentrator board's USART).
    pub fn backlog_to_modem(&self, node: usize) -> Duration {
        let drained = match (self.attach, node) {
            (Attach::Board, 0) => self.usart_down.drained_at(self.now),
            _ => self
                .nodes
                .get(node)
                .map_or(self.now, |n| n.down.drained_at(self.now)),
        };
        drained - self.now
    }

    /// When the bytes now on served node `node`'s UART (or the
    /// concentrator board's USART) have arrived, the earliest of the two
    /// ways still to come; `None` when none are on the way.
    pub fn uart_due_of(&self, node: usize) -> Option<Instant> {
        let (down, up) = match (self.attach, node) {
            (Attach::Board, 0) => (&self.usart_down, &self.usart_up),
            _ => {
                let n = self.nodes.get(node)?;
                (&n.down, &n.up)
            }
        };
        let end = |w: &Wire| Some(w.drained_at(self.now)).filter(|&t| t > self.now);
        earliest(end(down), end(up))
    }

    /// Purges the transmit side of served node `node`'s host (its serial
    /// driver dropping its buffer): the bytes it wrote that have not yet
    /// reached the modem (or the board's USART) are lost, and a T_REQ
    /// change waiting behind them takes effect now, at the level the host
    /// set last. The modem runs on.
    pub fn purge_to_modem(&mut self, node: usize) {
        if node >= self.served() {
            return;
        }
        let now = self.now;
        let board = self.attach == Attach::Board && node == 0;
        self.wire(node, Dir::HostToModem).purge(now);
        let mut treq_waited = false;
        self.queue.retain(|s| match s.0.ev {
            // A board's own firmware writes to node 0's modem: kept.
            Ev::ToModem { node: n, .. } => board || n != node,
            Ev::ToUsart { .. } => !board,
            Ev::Treq { node: n, .. } if n == node => {
                treq_waited = true;
                false
            }
            _ => true,
        });
        if treq_waited {
            let asserted = self.treq[node];
            self.schedule(now, Ev::Treq { node, asserted });
        }
    }

    /// Purges the receive side of served node `node`'s host: the bytes
    /// that reached it and are not yet read, and those on their way to it
    /// (not heard; the modem's UART still takes their time).
    pub fn purge_to_host(&mut self, node: usize) {
        if node >= self.served() {
            return;
        }
        let board = self.attach == Attach::Board && node == 0;
        self.queue.retain(|s| match s.0.ev {
            Ev::ToHost { node: n, .. } => board || n != node,
            Ev::FromUsart { .. } => !board,
            _ => true,
        });
        self.host_rx[node].clear();
    }

    /// Bytes that reached node 0's host by now, with their arrival times.
    pub fn host_read(&mut self) -> Vec<(Instant, u8)> {
        self.host_read_of(0)
    }

    /// Bytes that reached served node `node`'s host by now.
    pub fn host_read_of(&mut self, node: usize) -> Vec<(Instant, u8)> {
        match self.host_rx.get_mut(node) {
            Some(rx) => rx.drain(..).collect(),
            None => Vec::new(),
        }
    }

    /// The next line event, oldest first (the last few thousand are kept).
    pub fn poll_line_event(&mut self) -> Option<LineEvent> {
        self.log.pop_front()
    }

    /// The next moment anything happens, byte arrivals at the host
    /// included: a driver that advances to it never misses a byte.
    pub fn next_deadline(&self) -> Option<Instant> {
        earliest(
            self.queue.peek().map(|s| s.0.at),
            self.timers.peek().map(|t| t.0 .0),
        )
    }

    /// Events run so far: a byte, a modem's write reaching its board, a
    /// frame ending at one receiver, a component's deadline each count
    /// one. What a street costs, for tests and benchmarks.
    pub fn events_run(&self) -> u64 {
        self.events_run
    }

    /// Runs everything due up to `t`, then sets the clock to `t`.
    pub fn advance_to(&mut self, t: Instant) {
        while let Some(d) = self.next_deadline() {
            if d > t {
                break;
            }
            self.now = self.now.max(d);
            self.step();
        }
        self.now = self.now.max(t);
    }

    fn wire(&mut self, node: usize, dir: Dir) -> &mut Wire {
        let board = self.attach == Attach::Board && node == 0;
        let n = &mut self.nodes[node];
        match (board, dir) {
            (false, Dir::HostToModem) => &mut n.down,
            (false, Dir::ModemToHost) => &mut n.up,
            (true, Dir::HostToModem) => &mut self.usart_down,
            (true, Dir::ModemToHost) => &mut self.usart_up,
        }
    }

    /// Whether `node`'s host is outside and its cable in.
    fn connected(&self, node: usize) -> bool {
        self.plugged.get(node).copied().unwrap_or(true)
    }

    fn schedule(&mut self, at: Instant, ev: Ev) {
        self.seq += 1;
        self.queue.push(Reverse(Scheduled {
            at,
            seq: self.seq,
            ev,
        }));
    }

    fn record(&mut self, e: LineEvent) {
        if self.log.len() == LINE_LOG {
            self.log.pop_front();
        }
        self.log.push_back(e);
    }

    /// Everything due now: queued events first (a byte exactly T_IC after
    /// the previous one is in time), then the components' deadlines.
    fn step(&mut self) {
        let now = self.now;
        while self.queue.peek().is_some_and(|s| s.0.at <= now) {
            let Reverse(s) = self.queue.pop().expect("peeked");
            self.events_run += 1;
            self.dispatch(s.ev);
            self.flush();
        }
        let mut due: Vec<usize> = Vec::new();
        while let Some(Reverse((t, node))) = self.timers.peek().copied() {
            if t > now {
                break;
            }
            self.timers.pop();
            if self.deadlines[node] == Some(t) {
                // Filed again by `touch` below if still due later.
                self.deadlines[node] = None;
                due.push(node);
                self.events_run += 1;
            }
        }
        self.drop_stale_timers();
        for i in due {
            let n = &mut self.nodes[i];
            if n.modem.poll_timeout().is_some_and(|d| d <= now) {
                n.modem.handle_timeout(now);
            }
            if !n.inbox.is_empty() {
                self.take_inbox(i);
            }
            let Sim { nodes, rng, .. } = self;
            let n = &mut nodes[i];
            if n.host.poll_timeout().is_some_and(|d| d <= now) {
                match &mut n.host {
                    Host::Outside => {}
                    Host::Echo(e) => e.handle_timeout(now),
                    Host::Board(b) => b.handle_timeout(now, rng),
                }
            }
            self.touch(i);
        }
        self.flush();
    }

    /// Hands `node`'s inside host the bytes of its inbox that have
    /// arrived by now, each at its arrival time: the bytes of a write are
    /// taken together at its last byte's event, or, when the host has a
    /// deadline of its own (or is acted on) in the middle of a write,
    /// those before it first. The host sees each byte when it came, as if
    /// each were an event, at one event per write (a 500-lamp street's
    /// boards each hear every frame on the line).
    fn take_inbox(&mut self, node: usize) {
        let now = self.now;
        let Sim { nodes, rng, .. } = self;
        let n = &mut nodes[node];
        let come = n.inbox.partition_point(|b| b.0 <= now);
        let run = n.inbox.drain(..come);
        match &mut n.host {
            Host::Echo(app) => app.handle_rx(run),
            Host::Board(b) => b.handle_rx(run, rng),
            Host::Outside => {}
        }
    }

    fn dispatch(&mut self, ev: Ev) {
        let now = self.now;
        match &ev {
            Ev::ToModem { node, .. }
            | Ev::ToHost { node, .. }
            | Ev::HostBytes { node }
            | Ev::Treq { node, .. } => self.touch(*node),
            Ev::RxEnd { .. } => {}
            Ev::ToUsart { .. } => self.touch(0),
            Ev::FromUsart { .. } | Ev::TxStart(_) => {}
        }
        match ev {
            Ev::ToModem { node, byte } => {
                if self.connected(node) {
                    self.nodes[node].modem.handle_rx(now, &[byte]);
                }
            }
            Ev::ToHost { node, byte } => {
                if self.plugged[node] {
                    self.host_rx[node].push_back((now, byte));
                }
            }
            Ev::HostBytes { node } => self.take_inbox(node),
            Ev::ToUsart { byte } => {
                if let (true, Host::Board(b)) = (self.plugged[0], &mut self.nodes[0].host) {
                    b.usart_rx(now, &[byte], &mut self.rng);
                }
            }
            Ev::FromUsart { byte } => {
                if self.plugged[0] {
                    self.host_rx[0].push_back((now, byte));
                }
            }
            Ev::Treq { node, asserted } => {
                if self.connected(node) {
                    self.nodes[node].modem.set_treq(now, asserted);
                }
            }
            Ev::TxStart(tx) => self.start_transmission(*tx),
            Ev::RxEnd { id, nodes } => {
                // One after another, as if each had its own event.
                self.events_run += (nodes.len() as u64).saturating_sub(1);
                for node in nodes {
                    self.touch(node);
                    self.end_reception(node, id);
                    self.flush();
                }
            }
        }
    }

    /// Moves what the touched modems and apps produced onto the UARTs and
    /// the line, and files their new deadlines.
    fn flush(&mut self) {
        let now = self.now;
        while let Some(i) = self.dirty.pop() {
            self.is_dirty[i] = false;
            while let Some(bytes) = self.nodes[i].modem.poll_transmit() {
                let arrivals = self.nodes[i].up.write(now, &bytes, &mut self.rng);
                if matches!(self.nodes[i].host, Host::Outside) {
                    for (at, byte) in arrivals {
                        self.schedule(at, Ev::ToHost { node: i, byte });
                    }
                } else if let Some(&(last, _)) = arrivals.last() {
                    self.nodes[i].inbox.extend(arrivals);
                    self.schedule(last, Ev::HostBytes { node: i });
                }
            }
            while let Some(tx) = self.nodes[i].modem.poll_line() {
                self.schedule(tx.start, Ev::TxStart(Box::new(tx)));
            }
            while let Some(bytes) = match &mut self.nodes[i].host {
                Host::Board(b) => b.poll_usart(),
                _ => None,
            } {
                let arrivals = self.usart_up.write(now, &bytes, &mut self.rng);
                for (at, byte) in arrivals {
                    self.schedule(at, Ev::FromUsart { byte });
                }
            }
            while let Some(t) = self.nodes[i].host.poll_transmit() {
                match t {
                    Transmit::Bytes(bytes) => {
                        let arrivals = self.nodes[i].down.write(now, &bytes, &mut self.rng);
                        for (at, byte) in arrivals {
                            self.schedule(at, Ev::ToModem { node: i, byte });
                        }
                    }
                    Transmit::TReq { asserted } => {
                        let at = self.nodes[i].down.drained_at(now);
                        self.schedule(at, Ev::Treq { node: i, asserted });
                    }
                }
            }
            self.refresh_deadline(i);
        }
        self.follow_node_0();
    }

    /// [`Peers::EchoFollowing`]: node 0's MIB 00h and 01h, when they
    /// changed, applied to every echoing peer.
    fn follow_node_0(&mut self) {
        if self.peers != Peers::EchoFollowing {
            return;
        }
        for index in [0u8, 1] {
            let Some(now) = self.nodes[0].modem.mib(index) else {
                continue;
            };
            if self.followed[index as usize] == now {
                continue;
            }
            let now = now.to_vec();
            for i in 1..self.nodes.len() {
                if let Host::Echo(_) = self.nodes[i].host {
                    // Node 0's modem took the value: a peer takes it too
                    // (a MIB value only: no output, no new deadline).
                    let _ = self.nodes[i].modem.configure(index, &now);
                }
            }
            self.followed[index as usize] = now;
        }
    }

    /// A frame starts: every modem that can hear it starts receiving.
    fn start_transmission(&mut self, tx: Transmission) {
        let now = self.now;
        self.record(LineEvent::Sent {
            at: now,
            from: tx.from,
            modulation: tx.modulation,
            frequency: tx.frequency,
            bytes: tx.psdu.len(),
            airtime: tx.end - tx.start,
        });
        // A modem that starts sending drops what it was receiving.
        for rx in &mut self.nodes[tx.from].rx {
            rx.dropped = Some("receiver started transmitting");
        }
        self.touch(tx.from);
        self.seq += 1;
        let id = self.seq;
        if self.nodes[tx.from].cut {
            return;
        }
        let tx = Arc::new(tx);
        let mut receivers = Vec::new();
        for to in 0..self.nodes.len() {
            if to == tx.from || self.nodes[to].cut {
                continue;
            }
            let n = &self.nodes[to];
            let Some(channel) = line::channel_for(&n.modem.phy_config(), &tx) else {
                continue;
            };
            let level = line::tx_level(tx.gain) - self.line.attenuation(tx.from, to);
            let snr_db = level - self.line.noise_dbuv;
            let why = if !n.modem.is_on() {
                Some("receiver restarting")
            } else if n.modem.transmitting() {
                Some("receiver transmitting")
            } else if snr_db < line::required_snr(tx.modulation) {
                Some("signal too weak")
            } else {
                None
            };
            if let Some(why) = why {
                self.record(LineEvent::Missed {
                    at: now,
                    from: tx.from,
                    to,
                    why,
                });
                continue;
            }
            let n = &mut self.nodes[to];
            // Frames on one channel at once: each counts the others, and
            // at its end `line::overlap` says which one survives, if any.
            let (mut others, mut strongest) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
            for other in n.rx.iter_mut().filter(|r| r.channel == channel) {
                other.others = power_sum([other.others, level]);
                other.strongest = other.strongest.max(level);
                others = power_sum([others, other.level]);
                strongest = strongest.max(other.level);
            }
            n.rx.push(ActiveRx {
                id,
                tx: Arc::clone(&tx),
                channel,
                level,
                others,
                strongest,
                dropped: None,
            });
            n.modem.set_receiving(true);
            self.touch(to);
            receivers.push(to);
        }
        if !receivers.is_empty() {
            self.schedule(
                tx.end,
                Ev::RxEnd {
                    id,
                    nodes: receivers,
                },
            );
        }
    }

    /// A frame ends at one receiver: lost, corrupted or delivered.
    fn end_reception(&mut self, to: usize, id: u64) {
        let now = self.now;
        let n = &mut self.nodes[to];
        let Some(pos) = n.rx.iter().position(|r| r.id == id) else {
            return;
        };
        let rx = n.rx.remove(pos);
        n.modem.set_receiving(false);
        let from = rx.tx.from;
        let heard = match rx.dropped {
            Some(why) => Err(why),
            None => line::overlap(
                &self.line,
                rx.tx.modulation,
                rx.level,
                rx.others,
                rx.strongest,
            ),
        };
        let heard = match heard {
            Ok(_) if !n.modem.is_on() => Err("receiver restarting"),
            Ok(_) if self.rng.chance(self.line.loss) => Err("lost on the line"),
            heard => heard,
        };
        let snr_db = match heard {
            Ok(snr_db) => snr_db,
            Err(why) => {
                self.record(LineEvent::Missed {
                    at: now,
                    from,
                    to,
                    why,
                });
                return;
            }
        };
        let margin = snr_db - line::required_snr(rx.tx.modulation);
        // Within 3 dB of the modulation's threshold, a frame comes through
        // with a bit error one time in three (model).
        let weak = margin < 3.0 && self.rng.chance(1.0 / 3.0);
        let corrupted = weak || self.rng.chance(self.line.corruption);
        let mut psdu = rx.tx.psdu.clone();
        if corrupted && !psdu.is_empty() {
            let at = self.rng.below(psdu.len() as u64) as usize;
            psdu[at] ^= 1 << self.rng.below(8);
        }
        self.record(LineEvent::Heard {
            at: now,
            from,
            to,
            snr_db,
            corrupted,
        });
        let snr = if rx.tx.modulation == Modulation::BFsk {
            255
        } else {
            snr_db.round().clamp(-128.0, 127.0) as i8 as u8
        };
        self.nodes[to].modem.receive(
            now,
            Reception {
                modulation: rx.tx.modulation,
                channel: rx.channel,
                pga: line::pga(rx.level),
                snr,
                uw_end: rx.tx.uw_end,
                psdu,
            },
        );
    }
}
