//! Host-interface timeouts (UM0932 3.2.9 Table 9, MIB object 09h Table 61).

use crate::time::{Duration, MS};

/// The three host-interface timeouts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Timeouts {
    /// T_SR: status message to the first byte of the host's frame.
    pub t_sr: Duration,
    /// T_ACK: end of a frame to its ACK/NAK.
    pub t_ack: Duration,
    /// T_IC: the longest pause between two characters of one frame.
    pub t_ic: Duration,
}

impl Default for Timeouts {
    /// UM0932 Table 9: T_IC 10 ms, T_ACK 40 ms, T_SR 200 ms.
    fn default() -> Self {
        Timeouts::from_ms(200, 40, 10)
    }
}

impl Timeouts {
    /// Timeouts from milliseconds, in the order of MIB object 09h.
    pub const fn from_ms(t_sr: u8, t_ack: u8, t_ic: u8) -> Self {
        Timeouts {
            t_sr: t_sr as Duration * MS,
            t_ack: t_ack as Duration * MS,
            t_ic: t_ic as Duration * MS,
        }
    }
}
