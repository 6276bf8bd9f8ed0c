//! A board's firmware answers after a delay drawn from 0 to
//! [`FIRMWARE_JITTER`] (`plm_sim::board`): the time from the end of a
//! request on the line to the start of the lamp's answer varies by up to
//! that much, and the same seed gives the same delays.

use plm_core::app::{Message, RequesterConfig};
use plm_core::time::{Duration, MS};
use plm_sim::board::{street_address, FIRMWARE_JITTER};
use plm_sim::{Attach, LineEvent, Sim, SimConfig, StreetDriver};

/// Lamp 1's turnaround for each of `n` pings: from the end of the ping
/// at lamp 1 to the start of its answer.
fn turnarounds(seed: u64, n: usize) -> Vec<Duration> {
    let sim = Sim::new(SimConfig {
        seed,
        ..SimConfig::street(1, Attach::Board)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2_000 * MS);
    while d.sim.poll_line_event().is_some() {}
    let mut out = Vec::new();
    for _ in 0..n {
        let answer = d.ask(street_address(1), Message::Ping, 1_000 * MS);
        assert!(answer.is_ok(), "{answer:?}");
        let (mut heard, mut sent) = (None, None);
        while let Some(e) = d.sim.poll_line_event() {
            match e {
                LineEvent::Heard {
                    at, from: 0, to: 1, ..
                } => heard = Some(at),
                LineEvent::Sent { at, from: 1, .. } => sent = Some(at),
                _ => {}
            }
        }
        out.push(sent.expect("lamp 1 answered") - heard.expect("lamp 1 heard the ping"));
    }
    out
}

#[test]
fn lamps_answer_after_a_jittered_firmware_delay() {
    let t = turnarounds(3, 60);
    let (min, max) = (*t.iter().min().unwrap(), *t.iter().max().unwrap());
    // The rest of the turnaround (the UART both ways, the modem's TX
    // setup) is the same each time: the spread is the firmware's.
    assert!(max - min <= FIRMWARE_JITTER, "{min}..{max} µs");
    assert!(
        max - min >= FIRMWARE_JITTER * 3 / 4,
        "60 draws cover most of 0..={FIRMWARE_JITTER} µs: {min}..{max} µs"
    );
    let mut distinct = t.clone();
    distinct.sort();
    distinct.dedup();
    assert!(distinct.len() > 30, "{t:?}");
    assert_eq!(t, turnarounds(3, 60), "the same seed, the same delays");
    assert_ne!(t, turnarounds(4, 60), "another seed, other delays");
}
