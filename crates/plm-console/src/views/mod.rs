//! The views: small components, one concern each. They read the stores
//! of [`crate::stores::Console`] and send requests through it; none of
//! them parses a byte (plm-core does).

pub mod connection_bar;
pub mod data;
pub mod diagnostics;
pub mod files;
pub mod lamp;
pub mod modem;
pub mod serial_port;
pub mod simulator;
pub mod snr_plot;
pub mod street;
pub mod traffic;

use plm_core::time::Instant;

/// A time on the transport's clock as seconds with µs (`12.345678 s`).
pub fn seconds(at: Instant) -> String {
    format!("{}.{:06} s", at / 1_000_000, at % 1_000_000)
}

/// A duration as milliseconds (`3.2 ms`).
pub fn millis(us: u64) -> String {
    format!("{:.1} ms", us as f64 / 1_000.0)
}

/// Lowercase hex as spaced byte pairs (`02 00 2c`).
pub fn spaced(hex: &str) -> String {
    let mut s = String::with_capacity(hex.len() * 3 / 2);
    for (i, c) in hex.chars().enumerate() {
        if i > 0 && i % 2 == 0 {
            s.push(' ');
        }
        s.push(c);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        assert_eq!(seconds(12_000_345), "12.000345 s");
        assert_eq!(millis(3_249), "3.2 ms");
        assert_eq!(spaced("02002c"), "02 00 2c");
    }
}
