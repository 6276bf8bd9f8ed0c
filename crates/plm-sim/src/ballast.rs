//! The simulated HID ballast of a street-light controller board and its
//! lamp (STEVAL-IHP007V1 UM, Appendix A "HID commands"), in virtual time.
//!
//! The board talks to the ballast over the ballast's USART with frames
//! `[length, payload...]` ([`hid::ballast_frame`], Appendix A "Destination
//! HID ballast"); [`HidBallast::handle`] answers them. Parameters come from
//! the one description in `plm_core::app::hid` ([`Ballast::value`]).
//!
//! # The lamp model
//!
//! Every number below is a model choice (the seed lists the states and
//! the parameters, not their dynamics); each is a named constant.
//!
//! - **STARTUP** (01h, 02h, 03h): three ignition steps of
//!   [`IGNITION_STEP`] each, no arc yet (lamp voltage and power 0). The
//!   lamp power-on count increments when an ignition begins.
//! - **WARMUP** (04h for the first half of [`WARM_UP`], 05h for the second):
//!   the arc has struck; lamp voltage rises linearly from
//!   [`STRIKE_LAMP_VOLTAGE`] to [`RUN_LAMP_VOLTAGE`] and power from
//!   [`STRIKE_POWER_FRACTION`] of its run value to the run value.
//! - **RUN** (06h): power follows dimming,
//!   `P = rated × (MIN_POWER_FRACTION + (1 − MIN_POWER_FRACTION) × dimming / 100)`; lamp voltage
//!   [`BallastConfig::lamp_voltage`] ([`RUN_LAMP_VOLTAGE`] by default)
//!   whatever the dimming. Dimming 0 puts the lamp
//!   out: **IDLE** (00h). A later dimming above 0 ignites it again.
//! - **Age** ([`BallastConfig::ages`]): a high-pressure sodium lamp's arc
//!   voltage rises as it burns, [`AGE_VOLTAGE_RISE`] per 1 000 lifetime
//!   hours, and the ballast, regulating for the rated lamp, gets a little
//!   less power into it, [`AGE_POWER_LOSS`] per 1 000 hours; both from
//!   the lifetime hours the lamp started with (a night adds a few
//!   hundredths of a volt).
//! - **End of life** ([`BallastConfig::end_of_life`]): a worn lamp's arc
//!   voltage climbs while it burns until the ballast cannot hold it
//!   ([`MAX_LAMP_VOLTAGE`], reached at the time given); the arc goes out
//!   and the lamp is broken as by [`HidBallast::fail`] (last failure:
//!   status 06h, lamp voltage [`MAX_LAMP_VOLTAGE`]).
//! - **WAIT** (07h): a lamp that went out less than [`COOL_DOWN`] ago is
//!   too hot to restrike; the ballast waits until it has cooled, then
//!   ignites by itself.
//! - **FAILURE** (08h): the arc collapses (lamp voltage and power 0), the
//!   ballast stops (PFC off) and stays failed; [`LastFailure`] keeps the
//!   hardware status, bus voltage and lamp voltage just before.
//! - Bus voltage [`PFC_BUS_VOLTAGE`] from the PFC while the ballast drives
//!   the lamp (STARTUP, WARMUP, RUN, WAIT); in IDLE and FAILURE the PFC is
//!   off and the bus sits at the rectified mains peak (supply × √2); 0
//!   without mains. The PFC's set point is [`BallastConfig::bus_voltage`].
//! - Supply voltage: [`BallastConfig::supply_voltage`] (the mains at this
//!   pole), plus the street's slow drift when
//!   [`BallastConfig::supply_drift`] is set (a value in ±
//!   [`SUPPLY_DRIFT`] every [`SUPPLY_DRIFT_PERIOD`], linear in between,
//!   the same for every lamp of the street: one transformer), plus
//!   ± [`SUPPLY_NOISE`] changing every second (this ballast's own); all
//!   deterministic functions of the seeds and the time.
//! - Board temperature: a first-order lag (time constant
//!   [`THERMAL_TIME_CONSTANT`]) toward the ambient + [`HEATING_C_PER_W`]
//!   × lamp power, solved in closed form segment by segment. The ambient
//!   is [`AMBIENT_C`], or with [`BallastConfig::night`] the
//!   [`NIGHT_AMBIENT`] curve of the time of day (virtual time 0 is
//!   midnight, as the boards' clocks): piecewise linear, so the segments
//!   also end at its knots and the solution stays exact.
//! - Lamp lifetime hours grow while the arc burns (WARMUP and RUN), in
//!   virtual time, the fraction of an hour carried.
//!
//! # Decisions
//!
//! - [`HidBallast::new`]: the mains switch on at `now`, dimming is
//!   [`POWER_UP_DIMMING`] (100 %, lit) and a cold lamp ignites at once
//!   (`power_ons` + 1), unless [`BallastConfig::warm_start`] says the lamp
//!   was already running in RUN before the simulation began.
//! - A power cut loses the ballast's dimming: when the mains return it
//!   boots at [`POWER_UP_DIMMING`]; a lamp that burnt until the cut is hot,
//!   so it WAITs before it restrikes. Without mains the ballast does not
//!   answer (the board reports 12h, HID board response timeout) and
//!   reports IDLE with every voltage and the power 0.
//! - Software reset (AAh) restarts the ballast's logic: a running,
//!   starting or waiting lamp goes on undisturbed, a FAILURE is cleared and
//!   the ballast tries again (WAIT if hot, then STARTUP) if dimming > 0.
//! - Hardware reset (0Ch, the reset pin PA6 or the `'s'` frame) is a
//!   power-up with the mains on: the lamp goes out, dimming returns to
//!   [`POWER_UP_DIMMING`], a FAILURE is cleared, and it restrikes (after
//!   WAIT if hot).
//! - Two kinds of failure. Random failures (rate per lit hour, exponential,
//!   drawn at each strike from the ballast's own stream) are *transient*:
//!   the lamp stays in FAILURE until a reset or a power cycle, which
//!   relights it. [`HidBallast::fail`] breaks the lamp: every retry (reset,
//!   power cycle) goes through STARTUP and fails again at its end (last
//!   failure: status 03h, lamp voltage 0) until [`HidBallast::repair`].
//! - [`HidBallast::repair`]: a technician fits a new, cold lamp: the
//!   failure is cleared, the lamp's lifetime hours and power-on count
//!   start again from 0, and it ignites at once if dimming > 0 (the
//!   ignition counts 1). The last failure stays readable.
//! - Answers on the ballast's USART, [`PROCESSING_DELAY`] after the
//!   request: `'g' param` → `[len, 'g', param, value...]`; a set command
//!   (`'s' 00h`, `'s' 01h`) → `[2, 's']` (the seed's garbled "buffer[0] =
//!   2 ... 0x73"), after which the board ACKs with the `'s'` echo. A known
//!   set command with a value it does not take (dimming above 100, a reset
//!   type other than AAh/0Ch) → [`Reply::Refused`] (board: 10h, HID
//!   response error); anything else (unknown set character, command or
//!   parameter, wrong length) → [`Reply::Unknown`] (board: 11h, HID command
//!   unknown); a frame whose length byte is wrong is not heard at all.
//! - Dimming while FAILURE is stored and used when the lamp restarts.
//!
//! # Cost
//!
//! Nothing happens while nobody asks: the state is kept as the phase and
//! the time it began, and every call first advances the model to `now` in
//! closed form through at most a few phase boundaries (and, with the night
//! curve, one segment per knot passed). No events, no ticks.

use plm_core::app::error::ErrorCode;
use plm_core::app::hid::{self, Ballast, LampState, LastFailure};
use plm_core::time::{earliest, Duration, Instant, MS};

use crate::rng::Rng;

/// Microseconds in one second.
const SECOND: Duration = 1_000 * MS;
/// Microseconds in one hour.
const HOUR: Duration = 3_600 * SECOND;

/// Model choice: the length of each of the three ignition steps (STARTUP
/// 01h, 02h, 03h).
pub const IGNITION_STEP: Duration = SECOND;
/// Model choice: the warm-up time from the strike to RUN (WARMUP 04h for
/// the first half, 05h for the second); short enough for demos to see it.
pub const WARM_UP: Duration = 30 * SECOND;
/// Model choice: how long a lamp that went out must cool before it can
/// restrike (WAIT).
pub const COOL_DOWN: Duration = 60 * SECOND;
/// Model choice: the time the ballast takes to answer a frame on its USART.
pub const PROCESSING_DELAY: Duration = 5 * MS;
/// Model choice: dimming at power-up and after a hardware reset (lit).
pub const POWER_UP_DIMMING: u8 = hid::DIMMING_MAX;
/// Model choice: lamp power at the lowest dimming (1 %) as a fraction of the
/// power at 100 %; HID lamps do not dim much below half power.
pub const MIN_POWER_FRACTION: f64 = 0.5;
/// Model choice: lamp power just after the strike as a fraction of its run
/// value; it rises linearly to the run value over [`WARM_UP`].
pub const STRIKE_POWER_FRACTION: f64 = 0.3;
/// Model choice: lamp voltage just after the strike, V.
pub const STRIKE_LAMP_VOLTAGE: f64 = 20.0;
/// Model choice: lamp voltage in RUN, V (whatever the dimming).
pub const RUN_LAMP_VOLTAGE: f64 = 100.0;
/// Model choice: DC bus voltage the PFC regulates while the ballast drives
/// the lamp, V.
pub const PFC_BUS_VOLTAGE: u16 = 400;
/// Model choice: nominal mains voltage, V RMS.
pub const SUPPLY_VOLTAGE: u16 = 230;
/// Model choice: the supply voltage's noise, ± V, uniform.
pub const SUPPLY_NOISE: u16 = 2;
/// Model choice: the supply noise changes once per this period.
pub const SUPPLY_NOISE_PERIOD: Duration = SECOND;
/// Model choice: ambient temperature, °C (the board's temperature with the
/// lamp off).
pub const AMBIENT_C: f64 = 25.0;
/// Model choice: the board's steady temperature rise per watt of lamp
/// power, °C/W (150 W: +30 °C).
pub const HEATING_C_PER_W: f64 = 0.2;
/// Model choice: time constant of the board temperature's first-order lag.
pub const THERMAL_TIME_CONSTANT: Duration = 600 * SECOND;
/// Model choice: the ambient temperature of a spring night and day,
/// (hour of day, °C), linear in between and round the clock: coolest just
/// before dawn (05:00, 9 °C), warmest mid-afternoon (15:00, 19 °C).
pub const NIGHT_AMBIENT: [(u64, f64); 8] = [
    (0, 12.0),
    (2, 10.6),
    (5, 9.0),
    (8, 11.0),
    (12, 16.5),
    (15, 19.0),
    (19, 16.0),
    (22, 13.4),
];
/// Model choice: the slow drift of the street's mains, ± V (the load on
/// the network changes over the night; EN 50160 allows ± 10 %).
pub const SUPPLY_DRIFT: f64 = 5.0;
/// Model choice: the drift takes a new value every this period, linear in
/// between.
pub const SUPPLY_DRIFT_PERIOD: Duration = 600 * SECOND;
/// Model choice: an HPS lamp's arc voltage rise per 1 000 lifetime hours,
/// V (lamp makers give 1-2 V).
pub const AGE_VOLTAGE_RISE: f64 = 1.2;
/// Model choice: the fraction of its rated power an HPS lamp loses per
/// 1 000 lifetime hours on a ballast regulating for the new lamp.
pub const AGE_POWER_LOSS: f64 = 0.004;
/// Model choice: the highest lamp voltage the ballast holds the arc at, V;
/// a worn lamp whose arc needs more goes out (end-of-life cycling).
pub const MAX_LAMP_VOLTAGE: f64 = 140.0;

/// What a simulated ballast is at the start.
#[derive(Debug, Clone, PartialEq)]
pub struct BallastConfig {
    /// Rated lamp power at 100 % dimming, W.
    pub rated_power_w: u16,
    /// Hardware release xx.yy, BCD (parameter 00h).
    pub hardware: (u8, u8),
    /// Random (transient) lamp failures per lit hour; 0 for none.
    pub failure_rate_per_lit_hour: f64,
    /// Lamp lifetime hours at the start (parameter 09h).
    pub lifetime_hours: u16,
    /// Lamp power-on count at the start (parameter 08h).
    pub power_ons: u16,
    /// The seed of this ballast's random failures and supply noise; the
    /// simulator derives it from its one seeded RNG so that every ballast
    /// of a street differs and none depends on how often it is asked.
    pub seed: u64,
    /// The lamp was already burning in RUN before the simulation began
    /// (no ignition, no warm-up, board at its running temperature).
    pub warm_start: bool,
    /// The new lamp's voltage in RUN, V.
    pub lamp_voltage: f64,
    /// The lamp shows its age: voltage up and power down with the
    /// lifetime hours it started with ([`AGE_VOLTAGE_RISE`],
    /// [`AGE_POWER_LOSS`]).
    pub ages: bool,
    /// The DC bus voltage the PFC regulates, V.
    pub bus_voltage: u16,
    /// The mains at this pole, V RMS (before drift and noise).
    pub supply_voltage: f64,
    /// The seed of the street's slow mains drift ([`SUPPLY_DRIFT`]),
    /// shared by its lamps; `None`: no drift.
    pub supply_drift: Option<u64>,
    /// The ambient follows [`NIGHT_AMBIENT`] (else [`AMBIENT_C`]).
    pub night: bool,
    /// A worn lamp: its voltage climbs to [`MAX_LAMP_VOLTAGE`], reached at
    /// this time, and it fails then for good (until repaired).
    pub end_of_life: Option<Instant>,
}

impl Default for BallastConfig {
    fn default() -> Self {
        BallastConfig {
            rated_power_w: 150,
            hardware: (0x01, 0x00),
            failure_rate_per_lit_hour: 0.0,
            lifetime_hours: 0,
            power_ons: 0,
            seed: 0,
            warm_start: false,
            lamp_voltage: RUN_LAMP_VOLTAGE,
            ages: false,
            bus_voltage: PFC_BUS_VOLTAGE,
            supply_voltage: f64::from(SUPPLY_VOLTAGE),
            supply_drift: None,
            night: false,
            end_of_life: None,
        }
    }
}

/// What the ballast answers to a frame, and when.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Answer {
    /// When the answer is ready on the ballast's USART.
    pub at: Instant,
    /// The answer.
    pub reply: Reply,
}

/// The ballast's answer to a frame on its USART.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// An answer frame `[len, payload...]` (Appendix A, "Destination HID
    /// ballast"): `[len, 'g', param, value...]` or `[2, 's']`.
    Frame(Vec<u8>),
    /// The ballast does not know the command: the board reports 11h.
    Unknown,
    /// The ballast refused the command's value: the board reports 10h.
    Refused,
}

impl Reply {
    /// The HID error code the board reports for this answer (Appendix A:
    /// 10h HID response error, 11h HID command unknown), `None` for a frame.
    pub fn error(&self) -> Option<ErrorCode> {
        match self {
            Reply::Frame(_) => None,
            Reply::Unknown => Some(ErrorCode::HID_COMMAND_UNKNOWN),
            Reply::Refused => Some(ErrorCode(0x10)),
        }
    }
}

/// What the ballast is doing, from the time it began.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// No mains.
    Off,
    /// Mains on, lamp off (dimming 0).
    Idle,
    /// Hot lamp cooling; ignition at `until`.
    Wait { until: Instant },
    /// Igniting since `since` (three steps).
    Startup { since: Instant },
    /// The arc burns; warm-up ends at `warm_until`; a random failure is
    /// due at `fail_at`.
    Lit {
        warm_until: Instant,
        fail_at: Option<Instant>,
    },
    /// Failed; the ballast stopped.
    Failed,
}

/// A simulated HID ballast with its lamp (see the module doc).
#[derive(Debug, Clone)]
pub struct HidBallast {
    config: BallastConfig,
    /// The time the model has been advanced to.
    at: Instant,
    phase: Phase,
    /// Dimming set point, 0-100.
    dimming: u8,
    /// The lamp is broken ([`HidBallast::fail`]) until repaired.
    broken: bool,
    /// When the arc last went out (for the cool-down), `None` for a cold
    /// lamp.
    out_at: Option<Instant>,
    /// Microseconds the arc has burnt since the start (or repair).
    lit_us: u64,
    /// Lifetime hours at the start (or 0 after a repair).
    lifetime_base: u16,
    power_ons: u16,
    last_failure: LastFailure,
    /// Board temperature at `at`, °C.
    temperature: f64,
    /// Random failures per lit hour.
    failure_rate: f64,
    /// When the ballast was made (the start of a worn lamp's climb).
    born: Instant,
    /// A worn lamp's end, until it comes (or the lamp is replaced).
    end_of_life: Option<Instant>,
    /// This ballast's own stream of random failure times.
    rng: Rng,
}

impl HidBallast {
    /// A ballast whose mains switch on at `now`: dimming
    /// [`POWER_UP_DIMMING`], a cold lamp igniting at once (or already in
    /// RUN with [`BallastConfig::warm_start`]).
    pub fn new(now: Instant, config: BallastConfig) -> Self {
        let mut b = HidBallast {
            at: now,
            phase: Phase::Idle,
            dimming: POWER_UP_DIMMING,
            broken: false,
            out_at: None,
            lit_us: 0,
            lifetime_base: config.lifetime_hours,
            power_ons: config.power_ons,
            last_failure: LastFailure::default(),
            temperature: AMBIENT_C,
            failure_rate: config.failure_rate_per_lit_hour,
            rng: Rng::new(config.seed),
            born: now,
            end_of_life: config.end_of_life,
            config,
        };
        b.temperature = b.ambient(now);
        if b.config.warm_start {
            b.phase = Phase::Lit {
                warm_until: now,
                fail_at: b.draw_failure(now),
            };
            b.temperature = b.ambient(now) + HEATING_C_PER_W * b.run_power(b.dimming);
        } else {
            b.ignite(now);
        }
        b
    }

    /// A frame from the board on the ballast's USART (`[len, payload...]`,
    /// Appendix A "Destination HID ballast"): the answer and when it is
    /// ready, `None` when the ballast hears nothing (no mains, or a wrong
    /// length byte) and the board times out (12h).
    pub fn handle(&mut self, now: Instant, frame: &[u8]) -> Option<Answer> {
        let now = self.advance(now);
        if self.phase == Phase::Off {
            return None;
        }
        let payload = hid::ballast_payload(frame)?;
        let set_done = || Reply::Frame(hid::ballast_frame(&[hid::SET]));
        let reply = match *payload {
            [hid::SET, hid::SET_RESET, hid::RESET_SOFTWARE] => {
                self.software_reset(now);
                set_done()
            }
            [hid::SET, hid::SET_RESET, hid::RESET_HARDWARE] => {
                self.hardware_reset(now);
                set_done()
            }
            [hid::SET, hid::SET_RESET, _] => Reply::Refused,
            [hid::SET, hid::SET_DIMMING, d] if d <= hid::DIMMING_MAX => {
                self.set_dimming(now, d);
                set_done()
            }
            [hid::SET, hid::SET_DIMMING, _] => Reply::Refused,
            [hid::GET, code] => match self.report(now).value(code) {
                Some(value) => {
                    let mut p = vec![hid::GET, code];
                    p.extend_from_slice(&value);
                    Reply::Frame(hid::ballast_frame(&p))
                }
                None => Reply::Unknown,
            },
            _ => Reply::Unknown,
        };
        Some(Answer {
            at: now.saturating_add(PROCESSING_DELAY),
            reply,
        })
    }

    /// Every parameter at `now` (the `'g'` 0Ah values); a single parameter
    /// is [`Ballast::value`] of it.
    pub fn report(&mut self, now: Instant) -> Ballast {
        let now = self.advance(now);
        let supply = self.supply_voltage(now);
        Ballast {
            hardware: self.config.hardware,
            bus_voltage: self.bus_voltage(supply),
            lamp_voltage: round_u16(self.lamp_voltage(now)),
            status: self.status(now).word(),
            lamp_power: round_u16(self.lamp_power(now)),
            last_failure: self.last_failure,
            supply_voltage: supply,
            temperature: self
                .temperature
                .round()
                .clamp(i16::MIN as f64, i16::MAX as f64) as i16,
            power_ons: self.power_ons,
            lifetime_hours: self.lifetime_hours(),
        }
    }

    /// What the ballast was made as.
    pub fn config(&self) -> &BallastConfig {
        &self.config
    }

    /// The dimming set point, 0-100 %.
    pub fn dimming(&self) -> u8 {
        self.dimming
    }

    /// The lamp's state (hardware_status) at `now`.
    pub fn state(&mut self, now: Instant) -> LampState {
        let now = self.advance(now);
        self.status(now)
    }

    /// The lamp breaks now (on demand): FAILURE with the last failure
    /// captured, and every retry fails again until [`HidBallast::repair`].
    /// Without mains the break shows when the mains return.
    pub fn fail(&mut self, now: Instant) {
        let now = self.advance(now);
        self.break_lamp(now);
    }

    /// A technician fits a new, cold lamp: the failure is cleared, lifetime
    /// hours and power-on count start from 0, and the lamp ignites at once
    /// if dimming > 0 (and the mains are on).
    pub fn repair(&mut self, now: Instant) {
        let now = self.advance(now);
        self.broken = false;
        self.end_of_life = None;
        self.out_at = None;
        self.lit_us = 0;
        self.lifetime_base = 0;
        self.power_ons = 0;
        if self.phase != Phase::Off {
            if self.dimming > 0 {
                self.start_ignition(now);
            } else {
                self.phase = Phase::Idle;
            }
        }
    }

    /// The mains go off: the lamp goes out (hot) and the ballast forgets
    /// its dimming.
    pub fn power_cut(&mut self, now: Instant) {
        let now = self.advance(now);
        self.go_out(now);
        self.phase = Phase::Off;
    }

    /// The mains return: the ballast powers up (see the module doc).
    pub fn power_restored(&mut self, now: Instant) {
        let now = self.advance(now);
        if self.phase == Phase::Off {
            self.boot(now);
        }
    }

    /// The board pulls the ballast's reset pin (GPIO PA6, Appendix A "HID
    /// board reset", hardware reset): a power-up with the mains on.
    pub fn hardware_reset(&mut self, now: Instant) {
        let now = self.advance(now);
        if self.phase != Phase::Off {
            self.go_out(now);
            self.boot(now);
        }
    }

    /// Sets the random (transient) failure rate per lit hour from `now` on.
    pub fn set_failure_rate(&mut self, now: Instant, per_lit_hour: f64) {
        let now = self.advance(now);
        self.failure_rate = per_lit_hour;
        // Failures are memoryless: a burning lamp's next failure is drawn
        // again at the new rate.
        if let Phase::Lit { warm_until, .. } = self.phase {
            self.phase = Phase::Lit {
                warm_until,
                fail_at: self.draw_failure(now),
            };
        }
    }

    // --- commands -------------------------------------------------------

    fn set_dimming(&mut self, now: Instant, d: u8) {
        self.dimming = d;
        match self.phase {
            Phase::Idle if d > 0 => self.ignite(now),
            Phase::Wait { .. } | Phase::Startup { .. } if d == 0 => self.phase = Phase::Idle,
            Phase::Lit { .. } if d == 0 => {
                self.go_out(now);
                self.phase = Phase::Idle;
            }
            // RUN follows the new dimming by itself; FAILURE keeps it for
            // the restart.
            _ => {}
        }
    }

    fn software_reset(&mut self, now: Instant) {
        if self.phase == Phase::Failed {
            self.restart(now);
        }
    }

    /// Power-up with the mains on.
    fn boot(&mut self, now: Instant) {
        self.dimming = POWER_UP_DIMMING;
        self.restart(now);
    }

    fn restart(&mut self, now: Instant) {
        if self.dimming > 0 {
            self.ignite(now);
        } else {
            self.phase = Phase::Idle;
        }
    }

    // --- phases ---------------------------------------------------------

    /// Ignition, after a WAIT if the lamp is still hot.
    fn ignite(&mut self, now: Instant) {
        match self.out_at {
            Some(out) if now < out.saturating_add(COOL_DOWN) => {
                self.phase = Phase::Wait {
                    until: out.saturating_add(COOL_DOWN),
                };
            }
            _ => self.start_ignition(now),
        }
    }

    fn start_ignition(&mut self, now: Instant) {
        self.power_ons = self.power_ons.saturating_add(1);
        self.phase = Phase::Startup { since: now };
    }

    /// The arc goes out now (if it burns).
    fn go_out(&mut self, now: Instant) {
        if matches!(self.phase, Phase::Lit { .. }) {
            self.out_at = Some(now);
        }
    }

    fn break_lamp(&mut self, now: Instant) {
        self.broken = true;
        if !matches!(self.phase, Phase::Off | Phase::Failed) {
            self.enter_failure(now);
        }
    }

    fn enter_failure(&mut self, now: Instant) {
        let supply = self.supply_voltage(now);
        self.last_failure = LastFailure {
            status: self.status(now).word(),
            bus_voltage: self.bus_voltage(supply),
            lamp_voltage: round_u16(self.lamp_voltage(now)),
        };
        self.go_out(now);
        self.phase = Phase::Failed;
    }

    /// When the next random failure of an arc struck at `now` is due.
    fn draw_failure(&mut self, now: Instant) -> Option<Instant> {
        let rate = self.failure_rate;
        if !(rate > 0.0 && rate.is_finite()) {
            return None;
        }
        // Exponential lit time to failure; 1 − u is in (0, 1].
        let hours = -(1.0 - self.rng.unit()).ln() / rate;
        let us = hours * HOUR as f64;
        // Beyond ~30 000 years: never.
        (us < 1e18).then(|| now.saturating_add((us as u64).max(1)))
    }

    /// The next time the phase changes by itself (or, during warm-up, the
    /// end of the power ramp, or a worn lamp's end), after `self.at`.
    fn next_boundary(&self) -> Option<Instant> {
        earliest(self.next_phase_boundary(), self.end_of_life)
    }

    fn next_phase_boundary(&self) -> Option<Instant> {
        match self.phase {
            Phase::Wait { until } => Some(until),
            Phase::Startup { since } => Some(since.saturating_add(3 * IGNITION_STEP)),
            Phase::Lit {
                warm_until,
                fail_at,
            } => {
                let warm = (warm_until > self.at).then_some(warm_until);
                match (warm, fail_at) {
                    (Some(a), Some(b)) => Some(a.min(b)),
                    (a, b) => a.or(b),
                }
            }
            Phase::Off | Phase::Idle | Phase::Failed => None,
        }
    }

    /// Advances the model to `now` (never backwards) and returns the time
    /// it is at. Bounded: at most WAIT → STARTUP → WARMUP → RUN → FAILURE.
    fn advance(&mut self, now: Instant) -> Instant {
        let now = now.max(self.at);
        while let Some(t) = self.next_boundary().filter(|&t| t <= now) {
            self.integrate(t);
            if self.end_of_life.is_some_and(|e| e <= t) {
                self.break_lamp(t);
                self.end_of_life = None;
                continue;
            }
            match self.phase {
                Phase::Wait { .. } => self.start_ignition(t),
                Phase::Startup { .. } if self.broken => self.enter_failure(t),
                Phase::Startup { .. } => {
                    self.phase = Phase::Lit {
                        warm_until: t.saturating_add(WARM_UP),
                        fail_at: self.draw_failure(t),
                    }
                }
                Phase::Lit {
                    fail_at: Some(f), ..
                } if f <= t => self.enter_failure(t),
                // The end of the warm-up: only the power ramp ends.
                _ => {}
            }
        }
        self.integrate(now);
        now
    }

    /// Carries lifetime and temperature from `self.at` to `t` within one
    /// phase (power linear in time over the span), a piece of the ambient
    /// curve at a time (linear within it).
    fn integrate(&mut self, t: Instant) {
        while self.at < t {
            let to = match self.config.night {
                true => t.min(next_knot(self.at)),
                false => t,
            };
            self.integrate_piece(to);
        }
    }

    fn integrate_piece(&mut self, t: Instant) {
        let dt = t - self.at;
        if matches!(self.phase, Phase::Lit { .. }) {
            self.lit_us = self.lit_us.saturating_add(dt);
        }
        // dT/dt = (u(t) − T)/τ with u linear, u(s) = a + b·s: T(dt) =
        // u(dt) − bτ + (T0 − a + bτ)·e^(−dt/τ).
        let tau = THERMAL_TIME_CONSTANT as f64;
        let a = self.ambient(self.at) + HEATING_C_PER_W * self.lamp_power(self.at);
        let u1 = self.ambient(t) + HEATING_C_PER_W * self.lamp_power(t);
        let b = (u1 - a) / dt as f64;
        self.temperature =
            u1 - b * tau + (self.temperature - a + b * tau) * (-(dt as f64) / tau).exp();
        self.at = t;
    }

    /// The ambient temperature at `now`, °C.
    fn ambient(&self, now: Instant) -> f64 {
        if !self.config.night {
            return AMBIENT_C;
        }
        let s = now % DAY;
        let i = knot_before(s);
        let (h0, c0) = NIGHT_AMBIENT[i];
        let (h1, c1) = NIGHT_AMBIENT
            .get(i + 1)
            .copied()
            .unwrap_or((24, NIGHT_AMBIENT[0].1));
        let (t0, t1) = (h0 * HOUR, h1 * HOUR);
        c0 + (c1 - c0) * (s - t0) as f64 / (t1 - t0) as f64
    }

    // --- readings -------------------------------------------------------

    fn status(&self, now: Instant) -> LampState {
        match self.phase {
            Phase::Off | Phase::Idle => LampState::Idle,
            Phase::Wait { .. } => LampState::Wait,
            Phase::Startup { since } => {
                let step = (now.saturating_sub(since) / IGNITION_STEP).min(2) as u8;
                LampState::Startup(1 + step)
            }
            Phase::Lit { .. } if self.warm_progress(now) < 0.5 => LampState::Warmup(4),
            Phase::Lit { .. } if self.warm_progress(now) < 1.0 => LampState::Warmup(5),
            Phase::Lit { .. } => LampState::Run,
            Phase::Failed => LampState::Failure,
        }
    }

    /// 0 at the strike to 1 at the end of the warm-up (1 when not lit).
    fn warm_progress(&self, now: Instant) -> f64 {
        match self.phase {
            Phase::Lit { warm_until, .. } if now < warm_until => {
                1.0 - (warm_until - now) as f64 / WARM_UP as f64
            }
            _ => 1.0,
        }
    }

    /// The lamp's age at the start (or 0 after a repair), thousands of
    /// hours, when it shows.
    fn age_kh(&self) -> f64 {
        match self.config.ages {
            true => f64::from(self.lifetime_base) / 1_000.0,
            false => 0.0,
        }
    }

    fn run_power(&self, dimming: u8) -> f64 {
        let d = f64::from(dimming.min(hid::DIMMING_MAX)) / 100.0;
        let rated = f64::from(self.config.rated_power_w) * (1.0 - AGE_POWER_LOSS * self.age_kh());
        rated.max(0.0) * (MIN_POWER_FRACTION + (1.0 - MIN_POWER_FRACTION) * d)
    }

    /// Lamp voltage at the end of the warm-up: the lamp's, aged, and for a
    /// worn lamp climbing to [`MAX_LAMP_VOLTAGE`] at its end.
    fn run_voltage(&self, now: Instant) -> f64 {
        let v = self.config.lamp_voltage + AGE_VOLTAGE_RISE * self.age_kh();
        match self.end_of_life {
            Some(end) if end > self.born => {
                let x = (now.saturating_sub(self.born) as f64 / (end - self.born) as f64).min(1.0);
                v + (MAX_LAMP_VOLTAGE - v).max(0.0) * x
            }
            Some(_) => MAX_LAMP_VOLTAGE.max(v),
            None => v,
        }
    }

    fn lamp_power(&self, now: Instant) -> f64 {
        match self.phase {
            Phase::Lit { .. } => {
                let x = self.warm_progress(now);
                self.run_power(self.dimming)
                    * (STRIKE_POWER_FRACTION + (1.0 - STRIKE_POWER_FRACTION) * x)
            }
            _ => 0.0,
        }
    }

    fn lamp_voltage(&self, now: Instant) -> f64 {
        match self.phase {
            Phase::Lit { .. } => {
                let x = self.warm_progress(now);
                STRIKE_LAMP_VOLTAGE + (self.run_voltage(now) - STRIKE_LAMP_VOLTAGE) * x
            }
            _ => 0.0,
        }
    }

    fn supply_voltage(&self, now: Instant) -> u16 {
        if self.phase == Phase::Off {
            return 0;
        }
        // A hash of (seed, second): the same reading within a second, and
        // no draw from any stream, so asking does not change the future.
        let slot = now / SUPPLY_NOISE_PERIOD;
        let r = hash(self.config.seed, slot);
        let span = 2 * u64::from(SUPPLY_NOISE) + 1;
        let noise = (r % span) as f64 - f64::from(SUPPLY_NOISE);
        round_u16(self.config.supply_voltage + self.supply_drift(now) + noise)
    }

    /// The street's slow mains drift at `now`, V (0 without).
    fn supply_drift(&self, now: Instant) -> f64 {
        let Some(seed) = self.config.supply_drift else {
            return 0.0;
        };
        let k = now / SUPPLY_DRIFT_PERIOD;
        let knot = |k: u64| (hash(seed, k) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
        let x = (now % SUPPLY_DRIFT_PERIOD) as f64 / SUPPLY_DRIFT_PERIOD as f64;
        SUPPLY_DRIFT * (knot(k) + (knot(k + 1) - knot(k)) * x)
    }

    fn bus_voltage(&self, supply: u16) -> u16 {
        match self.phase {
            Phase::Off => 0,
            // PFC off: the bus capacitor holds the rectified mains peak.
            Phase::Idle | Phase::Failed => round_u16(f64::from(supply) * core::f64::consts::SQRT_2),
            _ => self.config.bus_voltage,
        }
    }

    fn lifetime_hours(&self) -> u16 {
        let hours = self.lit_us / HOUR;
        u16::try_from(u64::from(self.lifetime_base) + hours).unwrap_or(u16::MAX)
    }
}

/// Microseconds in a day.
const DAY: Duration = 24 * HOUR;

/// The index of the [`NIGHT_AMBIENT`] knot at or before `s` µs of the
/// day.
fn knot_before(s: Duration) -> usize {
    NIGHT_AMBIENT
        .iter()
        .rposition(|&(h, _)| h * HOUR <= s)
        .unwrap_or(0)
}

/// The first knot of the ambient curve after `now`.
fn next_knot(now: Instant) -> Instant {
    let s = now % DAY;
    let i = knot_before(s);
    let next = NIGHT_AMBIENT.get(i + 1).map_or(DAY, |&(h, _)| h * HOUR);
    (now - s).saturating_add(next)
}

/// A hash of (seed, slot): a reading that is the same within its slot and
/// draws from no stream, so asking does not change the future.
fn hash(seed: u64, slot: u64) -> u64 {
    Rng::new(seed ^ slot.wrapping_mul(0xA24B_AED4_963E_E407)).next_u64()
}

fn round_u16(v: f64) -> u16 {
    v.round().clamp(0.0, u16::MAX as f64) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: Duration = SECOND;

    fn get(b: &mut HidBallast, now: Instant, code: u8) -> Reply {
        b.handle(now, &hid::ballast_frame(&[hid::GET, code]))
            .expect("an answer")
            .reply
    }

    fn set(b: &mut HidBallast, now: Instant, cmd: u8, v: u8) -> Reply {
        b.handle(now, &hid::ballast_frame(&[hid::SET, cmd, v]))
            .expect("an answer")
            .reply
    }

    /// A ballast lit and in RUN at 100 s.
    fn running() -> (HidBallast, Instant) {
        let mut b = HidBallast::new(0, BallastConfig::default());
        assert_eq!(b.state(100 * S), LampState::Run);
        (b, 100 * S)
    }

    #[test]
    fn a_cold_start_goes_through_startup_and_warmup_to_run() {
        let mut b = HidBallast::new(10 * S, BallastConfig::default());
        let t0 = 10 * S;
        assert_eq!(b.state(t0), LampState::Startup(1));
        assert_eq!(b.state(t0 + S), LampState::Startup(2));
        assert_eq!(b.state(t0 + 3 * S - 1), LampState::Startup(3));
        assert_eq!(b.report(t0 + 2 * S).lamp_power, 0);
        let strike = t0 + 3 * S;
        assert_eq!(b.state(strike), LampState::Warmup(4));
        let r = b.report(strike);
        assert_eq!((r.lamp_voltage, r.lamp_power), (20, 45));
        assert_eq!(b.state(strike + 15 * S), LampState::Warmup(5));
        let r = b.report(strike + 15 * S);
        assert_eq!(r.lamp_voltage, 60);
        assert!(
            (97..=98).contains(&r.lamp_power),
            "150 × 0.65: {}",
            r.lamp_power
        );
        assert_eq!(b.state(strike + 30 * S - 1), LampState::Warmup(5));
        let r = b.report(strike + 30 * S);
        assert_eq!(r.state(), LampState::Run);
        assert_eq!(
            (r.bus_voltage, r.lamp_voltage, r.lamp_power),
            (400, 100, 150)
        );
        assert_eq!(r.power_ons, 1);
        assert!(
            (228..=232).contains(&r.supply_voltage),
            "{}",
            r.supply_voltage
        );
    }

    #[test]
    fn a_warm_start_is_running_at_once() {
        let cfg = BallastConfig {
            warm_start: true,
            power_ons: 7,
            ..BallastConfig::default()
        };
        let mut b = HidBallast::new(0, cfg);
        let r = b.report(0);
        assert_eq!(
            (r.state(), r.lamp_power, r.power_ons),
            (LampState::Run, 150, 7)
        );
        assert_eq!(r.temperature, 55);
    }

    #[test]
    fn power_follows_dimming_in_run() {
        let (mut b, t) = running();
        assert_eq!(
            set(&mut b, t, hid::SET_DIMMING, 50),
            Reply::Frame(vec![2, b's'])
        );
        assert_eq!(b.dimming(), 50);
        let r = b.report(t + S);
        assert_eq!(
            (r.state(), r.lamp_power, r.lamp_voltage),
            (LampState::Run, 113, 100)
        );
        set(&mut b, t + 2 * S, hid::SET_DIMMING, 1);
        assert_eq!(b.report(t + 2 * S).lamp_power, 76); // 150 × 0.505
        set(&mut b, t + 3 * S, hid::SET_DIMMING, 100);
        assert_eq!(b.report(t + 3 * S).lamp_power, 150);
    }

    #[test]
    fn dimming_0_puts_the_lamp_out_and_dimming_relights_it() {
        let (mut b, t) = running();
        set(&mut b, t, hid::SET_DIMMING, 0);
        let r = b.report(t + S);
        assert_eq!(
            (r.state(), r.lamp_power, r.lamp_voltage),
            (LampState::Idle, 0, 0)
        );
        assert_eq!(
            r.bus_voltage,
            round_u16(f64::from(r.supply_voltage) * 2f64.sqrt())
        );
        // Hot: relit 10 s later, it waits until 60 s after going out.
        set(&mut b, t + 10 * S, hid::SET_DIMMING, 80);
        assert_eq!(b.state(t + 10 * S), LampState::Wait);
        assert_eq!(b.state(t + 60 * S - 1), LampState::Wait);
        assert_eq!(b.state(t + 60 * S), LampState::Startup(1));
        assert_eq!(b.report(t + 60 * S).power_ons, 2);
        let r = b.report(t + 60 * S + 3 * S + WARM_UP);
        assert_eq!((r.state(), r.lamp_power), (LampState::Run, 135));
        // Cold: relit after the cool-down, it ignites at once.
        let t2 = t + 200 * S;
        set(&mut b, t2, hid::SET_DIMMING, 0);
        set(&mut b, t2 + COOL_DOWN, hid::SET_DIMMING, 100);
        assert_eq!(b.state(t2 + COOL_DOWN), LampState::Startup(1));
        assert_eq!(b.report(t2 + COOL_DOWN).power_ons, 3);
    }

    #[test]
    fn fail_on_demand_captures_the_last_failure_and_repair_restarts() {
        let (mut b, t) = running();
        b.fail(t);
        let r = b.report(t + S);
        assert_eq!(
            (r.state(), r.lamp_power, r.lamp_voltage),
            (LampState::Failure, 0, 0)
        );
        assert_eq!(
            r.last_failure,
            LastFailure {
                status: 6,
                bus_voltage: 400,
                lamp_voltage: 100
            }
        );
        // A broken lamp: a software reset retries and fails again at the
        // end of the ignition (after the cool-down).
        set(&mut b, t + 2 * S, hid::SET_RESET, hid::RESET_SOFTWARE);
        assert_eq!(b.state(t + 2 * S), LampState::Wait);
        assert_eq!(b.state(t + COOL_DOWN + S), LampState::Startup(2));
        let r = b.report(t + COOL_DOWN + 3 * S);
        assert_eq!(r.state(), LampState::Failure);
        assert_eq!(r.last_failure.status, 3);
        assert_eq!(r.last_failure.lamp_voltage, 0);
        // A new lamp: cold, ignites at once, counters from 0.
        let t2 = t + 100 * S;
        b.repair(t2);
        assert_eq!(b.state(t2), LampState::Startup(1));
        let r = b.report(t2 + 3 * S + WARM_UP);
        assert_eq!(
            (r.state(), r.lamp_power, r.power_ons),
            (LampState::Run, 150, 1)
        );
        assert_eq!(r.last_failure.status, 3, "the last failure stays readable");
    }

    #[test]
    fn a_power_cut_while_running_waits_after_the_mains_return_then_restrikes() {
        let (mut b, t) = running();
        set(&mut b, t, hid::SET_DIMMING, 40);
        b.power_cut(t + S);
        let r = b.report(t + 2 * S);
        assert_eq!(
            (r.state(), r.bus_voltage, r.supply_voltage, r.lamp_power),
            (LampState::Idle, 0, 0, 0)
        );
        assert_eq!(
            b.handle(t + 2 * S, &hid::ballast_frame(&[hid::GET, 3])),
            None
        );
        b.power_restored(t + 11 * S);
        assert_eq!(b.state(t + 11 * S), LampState::Wait);
        assert_eq!(b.dimming(), POWER_UP_DIMMING);
        assert_eq!(b.report(t + 11 * S).bus_voltage, 400);
        assert_eq!(b.state(t + S + COOL_DOWN), LampState::Startup(1));
        let r = b.report(t + S + COOL_DOWN + 3 * S + WARM_UP);
        assert_eq!(
            (r.state(), r.lamp_power, r.power_ons),
            (LampState::Run, 150, 2)
        );
    }

    #[test]
    fn a_hardware_reset_is_a_power_up() {
        let (mut b, t) = running();
        set(&mut b, t, hid::SET_DIMMING, 30);
        assert_eq!(
            set(&mut b, t + S, hid::SET_RESET, hid::RESET_HARDWARE),
            Reply::Frame(vec![2, b's'])
        );
        assert_eq!((b.state(t + S), b.dimming()), (LampState::Wait, 100));
        // A software reset leaves a burning lamp alone.
        let (mut c, t) = running();
        set(&mut c, t, hid::SET_RESET, hid::RESET_SOFTWARE);
        assert_eq!(c.state(t + S), LampState::Run);
    }

    #[test]
    fn a_transient_failure_is_cleared_by_a_reset() {
        let cfg = BallastConfig {
            failure_rate_per_lit_hour: 1000.0,
            seed: 3,
            ..BallastConfig::default()
        };
        let mut b = HidBallast::new(0, cfg);
        assert_eq!(b.state(3 * S - 1), LampState::Startup(3));
        assert_eq!(b.state(HOUR), LampState::Failure);
        let lf = b.report(HOUR).last_failure;
        assert!(matches!(lf.status, 4..=6), "{lf:?}");
        b.set_failure_rate(HOUR, 0.0);
        set(&mut b, HOUR, hid::SET_RESET, hid::RESET_SOFTWARE);
        assert_eq!(b.state(HOUR), LampState::Startup(1), "cooled by now");
        assert_eq!(b.state(HOUR + 3 * S + WARM_UP), LampState::Run);
    }

    #[test]
    fn lifetime_grows_by_the_hours_lit() {
        let cfg = BallastConfig {
            lifetime_hours: 1000,
            ..BallastConfig::default()
        };
        let mut b = HidBallast::new(0, cfg);
        let strike = 3 * S;
        assert_eq!(b.report(strike + 2 * HOUR - 1).lifetime_hours, 1001);
        assert_eq!(b.report(strike + 2 * HOUR).lifetime_hours, 1002);
        // Not lit: no hours; the fraction is carried over.
        set(&mut b, strike + 2 * HOUR + HOUR / 2, hid::SET_DIMMING, 0);
        set(&mut b, strike + 5 * HOUR, hid::SET_DIMMING, 100);
        assert_eq!(
            b.report(strike + 5 * HOUR + 3 * S + HOUR / 2 - 1)
                .lifetime_hours,
            1002
        );
        assert_eq!(
            b.report(strike + 5 * HOUR + 3 * S + HOUR / 2)
                .lifetime_hours,
            1003
        );
    }

    #[test]
    fn the_board_heats_with_power_and_cools_toward_ambient() {
        let (mut b, t) = running();
        assert!((26..=30).contains(&b.report(t).temperature));
        assert_eq!(b.report(t + 2 * HOUR).temperature, 55);
        set(&mut b, t + 2 * HOUR, hid::SET_DIMMING, 0);
        // One time constant later: 25 + 30/e ≈ 36 °C.
        assert_eq!(
            b.report(t + 2 * HOUR + THERMAL_TIME_CONSTANT).temperature,
            36
        );
        assert_eq!(b.report(t + 5 * HOUR).temperature, 25);
    }

    /// Which of 100 ballasts (seeds from `seed`, 0.05 failures per lit
    /// hour) are in FAILURE after 10 h, asked only then or every 10 min.
    #[test]
    fn the_closed_form_temperature_matches_a_step_by_step_integration() {
        let mut b = HidBallast::new(0, BallastConfig::default());
        // Euler, 10 ms steps, of dT/dt = (25 + 0.2 P(t) − T) / 600 s with
        // the cold start's power: 0 while igniting (3 s), then 45 W rising
        // to 150 W over 30 s.
        let power = |t: f64| match t {
            t if t < 3.0 => 0.0,
            t if t < 33.0 => 45.0 + 105.0 * (t - 3.0) / 30.0,
            _ => 150.0,
        };
        let (mut temp, dt) = (25.0f64, 0.01);
        for step in 0..120_000u64 {
            let t = step as f64 * dt;
            temp += dt * (25.0 + 0.2 * power(t) - temp) / 600.0;
            let at = step + 1;
            if at % 10_000 == 0 {
                let got = b.report(at * 10 * MS).temperature;
                assert!(
                    (f64::from(got) - temp).abs() <= 0.51,
                    "{} s: {got} vs {temp}",
                    at / 100
                );
            }
        }
    }

    fn failures(seed: u64, poll: bool) -> Vec<usize> {
        let mut seeds = Rng::new(seed);
        (0..100)
            .filter(|_| {
                let cfg = BallastConfig {
                    failure_rate_per_lit_hour: 0.05,
                    seed: seeds.next_u64(),
                    ..BallastConfig::default()
                };
                let mut b = HidBallast::new(0, cfg);
                if poll {
                    for i in 0..60 {
                        b.report(i * HOUR / 6);
                    }
                }
                b.state(10 * HOUR) == LampState::Failure
            })
            .collect()
    }

    #[test]
    fn random_failures_strike_some_ballasts_deterministically() {
        let failed = failures(42, false);
        // 1 − e^(−0.5) ≈ 39 % expected.
        assert!((20..=60).contains(&failed.len()), "{}", failed.len());
        // Same seed, same failures, however often they are asked.
        assert_eq!(failures(42, true), failed);
        assert_ne!(failures(43, false), failed);
        // No rate, no failure.
        let mut b = HidBallast::new(0, BallastConfig::default());
        assert_eq!(b.state(10_000 * HOUR), LampState::Run);
    }

    #[test]
    fn every_parameter_answers_with_its_length() {
        let (mut b, t) = running();
        for p in hid::PARAMS {
            let Reply::Frame(f) = get(&mut b, t, p.code) else {
                panic!("no frame for {}", p.name);
            };
            assert_eq!(f.len(), 3 + p.len, "{}", p.name);
            assert_eq!(hid::ballast_payload(&f).map(|x| x.len()), Some(2 + p.len));
            assert_eq!(&f[1..3], &[hid::GET, p.code]);
        }
        let Reply::Frame(f) = get(&mut b, t, hid::ALL) else {
            panic!()
        };
        let all = Ballast::decode(&f[3..]).unwrap();
        assert_eq!(all, b.report(t));
        assert_eq!(all.hardware, (0x01, 0x00));
        let a = b.handle(t, &hid::ballast_frame(&[hid::GET, 0x04])).unwrap();
        assert_eq!(a.at, t + PROCESSING_DELAY);
        assert_eq!(a.reply, Reply::Frame(vec![5, b'g', 0x04, 0, 150]));
    }

    #[test]
    fn unknown_commands_and_refused_values_are_told_apart() {
        let (mut b, t) = running();
        assert_eq!(get(&mut b, t, 0x0B), Reply::Unknown);
        assert_eq!(set(&mut b, t, 0x02, 0), Reply::Unknown);
        let a = b.handle(t, &hid::ballast_frame(b"x")).unwrap();
        assert_eq!(a.reply, Reply::Unknown);
        assert_eq!(a.reply.error(), Some(ErrorCode::HID_COMMAND_UNKNOWN));
        assert_eq!(set(&mut b, t, hid::SET_DIMMING, 101), Reply::Refused);
        assert_eq!(Reply::Refused.error(), Some(ErrorCode(0x10)));
        assert_eq!(b.dimming(), 100);
        assert_eq!(set(&mut b, t, hid::SET_RESET, 0x55), Reply::Refused);
        // A wrong length byte is not heard.
        assert_eq!(b.handle(t, &[9, b'g', 0]), None);
        assert_eq!(b.handle(t, &[]), None);
    }

    #[test]
    fn any_bytes_never_panic() {
        let mut b = HidBallast::new(0, BallastConfig::default());
        let mut rng = Rng::new(9);
        for i in 0..2_000u64 {
            let mut f = vec![0u8; rng.below(6) as usize];
            rng.fill(&mut f);
            if i % 2 == 0 && !f.is_empty() {
                f[0] = f.len() as u8;
            }
            let _ = b.handle(i * 37 * S, &f);
        }
        let _ = b.report(u64::MAX);
        let _ = b.report(0);
    }
}
