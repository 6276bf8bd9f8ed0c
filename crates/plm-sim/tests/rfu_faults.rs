//! The remote firmware update under faults (issue "never a bricked
//! board"): over many seeds, a street of simulated boards is updated by
//! plm-core's engine while random faults strike at random moments:
//!
//! - a line that loses and corrupts frames (the frames' CRC-16 catches the
//!   corruption, the engine repairs what went missing);
//! - a board's supply cut, sometimes in the middle of a flash write (the
//!   page under way torn), and restored later;
//! - a board reset (its RAM, and the campaign in it, lost);
//! - the host's cable pulled: the concentrator loses every request under
//!   way, the world goes on for a while, then a new concentrator goes on
//!   with the same campaign;
//! - the console closed and opened again: the campaign is read back from
//!   what it last saved ([`Update::save`], [`Update::resume`]);
//! - a segment whose bytes are wrong although its frame checks (a host or
//!   memory fault: only the image's CRC-32 can catch it).
//!
//! After every run, and after a last power cycle of every board: every
//! board boots, the image it runs passes its check, and every board the
//! campaign called updated runs the new release. The runs and faults tried
//! are printed (`cargo test --test rfu_faults -- --nocapture`) and recorded
//! in docs/protocol-notes.md, "The update engine".

use plm_core::app::update::{BoardState, Update, UpdateConfig};
use plm_core::app::{AppEvent, Happening, Message, Release, RequesterConfig, Service};
use plm_core::time::{Duration, MS};
use plm_sim::board::street_address;
use plm_sim::rfu::firmware_image;
use plm_sim::rng::Rng;
use plm_sim::{Attach, LineConfig, Sim, SimConfig, StreetDriver};

const S: Duration = 1_000 * MS;
const LAMPS: usize = 4;
const OLD: Release = Release { major: 1, minor: 4 };
const NEW: Release = Release { major: 2, minor: 0 };
const RUNS: u64 = 200;

/// The faults a run may meet, counted over the campaign.
#[derive(Debug, Default)]
struct Tried {
    lossy_lines: u32,
    power_cuts: u32,
    cuts_mid_flash_write: u32,
    resets: u32,
    cables_pulled: u32,
    consoles_closed: u32,
    bad_segments: u32,
}

/// One fault, due when the engine has handed out `at` requests.
#[derive(Debug, Clone, Copy)]
enum Fault {
    /// Node's supply off (its flash torn after `flash_ops` page
    /// operations, if any), back after `off`.
    Cut {
        node: usize,
        flash_ops: Option<u32>,
        off: Duration,
    },
    Reset(usize),
    Cable(Duration),
    Console(Duration),
    BadSegment,
}

fn faults(rng: &mut Rng, tried: &mut Tried) -> Vec<(u64, Fault)> {
    let mut out = Vec::new();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(60);
        let node = 1 + rng.below(LAMPS as u64) as usize;
        let fault = match rng.below(5) {
            0 => {
                let flash_ops = rng.chance(0.5).then(|| rng.below(6) as u32);
                tried.power_cuts += 1;
                tried.cuts_mid_flash_write += flash_ops.is_some() as u32;
                Fault::Cut {
                    node,
                    flash_ops,
                    off: (1 + rng.below(40)) * S,
                }
            }
            1 => {
                tried.resets += 1;
                Fault::Reset(node)
            }
            2 => {
                tried.cables_pulled += 1;
                Fault::Cable((1 + rng.below(30)) * S)
            }
            3 => {
                tried.consoles_closed += 1;
                Fault::Console((1 + rng.below(120)) * S)
            }
            _ => {
                tried.bad_segments += 1;
                Fault::BadSegment
            }
        };
        out.push((at, fault));
    }
    out
}

/// Outcome of one run: boards updated, boards left on their release.
fn run(seed: u64, tried: &mut Tried) -> (usize, usize) {
    let mut rng = Rng::new(seed ^ 0x5eed);
    let via = if seed % 4 == 3 {
        Attach::Modem
    } else {
        Attach::Board
    };
    let sim = Sim::new(SimConfig {
        seed,
        ..SimConfig::street(LAMPS, via)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2 * S);
    if rng.chance(0.6) {
        tried.lossy_lines += 1;
        let line = LineConfig {
            loss: rng.unit() * 0.15,
            corruption: rng.unit() * 0.05,
            ..d.sim_mut().line().clone()
        };
        d.sim_mut().set_line(line);
    }
    let plan = faults(&mut rng, tried);
    let image = firmware_image(NEW, 1_500 + rng.below(2_500) as usize);
    let targets: Vec<_> = (1..=LAMPS).map(street_address).collect();
    let mut u = Update::new(
        1 + rng.below(255) as u8,
        NEW,
        image.clone(),
        &targets,
        UpdateConfig::default(),
    )
    .unwrap();
    let mut saved;
    let mut handed = 0u64;
    let mut restore: Vec<(u64, usize)> = Vec::new();
    let limit = d.now() + 3_600 * S;
    while !u.is_done() {
        assert!(d.now() < limit, "seed {seed}: still running after an hour");
        restore.retain(|(when, node)| {
            if *when <= d.now() {
                d.sim.set_cut(*node, false);
                false
            } else {
                true
            }
        });
        let now = d.now();
        let Some(mut request) = u.poll(now) else {
            let until = u.poll_timeout().unwrap_or(now + 100 * MS);
            d.run_for(until.saturating_sub(now).clamp(1, 5 * S));
            continue;
        };
        let due: Vec<Fault> = plan
            .iter()
            .filter(|(at, _)| *at == handed)
            .map(|(_, f)| *f)
            .collect();
        handed += 1;
        saved = u.save();
        if let Message::Service(Service::RfuData { data, .. }) = &mut request.message {
            if due.iter().any(|f| matches!(f, Fault::BadSegment)) {
                data[0] ^= 0x40;
            }
        }
        let broadcast = request.broadcast;
        let id = d.submit(request);
        // Faults strike while the request is under way.
        let mut pulled = false;
        for fault in due {
            d.run_for(rng.below(1_500) * MS);
            match fault {
                Fault::Cut {
                    node,
                    flash_ops,
                    off,
                } => {
                    if let Some(ops) = flash_ops {
                        d.sim_mut()
                            .with_board(node, |b, _| b.rfu_mut().flash_mut().cut_after(ops));
                    }
                    d.sim_mut().set_cut(node, true);
                    restore.push((d.now() + off, node));
                }
                Fault::Reset(node) => {
                    d.sim_mut().with_board(node, |b, now| b.power_cycle(now));
                }
                Fault::Cable(gone) => {
                    d.pull_cable(gone);
                    pulled = true;
                }
                Fault::Console(gone) => {
                    d.pull_cable(gone);
                    // A new page: the campaign as it was last saved.
                    u = Update::resume(image.clone(), &saved, d.now())
                        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
                    pulled = true;
                }
                Fault::BadSegment => {}
            }
        }
        let answer = if pulled {
            Err("the cable was pulled".to_string())
        } else {
            let mut fate = None;
            d.run_until(120 * S, |h| match h {
                Happening::App(e) if e.fate_of() == Some(id) => {
                    fate = Some(e.clone());
                    true
                }
                _ => false,
            });
            match fate {
                Some(AppEvent::Answered { answer, .. }) => Ok(answer),
                Some(AppEvent::Failed { reason, .. }) => Err(reason),
                other => Err(format!("{other:?}")),
            }
        };
        if !broadcast {
            // After a resume the engine waits for no answer: ignored.
            u.on_answer(d.now(), answer.as_ref().map_err(String::as_str));
        }
    }
    // Power back everywhere, time to confirm, then one more start each.
    for (_, node) in restore {
        d.sim.set_cut(node, false);
    }
    d.run_for(30 * S);
    let mut updated = 0;
    for (i, (address, state)) in u.boards().enumerate() {
        let node = i + 1;
        let (runs, checks) = d
            .sim_mut()
            .with_board(node, |b, now| {
                b.power_cycle(now);
                let flash = b.rfu_mut().flash_mut();
                let checks = flash
                    .running()
                    .is_some_and(|boot| flash.verifies(&boot.record));
                (b.firmware(), checks)
            })
            .unwrap();
        assert!(
            checks,
            "seed {seed}: {address} does not boot an image that checks"
        );
        assert!(
            runs == OLD || runs == NEW,
            "seed {seed}: {address} runs {runs}"
        );
        if *state == BoardState::Done {
            assert_eq!(
                runs,
                NEW,
                "seed {seed}: {address} was called updated: {:?}",
                u.report()
            );
            updated += 1;
        }
    }
    for (address, words) in u.report() {
        if !words.starts_with("updated") {
            println!("seed {seed}: {address} {words}");
        }
    }
    (updated, LAMPS - updated)
}

/// Runs the campaign over `seeds`, prints what was tried and found.
fn campaign(seeds: std::ops::Range<u64>) {
    let mut tried = Tried::default();
    let (mut updated, mut left) = (0, 0);
    let runs = seeds.end - seeds.start;
    for seed in seeds.clone() {
        let (u, l) = run(seed, &mut tried);
        updated += u;
        left += l;
    }
    println!(
        "seeds {seeds:?}: {runs} runs of {LAMPS} boards: {updated} updated, {left} left on their \
         release, 0 that do not boot; faults tried: {tried:?}"
    );
    // Faults are recoverable: most boards end updated.
    assert!(
        updated * 10 >= (updated + left) * 9,
        "{updated} of {} updated",
        updated + left
    );
}

// Four quarters of the seeds, so that the test harness runs them side by
// side.
#[test]
fn no_fault_leaves_a_board_that_does_not_boot_1() {
    campaign(0..RUNS / 4);
}
#[test]
fn no_fault_leaves_a_board_that_does_not_boot_2() {
    campaign(RUNS / 4..RUNS / 2);
}
#[test]
fn no_fault_leaves_a_board_that_does_not_boot_3() {
    campaign(RUNS / 2..3 * RUNS / 4);
}
#[test]
fn no_fault_leaves_a_board_that_does_not_boot_4() {
    campaign(3 * RUNS / 4..RUNS);
}

/// With no fault at all, every board is updated.
#[test]
fn a_clean_street_is_updated_whole() {
    let sim = Sim::new(SimConfig {
        seed: 99,
        ..SimConfig::street(LAMPS, Attach::Board)
    });
    let mut d = StreetDriver::new(sim, RequesterConfig::default());
    d.run_for(2 * S);
    let targets: Vec<_> = (1..=LAMPS).map(street_address).collect();
    let mut u = Update::new(
        5,
        NEW,
        firmware_image(NEW, 3_000),
        &targets,
        UpdateConfig::default(),
    )
    .unwrap();
    d.update(&mut u);
    assert!(
        u.boards().all(|(_, s)| *s == BoardState::Done),
        "{:?}",
        u.report()
    );
}
