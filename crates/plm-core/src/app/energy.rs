//! A lamp's energy, estimated from the power readings a host took while
//! it watched the lamp.
//!
//! The board keeps no energy counter: of the ballast's parameters
//! (seed 004, Appendix A) only LAMP POWER bears on it, an instantaneous
//! figure. So the energy is the area under the readings, by the
//! trapezoid rule, over the spans the host watched: two readings further
//! apart than [`LONGEST_GAP`] say nothing of what the lamp drew between
//! them (it may have been switched off, failed or dimmed and restored),
//! and that span is left out rather than guessed. What is shown must say
//! both: an estimate, and over how long it was watched.

use crate::time::{Duration, Instant, MS};

/// Longest span between two readings that is still counted: a sweep of
/// 500 lamps reads each one every minute or so; a span ten times that
/// is a pause in watching, not a reading's gap.
pub const LONGEST_GAP: Duration = 10 * 60_000 * MS;

/// Watt-microseconds in a watt-hour.
const WATT_US_PER_WH: u64 = 3_600 * 1_000_000;

/// The energy of one lamp, or of a street (the sum of its lamps').
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Meter {
    /// The last reading: when, and the lamp power in W.
    last: Option<(Instant, u16)>,
    /// Energy counted so far, W·µs.
    watt_us: u64,
    /// Time counted so far (the spans between readings not further apart
    /// than [`LONGEST_GAP`]).
    watched: Duration,
}

impl Meter {
    /// Counts a reading of `power` W taken at `at`. A reading no later
    /// than the last one is taken as the new last one and counts nothing.
    pub fn record(&mut self, at: Instant, power: u16) {
        if let Some((then, before)) = self.last {
            let span = at.saturating_sub(then);
            if span > 0 && span <= LONGEST_GAP {
                let mean_x2 = u64::from(before) + u64::from(power);
                self.watt_us = self.watt_us.saturating_add(mean_x2 * span / 2);
                self.watched += span;
            }
        }
        self.last = Some((at, power));
    }

    /// The energy counted, Wh (rounded to the nearest).
    pub fn watt_hours(&self) -> u64 {
        (self.watt_us + WATT_US_PER_WH / 2) / WATT_US_PER_WH
    }

    /// The energy counted, tenths of a Wh (rounded to the nearest), for a
    /// short watch whose whole watt-hours would read 0.
    pub fn tenths_of_watt_hours(&self) -> u64 {
        (self.watt_us + WATT_US_PER_WH / 20) / (WATT_US_PER_WH / 10)
    }

    /// How long the counted energy covers.
    pub fn watched(&self) -> Duration {
        self.watched
    }

    /// Adds `other`'s count to this one (a street's total over its lamps).
    pub fn add(&mut self, other: &Meter) {
        self.watt_us = self.watt_us.saturating_add(other.watt_us);
        self.watched = self.watched.max(other.watched);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINUTE: Duration = 60_000 * MS;

    #[test]
    fn a_steady_lamp_counts_power_times_time() {
        let mut m = Meter::default();
        for i in 0..=60 {
            m.record(i * MINUTE, 150);
        }
        assert_eq!(m.watched(), 60 * MINUTE);
        assert_eq!(m.watt_hours(), 150);
    }

    #[test]
    fn a_change_of_power_counts_the_trapezoid() {
        let mut m = Meter::default();
        m.record(0, 100);
        m.record(6 * MINUTE, 50);
        m.record(12 * MINUTE, 100);
        assert_eq!(m.watt_hours(), 15);
        assert_eq!(m.tenths_of_watt_hours(), 150);
    }

    #[test]
    fn a_long_gap_is_left_out_not_guessed() {
        let mut m = Meter::default();
        m.record(0, 100);
        m.record(6 * MINUTE, 100);
        m.record(6 * MINUTE + LONGEST_GAP + 1, 100);
        m.record(12 * MINUTE + LONGEST_GAP + 1, 100);
        assert_eq!(m.watched(), 12 * MINUTE);
        assert_eq!(m.watt_hours(), 20);
    }

    #[test]
    fn one_reading_or_a_repeated_time_counts_nothing() {
        let mut m = Meter::default();
        m.record(5 * MINUTE, 250);
        m.record(5 * MINUTE, 250);
        m.record(MINUTE, 250);
        assert_eq!((m.watt_hours(), m.watched()), (0, 0));
    }

    #[test]
    fn a_street_adds_its_lamps() {
        let (mut a, mut b) = (Meter::default(), Meter::default());
        for i in 0..=12 {
            a.record(i * 5 * MINUTE, 100);
        }
        for i in 6..=12 {
            b.record(i * 5 * MINUTE, 250);
        }
        let mut street = Meter::default();
        street.add(&a);
        street.add(&b);
        assert_eq!(street.watt_hours(), 225);
        assert_eq!(street.watched(), 60 * MINUTE);
    }
}
