//! How the lamps of a simulated street differ: one description, drawn
//! from the street's seed, that [`crate::Sim`] applies to its boards'
//! ballasts ([`StreetProfile::shape`]) and to its line
//! ([`StreetProfile::weak_lamp`]).
//!
//! - [`StreetProfile::Uniform`]: every lamp alike (150 W, 100 V lamp,
//!   400 V bus, 230 V mains, 25 °C around it, nothing fails unless asked):
//!   for tests and benches that count exact values.
//! - [`StreetProfile::Realistic`]: a street that behaves like one, the
//!   demo's (the console's simulated street, `plm sim --street N`).
//!   Every number is a model choice (the board manual gives no lamp
//!   rating: lamp power is a 16-bit reading in W, UM Appendix A):
//!   - rated power one of [`RATINGS`], the high-pressure sodium lamps of
//!     street lighting, each with its arc voltage;
//!   - an age in lifetime hours uniform below [`MAX_AGE_HOURS`] (four
//!     years of nights at about 4 000 hours a year), a start each night
//!     of [`NIGHT_HOURS`]; the age shows in the lamp's voltage and power
//!     (the ballast's "Age");
//!   - the PFC's bus set point 400 V ± [`BUS_TOLERANCE`] (parts'
//!     tolerance);
//!   - the mains 230 V less the feeder's drop, growing along the street
//!     to [`FEEDER_DROP`] at the far end, with the street's slow drift and
//!     each ballast's noise (the ballast's "Supply voltage");
//!   - the ambient following the night ([`crate::ballast::NIGHT_AMBIENT`];
//!     virtual time 0 is midnight), the board's temperature following its
//!     lamp's power with its lag;
//!   - one worn lamp (never the far one), [`WORN_HOURS`] old, whose arc
//!     gives out [`END_OF_LIFE_AT`] ± [`END_OF_LIFE_JITTER`] into the
//!     simulation: about two minutes into the demo it is in FAILURE, and
//!     stays there until repaired;
//!   - the far lamp (the last node) behind a poor connection whose extra
//!     loss leaves its link to the concentrator at [`WEAK_SNR_DB`] at the
//!     factory TX gain: 3 dB above what B-PSK needs, so it still answers
//!     (and discovery finds it) but loses the collisions it meets and
//!     fails a faster modulation.

use crate::ballast::{BallastConfig, PFC_BUS_VOLTAGE, SUPPLY_VOLTAGE};
use crate::line::{tx_level, LineConfig};
use crate::rng::Rng;
use plm_core::st7580::mib::MibObject;
use plm_core::time::{Duration, Instant, MS};

/// Microseconds in one second.
const SECOND: Duration = 1_000 * MS;

/// Model choice: the lamps a street is made of, (rated power W, arc
/// voltage V in RUN when new): 70, 100, 150 and 250 W high-pressure
/// sodium.
pub const RATINGS: [(u16, f64); 4] = [(70, 90.0), (100, 100.0), (150, 100.0), (250, 100.0)];
/// Model choice: the oldest lamp of a street at work, lifetime hours.
pub const MAX_AGE_HOURS: u64 = 16_000;
/// Model choice: the hours of a night's burning (one start a night).
pub const NIGHT_HOURS: u16 = 11;
/// Model choice: the worn lamp's age, lifetime hours (from, to): an HPS
/// lamp's rated life is about 24 000 hours.
pub const WORN_HOURS: (u64, u64) = (22_000, 24_000);
/// Model choice: when the worn lamp's arc gives out, from the start.
pub const END_OF_LIFE_AT: Instant = 120 * SECOND;
/// Model choice: ± this around [`END_OF_LIFE_AT`], drawn from the seed.
pub const END_OF_LIFE_JITTER: Duration = 10 * SECOND;
/// Model choice: the PFC's set points differ by up to ± this, V.
pub const BUS_TOLERANCE: u16 = 4;
/// Model choice: the drop of the mains along the street's feeder at its
/// far end, V (under the 3-5 % a feeder is designed to).
pub const FEEDER_DROP: f64 = 8.0;
/// Model choice: the far lamp's SNR at the concentrator, dB: B-PSK needs
/// 4 (`line::required_snr`), and within 3 dB of that the line corrupts a
/// frame in three; at 7 dB the lamp is the street's weakest and still
/// answers every time.
pub const WEAK_SNR_DB: f64 = 7.0;

/// How the lamps of a street differ (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StreetProfile {
    /// Every lamp alike.
    #[default]
    Uniform,
    /// A street that behaves like one.
    Realistic,
}

impl StreetProfile {
    /// Gives the ballast of `node` (1..=`lamps`) of the street of `seed`
    /// its lamp, age, bus, mains and surroundings (nothing for
    /// [`StreetProfile::Uniform`]). The ballast's own seed (its failures,
    /// its noise) is left as it is.
    pub fn shape(self, seed: u64, node: usize, lamps: usize, b: &mut BallastConfig) {
        if self == StreetProfile::Uniform {
            return;
        }
        let mut r = Rng::new(mix(seed, 0x6C61_6D70, node as u64));
        let (watts, volts) = RATINGS[r.below(RATINGS.len() as u64) as usize];
        let worn = self.worn_lamp(seed, lamps) == Some(node);
        let hours = match worn {
            true => WORN_HOURS.0 + r.below(WORN_HOURS.1 - WORN_HOURS.0),
            false => r.below(MAX_AGE_HOURS),
        } as u16;
        let spread = u64::from(2 * BUS_TOLERANCE + 1);
        *b = BallastConfig {
            rated_power_w: watts,
            lamp_voltage: volts,
            ages: true,
            lifetime_hours: hours,
            power_ons: hours / NIGHT_HOURS + 1,
            bus_voltage: PFC_BUS_VOLTAGE - BUS_TOLERANCE + r.below(spread) as u16,
            supply_voltage: f64::from(SUPPLY_VOLTAGE)
                - FEEDER_DROP * node as f64 / lamps.max(1) as f64,
            supply_drift: Some(mix(seed, 0x6D61_696E, 0)),
            night: true,
            end_of_life: worn
                .then(|| END_OF_LIFE_AT - END_OF_LIFE_JITTER + r.below(2 * END_OF_LIFE_JITTER + 1)),
            ..b.clone()
        };
    }

    /// The node of the worn lamp of a street of `lamps` (never the far
    /// one; none on a street of one lamp).
    pub fn worn_lamp(self, seed: u64, lamps: usize) -> Option<usize> {
        (self == StreetProfile::Realistic && lamps >= 2)
            .then(|| 1 + Rng::new(mix(seed, 0x776F_726E, 0)).below(lamps as u64 - 1) as usize)
    }

    /// The far lamp and the extra loss of its connection to `line`, dB
    /// (`line::LineConfig::node_loss_db`), that leaves its link to the
    /// concentrator (node 0) at the factory TX gain at [`WEAK_SNR_DB`]
    /// (to a tenth of a dB above, never below).
    pub fn weak_lamp(self, lamps: usize, line: &LineConfig) -> Option<(usize, f64)> {
        if self == StreetProfile::Uniform || lamps == 0 {
            return None;
        }
        let gain = match MibObject::factory_default(1) {
            Some(MibObject::PhyConfig(p)) => p.tx_gain,
            _ => 0,
        };
        let snr = tx_level(gain) - line.attenuation(0, lamps) - line.noise_dbuv;
        let tenths = ((snr - WEAK_SNR_DB) * 10.0 - 0.5).floor();
        Some((lamps, tenths.max(0.0) / 10.0))
    }
}

/// A seed of its own for one use (`salt`) and one item of the street.
fn mix(seed: u64, salt: u64, item: u64) -> u64 {
    Rng::new(seed ^ salt.rotate_left(32) ^ item.wrapping_mul(0x9E37_79B9_7F4A_7C15)).next_u64()
}
