//! What the concentrator believes of the boards it has not found yet.
//!
//! All it can observe is how many boards a frame heard for the first
//! time: an empty slot and a collision sound alike, on a real line as on
//! the simulated one. So it keeps a belief over how many boards are left
//! (0 to a bound well above its guess), updated after every frame by
//! Bayes' rule with the chance of hearing that many new boards, then
//! shifted down by them (docs/protocol-notes.md, "Discovery").
//!
//! The chance counts the boards that answer (those whose draw is within
//! the share, less the ones that missed the request), the ones alone in
//! their slot, and those whose reply was not lost. For up to
//! [`EXACT_UP_TO`] boards it is exact (inclusion and exclusion over the
//! boards heard alone), which is what the stop rule leans on; for more,
//! a binomial with the exact mean.

use super::{Timing, MAX_SLOTS};
use alloc::vec::Vec;

/// The chance a frame is lost at a receiver that the belief allows for
/// (each request and each reply). A line that loses more makes the stop
/// rule less sure than it says.
pub const LOSS_ALLOWED: f64 = 0.05;

/// Discovery stops when its belief that any board is left falls below
/// this.
pub const STOP_RISK: f64 = 1e-5;

/// The most the belief allows for the chance that a slot several boards
/// answer in is heard all the same, the strongest reply captured. How
/// often a line captures depends on how far apart the levels are, so
/// any chance up to this one is allowed: a frame that hears a few boards
/// amid a crowd must not be read as "few are left".
pub const CAPTURE_ALLOWED: f64 = 0.75;

/// Boards up to which the chance of a frame's count is exact.
pub const EXACT_UP_TO: usize = 24;

/// One frame's shape, as the belief needs it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Plan {
    /// Reply slots.
    pub slots: u8,
    /// A board answers when its draw (0-255) is at most this.
    pub share: u8,
    /// Boards already found that answer too (heard and not yet named in
    /// a request).
    pub others: usize,
}

/// The belief: `belief[n]` is the chance that `n` boards are left.
#[derive(Debug, Clone)]
pub struct Estimate {
    belief: Vec<f64>,
}

impl Estimate {
    /// Before any frame: about `guess` boards (from half of it to twice
    /// it, [`BELL`] of the belief), and any number up to 64 times the
    /// guess (at least 256, at most [`MOST`]; the rest, spread evenly
    /// over the orders of magnitude): a street far larger than guessed
    /// (the console's first guess is 12) is still looked for, by frames
    /// that only a few boards answer.
    pub fn new(guess: usize) -> Estimate {
        let g = guess.max(1) as f64;
        let top = (64 * guess).clamp(256, MOST);
        let bell: Vec<f64> = (0..=top)
            .map(|n| {
                // Flat from half the guess to twice it, steep outside.
                let x = (n as f64 - 1.25 * g) / (0.75 * g);
                let x4 = x * x * x * x;
                1.0 / (1.0 + x4 * x4)
            })
            .collect();
        let bell_total: f64 = bell.iter().sum();
        let wide_total: f64 = (0..=top).map(|n| 1.0 / (n as f64 + 1.0)).sum();
        let belief = bell
            .iter()
            .enumerate()
            .map(|(n, b)| BELL * b / bell_total + (1.0 - BELL) / (n as f64 + 1.0) / wide_total)
            .collect();
        let mut e = Estimate { belief };
        e.normalise();
        e
    }

    /// Scales the belief to a total of 1 and drops what is negligible
    /// (the arithmetic then skips it); false when nothing is left.
    fn normalise(&mut self) -> bool {
        let total: f64 = self.belief.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return false;
        }
        for p in self.belief.iter_mut() {
            *p /= total;
            if *p < NEGLIGIBLE {
                *p = 0.0;
            }
        }
        let end = self
            .belief
            .iter()
            .rposition(|p| *p > 0.0)
            .map_or(1, |i| i + 1);
        self.belief.truncate(end);
        true
    }

    /// How many boards it believes are left (the mean).
    pub fn left(&self) -> f64 {
        self.belief
            .iter()
            .enumerate()
            .map(|(n, p)| n as f64 * p)
            .sum()
    }

    /// The chance that any board is left.
    pub fn anybody(&self) -> f64 {
        1.0 - self.belief[0]
    }

    /// A frame of `plan` heard `new` boards for the first time.
    pub fn observe(&mut self, plan: &Plan, new: usize) {
        let before = core::mem::take(&mut self.belief);
        self.belief = (0..before.len().max(1))
            .map(|m| match before.get(m + new) {
                Some(p) if *p > 0.0 => p * chance(m + new, new, plan),
                _ => 0.0,
            })
            .collect();
        if !self.normalise() {
            // The belief said this could not happen: start again from
            // what was heard.
            self.belief = Estimate::new(new.max(1)).belief;
        }
    }

    /// The next frame: the slots and share that find the most boards
    /// per second of line time, `heard` being the addresses its request
    /// names and `others` the boards found that will answer again. Over
    /// the whole belief: a small chance of many boards left makes a frame
    /// that few answer worth its time.
    pub fn plan(&self, timing: &Timing, heard: usize, others: usize) -> Plan {
        let mut best = (Plan::default(), -1.0);
        for slots in SLOT_CHOICES.iter().copied().filter(|s| *s <= MAX_SLOTS) {
            for share in SHARE_CHOICES {
                let plan = Plan {
                    slots,
                    share,
                    others,
                };
                let rate = self.expected_finds(&plan) / timing.frame(slots, heard) as f64;
                if rate > best.1 {
                    best = (plan, rate);
                }
            }
        }
        best.0
    }

    /// The mean number of new boards a frame of `plan` hears.
    fn expected_finds(&self, plan: &Plan) -> f64 {
        let (q, l) = (answering(plan.share), plan.slots as f64);
        let heard_alone = q * (1.0 - LOSS_ALLOWED);
        // (1 - q/l)^(n - 1 + others), kept from one n to the next.
        let mut apart = powi(1.0 - q / l, plan.others);
        let mut total = 0.0;
        for (n, p) in self.belief.iter().enumerate().skip(1) {
            total += p * n as f64 * heard_alone * apart;
            apart *= 1.0 - q / l;
        }
        total
    }
}

/// The largest street the belief holds.
pub const MOST: usize = 4_095;

/// The share of the first belief that is the bell around the guess.
const BELL: f64 = 0.998;

/// A chance below this is taken as none.
const NEGLIGIBLE: f64 = 1e-15;

/// The frame sizes a plan picks from.
const SLOT_CHOICES: [u8; 10] = [2, 3, 4, 6, 8, 12, 16, 20, 24, 32];

/// The shares a plan picks from: every board, then steps of √2.
const SHARE_CHOICES: [u8; 16] = [255, 180, 127, 90, 63, 44, 31, 22, 15, 10, 7, 5, 3, 2, 1, 0];

/// The chance a board answers a frame: its draw is within the share, and
/// it heard the request.
fn answering(share: u8) -> f64 {
    (share as f64 + 1.0) / 256.0 * (1.0 - LOSS_ALLOWED)
}

/// The chance that a frame of `plan` hears exactly `s` of `n` new
/// boards: on a line without capture, or with the capture chance (up to
/// [`CAPTURE_ALLOWED`]) that explains the count best, whichever is
/// larger: a count is never taken as proof against a crowd that capture
/// explains.
pub fn chance(n: usize, s: usize, plan: &Plan) -> f64 {
    if s > n {
        return 0.0;
    }
    let plain = without_capture(n, s, plan);
    if s == 0 {
        return plain;
    }
    // Slot by slot: one board alone is heard unless lost; a slot with
    // more is heard with the capture allowance; the one heard is new in
    // the share of new boards among those answering.
    let (q, l) = (answering(plan.share), plan.slots as f64);
    let crowd = n + plan.others;
    let empty = powi(1.0 - q / l, crowd);
    let alone = crowd as f64 * q / l * powi(1.0 - q / l, crowd - 1);
    let heard = |capture: f64| {
        (alone + capture * (1.0 - empty - alone)).max(0.0) * (1.0 - LOSS_ALLOWED) * n as f64
            / crowd as f64
    };
    let best = (s as f64 / l).min(heard(CAPTURE_ALLOWED)).max(heard(0.0));
    plain.max(binomial(plan.slots as usize, s, best))
}

/// `P(X = s)` for `X` binomial over `n` trials of chance `h`.
fn binomial(n: usize, s: usize, h: f64) -> f64 {
    if s > n {
        return 0.0;
    }
    let mut p = powi(1.0 - h, n - s);
    for i in 0..s {
        p *= (n - i) as f64 / (s - i) as f64 * h;
    }
    p
}

/// [`chance`] on a line where colliding replies are all lost.
fn without_capture(n: usize, s: usize, plan: &Plan) -> f64 {
    let (q, l) = (answering(plan.share), plan.slots as f64);
    let heard = q * (1.0 - LOSS_ALLOWED);
    if n <= EXACT_UP_TO {
        // Inclusion and exclusion over the sets of j boards each heard
        // alone: they answer, pick j different slots, their replies are
        // not lost, and every other board keeps out of those slots.
        let mut total = 0.0;
        let mut apart = 1.0; // l (l-1) ... (l-j+1) / l^j
        for j in 0..=n.min(plan.slots as usize) {
            if j > 0 {
                apart *= (l - (j - 1) as f64) / l;
            }
            if j < s {
                continue;
            }
            let term = choose(j, s)
                * choose(n, j)
                * powi(heard, j)
                * apart
                * powi(1.0 - j as f64 * q / l, n - j + plan.others);
            total += if (j - s).is_multiple_of(2) {
                term
            } else {
                -term
            };
        }
        total.clamp(0.0, 1.0)
    } else {
        binomial(n, s, heard * powi(1.0 - q / l, n - 1 + plan.others))
    }
}

fn choose(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64)
}

/// `x` to the `k` (core has no `powi` without std).
fn powi(mut x: f64, mut k: usize) -> f64 {
    let mut r = 1.0;
    while k > 0 {
        if k & 1 == 1 {
            r *= x;
        }
        x *= x;
        k >>= 1;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(slots: u8, share: u8) -> Plan {
        Plan {
            slots,
            share,
            others: 0,
        }
    }

    #[test]
    fn the_chances_of_a_frame_add_up_and_match_small_cases() {
        for n in [0, 1, 2, 5, 24, 25, 80] {
            for p in [plan(2, 255), plan(8, 255), plan(32, 100)] {
                let total: f64 = (0..=n).map(|s| without_capture(n, s, &p)).sum();
                assert!((total - 1.0).abs() < 1e-6, "n {n} {p:?}: {total}");
            }
        }
        // One board, every board answering: heard unless its request or
        // its reply was lost.
        let one = chance(1, 0, &plan(4, 255));
        assert!((one - (1.0 - 0.95 * 0.95)).abs() < 1e-12, "{one}");
        // Two boards, four slots: silent when both answer and collide
        // (0.95² × 1/4) or both replies are lost (0.95² × 3/4 × 0.05²),
        // when one answers and its reply is lost (2 × 0.95 × 0.05 × 0.05),
        // or when neither answers (0.05²).
        let two = chance(2, 0, &plan(4, 255));
        let want = 0.9025 * (0.25 + 0.75 * 0.0025) + 0.095 * 0.05 + 0.0025;
        assert!((two - want).abs() < 1e-12, "{two} {want}");
    }

    #[test]
    fn an_empty_street_is_believed_empty_within_a_few_seconds() {
        let mut e = Estimate::new(12);
        let (mut frames, mut line) = (0, 0);
        while e.anybody() >= STOP_RISK {
            let p = e.plan(&Timing::BPSK, 0, 0);
            e.observe(&p, 0);
            frames += 1;
            line += Timing::BPSK.frame(p.slots, 0);
        }
        // Larger streets than guessed are ruled out too, by wide frames few
        // boards answer: about 6 s in all.
        assert!(
            frames <= 12 && line <= 7_000_000,
            "{frames} frames, {line} µs"
        );
    }

    #[test]
    fn a_board_heard_amid_a_crowd_is_no_proof_that_few_are_left() {
        // 60 boards in 4 slots: without capture nobody is heard; with
        // capture one may be, and the belief must allow it.
        let p = plan(4, 255);
        assert!(without_capture(60, 1, &p) < 1e-4);
        assert!(chance(60, 1, &p) > 0.1, "{}", chance(60, 1, &p));
        // A silent frame stays likely for a crowd (no capture happened).
        assert!(chance(60, 0, &p) > 0.9);
    }
}
