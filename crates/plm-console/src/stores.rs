//! The console's shared state: a few stores of signals, passed to the
//! views by context as one [`Console`]. What the console does with them
//! is in its parts, each one thing:
//!
//! - [`connect`]: builds the transport of a profile (the simulated world
//!   or a WebSerial port) and the session over it;
//! - [`requests`]: the views' requests to the modem and MIB operations;
//! - [`tick`]: lets the sessions' time run with the page's clock and
//!   schedules the next run;
//! - [`apply`]: the one place that applies what a session did (its
//!   [`crate::session::Note`]s, the street's [`crate::street::StreetTick`])
//!   to the stores.
//!
//! Its logic is tested natively in `stores/tests.rs`, on the simulated
//! modem and street.

mod apply;
mod connect;
mod requests;
mod tick;

pub use requests::{refusal, unexpected, MibResult};

use crate::clock::page_now_us;
use crate::driver::ack::AckLatency;
use crate::driver::{Budget, Driver, TICK_BUDGET_US};
use crate::history_store;
use crate::profile::Profile;
use crate::session::{Note, Outcome, Session, Tick};
use crate::storage::load;
use crate::street::{Alert, Lamp, StreetSession, StreetTick, Sweep};
use crate::street_store;
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

/// Sets `signal` to `value` only if it differs (a set redraws what
/// reads it).
fn set_if_changed<T: PartialEq + Send + Sync + 'static>(signal: RwSignal<T>, value: T) {
    if signal.with_untracked(|v| *v != value) {
        signal.set(value);
    }
}

impl Console {
    fn session(&self) -> Rc<RefCell<Session>> {
        self.session.get_value()
    }
}

/// Native: the page's clock is set by the tests (`clock::set_page_now_us`).
#[cfg(all(test, not(target_arch = "wasm32")))]
mod tests;
