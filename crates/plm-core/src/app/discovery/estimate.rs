//! What the concentrator believes of the boards it has not found yet.
//!
//! All it can observe is how many boards a frame heard for the first
//! time: an empty slot and a collision sound alike, on a real line as on
//! the simulated one. So it keeps a belief over how many boards are left
//! (0 to a bound well above its guess) and how readily the line captures
//! one reply out of several, updated after every frame by Bayes' rule
//! with the chance of hearing that many new boards, then shifted down by
//! them (docs/protocol-notes.md, "Discovery").
//!
//! The chance counts the boards that answer (those whose draw is within
//! the share, less the ones that missed the request), the ones heard in
//! their slot (alone, or captured out of a collision), and those whose
//! reply was not lost. Without capture and for up to [`EXACT_UP_TO`]
//! boards it is exact (inclusion and exclusion over the boards heard
//! alone); otherwise a binomial over the slots with the exact mean. A
//! silent frame is weighed as on a line that does not capture, so that
//! silence never rules out a crowd, except for up to [`EXACT_UP_TO`]
//! boards, where it is exact with capture: the stop rule leans on it.
use super::super::frame::Address;
use super::{Timing, MAX_SLOTS};
use alloc::vec::Vec;

/// The chance a frame is lost at a receiver that the belief allows for
/// (each request and each reply). A line that loses more makes the stop
/// rule less sure than it says.
pub const LOSS_ALLOWED: f64 = 0.05;

/// Discovery stops when its belief that any board is left falls below
/// this.
pub const STOP_RISK: f64 = 1e-5;

/// How readily the line captures, the values the belief weighs: a slot
/// that k ≥ 2 boards answer is heard with chance `p^k` (the strongest
/// reply clears the receiver's margin over each of the others, as when
/// levels are spread evenly and the margin is `1 - p` of the spread).
/// The values give a two-reply slot a chance of 0, 0.15, 0.3, 0.45, 0.6
/// and 0.75. One value holds for the whole street (less and less of it,
/// [`CAPTURE_FADES`]): a line that captured in one frame captures in the
/// next, so that a few boards heard in a frame are read against what the
/// line showed before, not against the capture that best excuses a crowd.
pub const CAPTURES: [f64; 6] = [0.0, 0.387_298, 0.547_723, 0.670_820, 0.774_597, 0.866_025];

/// The share of the belief in each capture value that moves to the next
/// lower one after each frame, and the share of each count's belief
/// spread over every capture value ([`Estimate::observe`]).
pub const CAPTURE_FADES: f64 = 0.1;

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

/// `belief[n][k]`: the chance that `n` boards are left and the line
/// captures as `CAPTURES[k]` says.
type Row = [f64; CAPTURES.len()];

/// The belief over the boards left and the line's capture.
#[derive(Debug, Clone)]
pub struct Estimate {
    belief: Vec<Row>,
}

impl Estimate {
    /// Before any frame: about `guess` boards (from half of it to twice
    /// it, [`BELL`] of the belief), and any number up to 64 times the
    /// guess (at least 256, at most [`MOST`]; the rest, spread evenly
    /// over the orders of magnitude): a street far larger than guessed
    /// (the console's first guess is 12) is still looked for, by frames
    /// that only a few boards answer. Every capture value alike.
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
            .map(|(n, b)| {
                let p = BELL * b / bell_total + (1.0 - BELL) / (n as f64 + 1.0) / wide_total;
                [p; CAPTURES.len()]
            })
            .collect();
        let mut e = Estimate { belief };
        e.normalise();
        e
    }

    /// Scales the belief to a total of 1 and drops what is negligible
    /// (the arithmetic then skips it); false when nothing is left.
    fn normalise(&mut self) -> bool {
        let total: f64 = self.belief.iter().flatten().sum();
        if !(total > 0.0 && total.is_finite()) {
            return false;
        }
        for p in self.belief.iter_mut().flatten() {
            *p /= total;
            if *p < NEGLIGIBLE {
                *p = 0.0;
            }
        }
        let end = self
            .belief
            .iter()
            .rposition(|row| row.iter().any(|p| *p > 0.0))
            .map_or(1, |i| i + 1);
        self.belief.truncate(end);
        true
    }

    /// How many boards it believes are left: the median of its belief
    /// (the mean is pulled up by the small chance of a far larger
    /// street: with 11 of 12 lamps found it read "about 8 left").
    pub fn left(&self) -> f64 {
        let mut below = 0.0;
        for (n, row) in self.belief.iter().enumerate() {
            below += row.iter().sum::<f64>();
            if below >= 0.5 {
                return n as f64;
            }
        }
        self.belief.len().saturating_sub(1) as f64
    }

    /// The chance that any board is left.
    pub fn anybody(&self) -> f64 {
        1.0 - self.belief[0].iter().sum::<f64>()
    }

    /// A frame of `plan` heard `new` boards for the first time.
    pub fn observe(&mut self, plan: &Plan, new: usize) {
        let before = core::mem::take(&mut self.belief);
        // A silent frame on a line that captures: the exact chance for
        // the few boards the stop rule weighs (with others answering,
        // none: [`chance`]'s safe side). A line that lags or loses
        // requests wholesale silences a crowd too: silence is never taken
        // as proof against many boards.
        let silence = CAPTURES.map(|capture| {
            (new == 0 && plan.others == 0 && capture > 0.0)
                .then(|| silent_when_answering(plan, capture))
        });
        self.belief = (0..before.len().max(1))
            .map(|m| {
                let mut row = [0.0; CAPTURES.len()];
                if let Some(was) = before.get(m + new) {
                    for (k, p) in was.iter().enumerate().filter(|(_, p)| **p > 0.0) {
                        row[k] = p * match &silence[k] {
                            Some(by_answering) if m <= EXACT_UP_TO => silent(m, plan, by_answering),
                            _ => chance(m + new, new, plan, CAPTURES[k]),
                        };
                    }
                }
                row
            })
            .collect();
        if !self.normalise() {
            // The belief said this could not happen: start again from
            // what was heard.
            self.belief = Estimate::new(new.max(1)).belief;
        }
        // The strongest boards win the captures, so they are found
        // first: the boards left capture less and less. Each frame, a
        // share of the belief in each capture value moves to the next
        // lower one, and a share of each count's belief is spread over
        // every capture value (a line whose requests collide or lag looks
        // like one that stopped capturing), so that a line that captured
        // early cannot make a crowd look like a few.
        for row in self.belief.iter_mut() {
            for k in 1..CAPTURES.len() {
                let down = row[k] * CAPTURE_FADES;
                row[k] -= down;
                row[k - 1] += down;
            }
            let spread = row.iter().sum::<f64>() * CAPTURE_FADES / CAPTURES.len() as f64;
            for p in row.iter_mut() {
                *p = *p * (1.0 - CAPTURE_FADES) + spread;
            }
        }
    }

    /// The next frame: the slots and share that find the most boards
    /// per second of line time, `heard` being the addresses its request
    /// names and `others` the boards found that will answer again. Over
    /// the whole belief: a small chance of many boards left makes a frame
    /// that few answer worth its time.
    pub fn plan(&self, timing: &Timing, heard: &[Address], others: usize) -> Plan {
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
        let slots = plan.slots as f64;
        let mut total = 0.0;
        for (k, capture) in CAPTURES.iter().enumerate() {
            let mut slot = Slot::new(plan, *capture);
            let mut n = 1;
            while n < self.belief.len() {
                // Many boards are weighed in groups of a 64th of their
                // number (the chance changes little within one): the plan
                // costs a few hundred steps, not thousands; the belief
                // itself stays exact.
                let end = (n + (n / 64).max(1)).min(self.belief.len());
                let mass: f64 = self.belief[n..end].iter().map(|row| row[k]).sum();
                if mass > 0.0 {
                    total += mass * slots * slot.at(n);
                }
                n = end;
            }
        }
        total
    }
}

/// The chance that one slot of a frame hears a new board, for a growing
/// number of new boards (the powers carried from one to the next).
struct Slot {
    /// The chance a board answers in this slot.
    u: f64,
    capture: f64,
    others: usize,
    /// New boards.
    n: usize,
    /// `(1 - u)^(m - 1)` and `(1 - u + u capture)^m`, `m` the boards
    /// answering (new and others).
    apart: f64,
    captured: f64,
}

impl Slot {
    /// One new board.
    fn new(plan: &Plan, capture: f64) -> Slot {
        let u = answering(plan.share) / plan.slots as f64;
        Slot {
            u,
            capture,
            others: plan.others,
            n: 1,
            apart: powi(1.0 - u, plan.others),
            captured: powi(1.0 - u + u * capture, plan.others + 1),
        }
    }

    /// With `n` new boards (no fewer than the last asked): the chance
    /// the slot hears a new one.
    fn at(&mut self, n: usize) -> f64 {
        let (u, c) = (self.u, self.capture);
        let more = n - self.n;
        if more > 0 {
            self.apart *= powi(1.0 - u, more);
            self.captured *= powi(1.0 - u + u * c, more);
            self.n = n;
        }
        hears_new(u, c, n, n + self.others, self.apart, self.captured)
    }
}

/// The chance one slot hears a new board: `n` new boards, `m` answering
/// in all (new and others), each in this slot with chance `u`; `apart`
/// is `(1-u)^(m-1)` and `all` is `(1-u+uc)^m`. One board alone, or k ≥ 2
/// heard with chance `c^k`:
/// Σ C(m,k) u^k (1-u)^(m-k) c^k = (1-u+uc)^m - (1-u)^m - m u c (1-u)^(m-1).
fn hears_new(u: f64, c: f64, n: usize, m: usize, apart: f64, all: f64) -> f64 {
    let mf = m as f64;
    let alone = mf * u * apart;
    let crowd = (all - apart * (1.0 - u) - mf * u * c * apart).max(0.0);
    (alone + crowd) * (1.0 - LOSS_ALLOWED) * n as f64 / mf
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
/// boards on a line that captures as `capture` says ([`CAPTURES`]): a
/// binomial over the slots. A silent frame: the chance without capture,
/// which capture could only lower, so that silence never rules out a
/// crowd (a crowd is ruled out by a frame that few of it answer, where
/// it would be heard); [`Estimate::observe`] is exact with capture for
/// up to [`EXACT_UP_TO`] boards, which the stop rule leans on.
pub fn chance(n: usize, s: usize, plan: &Plan, capture: f64) -> f64 {
    if s > n {
        return 0.0;
    }
    if capture == 0.0 || s == 0 {
        return without_capture(n, s, plan);
    }
    let u = answering(plan.share) / plan.slots as f64;
    let m = n + plan.others;
    let h = hears_new(
        u,
        capture,
        n,
        m,
        powi(1.0 - u, m - 1),
        powi(1.0 - u + u * capture, m),
    );
    binomial(plan.slots as usize, s, h)
}

/// The chance that a frame of `plan` hears nobody when `a` of its boards
/// answer, for `a` up to [`EXACT_UP_TO`], on a line that captures as
/// `capture` says: the `a` replies spread evenly over the slots (the
/// multinomial, through its exponential generating function), a slot of
/// k ≥ 1 replies silent unless one is heard (alone: unless lost; more:
/// with chance `capture^k`, unless lost).
fn silent_when_answering(plan: &Plan, capture: f64) -> [f64; EXACT_UP_TO + 1] {
    const N: usize = EXACT_UP_TO + 1;
    let mut slot = [0.0; N]; // (1 - heard_k) / k!
    let mut factorial = 1.0;
    for (k, e) in slot.iter_mut().enumerate() {
        if k > 0 {
            factorial *= k as f64;
        }
        let heard = match k {
            0 => 0.0,
            1 => 1.0 - LOSS_ALLOWED,
            _ => powi(capture, k) * (1.0 - LOSS_ALLOWED),
        };
        *e = (1.0 - heard) / factorial;
    }
    let mut frame = [0.0; N];
    frame[0] = 1.0;
    for _ in 0..plan.slots {
        let mut next = [0.0; N];
        for (i, f) in frame.iter().enumerate().filter(|(_, f)| **f != 0.0) {
            for (j, e) in slot.iter().enumerate().take(N - i) {
                next[i + j] += f * e;
            }
        }
        frame = next;
    }
    // P(silent | a) = a! / L^a × [x^a] slot(x)^L.
    let mut scale = 1.0;
    let mut out = [0.0; N];
    for (a, o) in out.iter_mut().enumerate() {
        if a > 0 {
            scale *= a as f64 / plan.slots as f64;
        }
        *o = (scale * frame[a]).clamp(0.0, 1.0);
    }
    out
}

/// The chance that a frame of `plan` hears nobody from `n` boards
/// (`n` up to [`EXACT_UP_TO`]), from [`silent_when_answering`].
fn silent(n: usize, plan: &Plan, by_answering: &[f64; EXACT_UP_TO + 1]) -> f64 {
    let q = answering(plan.share);
    (0..=n)
        .map(|a| choose(n, a) * powi(q, a) * powi(1.0 - q, n - a) * by_answering[a])
        .sum()
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
        let one = chance(1, 0, &plan(4, 255), CAPTURES[5]);
        assert!((one - (1.0 - 0.95 * 0.95)).abs() < 1e-12, "{one}");
        // Two boards, four slots: silent when both answer and collide
        // (0.95² × 1/4) or both replies are lost (0.95² × 3/4 × 0.05²),
        // when one answers and its reply is lost (2 × 0.95 × 0.05 × 0.05),
        // or when neither answers (0.05²).
        let two = chance(2, 0, &plan(4, 255), CAPTURES[5]);
        let want = 0.9025 * (0.25 + 0.75 * 0.0025) + 0.095 * 0.05 + 0.0025;
        assert!((two - want).abs() < 1e-12, "{two} {want}");
    }

    #[test]
    fn the_exact_silence_with_capture_matches_the_chance_without_and_falls_with_capture() {
        for p in [plan(2, 255), plan(8, 255), plan(32, 100)] {
            let none = silent_when_answering(&p, 0.0);
            let some = silent_when_answering(&p, CAPTURES[3]);
            for n in 0..=EXACT_UP_TO {
                let exact = without_capture(n, 0, &p);
                let ours = silent(n, &p, &none);
                assert!((exact - ours).abs() < 1e-9, "n {n} {p:?}: {exact} {ours}");
                assert!(silent(n, &p, &some) <= ours + 1e-12);
            }
        }
        // Two boards in two slots, every board answering, capture 1/2 for
        // two replies: silent when both collide and the slot is not
        // captured or lost, or what is heard is lost, or nobody answers.
        let c = core::f64::consts::FRAC_1_SQRT_2;
        let p = plan(2, 255);
        let got = silent(2, &p, &silent_when_answering(&p, c));
        let (q, h) = (0.95, 0.95);
        let both = q * q * (0.5 * (1.0 - 0.5 * h) + 0.5 * (1.0 - h) * (1.0 - h));
        let one = 2.0 * q * (1.0 - q) * (1.0 - h);
        let want = both + one + (1.0 - q) * (1.0 - q);
        assert!((got - want).abs() < 1e-12, "{got} {want}");
    }

    #[test]
    fn an_empty_street_is_believed_empty_within_a_few_seconds() {
        let mut e = Estimate::new(12);
        let (mut frames, mut line) = (0, 0);
        while e.anybody() >= STOP_RISK {
            let p = e.plan(&Timing::BPSK, &[], 0);
            e.observe(&p, 0);
            frames += 1;
            line += Timing::BPSK.frame(p.slots, &[]);
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
        let most = chance(60, 1, &p, CAPTURES[5]);
        assert!(most > 0.1, "{most}");
        // A silent frame stays likely for a crowd, whatever the line
        // captures: silence never rules a crowd out.
        assert!(chance(60, 0, &p, 0.0) > 0.9);
        assert_eq!(chance(60, 0, &p, CAPTURES[5]), chance(60, 0, &p, 0.0));
    }

    #[test]
    fn a_line_that_captures_is_believed_to_and_the_stop_follows_in_a_few_frames() {
        // 40 boards, guessed 40, capture at 0.6 for two replies: a frame
        // of 32 slots that every board answers hears about 20 (alone or
        // captured); one that does not capture would hear about 9.
        let mut e = Estimate::new(40);
        e.observe(&plan(32, 255), 20);
        let capture: f64 = e.belief.iter().map(|r| r[4] + r[5]).sum();
        assert!(capture > 0.5, "{capture}");
        // The 20 left, all heard in turn, then silence: a few short frames
        // for the few that could be left, one a crowd would be heard in.
        e.observe(&plan(32, 255), 16);
        e.observe(&plan(8, 255), 4);
        let mut plans = Vec::new();
        while e.anybody() >= STOP_RISK {
            let p = e.plan(&Timing::BPSK, &[], 0);
            e.observe(&p, 0);
            plans.push((p.slots, p.share));
        }
        assert!(plans.len() <= 8, "{plans:?}");
    }
}
