//! The realistic street (plm-sim's `profile`) over a simulated night:
//! lamps of different powers and ages, temperature following power and
//! the night, the mains drifting within bounds, the worn lamp failing
//! about two minutes in, the weak far lamp found by discovery, and the
//! same seed giving the same street.

use plm_core::app::discovery::DiscoveryConfig;
use plm_core::app::hid::{self, Hid, LampState};
use plm_core::app::{Ballast, Message, RequesterConfig};
use plm_core::time::{Duration, Instant, MS};
use plm_sim::ballast::{
    BallastConfig, HidBallast, AMBIENT_C, HEATING_C_PER_W, MAX_LAMP_VOLTAGE, NIGHT_AMBIENT,
    SUPPLY_DRIFT, SUPPLY_NOISE, THERMAL_TIME_CONSTANT,
};
use plm_sim::board::street_address;
use plm_sim::profile::{END_OF_LIFE_AT, END_OF_LIFE_JITTER, FEEDER_DROP, RATINGS, WEAK_SNR_DB};
use plm_sim::{Attach, LineEvent, Sim, SimConfig, StreetDriver, StreetProfile};

const S: Duration = 1_000 * MS;
const MINUTE: Duration = 60 * S;
const HOUR: Duration = 60 * MINUTE;

fn config(lamps: usize, seed: u64) -> SimConfig {
    SimConfig {
        seed,
        profile: StreetProfile::Realistic,
        ..SimConfig::street(lamps, Attach::Board)
    }
}

/// Every lamp's parameters at `at`, straight from the ballasts.
fn reports(sim: &mut Sim, at: Instant) -> Vec<Ballast> {
    (1..sim.nodes())
        .map(|n| {
            sim.with_board(n, |b, _| b.ballast_mut().unwrap().report(at))
                .unwrap()
        })
        .collect()
}

fn ask(d: &mut StreetDriver, node: usize) -> Ballast {
    match d.ask(
        street_address(node),
        Message::Hid(Hid::Get(hid::ALL)),
        30 * S,
    ) {
        Ok(Message::Hid(Hid::Reply { value, .. })) => Ballast::decode(&value).unwrap(),
        other => panic!("node {node}: {other:?}"),
    }
}

/// The ambient of the night curve at `s` seconds of the day, °C.
fn ambient(s: f64) -> f64 {
    let h = s / 3_600.0 % 24.0;
    let knots: Vec<(f64, f64)> = NIGHT_AMBIENT
        .iter()
        .map(|&(h, c)| (h as f64, c))
        .chain([(24.0, NIGHT_AMBIENT[0].1)])
        .collect();
    let w = knots.windows(2).find(|w| h < w[1].0).unwrap();
    w[0].1 + (w[1].1 - w[0].1) * (h - w[0].0) / (w[1].0 - w[0].0)
}

#[test]
fn the_same_seed_gives_the_same_street_and_another_seed_another() {
    let mut a = Sim::new(config(12, 7));
    let mut b = Sim::new(config(12, 7));
    let mut c = Sim::new(config(12, 8));
    for at in [0, 15 * S, 3 * MINUTE, 5 * HOUR] {
        let ra = reports(&mut a, at);
        assert_eq!(ra, reports(&mut b, at), "at {at} µs");
        assert_ne!(ra, reports(&mut c, at), "at {at} µs");
    }
    assert_eq!(a.line(), b.line());
    // Lamps of different powers and ages, every power one of the ratings.
    let r = reports(&mut a, 0);
    let cfgs: Vec<BallastConfig> = (1..=12)
        .map(|n| a.board(n).unwrap().ballast().unwrap().config().clone())
        .collect();
    let mut powers: Vec<u16> = cfgs.iter().map(|c| c.rated_power_w).collect();
    assert!(powers.iter().all(|p| RATINGS.iter().any(|r| r.0 == *p)));
    powers.sort();
    powers.dedup();
    assert!(powers.len() >= 3, "ratings on the street: {powers:?}");
    let mut hours: Vec<u16> = r.iter().map(|b| b.lifetime_hours).collect();
    hours.dedup();
    assert!(hours.len() >= 10, "ages: {hours:?}");
    // Every lamp of the uniform street is the 150 W lamp of before.
    let mut u = Sim::new(SimConfig {
        seed: 7,
        ..SimConfig::street(12, Attach::Board)
    });
    for b in reports(&mut u, 0) {
        assert_eq!(
            (b.lamp_power, b.lamp_voltage, b.bus_voltage, b.temperature),
            (150, 100, 400, 55)
        );
    }
}

#[test]
fn age_shifts_the_lamp_voltage_up_and_its_power_down() {
    let lamp = |hours: u16| {
        let mut b = HidBallast::new(
            0,
            BallastConfig {
                warm_start: true,
                ages: true,
                lifetime_hours: hours,
                ..BallastConfig::default()
            },
        );
        let r = b.report(S);
        (r.lamp_voltage, r.lamp_power)
    };
    assert_eq!(lamp(0), (100, 150));
    // 1.2 V and 0.4 % of the power per 1 000 hours.
    assert_eq!(lamp(10_000), (112, 144));
    assert_eq!(lamp(20_000), (124, 138));
}

/// A night from midnight to noon, three boards: a 250 W lamp, a 70 W
/// lamp, and a 250 W lamp put out at 02:00. Each board's temperature
/// follows its lamp's power with its lag, and the night.
#[test]
fn the_board_temperature_follows_power_and_the_night() {
    let night = |watts: u16| {
        HidBallast::new(
            0,
            BallastConfig {
                rated_power_w: watts,
                warm_start: true,
                night: true,
                ..BallastConfig::default()
            },
        )
    };
    let (mut big, mut small, mut out) = (night(250), night(70), night(250));
    // Euler, 1 s steps, of dT/dt = (ambient(t) + 0.2 P − T) / τ for the
    // board whose lamp went out (P = 250 W until 02:00, then 0).
    let tau = THERMAL_TIME_CONSTANT as f64 / S as f64;
    let mut euler = ambient(0.0) + HEATING_C_PER_W * 250.0;
    let mut coolest = (f64::MAX, 0u64);
    for s in 0..12 * 3_600u64 {
        let p = if s < 2 * 3_600 { 250.0 } else { 0.0 };
        if s == 2 * 3_600 {
            out.handle(
                2 * HOUR,
                &hid::ballast_frame(&[hid::SET, hid::SET_DIMMING, 0]),
            );
        }
        euler += (ambient(s as f64) + HEATING_C_PER_W * p - euler) / tau;
        let at = (s + 1) * S;
        if (s + 1) % 600 != 0 {
            continue;
        }
        let amb = ambient((s + 1) as f64);
        let (b, m, o) = (big.report(at), small.report(at), out.report(at));
        // Lit: ambient + 0.2 °C/W, within the lag of the night's slope.
        assert!(
            (f64::from(b.temperature) - (amb + 50.0)).abs() <= 1.0,
            "{} s: 250 W at {} °C, ambient {amb:.1}",
            s + 1,
            b.temperature
        );
        assert!(
            (f64::from(m.temperature) - (amb + 14.0)).abs() <= 1.0,
            "{} s: 70 W at {} °C, ambient {amb:.1}",
            s + 1,
            m.temperature
        );
        // The closed form is the integration's, knots and all.
        assert!(
            (f64::from(o.temperature) - euler).abs() <= 0.6,
            "{} s: {} °C vs {euler:.2}",
            s + 1,
            o.temperature
        );
        if s + 1 > 4 * 3_600 && f64::from(o.temperature) < coolest.0 {
            coolest = (f64::from(o.temperature), s + 1);
        }
    }
    // Out since 02:00: it cooled to the night's ambient and is coolest
    // just before dawn (05:00), warming with the morning.
    let (t, at) = coolest;
    assert!((4 * 3_600..=6 * 3_600).contains(&at), "coolest at {at} s");
    assert!((t - 9.0).abs() <= 1.0, "coolest {t} °C");
    assert!(f64::from(out.report(12 * HOUR).temperature) > 15.0);
    // Without the night, the ambient stays put.
    let mut flat = HidBallast::new(0, BallastConfig::default());
    flat.handle(S, &hid::ballast_frame(&[hid::SET, hid::SET_DIMMING, 0]));
    assert_eq!(flat.report(12 * HOUR).temperature, AMBIENT_C as i16);
}

/// Every second of a night: each lamp's mains within its pole's nominal
/// ± (drift + noise), moving by the drift over the night, a second to
/// the next by no more than the noise; the drift the street's, so two
/// poles track each other.
#[test]
fn the_supply_voltage_drifts_within_its_bounds() {
    let lamps = 12;
    let sim = Sim::new(config(lamps, 21));
    let nominal = |node: usize| 230.0 - FEEDER_DROP * node as f64 / lamps as f64;
    let bound = SUPPLY_DRIFT + f64::from(SUPPLY_NOISE) + 0.5;
    let (near, far) = (1, lamps);
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    let (mut prev, mut gap_sum, mut n) = (None, 0.0, 0.0);
    let mut ballasts: Vec<HidBallast> = [near, far]
        .iter()
        .map(|&node| sim.board(node).unwrap().ballast().unwrap().clone())
        .collect();
    for s in (0..10 * 3_600u64).step_by(1) {
        let at = s * S;
        let v: Vec<f64> = ballasts
            .iter_mut()
            .map(|b| f64::from(b.report(at).supply_voltage))
            .collect();
        for (&vol, node) in v.iter().zip([near, far]) {
            assert!(
                (vol - nominal(node)).abs() <= bound,
                "{s} s node {node}: {vol} V, nominal {}",
                nominal(node)
            );
        }
        if let Some(p) = prev {
            let step: f64 = v[0] - p;
            assert!(
                step.abs() <= f64::from(2 * SUPPLY_NOISE) + 1.0,
                "{s} s: {p} V → {} V",
                v[0]
            );
        }
        prev = Some(v[0]);
        lo = lo.min(v[0]);
        hi = hi.max(v[0]);
        gap_sum += v[0] - v[1];
        n += 1.0;
    }
    assert!(
        hi - lo >= SUPPLY_DRIFT,
        "the mains moved {lo}..{hi} V over the night"
    );
    // The same drift at both poles: their mean gap is the feeder's drop.
    let gap = gap_sum / n;
    let drop = nominal(near) - nominal(far);
    assert!((gap - drop).abs() <= 0.5, "gap {gap:.2} V, feeder {drop} V");
}

/// The worn lamp burns, its voltage climbing, then fails about two
/// minutes in; the concentrator reads it as FAILURE with the last failure
/// captured, the others still burn, and a repair fits a new lamp.
#[test]
fn the_worn_lamp_fails_about_two_minutes_in_and_says_so() {
    let lamps = 12;
    let seed = 3;
    let worn = StreetProfile::Realistic
        .worn_lamp(seed, lamps)
        .expect("a worn lamp");
    assert_ne!(worn, lamps, "not the far lamp");
    let sim = Sim::new(config(lamps, seed));
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(15 * S);
    let early = ask(&mut d, worn);
    assert_eq!(early.state(), LampState::Run);
    d.run_for(END_OF_LIFE_AT - END_OF_LIFE_JITTER - 30 * S - d.now());
    let later = ask(&mut d, worn);
    assert_eq!(later.state(), LampState::Run);
    assert!(
        later.lamp_voltage > early.lamp_voltage,
        "the arc voltage climbs: {} V then {} V",
        early.lamp_voltage,
        later.lamp_voltage
    );
    d.run_for(END_OF_LIFE_AT + END_OF_LIFE_JITTER + S - d.now());
    let failed = ask(&mut d, worn);
    assert_eq!(failed.state(), LampState::Failure);
    assert_eq!((failed.lamp_power, failed.lamp_voltage), (0, 0));
    assert_eq!(failed.last_failure.status, 6, "it failed burning (RUN)");
    assert_eq!(
        failed.last_failure.lamp_voltage, MAX_LAMP_VOLTAGE as u16,
        "at the voltage the ballast could not hold"
    );
    for node in (1..=lamps).filter(|&n| n != worn) {
        assert_eq!(ask(&mut d, node).state(), LampState::Run, "node {node}");
    }
    // Broken for good: a reset retries and fails again.
    let now = d.now();
    d.sim.with_board(worn, |b, _| {
        b.ballast_mut().unwrap().handle(
            now,
            &hid::ballast_frame(&[hid::SET, hid::SET_RESET, hid::RESET_SOFTWARE]),
        );
    });
    d.run_for(2 * MINUTE);
    assert_eq!(ask(&mut d, worn).state(), LampState::Failure);
    // A new lamp burns on.
    let now = d.now();
    d.sim
        .with_board(worn, |b, _| b.ballast_mut().unwrap().repair(now));
    d.run_for(10 * MINUTE);
    let new = ask(&mut d, worn);
    assert_eq!((new.state(), new.lifetime_hours), (LampState::Run, 0));
}

/// Discovery finds every lamp of the realistic street, the weak far one
/// too, which hears the concentrator at the weakest SNR of all; it
/// answers every request, none of its frames lost or corrupted.
#[test]
fn discovery_finds_the_weak_far_lamp() {
    for lamps in [12, 60] {
        let sim = Sim::new(config(lamps, 5));
        let (far, extra) = StreetProfile::Realistic
            .weak_lamp(lamps, &SimConfig::street(lamps, Attach::Board).line)
            .unwrap();
        assert_eq!(far, lamps);
        assert!(extra > 0.0, "{lamps} lamps: {extra} dB");
        let mut d = StreetDriver::new(sim, RequesterConfig::default());
        d.run_for(2 * S);
        let found = d.discover(DiscoveryConfig::new(1, lamps));
        let missing: Vec<usize> = (1..=lamps)
            .filter(|n| !found.contains_key(&street_address(*n)))
            .collect();
        assert!(missing.is_empty(), "{lamps} lamps: not found {missing:?}");
        let weak = found[&street_address(far)].snr;
        assert_eq!(f64::from(weak), WEAK_SNR_DB, "{lamps} lamps");
        let others = found
            .iter()
            .filter(|(a, _)| **a != street_address(far))
            .map(|(_, f)| f.snr)
            .min()
            .unwrap();
        assert!(others > weak + 1, "{lamps} lamps: {others} dB vs {weak} dB");
        // And it answers what it is asked, at the first attempt.
        for _ in 0..20 {
            assert_eq!(ask(&mut d, far).state(), LampState::Run);
        }
        while let Some(e) = d.sim.poll_line_event() {
            match e {
                LineEvent::Missed { from, to, why, .. }
                    if (from, to) == (far, 0) || (from, to) == (0, far) =>
                {
                    assert!(!why.contains("weak"), "{lamps} lamps: {from} → {to} {why}")
                }
                LineEvent::Heard {
                    from,
                    to,
                    corrupted,
                    snr_db,
                    ..
                } if (from, to) == (far, 0) || (from, to) == (0, far) => {
                    assert!(!corrupted, "{lamps} lamps: {from} → {to} corrupted");
                    assert!((7.0..7.2).contains(&snr_db), "{snr_db}");
                }
                _ => {}
            }
        }
    }
}
