//! The S-FSK power line between simulated ST7570s (ST7570 UM 3.2-3.3,
//! 3.6): what one receiver measures and demodulates in one time slot,
//! given who sent what in it.
//!
//! The manual gives the frame (45 bytes, PRE+SSD, the 3-byte window), the
//! slot timing (Table 2), what a receiver estimates (S0/N0/S1/N1 on the
//! PRE+SSD, SNR0/SNR1 on the P_SDU, the ASK/SFSK counters, PGA 0..8, the
//! delta-phase codes of Table 4). Levels, losses and collisions are a
//! model, decided once here and written down in docs/protocol-notes.md
//! ("ST7570: simulated network").

use super::slots::{Heard, SlotUse};
use crate::rng::Rng;
use plm_core::st7570::fields::P_SDU_LEN;
use plm_core::st7570::{Demodulation, SignalNoise};

/// Bits of a P_SDU: the three demodulation counters sum to this (3.6.2).
pub const P_SDU_BITS: u16 = P_SDU_LEN as u16 * 8;
/// A receiver finds PRE+SSD (and hears an alarm or RC pattern) this many
/// dB above the noise (model).
pub const DETECT_SNR_DB: f64 = 3.0;
/// Below this SNR the P_SDU has bit errors (model): S-FSK decides a bit
/// from either tone, so the better channel counts.
pub const DECODE_SNR_DB: f64 = 8.0;
/// A transmission this many dB above every other one in its slot is
/// received despite them (capture, model).
pub const CAPTURE_DB: f64 = 10.0;
/// Tones a receiver listens for must be within this many Hz of its own.
pub const TONE_TOLERANCE: u32 = 500;
/// 10·64·log10(2)·2^-19 dB per SNR unit (3.6.1, Equation 2).
pub const SNR_DB_PER_UNIT: f64 = 10.0 * 64.0 * std::f64::consts::LOG10_2 / 524_288.0;

/// Conditions on the S-FSK line.
#[derive(Debug, Clone, PartialEq)]
pub struct SfskLine {
    /// 60 Hz mains rather than 50 Hz. A modem whose 00A1h says otherwise
    /// cannot lock its PLL: ZC_FAIL (Table 11).
    pub mains_60_hz: bool,
    /// Noise floor at every receiver, dBµV.
    pub noise_dbuv: f64,
    /// Level of a transmitter at gain 31 (0 dB), dBµV; a step below that
    /// per gain code (3.6.5: 32 steps of 1 dB).
    pub max_level_dbuv: f64,
    /// Attenuation between neighbours (adjacent node numbers), dB.
    pub attenuation_db: f64,
    /// Extra attenuation per further node along the line, dB.
    pub attenuation_per_hop_db: f64,
    /// Extra attenuation between nodes on different mains phases, dB.
    pub phase_coupling_db: f64,
    /// Extra attenuation of the f0 channel relative to f1 per 10 kHz of
    /// difference, per 10 dB of line loss (higher tones fade more), dB.
    pub tilt_db: f64,
    /// Probability a subframe is lost at a receiver that could hear it.
    pub loss: f64,
    /// Probability a received subframe has one byte corrupted.
    pub corruption: f64,
}

impl Default for SfskLine {
    fn default() -> Self {
        SfskLine {
            mains_60_hz: false,
            noise_dbuv: 60.0,
            max_level_dbuv: 120.0,
            attenuation_db: 20.0,
            attenuation_per_hop_db: 6.0,
            phase_coupling_db: 6.0,
            tilt_db: 0.3,
            loss: 0.0,
            corruption: 0.0,
        }
    }
}

impl SfskLine {
    /// Attenuation from node `a` to node `b`, on mains phases `pa`, `pb`
    /// (0..5, 60° steps).
    pub fn attenuation(&self, a: usize, b: usize, pa: u8, pb: u8) -> f64 {
        let hops = a.abs_diff(b).saturating_sub(1) as f64;
        let coupling = if pa % 3 != pb % 3 {
            self.phase_coupling_db
        } else {
            0.0
        };
        self.attenuation_db + hops * self.attenuation_per_hop_db + coupling
    }

    /// Level of a transmitter at `gain` (0..31), dBµV.
    pub fn tx_level(&self, gain: u8) -> f64 {
        self.max_level_dbuv - (31 - gain.min(31)) as f64
    }
}

/// One transmitter as a receiver sees it in a slot.
#[derive(Debug, Clone, Copy)]
pub struct Signal<'a> {
    /// Level at the receiver on f1, dBµV.
    pub level: f64,
    /// How much weaker f0 arrives, dB.
    pub tilt: f64,
    /// What it sent in the slot.
    pub slot: &'a SlotUse,
    /// Delta-phase code (Table 4) of its zero crossing against the
    /// receiver's.
    pub phase: u8,
}

/// Power sum of levels in dBµV.
pub fn power_sum(levels: impl IntoIterator<Item = f64>) -> f64 {
    // 10^(l/10) and log10 through `exp` and `ln`, which the simulated
    // ballast has anyway: libm's `pow` and `log10` would be 2.7 KB more of
    // the console's wasm.
    use std::f64::consts::LN_10;
    let p: f64 = levels.into_iter().map(|l| (l * (LN_10 / 10.0)).exp()).sum();
    if p > 0.0 {
        10.0 * p.ln() / LN_10
    } else {
        f64::NEG_INFINITY
    }
}

/// 100·dBµV, the raw unit of S0..N1 (3.6.1, Equation 1).
pub fn raw(dbuv: f64) -> u32 {
    (dbuv.max(0.0) * 100.0).round() as u32
}

/// The estimations of a level and a noise on both channels.
pub fn signal_noise(level: f64, tilt: f64, noise: f64) -> SignalNoise {
    SignalNoise {
        s0: raw(level - tilt),
        n0: raw(noise),
        s1: raw(level),
        n1: raw(noise),
    }
}

/// RX PGA code 0..8 (3.6.3): more gain for weaker signals, 6 dB a step
/// from 120 dBµV down (model), at most `max` (00ABh).
pub fn pga(level_dbuv: f64, max: u8) -> u8 {
    (((120.0 - level_dbuv) / 6.0).clamp(0.0, 8.0) as u8).min(max)
}

/// Delta-phase code of Table 4 for `sixths` sixths of a period (60°
/// steps) between the transmitter's zero crossing and the receiver's:
/// 0°, +60°, +120°, ±180°, -120°, -60° are codes 1..6.
pub fn phase_code(sixths: u8) -> u8 {
    sixths % 6 + 1
}

/// The delta-phase code a receiver on phase `rx` measures for a sender on
/// phase `tx` (60° steps), in slot `slot_number`. At 2400 bit/s a slot is
/// 7.5 mains periods, so slots start alternately on the positive and the
/// negative zero crossing and every other slot reads 180° off (4.9.1).
pub fn delta_phase(tx: u8, rx: u8, bit_rate_2400: bool, slot_number: u64) -> u8 {
    let flip = if bit_rate_2400 && slot_number % 2 == 1 {
        3
    } else {
        0
    };
    phase_code((tx + 6 - rx % 6 + flip) % 6)
}

/// ASK0/ASK1/SFSK counters of a P_SDU (3.6.2, model): the more the two
/// channels' SNRs differ, the more bits are decided from one tone alone,
/// those split by the bit values.
pub fn demodulation(p_sdu: &[u8; P_SDU_LEN], snr0: f64, snr1: f64) -> Demodulation {
    let ones: u16 = p_sdu.iter().map(|b| b.count_ones() as u16).sum();
    let zeros = P_SDU_BITS - ones;
    let share = ((snr0 - snr1).abs() / 20.0).clamp(0.0, 1.0);
    let ask0 = (zeros as f64 * share) as u16;
    let ask1 = (ones as f64 * share) as u16;
    Demodulation {
        ask0,
        ask1,
        fsk: P_SDU_BITS - ask0 - ask1,
    }
}

/// The SNR of Equation 2 in its raw unit.
pub fn snr_raw(db: f64) -> u32 {
    (db.max(0.0) / SNR_DB_PER_UNIT).round() as u32
}

/// What a receiver makes of the subframes sent in one slot, the line's
/// `noise` at it (dBµV): `None` when it finds no PRE+SSD.
///
/// Identical subframes (a repeater joining the originator's copies, 4.8)
/// add up; different ones collide: the strongest is received if it is
/// [`CAPTURE_DB`] above the rest (which then count as noise), otherwise
/// the PRE+SSD is found but the P_SDU is garbled. Below
/// [`DECODE_SNR_DB`] on both channels bytes are corrupted; loss and
/// corruption draw on `rng`.
pub fn receive(
    line: &SfskLine,
    signals: &[Signal<'_>],
    noise: f64,
    max_pga: u8,
    rng: &mut Rng,
) -> Option<Heard> {
    let subframes: Vec<(&Signal<'_>, &[u8; P_SDU_LEN])> = signals
        .iter()
        .filter_map(|s| match s.slot {
            SlotUse::Subframe(p) => Some((s, p)),
            _ => None,
        })
        .collect();
    let strongest = subframes
        .iter()
        .max_by(|a, b| a.0.level.total_cmp(&b.0.level))?;
    let (best, p_sdu) = *strongest;
    let same = subframes.iter().all(|(_, p)| *p == p_sdu);
    let total = power_sum(subframes.iter().map(|(s, _)| s.level));
    // Every PRE+SSD is the same pattern: it is found on the sum.
    let found = total - noise;
    let (level, noise_total, garbled) = if same {
        (total, noise, false)
    } else {
        let others = power_sum(
            subframes
                .iter()
                .filter(|(s, _)| !std::ptr::eq(*s, best))
                .map(|(s, _)| s.level),
        );
        (
            best.level,
            power_sum([noise, others]),
            best.level - others < CAPTURE_DB,
        )
    };
    let snr1 = level - noise_total;
    let snr0 = snr1 - best.tilt;
    if found.max(found - best.tilt) < DETECT_SNR_DB || rng.chance(line.loss) {
        return None;
    }
    let mut p = *p_sdu;
    if garbled {
        for b in p.iter_mut() {
            *b ^= rng.next_u64() as u8;
        }
    } else {
        let margin = snr1.max(snr0) - DECODE_SNR_DB;
        let errors = if margin < 0.0 {
            1 + (-margin) as usize * 2
        } else {
            0
        } + rng.chance(line.corruption) as usize;
        for _ in 0..errors {
            let at = rng.below(P_SDU_LEN as u64) as usize;
            p[at] ^= 1 << rng.below(8);
        }
    }
    Some(Heard {
        p_sdu: p,
        sn: signal_noise(level, best.tilt, noise_total),
        pga: pga(level, max_pga),
        phase: best.phase,
        demodulation: demodulation(&p, snr0, snr1),
        snr: (snr_raw(snr0), snr_raw(snr1)),
    })
}

/// The alarm pattern in a slot's window (7.2): heard (with its
/// estimations) when the alarms sent, which add up, are
/// [`DETECT_SNR_DB`] above the noise.
pub fn receive_alarm(signals: &[Signal<'_>], noise: f64) -> Option<SignalNoise> {
    let alarms: Vec<&Signal<'_>> = signals
        .iter()
        .filter(|s| matches!(s.slot, SlotUse::Alarm))
        .collect();
    let level = power_sum(alarms.iter().map(|s| s.level));
    let tilt = alarms.iter().map(|s| s.tilt).fold(0.0, f64::max);
    (level - noise >= DETECT_SNR_DB).then(|| signal_noise(level, tilt, noise))
}

/// The repeater call patterns heard in a slot's 21 sub-slots (7.3): per
/// sub-slot sent in, its S0..N1 (patterns in one sub-slot add up).
pub fn receive_rc(signals: &[Signal<'_>], noise: f64) -> Vec<(u16, SignalNoise)> {
    let mut heard: Vec<(u16, Vec<(f64, f64)>)> = Vec::new();
    for s in signals {
        if let SlotUse::RepeaterCall { position } = s.slot {
            match heard.iter_mut().find(|(p, _)| p == position) {
                Some((_, v)) => v.push((s.level, s.tilt)),
                None => heard.push((*position, vec![(s.level, s.tilt)])),
            }
        }
    }
    heard
        .into_iter()
        .filter_map(|(p, v)| {
            let level = power_sum(v.iter().map(|x| x.0));
            let tilt = v.iter().map(|x| x.1).fold(0.0, f64::max);
            (level - noise >= DETECT_SNR_DB).then(|| (p, signal_noise(level, tilt, noise)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_4_codes_and_the_2400_ambiguity() {
        // Same phase: 0°; +120°: code 3; -120°: code 5; reversed: ±180°.
        assert_eq!(delta_phase(0, 0, false, 1), 1);
        assert_eq!(delta_phase(2, 0, false, 1), 3);
        assert_eq!(delta_phase(0, 2, false, 1), 5);
        assert_eq!(delta_phase(3, 0, false, 0), 4);
        // 2400 bit/s: odd slots read 180° off.
        assert_eq!(delta_phase(0, 0, true, 0), 1);
        assert_eq!(delta_phase(0, 0, true, 1), 4);
        assert_eq!(delta_phase(2, 0, true, 3), 6);
    }

    #[test]
    fn counters_sum_to_304_bits() {
        let p = [0x0F; P_SDU_LEN];
        for (a, b) in [(20.0, 20.0), (30.0, 10.0), (5.0, 40.0)] {
            let d = demodulation(&p, a, b);
            assert_eq!(d.ask0 + d.ask1 + d.fsk, 304);
        }
        assert_eq!(demodulation(&p, 20.0, 20.0).fsk, 304);
        assert!(demodulation(&p, 40.0, 10.0).ask0 > 0);
    }
}
