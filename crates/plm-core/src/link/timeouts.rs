//! Host-interface timeouts: UM0932 3.2.9 Table 9 and MIB object 09h
//! (Table 61) for the ST7580; ST7570 UM 5.2.3 Table 14 and MIB object
//! 000Bh (6.5.12) for the ST7570.

use super::Dialect;
use crate::time::{wire_time, Duration, MS};

/// The host-interface timeouts of both chips. The ST7580 engines use T_SR,
/// T_ACK and T_IC; the ST7570 ones use all five.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Timeouts {
    /// T_SR: status message to the first byte of the host's frame.
    pub t_sr: Duration,
    /// T_ACK: end of a frame to its ACK/NAK.
    pub t_ack: Duration,
    /// T_IC: the longest pause between two characters of one frame.
    pub t_ic: Duration,
    /// T_POLL (ST7570 only): T_REQ low to the status message.
    pub t_poll: Duration,
    /// T_WBC (ST7570 only): NAK of a modem frame to the modem's repeat.
    pub t_wbc: Duration,
}

/// ST7570 UM Table 14: T_POLL 20 ms.
const T_POLL: Duration = 20 * MS;
/// ST7570 UM Table 14: T_WBC 5 ms.
const T_WBC: Duration = 5 * MS;

impl Default for Timeouts {
    /// UM0932 Table 9: T_IC 10 ms, T_ACK 40 ms, T_SR 200 ms (and the
    /// ST7570's T_POLL 20 ms, T_WBC 5 ms of its Table 14).
    fn default() -> Self {
        Timeouts::from_ms(200, 40, 10)
    }
}

impl Timeouts {
    /// Timeouts from milliseconds, in the order of ST7580 MIB object 09h;
    /// T_POLL and T_WBC take their ST7570 Table 14 values.
    pub const fn from_ms(t_sr: u8, t_ack: u8, t_ic: u8) -> Self {
        Timeouts {
            t_sr: t_sr as Duration * MS,
            t_ack: t_ack as Duration * MS,
            t_ic: t_ic as Duration * MS,
            t_poll: T_POLL,
            t_wbc: T_WBC,
        }
    }

    /// The timeouts a chip has after a reset with its UART at `baud`.
    ///
    /// ST7570: Table 14 for T_ACK, T_POLL, T_SR and T_WBC; T_IC as MIB
    /// 000Bh's factory default 00h selects it, 5 characters (see
    /// docs/protocol-notes.md, "ST7570: link", for the 10 ms of 5.2.2).
    pub fn at_reset(dialect: Dialect, baud: u32) -> Self {
        match dialect {
            Dialect::St7580 => Timeouts::default(),
            Dialect::St7570 => Timeouts::default().with_tic(TicSelector::FACTORY_DEFAULT, baud),
        }
    }

    /// These timeouts with T_IC as `tic` selects it at `baud`.
    pub fn with_tic(self, tic: TicSelector, baud: u32) -> Self {
        Timeouts {
            t_ic: tic.t_ic(baud),
            ..self
        }
    }
}

/// The ST7570's T_IC selector, bit 7 of MIB object 000Bh (UM 6.5.12,
/// Table 97).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TicSelector {
    /// b7 = 0: T_IC is 5 characters at the UART's baud rate.
    FiveCharacters,
    /// b7 = 1: T_IC is 10 ms.
    TenMs,
}

impl TicSelector {
    /// Table 97: factory default 00h, so b7 = 0.
    pub const FACTORY_DEFAULT: TicSelector = TicSelector::FiveCharacters;

    /// The selector in a value of MIB object 000Bh (b7; the other bits are
    /// the repeater setting and unused).
    pub const fn from_mib_000b(value: u8) -> Self {
        if value & 0x80 != 0 {
            TicSelector::TenMs
        } else {
            TicSelector::FiveCharacters
        }
    }

    /// T_IC at `baud`: 5 characters of 10 bits (UM 5.1), or 10 ms.
    pub fn t_ic(self, baud: u32) -> Duration {
        match self {
            TicSelector::FiveCharacters => wire_time(5, baud),
            TicSelector::TenMs => 10 * MS,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn st7570_table_14_and_000bh() {
        let t = Timeouts::at_reset(Dialect::St7570, 9600);
        assert_eq!(
            (t.t_ack, t.t_poll, t.t_sr, t.t_wbc),
            (40 * MS, 20 * MS, 200 * MS, 5 * MS)
        );
        // 5 characters of 10 bits at 9600 baud.
        assert_eq!(t.t_ic, 5_209);
        assert_eq!(Timeouts::at_reset(Dialect::St7570, 57_600).t_ic, 869);
        assert_eq!(TicSelector::from_mib_000b(0x80), TicSelector::TenMs);
        assert_eq!(
            TicSelector::from_mib_000b(0x7F),
            TicSelector::FiveCharacters
        );
        assert_eq!(t.with_tic(TicSelector::TenMs, 9600).t_ic, 10 * MS);
        assert_eq!(
            Timeouts::at_reset(Dialect::St7580, 9600),
            Timeouts::default()
        );
    }
}
