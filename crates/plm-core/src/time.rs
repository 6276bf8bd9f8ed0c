//! Virtual time for the sans-IO engines (time comes in as an argument,
//! docs/architecture.md). One tick is one microsecond.

/// A point in time, in microseconds since an arbitrary origin chosen by the
/// driver (browser `performance.now()`, simulator clock, test).
pub type Instant = u64;

/// A span of time in microseconds.
pub type Duration = u64;

/// Microseconds in one millisecond.
pub const MS: Duration = 1_000;

/// Time a UART needs to put `bytes` characters on the wire at `baud`:
/// 10 bit times per character (1 start, 8 data, 1 stop bit, UM0932 3.1).
pub fn wire_time(bytes: usize, baud: u32) -> Duration {
    (bytes as u64 * 10 * 1_000_000).div_ceil(baud.max(1) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_byte_at_9600_takes_ten_bit_times() {
        assert_eq!(wire_time(1, 9600), 1042);
        assert_eq!(wire_time(96, 9600), 100_000);
    }
}

/// When a UART transmitter will have sent every byte written to it: the
/// engines count T_ACK and T_SR from the last byte on the wire (UM0932
/// 3.2.7, 3.2.8), not from the moment the bytes were handed over.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TxClock {
    idle_at: Instant,
}

impl TxClock {
    /// Accounts for `bytes` characters written at `now` at `baud`; returns
    /// when the last one will have left.
    pub fn written(&mut self, now: Instant, bytes: usize, baud: u32) -> Instant {
        self.idle_at = self.idle_at.max(now) + wire_time(bytes, baud);
        self.idle_at
    }
}

/// The earlier of two optional deadlines.
pub fn earliest(a: Option<Instant>, b: Option<Instant>) -> Option<Instant> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}
