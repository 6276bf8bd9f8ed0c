//! Time slots and the seam to the S-FSK line (ST7570 UM 3.2, 3.3,
//! Table 2): what the simulated ST7570 puts on the line, slot by slot,
//! and what it is handed when the line delivers a subframe.
//!
//! The line itself (mains, attenuation, noise, collisions) is not here:
//! the model queues [`Transmission`]s for it and takes [`Heard`]
//! subframes from it. Until the line exists, the mains zero crossing the
//! slots are locked to is at virtual time 0 and every period after it.

use plm_core::st7570::fields::P_SDU_LEN;
use plm_core::st7570::mib::PlcConfiguration;
use plm_core::st7570::phy_frame::{PhyFrame, Window, PHY_FRAME_LEN};
use plm_core::st7570::{Demodulation, SignalNoise};
use plm_core::time::{Duration, Instant};

/// Bits in a time slot: a PHY frame of 45 bytes (3.2).
pub const SLOT_BITS: u64 = PHY_FRAME_LEN as u64 * 8;
/// Bits of PRE, SSD and the P_SDU: the frame before the pause/alarm
/// window of the last 3 bytes (3.2, 7.2).
pub const FRAME_BITS: u64 = SLOT_BITS - 24;

/// The slot timing of a PLC configuration (00A1h): 24 or 48 bits per
/// mains period at 50 or 60 Hz, so slots of 300/150 ms at 50 Hz and
/// 250/125 ms at 60 Hz (Table 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SlotClock {
    /// Slot length in µs.
    pub slot: Duration,
}

impl SlotClock {
    /// The clock 00A1h sets.
    pub fn of(plc: &PlcConfiguration) -> Self {
        let hz: u64 = if plc.mains_60_hz { 60 } else { 50 };
        let bits_per_period: u64 = if plc.bit_rate_2400 { 48 } else { 24 };
        SlotClock {
            slot: SLOT_BITS * 1_000_000 / (hz * bits_per_period),
        }
    }

    /// The duration of `bits` bits.
    pub fn bits(&self, bits: u64) -> Duration {
        self.slot * bits / SLOT_BITS
    }

    /// The first slot boundary after `now`: a request is served "in the
    /// next time slot" (5.3.12).
    pub fn next_slot(&self, now: Instant) -> Instant {
        (now / self.slot + 1) * self.slot
    }

    /// The number of the slot `t` falls in, counted from the first zero
    /// crossing.
    pub fn slot_number(&self, t: Instant) -> u64 {
        t / self.slot
    }
}

/// What one slot of a transmission carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlotUse {
    /// PRE, SSD and a P_SDU (a PHY frame, or one MAC subframe), then the
    /// pause window.
    Subframe([u8; P_SDU_LEN]),
    /// The alarm pattern 569E89h in the slot's last 3 bytes only (7.2).
    Alarm,
    /// A repeater call (7.3): the pattern 2EC5h in sub-slot `position` of
    /// the slot's 21 two-byte sub-slots.
    RepeaterCall {
        /// Sub-slot 0..20 (a Client calls at 0).
        position: u16,
    },
}

/// Sub-slots of a repeater call slot (7.3).
pub const RC_SUB_SLOTS: usize = 21;
/// The repeater call pattern (7.3).
pub const RC_PATTERN: u16 = 0x2EC5;

impl SlotUse {
    /// The slot's 45 bytes as a line capture shows them (an alarm-only
    /// slot is silent, 00h, before its window).
    pub fn bytes(&self) -> [u8; PHY_FRAME_LEN] {
        match self {
            SlotUse::Subframe(p_sdu) => PhyFrame {
                p_sdu: *p_sdu,
                window: Window::Pause,
            }
            .emit(),
            SlotUse::Alarm => {
                let mut b = [0u8; PHY_FRAME_LEN];
                b[PHY_FRAME_LEN - 3..].copy_from_slice(&Window::Alarm.value().to_be_bytes()[1..]);
                b
            }
            SlotUse::RepeaterCall { position } => {
                let mut b = [0u8; PHY_FRAME_LEN];
                let at = *position as usize * 2;
                if (*position as usize) < RC_SUB_SLOTS {
                    b[at..at + 2].copy_from_slice(&RC_PATTERN.to_be_bytes());
                }
                b
            }
        }
    }
}

/// What a modem puts on the line: consecutive slots from `start`, with the
/// tones and level 00A1h sets. A MAC frame's IC+1 copies (4.8) are all
/// here, each with its own CC.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Transmission {
    /// Start of the first slot (a zero-crossing-locked boundary).
    pub start: Instant,
    /// Slot length.
    pub slot: Duration,
    /// 2400 bit/s rather than 1200.
    pub bit_rate_2400: bool,
    /// f0 (space) in Hz.
    pub f0: u32,
    /// f1 (mark) in Hz.
    pub f1: u32,
    /// Target output gain, 0 (-31 dB) .. 31 (0 dB).
    pub gain: u8,
    /// One entry per slot, in order.
    pub slots: Vec<SlotUse>,
}

impl Transmission {
    /// When its last slot ends.
    pub fn end(&self) -> Instant {
        self.start + self.slot * self.slots.len() as u64
    }
}

/// What a modem in a Test mode puts on the line, continuously and with no
/// time slots (00A1h operating modes 4-6, Table 137), at the target gain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestTone {
    /// Mode 4 or 5: one tone (f0 or f1), in Hz.
    Single(u32),
    /// Mode 6: f0 and f1 in turn, in Hz.
    Alternate(u32, u32),
}

impl TestTone {
    /// The tone of an operating mode, `None` outside the Test modes.
    pub fn of(plc: &PlcConfiguration) -> Option<TestTone> {
        match plc.operating_mode {
            4 => Some(TestTone::Single(plc.f0)),
            5 => Some(TestTone::Single(plc.f1)),
            6 => Some(TestTone::Alternate(plc.f0, plc.f1)),
            _ => None,
        }
    }
}

/// A subframe the line delivered to this modem, with what its receiver
/// measured on the PRE+SSD and the P_SDU (3.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Heard {
    /// The P_SDU as received.
    pub p_sdu: [u8; P_SDU_LEN],
    /// S0, N0, S1, N1.
    pub sn: SignalNoise,
    /// RX PGA gain code, 0..8.
    pub pga: u8,
    /// Delta-phase code of Table 4 (0: not measured).
    pub phase: u8,
    /// ASK0, ASK1, FSK counters.
    pub demodulation: Demodulation,
    /// SNR0 and SNR1 (24 bits each).
    pub snr: (u32, u32),
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::st7570::mib::object;

    #[test]
    fn slot_lengths_of_table_2() {
        let mut plc = PlcConfiguration::decode(object(0x00A1).unwrap().default);
        let mut lens = Vec::new();
        for (hz60, fast) in [(false, false), (false, true), (true, false), (true, true)] {
            plc.mains_60_hz = hz60;
            plc.bit_rate_2400 = fast;
            lens.push(SlotClock::of(&plc).slot);
        }
        assert_eq!(lens, [300_000, 150_000, 250_000, 125_000]);
        let c = SlotClock { slot: 300_000 };
        assert_eq!((c.next_slot(0), c.next_slot(299_999)), (300_000, 300_000));
        assert_eq!(c.bits(FRAME_BITS), 280_000);
        assert_eq!(SlotUse::Alarm.bytes()[42..], [0x56, 0x9E, 0x89]);
    }
}
