//! What happens on the simulated line, in words: the Simulator view's
//! line log and the session's traffic notes.

use crate::numbers::{fixed, millis, seconds};
use plm_core::st7580::fields::MODULATIONS;
use plm_sim::LineEvent;

/// A line event in words.
pub fn describe(e: &LineEvent) -> String {
    match e {
        LineEvent::Sent {
            at,
            from,
            modulation,
            frequency,
            bytes,
            airtime,
        } => format!(
            "{}  node {from} sends {bytes} bytes, {} at {frequency} Hz, {} on the line",
            seconds(*at),
            MODULATIONS.get(modulation.bits() as usize).unwrap_or(&"?"),
            millis(*airtime)
        ),
        LineEvent::Heard {
            at,
            from,
            to,
            snr_db,
            corrupted,
        } => format!(
            "{}  node {to} hears node {from}, SNR {} dB{}",
            seconds(*at),
            fixed(*snr_db, 1),
            if *corrupted {
                ", with a corrupted byte"
            } else {
                ""
            }
        ),
        LineEvent::Missed { at, from, to, why } => {
            format!("{}  node {to} misses node {from}: {why}", seconds(*at))
        }
    }
}
