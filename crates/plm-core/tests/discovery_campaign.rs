//! Discovery rule 2 against a line model, in virtual time: street sizes
//! 1, 12, 100 and 500; frame loss 0 to 5 %; capture on and off; the
//! concentrator's guess from half to twice the truth; 50 seeds a cell.
//! No board may be missed. The boards answer by plm-core's own
//! [`Responder`]; the line model works slot by slot: a reply alone in its
//! slot is heard unless lost, two or more collide, and with capture the
//! strongest survives when it is [`CAPTURE_DB`] above the next.

use plm_core::app::discovery::{Discovery, DiscoveryConfig, Responder, Timing, STOP_RISK};
use plm_core::app::service::{Discovered, Service};
use plm_core::app::{Address, Message};
use plm_core::time::MS;

/// The capture margin of the simulated line (plm-sim's line model).
const CAPTURE_DB: f64 = 6.0;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        // xorshift64*
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    fn level(&mut self) -> f64 {
        (self.next() % 300) as f64 / 10.0
    }
}

#[derive(Debug, Clone, Copy)]
struct Line {
    loss: f64,
    capture: bool,
}

/// One discovery of `boards` boards: found, frames, line time (s).
fn run(boards: usize, guess: usize, line: Line, seed: u64) -> (usize, u8, f64) {
    let trace = std::env::var("TRACE").is_ok();
    let mut rng = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let mut street: Vec<(Address, Responder, f64)> = (0..boards)
        .map(|i| {
            let b = (i as u32 + 1).to_be_bytes();
            let level = rng.level();
            (
                Address([0, 0x80, 0xE1, b[1], b[2], b[3]]),
                Responder::default(),
                level,
            )
        })
        .collect();
    let (mut d, mut request) = Discovery::start(0, DiscoveryConfig::new(1, guess));
    let slot_us = Timing::BPSK.slot_ms() as u64 * MS;
    loop {
        let Message::Service(service) = &request.message else {
            panic!("a discovery sends service frames")
        };
        let Service::DiscoverFrame(frame) = service else {
            panic!("rule 2 only: {service:?}")
        };
        let mut slots: Vec<Vec<usize>> = vec![Vec::new(); frame.slots as usize];
        for (i, (me, r, _)) in street.iter_mut().enumerate() {
            if rng.chance(line.loss) {
                continue;
            }
            if let Some(slot) = r.on_request(me, service) {
                slots[(slot.start / slot_us) as usize].push(i);
            }
        }
        for slot in &slots {
            let heard = match slot.len() {
                0 => None,
                1 => Some(slot[0]),
                _ if line.capture => {
                    let mut by_level = slot.clone();
                    by_level.sort_by(|a, b| street[*b].2.total_cmp(&street[*a].2));
                    (street[by_level[0]].2 - street[by_level[1]].2 >= CAPTURE_DB)
                        .then_some(by_level[0])
                }
                _ => None,
            };
            if let Some(i) = heard.filter(|_| !rng.chance(line.loss)) {
                let reply = Message::Service(Service::DiscoverReply(Discovered::default()));
                assert_eq!(
                    d.on_message(street[i].0, &reply),
                    None,
                    "rule 2 sends no ACK"
                );
            }
        }
        if trace {
            let heard = slots.iter().filter(|s| s.len() == 1).count();
            println!(
                "frame {} slots {} share {} others {} named {} found {} left {:.1} singles {heard}",
                d.frames(),
                d.plan().slots,
                d.plan().share,
                d.plan().others,
                frame.heard.len(),
                d.found().len(),
                d.left()
            );
        }
        // The next request, or the end (a frame that ends the discovery
        // is waited out to its last reply first).
        request = loop {
            let now = d.poll_timeout().expect("a frame is running");
            match d.handle_timeout(now) {
                Some(r) => break r,
                None if d.is_done() => return (d.found().len(), d.frames(), now as f64 / 1e6),
                None => {}
            }
        };
    }
}

#[test]
#[ignore]
fn trace() {
    let n = |k: &str| std::env::var(k).unwrap().parse::<usize>().unwrap();
    let line = Line {
        loss: n("LOSS") as f64 / 100.0,
        capture: n("CAPTURE") == 1,
    };
    println!("{:?}", run(n("BOARDS"), n("GUESS"), line, n("SEED") as u64));
}

/// The guesses tried: half the truth to twice; for 500 lamps also the
/// console's first guess of 12 (a street never seen).
fn guesses(boards: usize) -> Vec<usize> {
    let mut g = vec![boards.div_ceil(2), boards, 2 * boards];
    if boards == 500 {
        g.push(12);
    }
    g
}

/// Every cell of one street size: no board missed; the times printed.
fn campaign(boards: usize) {
    let mut missed = Vec::new();
    println!("boards loss capture guess: runs, mean and worst line time (s), mean frames");
    for loss in [0.0, 0.02, 0.05] {
        for capture in [false, true] {
            for guess in guesses(boards) {
                let line = Line { loss, capture };
                let (mut total, mut worst, mut frames) = (0.0, 0.0f64, 0usize);
                for seed in 0..50 {
                    let (found, f, t) = run(boards, guess, line, seed);
                    if found != boards {
                        missed.push((loss, capture, guess, seed, boards - found));
                    }
                    total += t;
                    worst = worst.max(t);
                    frames += f as usize;
                }
                println!(
                    "{boards:>4} {loss:.2} {capture:>5} {guess:>4}: 50, {:.2} {:.2}, {:.1}",
                    total / 50.0,
                    worst,
                    frames as f64 / 50.0
                );
            }
        }
    }
    assert!(
        missed.is_empty(),
        "{boards} boards, missed (loss, capture, guess, seed, how many): {missed:?}"
    );
}

#[test]
fn campaign_1() {
    campaign(1);
}

#[test]
fn campaign_12() {
    campaign(12);
}

#[test]
fn campaign_100() {
    campaign(100);
}

#[test]
fn campaign_500() {
    campaign(500);
}

/// The stop rule's stated risk against what happens: on a line that
/// loses 30 % of frames, far more than the belief allows, the risk of
/// ending with a board unheard is measurable; at the allowed loss it is
/// below [`STOP_RISK`] per board and shows as none.
#[test]
fn the_stop_rule_misses_about_what_it_says() {
    let runs = 400;
    let missed_at = |loss| {
        (0..runs)
            .map(|seed| {
                12 - run(
                    12,
                    12,
                    Line {
                        loss,
                        capture: false,
                    },
                    1_000 + seed,
                )
                .0
            })
            .sum::<usize>()
    };
    assert_eq!(missed_at(0.05), 0);
    let harsh = missed_at(0.3);
    println!("12 boards, 30 % loss: {harsh} missed in {runs} runs (stop risk {STOP_RISK})");
    assert!(
        harsh > 0,
        "a line far worse than allowed must show the risk"
    );
}
