//! Two frames overlapping at one receiver (`plm_sim::line::overlap`): at
//! equal levels both are lost; one heard [`CAPTURE_DB`] or more above the
//! other survives and the other is lost to it, in words; with capture off
//! both are lost whatever their levels.

use plm_core::st7580::mib::{index, ModemConfig};
use plm_core::st7580::{Command, DataRequest, Modulation, TxParams};
use plm_core::time::MS;
use plm_sim::line::CAPTURE_DB;
use plm_sim::{LineConfig, LineEvent, Peers, Sim, SimConfig};

/// What node 0 made of the frames nodes 1 and 2 start at the same
/// instant, `gap_db` apart at node 0 (node 1 the stronger): for each
/// sender, `Ok(snr)` when node 0 received it, `Err(why)` when not.
fn overlap(
    gap_db: f64,
    capture_db: Option<f64>,
    modulation: Modulation,
) -> [Result<f64, String>; 2] {
    let mut sim = Sim::new(SimConfig {
        nodes: 3,
        peers: Peers::Echo,
        line: LineConfig {
            // Node 2 is one node further from node 0 than node 1.
            attenuation_per_hop_db: gap_db,
            // Quiet enough that 8-PSK is heard from both.
            noise_dbuv: 30.0,
            capture_db,
            ..LineConfig::default()
        },
        ..SimConfig::default()
    });
    let phy_mode = ModemConfig {
        access_mode: 0,
        sniffer_mode: false,
        crc_length: 0,
        dl_crc_on_phy_length: false,
    };
    for n in 0..3 {
        sim.configure(n, index::MODEM_CONFIG, &phy_mode.encode())
            .expect("PHY mode");
    }
    sim.advance_to(100 * MS);
    while sim.poll_line_event().is_some() {}
    let frame = Command::PhyDataRequest(DataRequest {
        params: TxParams {
            modulation,
            ..TxParams::default()
        },
        payload: b"same length, same start".to_vec(),
    });
    sim.peer_request(1, &frame);
    sim.peer_request(2, &frame);
    sim.advance_to(sim.now() + 500 * MS);
    let mut got: [Result<f64, String>; 2] = [Err("nothing".into()), Err("nothing".into())];
    let mut starts = Vec::new();
    while let Some(e) = sim.poll_line_event() {
        match e {
            LineEvent::Sent { at, from, .. } => starts.push((from, at)),
            LineEvent::Heard {
                from,
                to: 0,
                snr_db,
                ..
            } => got[from - 1] = Ok(snr_db),
            LineEvent::Missed {
                from, to: 0, why, ..
            } => got[from - 1] = Err(why.into()),
            _ => {}
        }
    }
    assert_eq!(starts.len(), 2, "{starts:?}");
    assert_eq!(starts[0].1, starts[1].1, "the frames start together");
    got
}

#[test]
fn frames_at_equal_levels_are_both_lost() {
    let [a, b] = overlap(0.0, Some(CAPTURE_DB), Modulation::BPsk);
    assert_eq!(a, Err("collision".into()));
    assert_eq!(b, Err("collision".into()));
}

#[test]
fn a_frame_10_db_stronger_survives_and_the_weaker_is_lost_to_it() {
    let [strong, weak] = overlap(10.0, Some(CAPTURE_DB), Modulation::BPsk);
    // Heard with the weaker frame counted as noise: 60 dBµV against
    // 30 and 50 dBµV summed.
    let snr = strong.expect("the stronger frame survives");
    assert!((9.0..10.0).contains(&snr), "{snr}");
    assert_eq!(weak, Err("lost to a stronger frame".into()));
}

#[test]
fn the_margin_is_the_line_s_and_below_it_nobody_wins() {
    let [a, b] = overlap(CAPTURE_DB - 1.0, Some(CAPTURE_DB), Modulation::BPsk);
    assert_eq!((a, b), (Err("collision".into()), Err("collision".into())));
    let [strong, _] = overlap(13.0, Some(12.0), Modulation::BPsk);
    assert!(strong.is_ok(), "a wider margin, met");
    let [a, b] = overlap(10.0, Some(12.0), Modulation::BPsk);
    assert_eq!(a, Err("collision".into()), "a wider margin, not met");
    assert_eq!(b, Err("collision".into()));
}

#[test]
fn a_modulation_that_needs_more_snr_than_the_margin_gives_is_not_captured() {
    // 8-PSK needs 12 dB: 10 dB above the other frame is not enough.
    let [strong, weak] = overlap(10.0, Some(CAPTURE_DB), Modulation::EightPsk);
    assert_eq!(strong, Err("collision".into()));
    assert_eq!(weak, Err("lost to a stronger frame".into()));
}

#[test]
fn with_capture_off_both_are_lost_whatever_their_levels() {
    let [a, b] = overlap(10.0, None, Modulation::BPsk);
    assert_eq!(a, Err("collision".into()));
    assert_eq!(b, Err("collision".into()));
}
