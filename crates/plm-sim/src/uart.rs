//! One direction of a UART at byte level (UM0932 3.1: 8N1, so 10 bit times
//! a character), with fault injection at the transmitter.
//!
//! Bytes written while the line is busy queue behind the ones before: a
//! run of `k` bytes started at `s` has its last byte arrive at
//! `s + wire_time(k)`, the arithmetic of the link engines' `TxClock`.
//! A dropped byte still takes its time on the wire (the receiver just
//! gets nothing); a delayed byte stalls the line, and every byte after it
//! waits too.

use crate::rng::Rng;
use plm_core::time::{wire_time, Duration, Instant, MS};
use std::collections::VecDeque;

pub use plm_core::link::BAUD_RATES;

/// Faults applied at random to every byte, with these probabilities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ByteFaults {
    /// Probability a byte is lost.
    pub drop: f64,
    /// Probability a byte arrives with one bit flipped.
    pub corrupt: f64,
    /// Probability the line stalls `delay_by` before a byte.
    pub delay: f64,
    /// How long a delayed byte is held back.
    pub delay_by: Duration,
}

impl Default for ByteFaults {
    fn default() -> Self {
        ByteFaults {
            drop: 0.0,
            corrupt: 0.0,
            delay: 0.0,
            // Past the reset T_IC of 10 ms (UM0932 Table 9).
            delay_by: 15 * MS,
        }
    }
}

/// A fault for the next byte written, whatever the probabilities.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OneShot {
    /// Lose it.
    Drop,
    /// XOR it with this mask.
    Corrupt(u8),
    /// Stall the line this long before it.
    Delay(Duration),
}

/// One direction of a UART.
#[derive(Debug, Clone)]
pub struct Wire {
    baud: u32,
    idle_at: Instant,
    /// Start and length of the current run of back-to-back bytes: the
    /// `k`-th arrives at `start + wire_time(k)`, without rounding drift.
    run: (Instant, usize),
    /// Random faults.
    pub faults: ByteFaults,
    one_shots: VecDeque<OneShot>,
}

impl Wire {
    /// An idle wire at `baud`.
    pub fn new(baud: u32) -> Self {
        Wire {
            baud,
            idle_at: 0,
            run: (0, 0),
            faults: ByteFaults::default(),
            one_shots: VecDeque::new(),
        }
    }

    /// The baud rate.
    pub fn baud(&self) -> u32 {
        self.baud
    }

    /// Changes the baud rate for bytes written from now on.
    pub fn set_baud(&mut self, baud: u32) {
        self.baud = baud;
        self.run = (self.idle_at, 0);
    }

    /// Queues a fault for the next byte written.
    pub fn inject(&mut self, fault: OneShot) {
        self.one_shots.push_back(fault);
    }

    /// When every byte written so far will have left, seen from `now`.
    pub fn drained_at(&self, now: Instant) -> Instant {
        self.idle_at.max(now)
    }

    /// A purge of the transmitter at `now` (a host's serial driver
    /// dropping its transmit buffer): the line is idle from `now`, and the
    /// caller drops the arrivals after `now` that [`Wire::write`] gave it.
    pub fn purge(&mut self, now: Instant) {
        if self.idle_at > now {
            self.idle_at = now;
            self.run = (now, 0);
        }
    }

    /// Writes `bytes` at `now`; returns each byte that arrives, with its
    /// arrival time (the end of its stop bit).
    pub fn write(&mut self, now: Instant, bytes: &[u8], rng: &mut Rng) -> Vec<(Instant, u8)> {
        let mut out = Vec::with_capacity(bytes.len());
        for &b in bytes {
            let fault = self
                .one_shots
                .pop_front()
                .or_else(|| self.random_fault(rng));
            let mut byte = Some(b);
            let mut stall = 0;
            match fault {
                Some(OneShot::Drop) => byte = None,
                Some(OneShot::Corrupt(mask)) => byte = Some(b ^ mask.max(1)),
                Some(OneShot::Delay(d)) => stall = d,
                None => {}
            }
            if now > self.idle_at || stall > 0 {
                self.run = (self.idle_at.max(now) + stall, 0);
            }
            self.run.1 += 1;
            self.idle_at = self.run.0 + wire_time(self.run.1, self.baud);
            if let Some(b) = byte {
                out.push((self.idle_at, b));
            }
        }
        out
    }

    fn random_fault(&self, rng: &mut Rng) -> Option<OneShot> {
        let f = &self.faults;
        if f.drop <= 0.0 && f.corrupt <= 0.0 && f.delay <= 0.0 {
            return None;
        }
        if rng.chance(f.drop) {
            Some(OneShot::Drop)
        } else if rng.chance(f.corrupt) {
            Some(OneShot::Corrupt(1 << rng.below(8)))
        } else if rng.chance(f.delay) {
            Some(OneShot::Delay(f.delay_by))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_queue_behind_each_other_at_the_baud_rate() {
        let mut w = Wire::new(9_600);
        let mut rng = Rng::new(1);
        let got = w.write(0, &[1, 2, 3], &mut rng);
        // The arithmetic of the engines' TxClock: no drift over a run.
        assert_eq!(got, vec![(1042, 1), (2084, 2), (3125, 3)]);
        // Written while busy: behind the others.
        assert_eq!(w.write(100, &[4], &mut rng), vec![(4167, 4)]);
        assert_eq!(w.drained_at(0), 4167);
        // Idle again: a new run.
        assert_eq!(w.write(10_000, &[5], &mut rng), vec![(11_042, 5)]);
    }

    #[test]
    fn a_purged_wire_is_idle_at_once() {
        let mut w = Wire::new(9_600);
        let mut rng = Rng::new(1);
        w.write(0, &[0; 100], &mut rng);
        assert_eq!(w.drained_at(2_000), wire_time(100, 9_600));
        w.purge(2_000);
        assert_eq!(w.drained_at(2_000), 2_000);
        // The next byte starts a run of its own at once.
        assert_eq!(w.write(2_000, &[7], &mut rng), vec![(3_042, 7)]);
        // An idle wire is left as it is.
        w.purge(1_000_000);
        assert_eq!(w.drained_at(0), 3_042);
    }

    #[test]
    fn one_shot_faults_hit_the_next_byte_only() {
        let mut w = Wire::new(57_600);
        let mut rng = Rng::new(1);
        w.inject(OneShot::Drop);
        w.inject(OneShot::Corrupt(0x80));
        w.inject(OneShot::Delay(20 * MS));
        let got = w.write(0, &[1, 2, 3, 4], &mut rng);
        let one = wire_time(1, 57_600);
        assert_eq!(
            got,
            vec![
                (2 * one, 0x82),
                (3 * one + 20 * MS, 3),
                (4 * one + 20 * MS, 4)
            ]
        );
    }
}
