//! The IEC 61334-5-1 long MAC frame on the line (ST7570 UM 4.4; its
//! Figures 10-11 are lost, the layout follows the standard as public
//! implementations encode it: `docs/protocol-notes.md`, "ST7570: MAC and
//! PHY frames on the line").
//!
//! ```text
//! long MAC frame, 36·NS bytes (NS = 1..7):
//!   NS (2) | CREDIT (1) | ADDRESS (3) | PAD (1) | M_sdu (1..242) | pad (PAD) | FCS (3)
//! MAC subframe (M_pdu = P_sdu), 38 bytes:
//!   FI (2) | the next 36 bytes of the long frame
//! ```
//!
//! CREDIT, ADDRESS and PAD are the bytes of Table 38 ([`mac_data`]), two
//! bytes further on. Two levels, after smoltcp: [`LongFrame`] is a checked
//! view over the bytes (it also shows a frame whose FCS is wrong, and says
//! which of the known [`FcsForm`]s it carries), and [`MacFrame`] the
//! validated typed frame with `parse` and `emit`. Nothing here panics on
//! any input.

use super::fields::{mac_data, P_SDU_LEN};
use super::types::{Address, Credit};
use crate::field::Field;
use crate::CrcImpl;
use alloc::vec::Vec;
use core::fmt;
use crc::{Algorithm, Crc};

/// Bytes of one MAC subframe, the P_sdu of a PHY frame (3.2, 4.4).
pub const SUBFRAME_LEN: usize = P_SDU_LEN;
/// Bytes of the long frame each subframe carries after its FI.
pub const CHUNK_LEN: usize = SUBFRAME_LEN - 2;
/// Most subframes (time slots) of one long MAC frame (4.4).
pub const MAX_SUBFRAMES: usize = 7;
/// Longest M_sdu (4.4: "from 1 up to 242 bytes").
pub const MAX_M_SDU: usize = 242;
/// Bytes before M_sdu: NS, CREDIT, ADDRESS, PAD.
pub const HEADER_LEN: usize = 7;
/// Bytes of the FCS (4.4: "24 bit CRC").
pub const FCS_LEN: usize = 3;
/// FI of a subframe of a long MAC frame (4.4; MIB 0012h default).
pub const LONG_MAC_FRAME: u16 = 0x0000;

/// NS of 1..7 subframes: the seven non-zero words of the [7,3,4] simplex
/// code (any two differ in 4 bits), the byte sent twice.
const NS_CODES: [u8; MAX_SUBFRAMES] = [0x6C, 0x3A, 0x56, 0x71, 0x1D, 0x4B, 0x27];

/// The FCS: CRC-24 with the IEC 61334-5-1 generator polynomial
/// x^24+x^22+x^20+x^19+x^18+x^16+x^14+x^13+x^11+x^10+x^8+x^7+x^6+x^3+x+1
/// (5D6DCBh, the FlexRay polynomial), register starting at 0, MSBit
/// first, no final XOR. Sent MSByte first (3.2).
pub const FCS_ALGORITHM: Algorithm<u32> = Algorithm {
    width: 24,
    poly: 0x5D_6DCB,
    init: 0,
    refin: false,
    refout: false,
    xorout: 0,
    check: 0xB0_C390,
    residue: 0,
};
const FCS: Crc<u32, CrcImpl> = Crc::<u32, CrcImpl>::new(&FCS_ALGORITHM);

/// The FCS of `bytes` (in a long frame: CREDIT up to the last pad byte).
pub fn fcs(bytes: &[u8]) -> u32 {
    FCS.checksum(bytes)
}

/// The FCS of `bytes` in Gurux's register form: the remainder of the
/// message itself (not of message·x^24) by the same polynomial, its 24
/// bits reversed; sent MSByte first like ours. No CRC catalogue lists it
/// (docs/protocol-notes.md, "ST7570: MAC and PHY frames on the line").
pub fn gurux_fcs(bytes: &[u8]) -> u32 {
    let mut r: u32 = 0;
    for b in bytes {
        for i in (0..8).rev() {
            let out = r >> 23 & 1;
            r = (r << 1 | (*b as u32 >> i & 1)) & 0xFF_FFFF;
            if out == 1 {
                r ^= FCS_ALGORITHM.poly;
            }
        }
    }
    r.reverse_bits() >> 8
}

/// The forms of FCS a long frame on the line may carry: the two
/// IEC 61334-5-1 encoders known write different ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FcsForm {
    /// [`fcs`] over CREDIT up to the last pad byte: the catalogue CRC-24
    /// this project sends, and the only form its simulated modems accept.
    Catalogue,
    /// [`gurux_fcs`] over the same bytes: what Gurux's C and C# writers
    /// send (their pad count is spent by the loop that writes the pad
    /// bytes before the FCS length is taken).
    Gurux,
    /// [`gurux_fcs`] over CREDIT up to the last M_sdu byte, the pad bytes
    /// left out, as Gurux's writer's FCS length reads. The same as
    /// [`FcsForm::Gurux`] for a frame without pad bytes.
    GuruxWithoutPad,
}

impl FcsForm {
    /// Its name in `plm decode` output.
    pub fn name(self) -> &'static str {
        match self {
            FcsForm::Catalogue => "catalogue",
            FcsForm::Gurux => "gurux",
            FcsForm::GuruxWithoutPad => "gurux_without_pad",
        }
    }
}

/// The field layout of a long MAC frame's header, for decoders and forms.
pub mod fields {
    use super::*;
    /// NS, the number of subframes as its 2-byte code ([`ns_count`]).
    pub const NS: Field = Field::bytes("ns", "NS", 0, 2);
    /// Initial credit (4.8.1).
    pub const IC: Field = mac_data::IC.shifted(2);
    /// Current credit (4.8.2).
    pub const CC: Field = mac_data::CC.shifted(2);
    /// Delta credit (4.8.3).
    pub const DC: Field = mac_data::DC.shifted(2);
    /// Source address (4.5).
    pub const SA: Field = mac_data::SA.shifted(2);
    /// Destination address (4.5).
    pub const DA: Field = mac_data::DA.shifted(2);
    /// Number of pad bytes between M_sdu and FCS (Table 38's PAD).
    pub const PAD: Field = mac_data::PAD.shifted(2);
    /// The header after NS, named as in Table 38.
    pub const HEADER: &[Field] = &[IC, CC, DC, SA, DA, PAD];
    /// FI at the start of every subframe (4.4, MIB 0012h), MSByte first.
    pub const FI: Field = Field::uint("fi", "FI", 0, 2);
}

/// The number of subframes a 2-byte NS field says, if it is one of the
/// seven codes.
pub fn ns_count(code: [u8; 2]) -> Option<usize> {
    let i = NS_CODES.iter().position(|c| *c == code[0])?;
    (code[1] == code[0]).then_some(i + 1)
}

/// The NS field of `count` subframes (1..=7).
pub fn ns_code(count: usize) -> Option<[u8; 2]> {
    let c = *NS_CODES.get(count.checked_sub(1)?)?;
    Some([c, c])
}

/// Subframes a long frame with an M_sdu of `len` bytes takes.
pub fn subframes_for(len: usize) -> usize {
    (HEADER_LEN + len + FCS_LEN).div_ceil(CHUNK_LEN)
}

/// Why bytes are not a MAC frame, subframes or PHY frames, in words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MacError {
    /// An M_sdu outside 1..=242 bytes.
    MsduLength(usize),
    /// A long frame whose length is not 36·NS bytes for NS in 1..=7.
    FrameLength(usize),
    /// An NS field that is not the code of 1..7 subframes.
    Ns([u8; 2]),
    /// NS and the length disagree.
    NsLength {
        /// Subframes NS says.
        ns: usize,
        /// Bytes of the long frame.
        len: usize,
    },
    /// A PAD that leaves no M_sdu or would fill a whole subframe.
    Pad {
        /// PAD as received.
        pad: u8,
        /// Subframes NS says.
        ns: usize,
    },
    /// The FCS received is not the FCS of the frame.
    Fcs {
        /// As received.
        received: u32,
        /// As computed.
        computed: u32,
    },
    /// The FCS received is none of the known forms' ([`FcsForm`]).
    FcsForms {
        /// As received.
        received: u32,
        /// The catalogue form's.
        catalogue: u32,
        /// Gurux's, over the pad bytes.
        gurux: u32,
        /// Gurux's without the pad bytes, when there are any.
        gurux_without_pad: Option<u32>,
    },
    /// Subframes whose bytes are not a whole number of 38-byte subframes.
    SubframeLength(usize),
    /// A number of subframes outside 1..=7.
    SubframeCount(usize),
    /// Subframes of one frame with different FIs.
    Fi {
        /// Index of the subframe (0 = first).
        index: usize,
        /// Its FI.
        fi: u16,
        /// The first subframe's FI.
        first: u16,
    },
    /// PHY frames whose bytes are not a whole number of 45-byte frames.
    PhyLength(usize),
    /// A PHY frame whose preamble is not AAAAh.
    Preamble(u16),
    /// A PHY frame whose start subframe delimiter is not 54C7h.
    Delimiter(u16),
}

impl fmt::Display for MacError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MacError::MsduLength(n) => write!(
                f,
                "an M_sdu of {n} bytes: a long MAC frame carries 1 to {MAX_M_SDU}"
            ),
            MacError::FrameLength(n) => write!(
                f,
                "{n} bytes is not a long MAC frame: it is 36 bytes per subframe, 1 to 7 subframes"
            ),
            MacError::Ns(c) => write!(
                f,
                "NS {:02X}{:02X}h is not the code of a subframe count 1 to 7",
                c[0], c[1]
            ),
            MacError::NsLength { ns, len } => write!(
                f,
                "NS says {ns} subframes ({} bytes) but the frame has {len} bytes",
                ns * CHUNK_LEN
            ),
            MacError::Pad { pad, ns } => write!(
                f,
                "PAD {pad} is wrong for {ns} subframes: it must leave 1 to {} M_sdu bytes and be under 36",
                ns * CHUNK_LEN - HEADER_LEN - FCS_LEN
            ),
            MacError::Fcs { received, computed } => write!(
                f,
                "bad FCS: received {received:06X}h, the frame's is {computed:06X}h"
            ),
            MacError::FcsForms {
                received,
                catalogue,
                gurux,
                gurux_without_pad,
            } => {
                write!(
                    f,
                    "bad FCS: received {received:06X}h, in no known form: the frame's would be \
                     {catalogue:06X}h (catalogue)"
                )?;
                match gurux_without_pad {
                    Some(g) => write!(
                        f,
                        ", {gurux:06X}h (Gurux) or {g:06X}h (Gurux without the pad bytes)"
                    ),
                    None => write!(f, " or {gurux:06X}h (Gurux)"),
                }
            }
            MacError::SubframeLength(n) => {
                write!(f, "{n} bytes is not a whole number of 38-byte subframes")
            }
            MacError::SubframeCount(n) => write!(
                f,
                "{n} subframes: a long MAC frame takes 1 to 7 subframes (time slots)"
            ),
            MacError::Fi { index, fi, first } => write!(
                f,
                "subframe {} has FI {fi:04X}h but the first has {first:04X}h",
                index + 1
            ),
            MacError::PhyLength(n) => {
                write!(f, "{n} bytes is not a whole number of 45-byte PHY frames")
            }
            MacError::Preamble(p) => write!(f, "preamble {p:04X}h, expected AAAAh"),
            MacError::Delimiter(d) => {
                write!(f, "start subframe delimiter {d:04X}h, expected 54C7h")
            }
        }
    }
}

/// A checked view over the bytes of a long MAC frame. Its accessors never
/// panic: [`LongFrame::new_checked`] has checked the length, NS and PAD.
/// The FCS is not checked, so that a decoder can show a damaged frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LongFrame<'a> {
    bytes: &'a [u8],
    ns: usize,
}

impl<'a> LongFrame<'a> {
    /// Checks length, NS and PAD.
    pub fn new_checked(bytes: &'a [u8]) -> Result<Self, MacError> {
        let len = bytes.len();
        if len < CHUNK_LEN {
            return Err(MacError::FrameLength(len));
        }
        let ns = ns_count([bytes[0], bytes[1]]).ok_or(MacError::Ns([bytes[0], bytes[1]]))?;
        if len != ns * CHUNK_LEN {
            return Err(MacError::NsLength { ns, len });
        }
        let pad = bytes[HEADER_LEN - 1];
        let room = len - HEADER_LEN - FCS_LEN;
        if pad as usize >= CHUNK_LEN || pad as usize >= room {
            return Err(MacError::Pad { pad, ns });
        }
        Ok(LongFrame { bytes, ns })
    }

    /// The bytes of the frame.
    pub fn bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// NS: the number of subframes.
    pub fn ns(&self) -> usize {
        self.ns
    }

    /// CREDIT: IC, CC, DC.
    pub fn credit(&self) -> Credit {
        Credit::from_byte(self.bytes[2])
    }

    /// ADDRESS: SA and DA.
    pub fn address(&self) -> Address {
        Address::from_bytes([self.bytes[3], self.bytes[4], self.bytes[5]])
    }

    /// PAD: the number of pad bytes.
    pub fn pad_len(&self) -> usize {
        self.bytes[HEADER_LEN - 1] as usize
    }

    fn fcs_at(&self) -> usize {
        self.bytes.len() - FCS_LEN
    }

    /// The M_sdu.
    pub fn m_sdu(&self) -> &'a [u8] {
        &self.bytes[HEADER_LEN..self.fcs_at() - self.pad_len()]
    }

    /// The pad bytes (00h when emitted here; kept as received).
    pub fn pad(&self) -> &'a [u8] {
        &self.bytes[self.fcs_at() - self.pad_len()..self.fcs_at()]
    }

    /// The FCS as received.
    pub fn fcs(&self) -> u32 {
        let f = &self.bytes[self.fcs_at()..];
        u32::from_be_bytes([0, f[0], f[1], f[2]])
    }

    /// The FCS of the frame: over CREDIT up to the last pad byte.
    pub fn computed_fcs(&self) -> u32 {
        fcs(&self.bytes[2..self.fcs_at()])
    }

    /// Whether the FCS received is the frame's in the catalogue form, the
    /// one this project sends and its simulated modems accept.
    pub fn fcs_ok(&self) -> bool {
        self.fcs() == self.computed_fcs()
    }

    /// Which known form the FCS received is in, or, when it is in none,
    /// what each form's would be.
    pub fn fcs_form(&self) -> Result<FcsForm, MacError> {
        let received = self.fcs();
        let body = &self.bytes[2..self.fcs_at()];
        let catalogue = self.computed_fcs();
        let gurux = gurux_fcs(body);
        let gurux_without_pad =
            (self.pad_len() > 0).then(|| gurux_fcs(&body[..body.len() - self.pad_len()]));
        if received == catalogue {
            Ok(FcsForm::Catalogue)
        } else if received == gurux {
            Ok(FcsForm::Gurux)
        } else if Some(received) == gurux_without_pad {
            Ok(FcsForm::GuruxWithoutPad)
        } else {
            Err(MacError::FcsForms {
                received,
                catalogue,
                gurux,
                gurux_without_pad,
            })
        }
    }
}

/// A long MAC frame (4.4): header, M_sdu; NS, PAD and FCS follow from
/// them when emitted.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct MacFrame {
    /// IC, CC, DC (4.8).
    pub credit: Credit,
    /// SA, DA (4.5).
    pub address: Address,
    /// The MAC service data unit, 1..=242 bytes.
    pub m_sdu: Vec<u8>,
}

impl MacFrame {
    /// The frame of a view whose FCS is right.
    pub fn parse(frame: &LongFrame<'_>) -> Result<MacFrame, MacError> {
        if !frame.fcs_ok() {
            return Err(MacError::Fcs {
                received: frame.fcs(),
                computed: frame.computed_fcs(),
            });
        }
        Ok(MacFrame {
            credit: frame.credit(),
            address: frame.address(),
            m_sdu: frame.m_sdu().to_vec(),
        })
    }

    /// Parses the bytes of a long frame (length, NS, PAD, FCS).
    pub fn parse_bytes(bytes: &[u8]) -> Result<MacFrame, MacError> {
        MacFrame::parse(&LongFrame::new_checked(bytes)?)
    }

    /// NS: the subframes this frame takes.
    pub fn ns(&self) -> usize {
        subframes_for(self.m_sdu.len())
    }

    /// The long frame's bytes, 36·NS of them; the pad bytes are 00h.
    /// Refuses an M_sdu outside 1..=242 bytes.
    pub fn emit(&self) -> Result<Vec<u8>, MacError> {
        let len = self.m_sdu.len();
        if !(1..=MAX_M_SDU).contains(&len) {
            return Err(MacError::MsduLength(len));
        }
        let ns = self.ns();
        let pad = ns * CHUNK_LEN - HEADER_LEN - len - FCS_LEN;
        let mut out = Vec::with_capacity(ns * CHUNK_LEN);
        out.extend_from_slice(&ns_code(ns).unwrap_or_default());
        out.push(self.credit.byte());
        out.extend_from_slice(&self.address.to_bytes());
        out.push(pad as u8);
        out.extend_from_slice(&self.m_sdu);
        out.resize(out.len() + pad, 0);
        let fcs = fcs(&out[2..]).to_be_bytes();
        out.extend_from_slice(&fcs[1..]);
        Ok(out)
    }

    /// The frame cut into subframes with frame indicator `fi`
    /// ([`LONG_MAC_FRAME`] unless MIB 0012h says otherwise).
    pub fn to_subframes(&self, fi: u16) -> Result<Vec<[u8; SUBFRAME_LEN]>, MacError> {
        Ok(split(&self.emit()?, fi))
    }

    /// The frame of 1..7 subframes sharing one FI, and that FI.
    pub fn from_subframes(subframes: &[[u8; SUBFRAME_LEN]]) -> Result<(u16, MacFrame), MacError> {
        let (fi, long) = join(subframes)?;
        Ok((fi, MacFrame::parse_bytes(&long)?))
    }
}

/// Cuts a long frame into subframes: each one FI, then the next 36 bytes
/// (the last one 00h-filled if the frame is not 36·NS bytes).
pub fn split(long: &[u8], fi: u16) -> Vec<[u8; SUBFRAME_LEN]> {
    long.chunks(CHUNK_LEN)
        .map(|chunk| {
            let mut s = [0u8; SUBFRAME_LEN];
            fields::FI.set(&mut s, fi as i64);
            s[2..2 + chunk.len()].copy_from_slice(chunk);
            s
        })
        .collect()
}

/// Joins 1..7 subframes sharing one FI: that FI and the long frame.
pub fn join(subframes: &[[u8; SUBFRAME_LEN]]) -> Result<(u16, Vec<u8>), MacError> {
    if !(1..=MAX_SUBFRAMES).contains(&subframes.len()) {
        return Err(MacError::SubframeCount(subframes.len()));
    }
    let fi_of = |s: &[u8; SUBFRAME_LEN]| fields::FI.get(s).unwrap_or(0) as u16;
    let first = fi_of(&subframes[0]);
    let mut long = Vec::with_capacity(subframes.len() * CHUNK_LEN);
    for (index, s) in subframes.iter().enumerate() {
        let fi = fi_of(s);
        if fi != first {
            return Err(MacError::Fi { index, fi, first });
        }
        long.extend_from_slice(&s[2..]);
    }
    Ok((first, long))
}

/// Cuts bytes into 38-byte subframes (1..7 of them).
pub fn subframes_of(bytes: &[u8]) -> Result<Vec<[u8; SUBFRAME_LEN]>, MacError> {
    if bytes.is_empty() || !bytes.len().is_multiple_of(SUBFRAME_LEN) {
        return Err(MacError::SubframeLength(bytes.len()));
    }
    let n = bytes.len() / SUBFRAME_LEN;
    if n > MAX_SUBFRAMES {
        return Err(MacError::SubframeCount(n));
    }
    Ok(bytes
        .chunks_exact(SUBFRAME_LEN)
        .map(|c| {
            let mut s = [0u8; SUBFRAME_LEN];
            s.copy_from_slice(c);
            s
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The remainder of `bytes`·x^`shift` by the generator, long division
    /// on a whole number (a different computation from both FCS
    /// functions).
    fn remainder(bytes: &[u8], shift: u32) -> u32 {
        const G: u128 = 1 << 24 | 0x5D_6DCB;
        let mut m = bytes.iter().fold(0u128, |m, b| m << 8 | *b as u128) << shift;
        while m >> 24 != 0 {
            m ^= G << (127 - m.leading_zeros() - 24);
        }
        m as u32
    }

    #[test]
    fn both_fcs_forms_are_remainders_of_the_generator() {
        // Catalogue: message·x^24 mod G. Gurux: message mod G, bits
        // reversed. 13 bytes at most: the dividend fits 128 bits.
        for msg in [&b"123456789"[..], &[0x00], &[0xFF; 13], &[0x80, 0, 0, 1]] {
            assert_eq!(fcs(msg), remainder(msg, 24), "{msg:02x?}");
            let r = remainder(msg, 0);
            assert_eq!(gurux_fcs(msg), r.reverse_bits() >> 8, "{msg:02x?}");
        }
        assert_eq!(fcs(b"123456789"), FCS_ALGORITHM.check);
        // Three bytes or fewer are their own remainder.
        assert_eq!(gurux_fcs(&[0x00, 0x00, 0x01]), 0x80_0000);
    }

    #[test]
    fn ns_codes_are_a_simplex_code() {
        // Any two code words differ in exactly 4 of 7 bits (4 ones each).
        for (i, a) in NS_CODES.iter().enumerate() {
            assert_eq!(a.count_ones(), 4);
            for b in &NS_CODES[i + 1..] {
                assert_eq!((a ^ b).count_ones(), 4);
            }
        }
        for n in 1..=7 {
            assert_eq!(ns_count(ns_code(n).unwrap()), Some(n));
        }
        assert_eq!(ns_code(0), None);
        assert_eq!(ns_code(8), None);
        assert_eq!(ns_count([0x6C, 0x3A]), None);
    }

    #[test]
    fn subframe_counts_at_the_edges() {
        // 10 bytes of overhead: 26 bytes fit one subframe, 242 fill seven.
        assert_eq!(subframes_for(1), 1);
        assert_eq!(subframes_for(26), 1);
        assert_eq!(subframes_for(27), 2);
        assert_eq!(subframes_for(MAX_M_SDU), 7);
        assert_eq!(subframes_for(MAX_M_SDU + 1), 8);
    }

    #[test]
    fn header_fields_read_the_emitted_bytes() {
        let f = MacFrame {
            credit: Credit {
                ic: 3,
                cc: 2,
                dc: 1,
            },
            address: Address {
                sa: 0xC00,
                da: 0x001,
            },
            m_sdu: alloc::vec![0xAB; 5],
        };
        let b = f.emit().unwrap();
        let v = |field: &Field| field.get(&b).unwrap();
        assert_eq!(v(&fields::IC), 3);
        assert_eq!(v(&fields::CC), 2);
        assert_eq!(v(&fields::DC), 1);
        assert_eq!(v(&fields::SA), 0xC00);
        assert_eq!(v(&fields::DA), 0x001);
        assert_eq!(v(&fields::PAD), 36 - 10 - 5);
    }
}
