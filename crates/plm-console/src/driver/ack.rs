//! How quickly the host ACKs the modem's frames (UM0932 3.2.8: within
//! T_ACK; ST7570 UM 5.2.3), measured by the driver for every session whose
//! host engine ACKs a modem ([`super::Driver`]).

use plm_core::time::Duration;
use std::collections::VecDeque;

/// ACK latencies kept for the percentiles (the most recent ones).
pub const ACK_SAMPLES: usize = 1_000;

/// The spread of a set of durations, µs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Spread {
    /// Median.
    pub p50: Duration,
    /// 99th percentile (nearest rank).
    pub p99: Duration,
    /// Longest.
    pub max: Duration,
}

impl Spread {
    /// The spread of `samples`, in order.
    fn of(samples: &[Duration]) -> Spread {
        // Nearest rank: the smallest value with at least p of the samples
        // at or below it.
        let rank = |p: usize| samples[(samples.len() * p).div_ceil(100).max(1) - 1];
        match samples.last() {
            None => Spread::default(),
            Some(&max) => Spread {
                p50: rank(50),
                p99: rank(99),
                max,
            },
        }
    }
}

/// How quickly the host ACKs the modem's frames: from the arrival of a
/// frame's last byte to the ACK written (UM0932 3.2.8: within T_ACK),
/// over the last [`ACK_SAMPLES`] frames.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AckLatency {
    /// Frames ACKed since connecting.
    pub count: u64,
    /// On the transport's clock: what the modem saw. The session steps
    /// the transport's time to each byte's arrival, and the simulated
    /// modem's virtual time waits for the page, so this is 0 there.
    pub link: Spread,
    /// On the page's clock: how long after the byte arrived the page got
    /// round to writing the ACK. It includes how late the page woke and
    /// any stall, which a real modem would see as they are.
    pub page: Spread,
}

/// The raw ACK latencies, bounded, and the same kept in order (a sample
/// goes in and out by binary search: no sort, whose code would cost the
/// page 1.5 KiB for this one list).
#[derive(Debug, Default)]
pub(crate) struct AckTimes {
    count: u64,
    /// (transport's clock, page's clock), oldest first.
    samples: VecDeque<(Duration, Duration)>,
    /// When each was written, on the page's clock (µs, the page's origin).
    written: VecDeque<f64>,
    /// The transport's clock's and the page's, each in order.
    link: Vec<Duration>,
    page: Vec<Duration>,
}

impl AckTimes {
    pub(crate) fn record(&mut self, link: Duration, page: Duration, written: f64) {
        if self.samples.len() == ACK_SAMPLES {
            self.written.pop_front();
            if let Some((l, p)) = self.samples.pop_front() {
                take_out(&mut self.link, l);
                take_out(&mut self.page, p);
            }
        }
        self.samples.push_back((link, page));
        self.written.push_back(written);
        put_in(&mut self.link, link);
        put_in(&mut self.page, page);
        self.count += 1;
    }

    /// Each sample: when it was written (page's clock) and its latency on
    /// both clocks, oldest first.
    pub(crate) fn samples(&self) -> Vec<(f64, Duration, Duration)> {
        let at = self.written.iter();
        at.zip(self.samples.iter())
            .map(|(&w, &(l, p))| (w, l, p))
            .collect()
    }

    /// When the last ACK was written (page's clock, µs).
    pub(crate) fn last_written(&self) -> Option<f64> {
        self.written.back().copied()
    }

    pub(crate) fn stats(&self) -> AckLatency {
        AckLatency {
            count: self.count,
            link: Spread::of(&self.link),
            page: Spread::of(&self.page),
        }
    }
}

/// Puts `x` into the ordered `v`.
fn put_in(v: &mut Vec<Duration>, x: Duration) {
    let i = v.partition_point(|&y| y <= x);
    v.insert(i, x);
}

/// Takes one `x` out of the ordered `v`.
fn take_out(v: &mut Vec<Duration>, x: Duration) {
    let i = v.partition_point(|&y| y < x);
    if v.get(i) == Some(&x) {
        v.remove(i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ack_latency_percentiles_cover_the_most_recent_samples() {
        assert_eq!(Spread::of(&[]), Spread::default());
        let one = Spread::of(&[7]);
        assert_eq!((one.p50, one.p99, one.max), (7, 7, 7));
        let mut backwards = AckTimes::default();
        for i in (1..=100).rev() {
            backwards.record(i, i, 0.0);
        }
        let hundred = backwards.stats().link;
        assert_eq!((hundred.p50, hundred.p99, hundred.max), (50, 99, 100));
        let mut t = AckTimes::default();
        for i in 0..ACK_SAMPLES as u64 + 500 {
            t.record(i, 2 * i, i as f64);
        }
        let l = t.stats();
        assert_eq!(l.count, ACK_SAMPLES as u64 + 500);
        assert_eq!(t.samples.len(), ACK_SAMPLES);
        assert_eq!(l.link.max, ACK_SAMPLES as u64 + 499);
        assert_eq!(l.link.p50, 500 + ACK_SAMPLES as u64 / 2 - 1);
        assert_eq!(l.page.max, 2 * l.link.max);
    }
}
