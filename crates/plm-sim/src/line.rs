//! The power line between the simulated modems: airtime, who can hear a
//! frame, signal levels, SNR and PGA, losses, and the mains zero crossing.
//!
//! The seeds give the modulations, bit rates, preamble and unique word
//! lengths (UM0932 2.1, 3.3.12 Table 35, 4.2.2 Table 54). The rest is a
//! model, decided here once and written down in docs/protocol-notes.md
//! ("Simulated ST7580 and power line", its Levels): levels in dBµV, a noise floor, per-link
//! attenuation growing with the distance along the street, and an SNR
//! each modulation needs.

use crate::st7570::line::power_sum;
use plm_core::st7580::mib::PhyConfig;
use plm_core::st7580::{Channel, Modulation};
use plm_core::time::{Duration, Instant};

/// Mains period at 50 Hz, µs.
pub const MAINS_PERIOD: Duration = 20_000;
/// The ZC delay unit of UM0932 Tables 37, 39 and 54: 13 µs.
pub const ZC_STEP: Duration = 13;
/// A receiver locks onto a carrier within this many Hz of its channel.
pub const FREQUENCY_TOLERANCE: u32 = 500;
/// PSK frames carry a 16-bit unique word and a 16-bit mode header, both
/// sent in B-PSK whatever the payload modulation (model).
const PSK_SYNC_BITS: u64 = 32;
/// Bit rate of the PSK preamble, unique word and mode header.
const PSK_SYNC_RATE: u64 = 9_600;
/// Capture: of frames overlapping on one receiver channel, one whose level
/// is this many dB above the others (their powers summed) is received
/// despite them, the others are lost. A model decision (the seeds give no
/// figure): B-PSK's required SNR (4 dB) plus 2 dB, as the S-FSK line's
/// capture is its decoding SNR plus 2 dB (`st7570::line::CAPTURE_DB`);
/// the survivor must still meet its own modulation's SNR with the others
/// counted as noise, so a faster modulation needs more.
pub const CAPTURE_DB: f64 = 6.0;

/// Conditions on the line.
#[derive(Debug, Clone, PartialEq)]
pub struct LineConfig {
    /// Noise floor at every receiver, dBµV.
    pub noise_dbuv: f64,
    /// Attenuation between neighbours (adjacent node numbers), dB.
    pub attenuation_db: f64,
    /// Extra attenuation per further node along the street, dB.
    pub attenuation_per_hop_db: f64,
    /// Probability a frame is lost at a receiver that could hear it.
    pub loss: f64,
    /// Capture margin, dB: of overlapping frames on one receiver channel,
    /// one this much stronger than the others survives ([`CAPTURE_DB`] by
    /// default); `None`: every overlap loses them all.
    pub capture_db: Option<f64>,
    /// Probability a received frame has one byte corrupted.
    pub corruption: f64,
    /// Extra attenuation between nodes on different mains phases (node
    /// `n` is on phase `n % 3`): the signal crosses at the transformer
    /// or through coupling capacitors (STEVAL UM 2, Figure 3), dB.
    pub phase_coupling_db: f64,
    /// Extra loss of some nodes' connection to the line (a long service
    /// cable, a poor joint): (node, dB), added to every link to or from
    /// the node.
    pub node_loss_db: Vec<(usize, f64)>,
}

impl Default for LineConfig {
    fn default() -> Self {
        LineConfig {
            noise_dbuv: 40.0,
            attenuation_db: 30.0,
            attenuation_per_hop_db: 2.0,
            loss: 0.0,
            capture_db: Some(CAPTURE_DB),
            corruption: 0.0,
            phase_coupling_db: 0.0,
            node_loss_db: Vec::new(),
        }
    }
}

impl LineConfig {
    /// Attenuation from node `a` to node `b`.
    pub fn attenuation(&self, a: usize, b: usize) -> f64 {
        let hops = a.abs_diff(b).saturating_sub(1) as f64;
        let coupling = if a % 3 != b % 3 {
            self.phase_coupling_db
        } else {
            0.0
        };
        let own: f64 = self
            .node_loss_db
            .iter()
            .filter(|&&(n, _)| n == a || n == b)
            .map(|&(_, db)| db)
            .sum();
        self.attenuation_db + hops * self.attenuation_per_hop_db + coupling + own
    }

    /// A street of `lamps` boards behind a concentrator (model): lamps on
    /// the three phases in turn, the line's loss spread so that the far
    /// end still hears B-PSK with a few dB to spare at the factory TX gain
    /// (21, 90 dBµV; 15 dB to the neighbour, 20 dB more along the whole
    /// street, 6 dB across phases, 40 dBµV noise: 9 dB SNR at the far
    /// end, 29 dB next door).
    pub fn street(lamps: usize) -> LineConfig {
        LineConfig {
            attenuation_db: 15.0,
            attenuation_per_hop_db: 20.0 / lamps.max(1) as f64,
            phase_coupling_db: 6.0,
            ..LineConfig::default()
        }
    }
}

/// Payload bit rate of a frame modulation, bits per second (UM0932 2.1:
/// B-PSK 9.6, Q-PSK 19.2, 8-PSK 28.8 kbps, coded PSK at half rate; B-FSK
/// from the PHY_Config FSK bit rate).
pub fn bit_rate(modulation: Modulation, phy: &PhyConfig) -> u64 {
    match modulation {
        Modulation::BPsk => 9_600,
        Modulation::QPsk => 19_200,
        Modulation::EightPsk => 28_800,
        Modulation::BPskCoded | Modulation::BPskCodedPna => 4_800,
        Modulation::QPskCoded => 9_600,
        Modulation::BFsk => fsk_bit_rate(phy.fsk_bit_rate),
        // Refused before transmission (validate::check_request).
        Modulation::Reserved => 9_600,
    }
}

/// FSK bit rate of a PHY_Config code (Table 54 byte 11 bits 0-1).
pub fn fsk_bit_rate(code: u8) -> u64 {
    1_200 << (code & 3)
}

/// Preamble bits of a PHY_Config length code (Table 54: 16, 24, 32, 40).
fn preamble_bits(code: u8) -> u64 {
    16 + 8 * (code & 3) as u64
}

/// The shape of a frame's start on the line: `(preamble and unique word
/// time, time per payload byte)`.
pub fn timing(modulation: Modulation, phy: &PhyConfig) -> (Duration, f64) {
    let rate = bit_rate(modulation, phy);
    let sync = if modulation == Modulation::BFsk {
        let uw = if phy.fsk_unique_word_16 { 16 } else { 8 };
        (preamble_bits(phy.fsk_preamble_length) + uw) * 1_000_000 / rate
    } else {
        (preamble_bits(phy.psk_preamble_length) + PSK_SYNC_BITS) * 1_000_000 / PSK_SYNC_RATE
    };
    (sync, 8.0 * 1_000_000.0 / rate as f64)
}

/// Airtime of a frame of `psdu` bytes (length byte included): preamble,
/// unique word, then the bytes at the modulation's bit rate.
pub fn airtime(modulation: Modulation, phy: &PhyConfig, psdu: usize) -> Duration {
    let (sync, per_byte) = timing(modulation, phy);
    sync + (per_byte * psdu as f64).ceil() as Duration
}

/// SNR a modulation needs to be received cleanly, dB (model: coded and
/// binary modulations are the robust ones).
pub fn required_snr(modulation: Modulation) -> f64 {
    match modulation {
        Modulation::BPskCodedPna | Modulation::BPskCoded => 0.0,
        Modulation::QPskCoded => 3.0,
        Modulation::BPsk => 4.0,
        Modulation::QPsk => 7.0,
        Modulation::EightPsk => 12.0,
        Modulation::BFsk => 9.0,
        Modulation::Reserved => f64::INFINITY,
    }
}

/// What a receiver makes of a frame it hears at `level` (dBµV) while
/// other frames overlap it on its channel: `others` their powers summed
/// and `strongest` the strongest of them (`-inf` both when none did).
/// Its SNR, the others counted as noise, when it is received; why it is
/// lost otherwise: outdone by [`LineConfig::capture_db`] or more, or a
/// collision that nobody wins.
pub fn overlap(
    line: &LineConfig,
    modulation: Modulation,
    level: f64,
    others: f64,
    strongest: f64,
) -> Result<f64, &'static str> {
    if others == f64::NEG_INFINITY {
        return Ok(level - line.noise_dbuv);
    }
    let snr = level - power_sum([line.noise_dbuv, others]);
    match line.capture_db {
        Some(c) if level - others >= c && snr >= required_snr(modulation) => Ok(snr),
        Some(c) if strongest - level >= c => Err("lost to a stronger frame"),
        _ => Err("collision"),
    }
}

/// Transmit level of a TX gain (0..31), dBµV: 1 dB a step below 100 dBµV
/// at full gain (model).
pub fn tx_level(gain: u8) -> f64 {
    100.0 - (31 - gain.min(31)) as f64
}

/// PGA a receiver settles at for a level, 0..15: more gain for weaker
/// signals, 4 dB a step (model).
pub fn pga(level_dbuv: f64) -> u8 {
    ((95.0 - level_dbuv) / 4.0).clamp(0.0, 15.0) as u8
}

/// What is on the line: one frame from one modem.
#[derive(Debug, Clone, PartialEq)]
pub struct Transmission {
    /// Sender node.
    pub from: usize,
    /// Start of the preamble.
    pub start: Instant,
    /// End of the unique word (the ZC delay is measured here).
    pub uw_end: Instant,
    /// End of the last byte.
    pub end: Instant,
    /// Frame modulation.
    pub modulation: Modulation,
    /// Carrier frequency, Hz.
    pub frequency: u32,
    /// TX gain used.
    pub gain: u8,
    /// FSK shape (bit rate code, deviation, unique word) when B-FSK.
    pub fsk: Option<FskShape>,
    /// The bytes after the unique word: PHY length, then the rest.
    pub psdu: Vec<u8>,
}

/// What an FSK receiver must match to lock onto a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FskShape {
    /// PHY_Config FSK bit rate code.
    pub bit_rate: u8,
    /// Deviation 1 (not 0.5).
    pub deviation_1: bool,
    /// 16-bit unique word (not 8-bit).
    pub unique_word_16: bool,
    /// The unique word (low byte only when 8-bit).
    pub unique_word: u16,
}

impl FskShape {
    /// The FSK settings of a PHY_Config.
    pub fn of(phy: &PhyConfig) -> Self {
        FskShape {
            bit_rate: phy.fsk_bit_rate,
            deviation_1: phy.fsk_deviation_1,
            unique_word_16: phy.fsk_unique_word_16,
            unique_word: if phy.fsk_unique_word_16 {
                phy.fsk_unique_word
            } else {
                phy.fsk_unique_word & 0xFF
            },
        }
    }
}

/// The channel on which a receiver configured by `phy` hears `tx`, if any
/// (Table 54: the high channel always, the low one in dual mode; each
/// channel demodulates PSK or FSK; FSK needs the same bit rate, deviation
/// and unique word).
pub fn channel_for(phy: &PhyConfig, tx: &Transmission) -> Option<Channel> {
    let near = |f: u32| f.abs_diff(tx.frequency) <= FREQUENCY_TOLERANCE;
    let fits = |psk: bool| match tx.fsk {
        None => psk,
        Some(shape) => !psk && shape == FskShape::of(phy),
    };
    if near(phy.high_frequency) && fits(phy.rx_high_psk) {
        Some(Channel::High)
    } else if phy.rx_mode_dual && near(phy.low_frequency) && fits(phy.rx_low_psk) {
        Some(Channel::Low)
    } else {
        None
    }
}

/// Signed ZC delay, 13 µs steps, of `at` against the mains zero crossings
/// of a node whose phase is shifted by `phase` µs: from the nearest
/// crossing, positive when `at` comes after it.
pub fn zc_delay(at: Instant, phase: Duration) -> i16 {
    let t = (at + MAINS_PERIOD - phase % MAINS_PERIOD) % MAINS_PERIOD;
    let d = if t > MAINS_PERIOD / 2 {
        t as i64 - MAINS_PERIOD as i64
    } else {
        t as i64
    };
    (d / ZC_STEP as i64) as i16
}

/// The first instant at or after `now` that is `delay` 13 µs steps past a
/// zero crossing of a node of `phase` (ZC-synchronised transmission).
pub fn next_zc_slot(now: Instant, phase: Duration, delay: i16) -> Instant {
    let offset = (phase as i64 + delay as i64 * ZC_STEP as i64).rem_euclid(MAINS_PERIOD as i64);
    let base = now - now % MAINS_PERIOD + offset as u64;
    if base >= now {
        base
    } else {
        base + MAINS_PERIOD
    }
}

/// Mains phase of node `n`: nodes sit on L1, L2, L3 in turn.
pub fn phase_of(node: usize) -> Duration {
    (node % 3) as Duration * MAINS_PERIOD / 3
}

/// Network period of MIB 06h (Table 58): the mains period in 13 µs steps.
pub fn network_period() -> u16 {
    (MAINS_PERIOD / ZC_STEP) as u16
}

#[cfg(test)]
mod tests {
    use super::*;
    use plm_core::st7580::mib::MibObject;

    fn phy() -> PhyConfig {
        match MibObject::factory_default(1) {
            Some(MibObject::PhyConfig(p)) => p,
            _ => unreachable!(),
        }
    }

    #[test]
    fn airtime_follows_the_bit_rates() {
        let p = phy();
        // 32-bit preamble + 32 sync bits at 9600 bps = 6666 µs.
        assert_eq!(airtime(Modulation::BPsk, &p, 0), 6_666);
        let b = airtime(Modulation::BPsk, &p, 100) - 6_666;
        let q = airtime(Modulation::QPsk, &p, 100) - 6_666;
        let e = airtime(Modulation::EightPsk, &p, 100) - 6_666;
        let c = airtime(Modulation::BPskCoded, &p, 100) - 6_666;
        assert_eq!((b, q, e, c), (83_334, 41_667, 27_778, 166_667));
        let fsk = FskShape::of(&p);
        assert!(fsk.bit_rate <= 3);
        assert_eq!(fsk_bit_rate(0), 1_200);
        assert_eq!(fsk_bit_rate(3), 9_600);
    }

    #[test]
    fn receivers_hear_only_their_channels() {
        let p = phy();
        let mut tx = Transmission {
            from: 0,
            start: 0,
            uw_end: 0,
            end: 0,
            modulation: Modulation::BPsk,
            frequency: p.high_frequency,
            gain: 21,
            fsk: None,
            psdu: vec![0],
        };
        assert_eq!(channel_for(&p, &tx), Some(Channel::High));
        tx.frequency = p.low_frequency;
        let dual = PhyConfig {
            rx_mode_dual: true,
            ..p
        };
        assert_eq!(channel_for(&dual, &tx), Some(Channel::Low));
        assert_eq!(
            channel_for(
                &PhyConfig {
                    rx_mode_dual: false,
                    ..p
                },
                &tx
            ),
            None
        );
        tx.fsk = Some(FskShape::of(&p));
        assert_eq!(channel_for(&dual, &tx), None, "PSK channels ignore FSK");
        let fsk_low = PhyConfig {
            rx_low_psk: false,
            ..dual
        };
        assert_eq!(channel_for(&fsk_low, &tx), Some(Channel::Low));
    }

    #[test]
    fn zero_crossing_delay_and_slots() {
        assert_eq!(zc_delay(130, 0), 10);
        assert_eq!(zc_delay(MAINS_PERIOD - 130, 0), -10);
        let slot = next_zc_slot(25_000, 0, 10);
        assert_eq!(slot, 40_130);
        assert_eq!(zc_delay(slot, 0), 10);
        assert_eq!(
            next_zc_slot(25_000, phase_of(1), 0) % MAINS_PERIOD,
            phase_of(1)
        );
    }
}
