//! The application frames' CRC-16 (STEVAL-IHP007V1 UM, Appendix C).
//!
//! The seed gives the polynomial X^16 + X^15 + X^2 + 1 and a table-driven
//! `CalcCRC16` that starts at 0 and shifts right: that is the catalogue
//! algorithm CRC-16/ARC (reflected polynomial A001h, init 0, no final XOR,
//! check value BB3Dh). The seed's printed table has 14 wrong entries; the
//! polynomial wins (docs/protocol-notes.md, "STEVAL-IHP007V1").

use crate::CrcImpl;
use crc::{Crc, CRC_16_ARC};

const ARC: Crc<u16, CrcImpl> = Crc::<u16, CrcImpl>::new(&CRC_16_ARC);

/// CRC-16 of `bytes` as `CalcCRC16` computes it.
pub fn crc16(bytes: &[u8]) -> u16 {
    ARC.checksum(bytes)
}

/// The entries of the seed's `TableCRC16` that disagree with the
/// polynomial (index, as printed): kept so that a test shows them.
pub const SEED_TABLE_TYPOS: &[(u8, u16)] = &[
    (0x15, 0xCF41),
    (0x25, 0xDB41),
    (0x29, 0xDE41),
    (0x3D, 0xD141),
    (0x45, 0xF341),
    (0x5D, 0xF941),
    (0x6D, 0xED41),
    (0x75, 0xE741),
    (0x85, 0xA341),
    (0x9D, 0xA941),
    (0xB5, 0xB741),
    (0xDD, 0x99C0),
    (0xDE, 0x9880),
    (0xFD, 0x8141),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_check_value() {
        assert_eq!(crc16(b"123456789"), 0xBB3D);
        assert_eq!(crc16(&[]), 0);
    }
}
