//! The console's shared state: a few stores of signals, passed to the
//! views by context as one [`Console`], and the one place that applies a
//! session's [`Note`]s to them.

use crate::clock::page_now_us;
use crate::driver::ack::AckLatency;
use crate::driver::{Budget, Driver, TICK_BUDGET_US};
use crate::history_store;
use crate::profile::Profile;
use crate::session::{Note, Outcome, Session, Tick};
use crate::storage::load;
use crate::street::{Alert, Lamp, StreetSession, StreetTick, Sweep};
use crate::street_store;
use crate::throttle::Throttle;
use crate::traffic::TrafficLog;
use crate::transport::sim::SimTransport;
use crate::transport::Transport;
use crate::transport::{LinkState, Simulator};
use crate::views::widgets::signal;
use leptos::prelude::*;
use plm_core::app::{Concentrator, RequesterConfig};
use plm_core::chip::Chip;
use plm_core::link::LocalFrame;
use plm_core::link::Timeouts;
use plm_core::st7580::{Command, TxParams};
use plm_core::time::Instant;
use plm_sim::StreetProfile;
use std::cell::RefCell;
use std::collections::{BTreeMap, VecDeque};
use std::rc::Rc;

/// Where the profile chosen last is kept (the chip is remembered).
pub const PROFILE_KEY: &str = "plm-console.profile";

/// Seed of the simulated world (the same page, the same run).
pub const SIM_SEED: u64 = 7580;
/// Line events kept for the Simulator view.
pub const LINE_EVENTS: usize = 200;

/// The longest the page sleeps with nothing due, µs: within the session's
/// catch-up limit, so that a simulated world keeps the page's time.
pub const IDLE_WAKE_US: f64 = 50_000.0;

/// The Street and Firmware update views are drawn again at most five
/// times a second; a change waits at most this and one tick
/// ([`IDLE_WAKE_US`]).
pub const STREET_DRAW_US: f64 = 200_000.0;

thread_local! {
    /// When the street's changes were last shown.
    static STREET_SHOWN: std::cell::RefCell<Throttle> =
        const { std::cell::RefCell::new(Throttle::new(STREET_DRAW_US)) };
    /// Application frames sent to the street and not shown yet.
    static STREET_SENT: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// How long a hardware reset holds RESETN low (DTR asserted). UM0932
/// gives no minimum; 20 ms is far beyond any reset filter.
pub const RESETN_PULSE_MS: u64 = 20;

/// What to do when T_REQ gets no status message twice in a row over
/// WebSerial (docs/console.md, "Real adapters").
pub const TREQ_ADVICE: &str = "Two requests in a row got no status message after T_REQ. On Windows, tick \"Send each RTS change twice\" in the WebSerial panel and connect again (its driver sets RTS one call late); else check the T_REQ wiring (RTS) and polarity.";

/// The connection bar's state.
#[derive(Clone, Copy)]
pub struct ConnectionStore {
    /// Whether bytes flow, and if not why.
    pub state: RwSignal<LinkState>,
    /// `Simulated`, or none.
    pub kind: RwSignal<String>,
    /// Which port or device.
    pub port: RwSignal<String>,
    /// UART baud rate.
    pub baud: RwSignal<u32>,
    /// T_REQ asserted (low).
    pub treq: RwSignal<bool>,
    /// The link engine's timeouts (MIB 09h).
    pub timeouts: RwSignal<Timeouts>,
    /// Attempts repeated by the link since connecting.
    pub retries: RwSignal<u32>,
    /// The last link problem, in words.
    pub last_problem: RwSignal<Option<String>>,
    /// This port's DTR is wired to the modem's RESETN (a setting kept per
    /// port, off by default): DTR is kept released and "Reset modem
    /// (RESETN)" pulses it.
    pub resetn_on_dtr: RwSignal<bool>,
    /// What to do about a link that does not work, in words (shown under
    /// the connection bar until dismissed).
    pub advice: RwSignal<Option<String>>,
}

/// The traffic inspector's log.
#[derive(Clone, Copy)]
pub struct TrafficStore {
    /// Every element both ways.
    pub log: RwSignal<TrafficLog>,
    /// While paused: the last sequence number shown.
    pub paused_at: RwSignal<Option<u64>>,
}

/// What the console knows of the modem.
#[derive(Clone, Copy)]
pub struct ModemStore {
    /// The last status message byte and when it came ([`stamped`]).
    pub status: RwSignal<Option<u64>>,
    /// The last BIO_ResetIndication's ResetData and when it came
    /// ([`stamped`]).
    pub last_reset: RwSignal<Option<u64>>,
    /// The value of each MIB object as last read or written.
    pub mib: RwSignal<crate::mibform::MibValues>,
    /// What an ST7570 told of its S-FSK network (the Network view).
    pub network: RwSignal<crate::network::NetworkLog>,
}

/// A byte and when it came (µs) in one u64, the time above the byte: the
/// modem store's signals are of a type the page has rather than one of
/// their own (docs/console.md, "Size"). Times up to 2^56 µs (2 284 years).
pub fn stamped(at: Instant, byte: u8) -> u64 {
    at << 8 | u64::from(byte)
}

/// The time and byte of [`stamped`].
pub fn unstamped(v: u64) -> (Instant, u8) {
    (v >> 8, v as u8)
}

/// The Simulator view's state.
#[derive(Clone, Copy)]
pub struct SimStore {
    /// Modems on the simulated line (1 = alone).
    pub nodes: RwSignal<usize>,
    /// Lamps on the simulated street.
    pub lamps: RwSignal<usize>,
    /// Random lamp failures per lamp per lit hour on the simulated street
    /// (0: none); kept when the street restarts. The `f64`'s bits: a
    /// signal type the page has (each type brings its own code).
    pub failure_rate: RwSignal<u64>,
    /// Whether the simulated cable is plugged in.
    pub plugged: RwSignal<bool>,
    /// Frames echoed by the peers.
    pub echoed: RwSignal<u64>,
    /// Recent power line events, in words, newest last.
    pub line_events: RwSignal<Vec<String>>,
    /// How much faster than the page's clock a simulated street runs
    /// (`?speed=N`, demos and tests; 1 by default).
    pub speed: RwSignal<u32>,
    /// Every lamp of the simulated street alike (`?street=uniform`, for
    /// tests that count exact values); else its lamps differ as a real
    /// street's do (plm-sim's `profile`).
    pub uniform: RwSignal<bool>,
    /// The simulated ST7570 Servers, as the Network view shows them.
    pub servers: RwSignal<Vec<crate::transport::sfsk::SimServer>>,
}

/// Lamps on the simulated street the page opens on.
pub const STREET_LAMPS: usize = 12;
/// The longest simulated street.
pub const MAX_LAMPS: usize = 500;
/// Alerts kept, newest first.
pub const ALERTS: usize = 200;

/// The Street view's state. The fleet itself stays in the session (500
/// lamps with their histories are not copied at every answer); views read
/// it with [`StreetStore::with_fleet`] when `version` changes.
#[derive(Clone, Copy)]
pub struct StreetStore {
    session: StoredValue<Rc<RefCell<StreetSession>>, LocalStorage>,
    /// Bumped whenever the fleet changed.
    pub version: RwSignal<u64>,
    /// Alerts, newest first.
    pub alerts: RwSignal<VecDeque<Raised>>,
    /// The background sweep.
    pub sweep: RwSignal<Sweep>,
    /// While a discovery runs: the lamps found (high 32 bits) and how
    /// many it believes are left (low 32), packed in a u64: a signal type
    /// of its own would bring its own copy of the signal code
    /// (docs/console.md "Size").
    pub discovering: RwSignal<Option<u64>>,
    /// What the street is reached through, in words.
    pub port: RwSignal<String>,
    /// Application frames sent to the street so far.
    pub sent: RwSignal<u64>,
    /// The lamps ticked in the Street view, in the order they were
    /// ticked (the Update view offers them as targets).
    pub selected: RwSignal<Vec<plm_core::app::Address>>,
    /// Bumped whenever the update campaign changed.
    pub campaign: RwSignal<u64>,
    /// The connection the street is remembered for
    /// ([`crate::street_store::connection`]); empty: none.
    pub kept_as: RwSignal<String>,
}

impl StreetStore {
    fn session(&self) -> Rc<RefCell<StreetSession>> {
        self.session.get_value()
    }

    /// Reads the fleet.
    pub fn with_fleet<R>(&self, f: impl FnOnce(&BTreeMap<plm_core::app::Address, Lamp>) -> R) -> R {
        self.read(|s| f(s.fleet()))
    }

    /// Reads the street session (no tick is asked for).
    pub fn read<R>(&self, f: impl FnOnce(&StreetSession) -> R) -> R {
        f(&self.session().borrow())
    }

    /// Writes the lamps' readings to the browser's storage, at a modest
    /// rate, or at once if `now` (`history_store::keep`).
    pub fn keep_history(&self, now: bool) {
        self.with_fleet(|f| history_store::keep(f, page_now_us(), now));
    }

    /// Acts on the street session; the console shows what changed at
    /// its next tick, which comes at once.
    pub fn act<R>(&self, f: impl FnOnce(&mut StreetSession) -> R) -> R {
        crate::wake::soon();
        f(&mut self.session().borrow_mut())
    }
}

/// An alert with the computer's time when it was raised.
#[derive(Debug, Clone, PartialEq)]
pub struct Raised {
    /// `HH:MM:SS`, the computer's local time.
    pub wall: String,
    /// The alert.
    pub alert: Alert,
}

/// The computer's local time of day, `HH:MM:SS`.
pub fn wall_clock() -> String {
    #[cfg(target_arch = "wasm32")]
    {
        let d = js_sys::Date::new_0();
        format!(
            "{:02}:{:02}:{:02}",
            d.get_hours(),
            d.get_minutes(),
            d.get_seconds()
        )
    }
    #[cfg(not(target_arch = "wasm32"))]
    String::from("--:--:--")
}

/// Everything the views share; `Copy`, provided by context.
#[derive(Clone, Copy)]
pub struct Console {
    session: StoredValue<Rc<RefCell<Session>>, LocalStorage>,
    /// Connection bar.
    pub conn: ConnectionStore,
    /// Traffic inspector.
    pub traffic: TrafficStore,
    /// Modem state.
    pub modem: ModemStore,
    /// Simulator.
    pub sim: SimStore,
    /// The street of lamps.
    pub street: StreetStore,
    /// What the console is connected to.
    pub profile: RwSignal<Profile>,
}

/// The console of the page; call once, in the root component.
pub fn provide_console() -> Console {
    let console = Console {
        session: StoredValue::new_local(Rc::new(RefCell::new(Session::new(
            None,
            plm_core::link::Dialect::St7580,
        )))),
        conn: ConnectionStore {
            state: signal(LinkState::Disconnected("not connected".into())),
            kind: signal(String::new()),
            port: signal(String::new()),
            baud: signal(57_600),
            treq: signal(false),
            timeouts: signal(Timeouts::default()),
            retries: signal(0),
            last_problem: signal(None),
            resetn_on_dtr: signal(false),
            advice: signal(None),
        },
        traffic: TrafficStore {
            log: signal(TrafficLog::default()),
            paused_at: signal(None),
        },
        modem: ModemStore {
            status: signal(None),
            last_reset: signal(None),
            mib: signal(Default::default()),
            network: signal(Default::default()),
        },
        sim: SimStore {
            nodes: signal(1),
            lamps: signal(STREET_LAMPS),
            failure_rate: signal(0f64.to_bits()),
            plugged: signal(true),
            echoed: signal(0),
            line_events: signal(Vec::new()),
            servers: signal(Vec::new()),
            speed: signal(1),
            uniform: signal(false),
        },
        street: StreetStore {
            session: StoredValue::new_local(Rc::new(RefCell::new(StreetSession::idle()))),
            version: signal(0),
            alerts: signal(VecDeque::new()),
            sweep: signal(Sweep::default()),
            discovering: signal(None),
            port: signal(String::new()),
            sent: signal(0),
            selected: signal(Vec::new()),
            campaign: signal(0),
            kept_as: signal(String::new()),
        },
        profile: signal(Profile::default()),
    };
    provide_context(console);
    console
}

/// The console provided by the root component.
pub fn use_console() -> Console {
    expect_context::<Console>()
}

/// An answer that is not the one a request waits for, in words.
pub fn unexpected(answer: &Command) -> String {
    match answer.name() {
        Some(n) => format!("unexpected answer {n}"),
        None => format!("unexpected answer, code {:02X}h", answer.code()),
    }
}

/// What is wrong with an ST7580 answer, if it is a refusal, in words.
pub fn refusal(answer: &Command) -> Option<String> {
    plm_core::chip::st7580_refusal(answer)
}

impl Console {
    fn session(&self) -> Rc<RefCell<Session>> {
        self.session.get_value()
    }

    /// Connects the simulated world of the current profile: a street of
    /// [`STREET_LAMPS`] lamps, or a modem with `sim.nodes - 1` echoing
    /// peers.
    pub fn connect_simulated(&self) {
        let profile = self.profile.get_untracked();
        let baud = self.conn.baud.get_untracked();
        let t: Box<dyn Transport> = if profile.is_street() {
            let mut street = SimTransport::street(
                self.sim.lamps.get_untracked(),
                profile.attach(),
                baud,
                SIM_SEED,
                match self.sim.uniform.get_untracked() {
                    true => StreetProfile::Uniform,
                    false => StreetProfile::Realistic,
                },
            );
            street.set_failure_rate(f64::from_bits(self.sim.failure_rate.get_untracked()));
            Box::new(street)
        } else if profile == Profile::St7570 {
            Box::new(crate::transport::sfsk::SfskTransport::new(
                plm_sim::st7570::net::SERVED_LINE_NODES,
                baud,
                SIM_SEED,
            ))
        } else {
            Box::new(SimTransport::new(
                self.sim.nodes.get_untracked(),
                baud,
                SIM_SEED,
            ))
        };
        self.sim.line_events.set(Vec::new());
        self.connect_transport(t);
        let speed = self.sim.speed.get_untracked();
        self.street.act(|s| s.set_speed(speed));
    }

    /// Connects over `transport` (the simulated world, or a WebSerial
    /// port the port chooser opened, `views::serial_port`) with the
    /// current profile; the other session lets go of its transport.
    pub fn connect_transport(&self, transport: Box<dyn Transport>) {
        let profile = self.profile.get_untracked();
        let mut problem = None;
        // The street left behind keeps its readings.
        self.street.keep_history(true);
        if profile.is_street() {
            self.session()
                .borrow_mut()
                .replace_transport(None, profile.dialect());
            let baud = transport.baud();
            let conc = match profile {
                Profile::StreetBoard => Concentrator::usart(RequesterConfig::default()),
                _ => Concentrator::modem(
                    RequesterConfig::default(),
                    baud,
                    Concentrator::ADDRESS,
                    TxParams::default(),
                ),
            };
            self.street.port.set(transport.port());
            let simulated = transport.kind() == "Simulated";
            let id = street_store::connection(
                profile.key(),
                &transport.port(),
                baud,
                simulated.then_some(SIM_SEED),
            );
            let mut street = StreetSession::new(transport, conc);
            match street_store::recall(&id) {
                Ok(Some(r)) => street.recall(r.session, r.lamps),
                kept => {
                    problem = kept.err();
                    // Boards heard in a session stay quiet in it: a street
                    // this browser does not know may have been found in
                    // session 1 by another.
                    if !simulated {
                        street.set_session(street_store::fresh_session());
                    }
                    street.discover();
                }
            }
            if let Some(p) = history_store::start(&id, street.now()) {
                problem = Some(problem.map_or(p.clone(), |q| format!("{q} {p}")));
            }
            self.street.kept_as.set(id);
            *self.street.session().borrow_mut() = street;
            self.street.alerts.set(VecDeque::new());
            self.street.sent.set(0);
        } else {
            *self.street.session().borrow_mut() = StreetSession::idle();
            self.street.port.set(String::new());
            self.street.kept_as.set(String::new());
            history_store::start("", 0);
            self.session()
                .borrow_mut()
                .replace_transport(Some(transport), profile.dialect());
        }
        self.street.version.update(|v| *v += 1);
        self.modem.mib.set(Default::default());
        self.modem.status.set(None);
        self.modem.network.update(|n| n.clear());
        self.conn.retries.set(0);
        self.conn.last_problem.set(None);
        self.conn.advice.set(problem);
        self.refresh();
        let wired = load(&self.resetn_key()).is_some();
        self.conn.resetn_on_dtr.set(false);
        self.set_resetn_on_dtr(wired);
    }

    /// Where the RESETN-on-DTR setting of the port in use is kept.
    fn resetn_key(&self) -> String {
        let port = self.conn.port.get_untracked();
        format!(
            "plm-console.resetn-on-dtr.{}",
            port.split(" (").next().unwrap_or("")
        )
    }

    /// Says whether this port's DTR is wired to the modem's RESETN, and
    /// remembers it for the port. Wired, DTR is released at once (the OS
    /// asserts DTR when it opens a port, which holds such a modem in
    /// reset).
    pub fn set_resetn_on_dtr(&self, wired: bool) {
        if wired && !self.conn.resetn_on_dtr.get_untracked() {
            self.with_active(|t, _| t.map(|t| t.set_dtr(false)));
        }
        crate::storage::store(&self.resetn_key(), wired.then_some("1"));
        self.conn.resetn_on_dtr.set(wired);
        self.refresh();
    }

    /// A hardware reset: DTR (RESETN) asserted for [`RESETN_PULSE_MS`],
    /// then released; the modem boots and sends BIO_ResetIndication
    /// (UM0932 Table 19, cause 0).
    pub fn pulse_resetn(&self) {
        if !self.conn.resetn_on_dtr.get_untracked() {
            return;
        }
        self.with_active(|t, _| t.map(|t| t.set_dtr(true)));
        self.refresh();
        let c = *self;
        gloo_timers::callback::Timeout::new(RESETN_PULSE_MS as u32, move || {
            c.with_active(|t, _| t.map(|t| t.set_dtr(false)));
            c.refresh();
        })
        .forget();
    }

    /// Changes the profile and connects its simulated world.
    pub fn set_profile(&self, profile: Profile) {
        crate::storage::store(PROFILE_KEY, Some(profile.key()));
        if self.profile.get_untracked() != profile {
            self.profile.set(profile);
            self.traffic.log.update(|l| l.clear());
        }
        self.connect_simulated();
    }

    /// Closes the connection.
    pub fn disconnect(&self) {
        let dialect = self.profile.get_untracked().dialect();
        self.session().borrow_mut().replace_transport(None, dialect);
        *self.street.session().borrow_mut() = StreetSession::idle();
        self.street.port.set(String::new());
        self.street.kept_as.set(String::new());
        self.refresh();
    }

    /// Changes the baud rate.
    pub fn set_baud(&self, baud: u32) {
        self.session().borrow_mut().set_baud(baud);
        if let Some(t) = self.street.session().borrow_mut().transport_mut() {
            t.set_baud(baud);
        }
        self.conn.baud.set(baud);
        self.refresh();
    }

    /// Sends the request `frame` to the modem of any chip; `reply` gets
    /// its outcome.
    pub fn request_frame(&self, frame: LocalFrame, reply: impl FnOnce(Outcome) + 'static) {
        self.session().borrow_mut().request(frame, Box::new(reply));
        self.refresh();
    }

    /// Sends an ST7580 `command` (the views of what only the ST7580 has);
    /// `reply` gets its outcome, the answer read as an ST7580 command.
    pub fn request(&self, command: Command, reply: impl FnOnce(Outcome<Command>) + 'static) {
        self.request_boxed(command, Box::new(reply));
    }

    /// [`Console::request`] for every caller: one copy of the reading of
    /// the answer in the page, not one per reply closure.
    fn request_boxed(&self, command: Command, reply: Box<dyn FnOnce(Outcome<Command>)>) {
        self.request_frame(command.to_frame(), move |o| {
            reply(o.read(|f| {
                Command::from_frame(f).map_err(|e| format!("the modem's answer does not fit: {e}"))
            }))
        });
    }

    /// The transport's clock now (µs), as the traffic log counts it.
    pub fn now(&self) -> Instant {
        let session = self.session();
        let s = session.borrow();
        s.log_time(s.now())
    }

    /// Reads from the chip's host interface description.
    pub fn with_chip<R>(&self, f: impl FnOnce(&dyn Chip) -> R) -> R {
        f(self.session().borrow().chip())
    }

    /// Reads MIB object `index` into the modem store; `done` gets the value
    /// or what went wrong.
    pub fn read_mib(&self, index: u16, done: impl FnOnce(MibResult) + 'static) {
        self.mib_request(MibOp::Read, index, Box::new(done));
    }

    /// Writes `data` to MIB object `index`; the modem store keeps it once
    /// confirmed.
    pub fn write_mib(&self, index: u16, data: Vec<u8>, done: impl FnOnce(MibResult) + 'static) {
        self.mib_request(MibOp::Write(data), index, Box::new(done));
    }

    /// Erases MIB object `index` (a chip without erase says so); the
    /// modem store forgets its value once confirmed.
    pub fn erase_mib(&self, index: u16, done: impl FnOnce(MibResult) + 'static) {
        self.mib_request(MibOp::Erase, index, Box::new(done));
    }

    /// Sends the request of MIB operation `op` on object `index`; `done`
    /// gets what the answer says ([`Chip::verdict`]), and the modem store
    /// what the object holds now: the value read or written, or nothing
    /// once erased. One function for every caller (the callback boxed):
    /// one copy of it in the page.
    fn mib_request(&self, op: MibOp, index: u16, done: Box<dyn FnOnce(MibResult)>) {
        let request = self.with_chip(|c| match &op {
            MibOp::Read => Ok(c.mib_read(index)),
            MibOp::Write(data) => Ok(c.mib_write(index, data)),
            MibOp::Erase => c.mib_erase(index).ok_or(c.name()),
        });
        let frame = match request {
            Ok(frame) => frame,
            Err(chip) => return done(Err(format!("the {chip} has no MIB erase"))),
        };
        let (c, mib) = (*self, self.modem.mib);
        self.request_frame(frame, move |o| {
            let got = match o {
                Outcome::Answer {
                    command: Some(f), ..
                } => c.with_chip(|chip| chip.verdict(&f)),
                Outcome::Answer { command: None, .. } => Ok(Vec::new()),
                Outcome::Failed(why) => Err(why),
            };
            if let Ok(value) = &got {
                match op {
                    MibOp::Read => mib.update(|m| m.insert(index, value.clone())),
                    MibOp::Write(data) => mib.update(|m| m.insert(index, data)),
                    MibOp::Erase => mib.update(|m| m.remove(index)),
                }
            }
            done(got)
        });
    }

    /// Does something to the simulated world, if that is what is connected.
    pub fn with_simulator(&self, f: impl FnOnce(&mut dyn Simulator)) {
        self.with_active(|t, _| {
            if let Some(sim) = t.and_then(|t| t.simulator()) {
                f(sim);
            }
        });
        self.refresh();
    }

    /// Does something to the simulated S-FSK network, if that is what is
    /// connected.
    pub fn with_sfsk(&self, f: impl FnOnce(&mut crate::transport::sfsk::SfskTransport)) {
        self.with_active(|t, _| {
            if let Some(net) = t.and_then(|t| t.sfsk()) {
                f(net);
            }
        });
        self.refresh();
    }

    /// The drive loop of the profile in use.
    fn with_driver<R>(&self, f: impl FnOnce(&Driver) -> R) -> R {
        if self.profile.get_untracked().is_street() {
            f(self.street.session().borrow().driver())
        } else {
            f(self.session().borrow().driver())
        }
    }

    /// How quickly the console has ACKed the modem's frames since
    /// connecting (the bare modem of the street's concentrator profile
    /// included).
    pub fn ack_latency(&self) -> AckLatency {
        self.with_driver(Driver::ack_latency)
    }

    /// [`Driver::ack_samples`].
    pub fn ack_samples(&self) -> Vec<(f64, plm_core::time::Duration, plm_core::time::Duration)> {
        self.with_driver(Driver::ack_samples)
    }

    /// Lets time pass up to the page's clock, then asks to be run again
    /// when something is next due ([`crate::wake`]).
    pub fn tick(&self) {
        // Notes were handed out since the last tick, and the line waits:
        // the page lays them out now rather than while a frame may be
        // ending ([`crate::session::Session::holds_line`]).
        if self.session().borrow().drawing() {
            crate::wake::lay_out();
        }
        let budget = || Budget::wall(page_now_us, TICK_BUDGET_US);
        let tick = self.session().borrow_mut().tick(page_now_us(), budget());
        self.apply(tick);
        let street = self
            .street
            .session()
            .borrow_mut()
            .tick(page_now_us(), budget());
        self.apply_street(street);
        self.refresh_sim();
        let now = page_now_us();
        let due = [
            self.session().borrow().next_wake(),
            self.street.session().borrow().next_wake(),
        ]
        .into_iter()
        .flatten()
        .fold(now + IDLE_WAKE_US, f64::min);
        crate::wake::at(due);
    }

    /// Applies what happened without letting time pass, and has the
    /// sessions run at once (a request may wait to be sent).
    fn refresh(&self) {
        crate::wake::soon();
        let tick = self.session().borrow_mut().take_due(page_now_us());
        let street = self.street.session().borrow_mut().take();
        let (state, kind, port) = self.with_active(|t, state| {
            let (kind, port) = t.map_or((String::new(), String::new()), |t| {
                (t.kind().into(), t.port())
            });
            (state, kind, port)
        });
        set_if_changed(self.conn.state, state);
        set_if_changed(self.conn.kind, kind);
        set_if_changed(self.conn.port, port);
        self.apply(tick);
        self.apply_street(street);
        self.refresh_sim();
    }

    /// Calls `f` with the transport of the profile in use (the street
    /// session's or the modem session's) and its state; no session is
    /// borrowed once it returns.
    fn with_active<R>(
        &self,
        f: impl FnOnce(Option<&mut (dyn Transport + 'static)>, LinkState) -> R,
    ) -> R {
        if self.profile.get_untracked().is_street() {
            let street = self.street.session();
            let mut s = street.borrow_mut();
            let state = s.state();
            f(s.transport_mut(), state)
        } else {
            let session = self.session();
            let mut s = session.borrow_mut();
            let state = s.state();
            f(s.transport_mut(), state)
        }
    }

    fn refresh_sim(&self) {
        let (events, echoed, plugged, state, servers) = self.with_active(|t, state| {
            let servers = |t: &mut dyn Transport| t.sfsk().map(|s| s.servers());
            match t {
                Some(t) => match t.simulator() {
                    Some(sim) => (
                        sim.line_events(),
                        sim.echoed(),
                        sim.plugged(),
                        Some(state),
                        None,
                    ),
                    None => (Vec::new(), 0, true, None, servers(t)),
                },
                None => (Vec::new(), 0, true, None, None),
            }
        });
        let mut servers = servers.unwrap_or_default();
        {
            let session = self.session();
            let s = session.borrow();
            for (at, _) in servers.iter_mut().flat_map(|v| v.syncs.iter_mut()) {
                *at = s.log_time(*at);
            }
        }
        set_if_changed(self.sim.servers, servers);
        if let Some(state) = state {
            set_if_changed(self.conn.state, state);
        }
        set_if_changed(self.sim.echoed, echoed);
        set_if_changed(self.sim.plugged, plugged);
        if !events.is_empty() {
            self.sim.line_events.update(|l| {
                for e in events {
                    l.push(crate::line_events::describe(&e));
                    if l.len() > LINE_EVENTS {
                        l.remove(0);
                    }
                }
            });
        }
    }

    /// Applies what the street session did to the stores, then calls its
    /// replies (the session is not borrowed any more).
    fn apply_street(&self, tick: StreetTick) {
        let StreetTick {
            changed,
            alerts,
            replies,
            traffic,
            sent,
            campaign,
            found,
        } = tick;
        let (sweep, discovering) = {
            let session = self.street.session();
            let s = session.borrow();
            let packed = s
                .discovering()
                .map(|(found, left)| ((found as u64) << 32) | left as u64);
            (s.sweep(), packed)
        };
        let street = self.street;
        // The progress, the count sent and the lamps are shown together,
        // so that what the page says is of one moment.
        let progress = street.sweep.with_untracked(|s| *s != sweep)
            || street.discovering.get_untracked() != discovering;
        let unshown = STREET_SENT.get() + sent;
        STREET_SENT.set(unshown);
        let due = changed || progress || sent > 0;
        if STREET_SHOWN.with_borrow_mut(|t| t.show(due, page_now_us())) {
            set_if_changed(street.sweep, sweep);
            set_if_changed(street.discovering, discovering);
            if unshown > 0 {
                street.sent.update(|n| *n += unshown);
                STREET_SENT.set(0);
            }
            street.version.update(|v| *v += 1);
            street.keep_history(false);
        }
        if found {
            let (session, lamps) = self.street.read(|s| s.remembered());
            let r = street_store::Remembered { session, lamps };
            street.kept_as.with_untracked(|id| {
                if !id.is_empty() {
                    street_store::save(id, &r)
                }
            });
        }
        if campaign {
            self.street.read(crate::campaign_store::save);
            street.campaign.update(|v| *v += 1);
        }
        if !traffic.is_empty() {
            self.traffic.log.update(|log| {
                for (at, d) in traffic {
                    log.push(Some(at), d);
                }
            });
        }
        if !alerts.is_empty() {
            let wall = wall_clock();
            street.alerts.update(|l| {
                for alert in alerts {
                    l.push_front(Raised {
                        wall: wall.clone(),
                        alert,
                    });
                }
                l.truncate(ALERTS);
            });
        }
        for (reply, r) in replies {
            reply(r);
        }
    }

    /// Applies notes to the stores, then calls the replies (the session is
    /// not borrowed any more: a reply may send the next request).
    fn apply(&self, tick: Tick) {
        let Tick { notes, replies } = tick;
        let mut traffic = Vec::new();
        // The last status message only: the views show the latest, and
        // each one set redrew them (one per exchange).
        let mut status = None;
        for n in notes {
            match n {
                Note::Traffic { at, decoded } => traffic.push((at, *decoded)),
                Note::Status { at, message } => {
                    let data = message.data();
                    status = Some((at, data[0]));
                    if data.len() == 3 {
                        self.modem.network.update(|n| n.on_status(at, data));
                    }
                }
                Note::TReq(level) => set_if_changed(self.conn.treq, level),
                Note::Unsolicited {
                    at,
                    frame,
                    reset: true,
                    ..
                } => {
                    let cause = frame.data.first().copied().unwrap_or(0);
                    self.modem.last_reset.set(Some(stamped(at, cause)));
                }
                Note::Unsolicited { at, frame, .. } => {
                    if self.profile.get_untracked() == Profile::St7570 {
                        self.modem.network.update(|n| n.on_indication(at, &frame));
                    }
                }
                Note::Retry { cause, .. } => {
                    self.conn.retries.update(|r| *r += 1);
                    self.conn.last_problem.set(Some(cause));
                }
                Note::Timeouts(t) => set_if_changed(self.conn.timeouts, t),
                Note::TReqUnanswered(n) => {
                    if n == 2 && self.conn.kind.get_untracked() == "WebSerial" {
                        self.conn.advice.set(Some(TREQ_ADVICE.into()));
                    }
                }
            }
        }
        if status.is_some() {
            self.modem.status.set(status.map(|(at, b)| stamped(at, b)));
        }
        if !traffic.is_empty() {
            self.traffic.log.update(|log| {
                for (at, d) in traffic {
                    log.push(Some(at), d);
                }
            });
        }
        for (reply, outcome) in replies {
            if let Outcome::Failed(why) = &outcome {
                self.conn.last_problem.set(Some(why.clone()));
            }
            reply(outcome);
        }
    }
}

fn set_if_changed<T: PartialEq + Send + Sync + 'static>(signal: RwSignal<T>, value: T) {
    if signal.with_untracked(|v| *v != value) {
        signal.set(value);
    }
}

/// What a MIB request's callback gets: the object's data, or why not.
pub type MibResult = Result<Vec<u8>, String>;

/// A MIB operation of [`Console::mib_request`].
enum MibOp {
    Read,
    Write(Vec<u8>),
    Erase,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stamped_byte_keeps_its_time_and_value() {
        for (at, byte) in [(0, 0), (12_000_345, 0x3f), ((1 << 56) - 1, 0xff)] {
            assert_eq!(unstamped(stamped(at, byte)), (at, byte));
        }
    }
}
