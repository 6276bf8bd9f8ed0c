//! ST7580 power line frames (UM0932 2.2-2.4): the PHY, DL and SS frame
//! structures of Figures 2-4 and Tables 2-4, with the DL CRC options of
//! MIB 00h (Table 53) and the SS security service (AES-128 CTR + AES-CMAC).
//!
//! The seed leaves the CRC polynomials and the AES-CTR counter block open;
//! the choices are in `docs/protocol-notes.md`, "Power line frames". The
//! simulated modem and the console both use this module, so they agree.
//!
//! Nothing here panics: every malformed input is an error.

use super::mib::ModemConfig;
use crate::CrcImpl;
use aes::Aes128;
use alloc::vec::Vec;
use cmac::{Cmac, Mac};
use core::fmt;
use crc::{Crc, CRC_16_IBM_3740, CRC_32_ISO_HDLC, CRC_8_SMBUS};
use ctr::cipher::{KeyIvInit, StreamCipher};

/// Largest value of the PHY length byte (UM0932 Table 2).
pub const MAX_LENGTH: usize = 255;

const CRC8: Crc<u8, CrcImpl> = Crc::<u8, CrcImpl>::new(&CRC_8_SMBUS);
const CRC16: Crc<u16, CrcImpl> = Crc::<u16, CrcImpl>::new(&CRC_16_IBM_3740);
const CRC32: Crc<u32, CrcImpl> = Crc::<u32, CrcImpl>::new(&CRC_32_ISO_HDLC);

/// The DL CRC of MIB 00h bits 3-4 (UM0932 Table 53; algorithms per
/// `docs/protocol-notes.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum DlCrc {
    /// Code 0: 1 byte, CRC-8/SMBUS (poly 07h).
    Crc8,
    /// Code 1: 2 bytes big endian, CRC-16/IBM-3740 (CCITT-FALSE).
    Crc16Be,
    /// Code 2: 4 bytes little endian, CRC-32/ISO-HDLC (Ethernet). The
    /// factory default of MIB 00h (Table 53).
    #[default]
    Crc32Le,
    /// Code 3: 4 bytes big endian, CRC-32/ISO-HDLC (Ethernet).
    Crc32Be,
}

impl DlCrc {
    /// The option of a 2-bit CRC length code (Table 53); higher bits are
    /// ignored.
    pub fn from_code(code: u8) -> DlCrc {
        match code & 3 {
            0 => DlCrc::Crc8,
            1 => DlCrc::Crc16Be,
            2 => DlCrc::Crc32Le,
            _ => DlCrc::Crc32Be,
        }
    }

    /// The 2-bit CRC length code of MIB 00h (Table 53).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// Length of the CRC field in bytes: 1, 2 or 4 (Table 3).
    #[allow(clippy::len_without_is_empty)] // never empty
    pub fn len(self) -> usize {
        match self {
            DlCrc::Crc8 => 1,
            DlCrc::Crc16Be => 2,
            DlCrc::Crc32Le | DlCrc::Crc32Be => 4,
        }
    }
}

/// How DL (and SS) frames are checked: MIB 00h bits 3-4 and 6 (Table 53).
/// The default is the factory default of MIB 00h.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct DlOptions {
    /// CRC algorithm, length and byte order.
    pub crc: DlCrc,
    /// "DL CRC on PHY length": the CRC also covers the PHY length byte,
    /// which precedes the payload in the calculation.
    pub crc_on_phy_length: bool,
}

impl DlOptions {
    /// The options configured in MIB 00h (Table 53).
    pub fn from_modem_config(c: &ModemConfig) -> Self {
        DlOptions {
            crc: DlCrc::from_code(c.crc_length),
            crc_on_phy_length: c.dl_crc_on_phy_length,
        }
    }

    /// The CRC field for `payload` in a frame whose PHY length byte is
    /// `phy_length` (Figure 3), in the option's byte order.
    pub fn crc(&self, phy_length: u8, payload: &[u8]) -> Vec<u8> {
        let len = [phy_length];
        let prefix: &[u8] = if self.crc_on_phy_length { &len } else { &[] };
        match self.crc {
            DlCrc::Crc8 => {
                let mut d = CRC8.digest();
                d.update(prefix);
                d.update(payload);
                [d.finalize()].to_vec()
            }
            DlCrc::Crc16Be => {
                let mut d = CRC16.digest();
                d.update(prefix);
                d.update(payload);
                d.finalize().to_be_bytes().to_vec()
            }
            DlCrc::Crc32Le | DlCrc::Crc32Be => {
                let mut d = CRC32.digest();
                d.update(prefix);
                d.update(payload);
                let v = d.finalize();
                if self.crc == DlCrc::Crc32Le {
                    v.to_le_bytes().to_vec()
                } else {
                    v.to_be_bytes().to_vec()
                }
            }
        }
    }
}

/// A power line frame that cannot be built or opened (UM0932 2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PlcError {
    /// The frame's length field would exceed its maximum (Tables 2-4).
    TooLong {
        /// Bytes asked for.
        len: usize,
        /// Largest allowed.
        max: usize,
    },
    /// No PHY length byte (Table 2).
    Empty,
    /// The PHY length byte disagrees with the bytes that follow it.
    LengthMismatch {
        /// Value of the length byte.
        declared: usize,
        /// Bytes after it.
        got: usize,
    },
    /// A DL frame shorter than its CRC field (Table 3).
    TooShortForCrc {
        /// DL length.
        len: usize,
        /// CRC length of the configured option.
        crc_len: usize,
    },
    /// An SS header longer than the user data (Table 4).
    HeaderTooLong {
        /// Header length asked for.
        header_len: usize,
        /// Header and payload bytes given.
        len: usize,
    },
}

impl fmt::Display for PlcError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlcError::TooLong { len, max } => {
                write!(f, "{len} bytes do not fit a frame of at most {max}")
            }
            PlcError::Empty => f.write_str("no PHY length byte"),
            PlcError::LengthMismatch { declared, got } => write!(
                f,
                "the length byte says {declared} bytes but {got} follow it"
            ),
            PlcError::TooShortForCrc { len, crc_len } => write!(
                f,
                "a DL frame of {len} bytes cannot hold a {crc_len}-byte CRC"
            ),
            PlcError::HeaderTooLong { header_len, len } => write!(
                f,
                "header length {header_len} exceeds the {len} bytes of user data"
            ),
        }
    }
}

/// The PHY frame bytes after preamble and unique word: the length byte and
/// the payload (Figure 2, Table 2).
pub fn phy_frame(payload: &[u8]) -> Result<Vec<u8>, PlcError> {
    let len = u8::try_from(payload.len()).map_err(|_| PlcError::TooLong {
        len: payload.len(),
        max: MAX_LENGTH,
    })?;
    let mut out = Vec::with_capacity(payload.len() + 1);
    out.push(len);
    out.extend_from_slice(payload);
    Ok(out)
}

/// The payload of a PHY frame (Table 2); the length byte must match.
pub fn phy_open(psdu: &[u8]) -> Result<&[u8], PlcError> {
    let (&len, payload) = psdu.split_first().ok_or(PlcError::Empty)?;
    if payload.len() != len as usize {
        return Err(PlcError::LengthMismatch {
            declared: len as usize,
            got: payload.len(),
        });
    }
    Ok(payload)
}

/// A DL frame: PHY length (payload + CRC), payload, CRC (Figure 3, Table 3).
pub fn dl_frame(opts: &DlOptions, payload: &[u8]) -> Result<Vec<u8>, PlcError> {
    let max = MAX_LENGTH - opts.crc.len();
    if payload.len() > max {
        return Err(PlcError::TooLong {
            len: payload.len(),
            max,
        });
    }
    let len = (payload.len() + opts.crc.len()) as u8;
    let mut out = phy_frame(payload)?;
    out[0] = len;
    out.extend(opts.crc(len, payload));
    Ok(out)
}

/// A DL frame received from the power line (UM0932 2.4).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum DlReceived {
    /// The CRC is right: a DL_DataIndication.
    Good {
        /// DL payload.
        payload: Vec<u8>,
    },
    /// The CRC is wrong: a DL_SnifferIndication when the sniffer is on.
    WrongCrc {
        /// DL payload.
        payload: Vec<u8>,
        /// The CRC field as received.
        crc: Vec<u8>,
    },
}

/// Opens a DL frame (Table 3) and checks its CRC.
pub fn dl_open(opts: &DlOptions, psdu: &[u8]) -> Result<DlReceived, PlcError> {
    let body = phy_open(psdu)?;
    let crc_len = opts.crc.len();
    if body.len() < crc_len {
        return Err(PlcError::TooShortForCrc {
            len: body.len(),
            crc_len,
        });
    }
    let (payload, crc) = body.split_at(body.len() - crc_len);
    Ok(check_crc(opts, psdu[0], payload, crc))
}

fn check_crc(opts: &DlOptions, phy_length: u8, payload: &[u8], crc: &[u8]) -> DlReceived {
    let payload = payload.to_vec();
    if opts.crc(phy_length, &payload) == crc {
        DlReceived::Good { payload }
    } else {
        DlReceived::WrongCrc {
            payload,
            crc: crc.to_vec(),
        }
    }
}

/// An SS frame around an SS_SDU ([`ss_seal`]): the PHY length byte counts
/// the SS_SDU only, then the DL CRC of MIB 00h follows, uncounted. Table 4
/// gives the encrypted payload `LEN-29-HL` bytes, so LEN (the frame's
/// length) holds header, payload, IV, HL and digest and no CRC; and Tables
/// 45 and 48 allow 226 bytes of header and payload, 255 with the 29, with
/// every CRC length. See `docs/protocol-notes.md`.
pub fn ss_frame(opts: &DlOptions, sdu: &[u8]) -> Result<Vec<u8>, PlcError> {
    let mut out = phy_frame(sdu)?;
    out.extend(opts.crc(out[0], sdu));
    Ok(out)
}

/// Opens an SS frame ([`ss_frame`]): the SS_SDU its length byte announces,
/// then the CRC, which is checked.
pub fn ss_frame_open(opts: &DlOptions, psdu: &[u8]) -> Result<DlReceived, PlcError> {
    let (&len, rest) = psdu.split_first().ok_or(PlcError::Empty)?;
    let declared = len as usize + opts.crc.len();
    if rest.len() != declared {
        return Err(PlcError::LengthMismatch {
            declared,
            got: rest.len(),
        });
    }
    let (sdu, crc) = rest.split_at(len as usize);
    Ok(check_crc(opts, len, sdu, crc))
}

/// Length of the AES-CTR initialization vector of an SS frame (Table 4).
pub const IV_LEN: usize = 12;
/// Length of the AES-CMAC digest of an SS frame (Table 4).
pub const DIGEST_LEN: usize = 16;
/// Bytes an SS frame adds to the user data: IV, HL and digest (Table 4).
pub const SS_OVERHEAD: usize = IV_LEN + 1 + DIGEST_LEN;

/// AES-128 in counter mode (NIST SP 800-38A) from `counter_block`, whose
/// low 32 bits count big endian and wrap (GCM's inc32). XORs the key
/// stream into `data`; applying it twice gives the data back.
pub fn ctr_apply(key: &[u8; 16], counter_block: &[u8; 16], data: &mut [u8]) {
    // Chunks keep each cipher well inside its 2^32-block limit, so the
    // crate never panics; the counter of each chunk continues the last one.
    const CHUNK_BLOCKS: u32 = 1 << 12;
    let start = u32::from_be_bytes([
        counter_block[12],
        counter_block[13],
        counter_block[14],
        counter_block[15],
    ]);
    for (i, chunk) in data.chunks_mut(CHUNK_BLOCKS as usize * 16).enumerate() {
        let mut block = *counter_block;
        let ctr = start.wrapping_add((i as u32).wrapping_mul(CHUNK_BLOCKS));
        block[12..].copy_from_slice(&ctr.to_be_bytes());
        ctr::Ctr32BE::<Aes128>::new(key.into(), &block.into()).apply_keystream(chunk);
    }
}

/// AES-CMAC (RFC 4493), full 16-byte tag, over the concatenation of
/// `parts`.
pub fn cmac(key: &[u8; 16], parts: &[&[u8]]) -> [u8; 16] {
    mac(key, parts).finalize().into_bytes().into()
}

fn mac(key: &[u8; 16], parts: &[&[u8]]) -> Cmac<Aes128> {
    let mut m = <Cmac<Aes128> as Mac>::new(key.into());
    for p in parts {
        m.update(p);
    }
    m
}

/// The SS counter block: IV || 00000001h (see protocol notes).
fn counter_block(iv: &[u8; IV_LEN]) -> [u8; 16] {
    let mut block = [0u8; 16];
    block[..IV_LEN].copy_from_slice(iv);
    block[15] = 1;
    block
}

/// The SS_SDU of UM0932 Figure 4, Table 4: header (clear) | encrypted
/// payload | IV | HL | digest. `header_and_payload` is the user data of
/// SS_DataRequest (Table 45), its first `header_len` bytes the header.
/// The SDU still needs its frame ([`ss_frame`]) around it.
pub fn ss_seal(
    key: &[u8; 16],
    iv: &[u8; IV_LEN],
    header_len: usize,
    header_and_payload: &[u8],
) -> Result<Vec<u8>, PlcError> {
    let len = header_and_payload.len();
    let max = MAX_LENGTH - SS_OVERHEAD;
    if len > max {
        return Err(PlcError::TooLong { len, max });
    }
    if header_len > len {
        return Err(PlcError::HeaderTooLong { header_len, len });
    }
    let mut sdu = Vec::with_capacity(len + SS_OVERHEAD);
    sdu.extend_from_slice(header_and_payload);
    ctr_apply(key, &counter_block(iv), &mut sdu[header_len..]);
    sdu.extend_from_slice(iv);
    sdu.push(header_len as u8);
    let digest = cmac(key, &[&sdu]);
    sdu.extend_from_slice(&digest);
    Ok(sdu)
}

/// Why an SS_SDU is not delivered. Each counts as failed authentication:
/// the modem reports the SDU in an SS_SnifferIndication when the sniffer is
/// on (UM0932 2.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SsError {
    /// Shorter than IV, HL and digest (29 bytes).
    TooShort,
    /// The digest matches but HL is larger than the bytes before the IV.
    BadHeaderLength,
    /// The digest does not match.
    Authentication,
}

impl fmt::Display for SsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SsError::TooShort => "SS frame shorter than its 29 bytes of IV, HL and digest",
            SsError::BadHeaderLength => "SS header length exceeds the frame",
            SsError::Authentication => "SS digest does not match (wrong key or corrupted)",
        })
    }
}

/// Verifies the digest of an SS_SDU (Table 4) in constant time, then
/// decrypts it: returns header || plaintext payload.
pub fn ss_open(key: &[u8; 16], sdu: &[u8]) -> Result<Vec<u8>, SsError> {
    let data_len = sdu
        .len()
        .checked_sub(SS_OVERHEAD)
        .ok_or(SsError::TooShort)?;
    let (signed, digest) = sdu.split_at(sdu.len() - DIGEST_LEN);
    // The digest covers HL, so a corrupted HL fails here first.
    mac(key, &[signed])
        .verify_slice(digest)
        .map_err(|_| SsError::Authentication)?;
    let header_len = signed[signed.len() - 1] as usize;
    if header_len > data_len {
        return Err(SsError::BadHeaderLength);
    }
    let mut iv = [0u8; IV_LEN];
    iv.copy_from_slice(&signed[data_len..data_len + IV_LEN]);
    let mut out = signed[..data_len].to_vec();
    ctr_apply(key, &counter_block(&iv), &mut out[header_len..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_codes_round_trip_and_lengths() {
        for code in 0..4 {
            assert_eq!(DlCrc::from_code(code).code(), code);
        }
        assert_eq!(DlCrc::from_code(0b110), DlCrc::Crc32Le);
        let lens: Vec<usize> = (0..4).map(|c| DlCrc::from_code(c).len()).collect();
        assert_eq!(lens, [1, 2, 4, 4]);
    }

    #[test]
    fn ctr_chunks_continue_one_key_stream() {
        let key = [7u8; 16];
        let mut cb = [9u8; 16];
        cb[12..].copy_from_slice(&0xFFFF_FFF0u32.to_be_bytes());
        let mut chunked = alloc::vec![0u8; 3 * (1 << 12) * 16 + 5];
        let mut whole = chunked.clone();
        ctr_apply(&key, &cb, &mut chunked);
        ctr::Ctr32BE::<Aes128>::new(&key.into(), &cb.into()).apply_keystream(&mut whole);
        assert_eq!(chunked, whole);
    }

    #[test]
    fn an_ss_frame_of_226_bytes_fits_with_every_crc() {
        // UM0932 Tables 45 and 48: up to 226 bytes of header and payload.
        let key = [3u8; 16];
        let data: Vec<u8> = (0..226u32).map(|i| i as u8).collect();
        let sdu = ss_seal(&key, &[1; IV_LEN], 4, &data).unwrap();
        assert_eq!(sdu.len(), MAX_LENGTH);
        for code in 0..4 {
            let opts = DlOptions {
                crc: DlCrc::from_code(code),
                crc_on_phy_length: code == 3,
            };
            let psdu = ss_frame(&opts, &sdu).unwrap();
            assert_eq!(psdu[0], 255, "the length counts the SS_SDU only");
            assert_eq!(psdu.len(), 1 + 255 + opts.crc.len());
            let Ok(DlReceived::Good { payload }) = ss_frame_open(&opts, &psdu) else {
                panic!("CRC code {code}");
            };
            assert_eq!(ss_open(&key, &payload).unwrap(), data);
            let mut bad = psdu.clone();
            bad[10] ^= 1;
            assert!(matches!(
                ss_frame_open(&opts, &bad),
                Ok(DlReceived::WrongCrc { .. })
            ));
            assert!(ss_frame_open(&opts, &psdu[..psdu.len() - 1]).is_err());
        }
    }
}
