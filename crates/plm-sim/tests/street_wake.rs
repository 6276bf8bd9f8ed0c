//! A board with nothing to do costs nothing: each board and modem is
//! woken by its own next deadline, never by a tick, and a board takes
//! each write of its modem in one event (plm-sim's `sim` module docs).

use plm_core::app::hid::{self, Hid};
use plm_core::app::{Message, RequesterConfig};
use plm_core::time::{Duration, MS};
use plm_sim::board::street_address;
use plm_sim::{Attach, LineEvent, Sim, SimConfig, StreetDriver};

const S: Duration = 1_000 * MS;
const LAMPS: usize = 100;

/// A street of [`LAMPS`] lamps behind a concentrator board, booted.
fn street() -> StreetDriver {
    let sim = Sim::new(SimConfig {
        seed: 3,
        ..SimConfig::street(LAMPS, Attach::Board)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2 * S);
    d
}

#[test]
fn a_street_with_nothing_to_do_runs_an_hour_in_no_events() {
    let mut d = street();
    let before = d.sim.events_run();
    d.run_for(3_600 * S);
    assert_eq!(
        d.sim.events_run() - before,
        0,
        "a quiet street of {LAMPS} lamps woke something"
    );
}

#[test]
fn a_frame_heard_costs_each_board_a_few_events() {
    let mut d = street();
    while d.sim.poll_line_event().is_some() {}
    let before = d.sim.events_run();
    // A read of the farthest lamp: its request and its reply cross the
    // line, and every board hears both.
    let answer = d.ask(
        street_address(LAMPS),
        Message::Hid(Hid::Get(hid::ALL)),
        30 * S,
    );
    assert!(
        matches!(answer, Ok(Message::Hid(Hid::Reply { .. }))),
        "{answer:?}"
    );
    let events = d.sim.events_run() - before;
    let frames = std::iter::from_fn(|| d.sim.poll_line_event())
        .filter(|e| matches!(e, LineEvent::Sent { .. }))
        .count() as u64;
    assert_eq!(frames, 2, "the request and its reply");
    // Per board and frame heard: its end at the modem, the modem's
    // indication reaching the board, the board's ACK reaching the modem,
    // and a deadline or two; one event per byte would be some 40.
    let per_board = events as f64 / (frames * LAMPS as u64) as f64;
    assert!(
        per_board <= 5.0,
        "{events} events for {frames} frames heard by {LAMPS} boards: {per_board:.1} each"
    );
}
