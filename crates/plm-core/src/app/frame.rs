//! Application frames as the board's USART carries them (STEVAL-IHP007V1
//! UM 4.5-4.6, Appendix A):
//!
//! ```text
//! [length] [type | BROADCAST_FLAG] [address: 6 bytes] [payload...] [CRC-16]
//! ```
//!
//! `length` counts every byte of the frame, itself and the CRC included
//! (a ping is 10 bytes, a service frame `n + 11`). The address is the
//! remote board's: the target of what the host sends, the source of what
//! comes back ("source_module.address" in the HID replies). The CRC covers
//! every byte before it and is sent high byte first, like every other
//! multi-byte field of the seed (docs/protocol-notes.md).

use super::crc::crc16;
use alloc::vec::Vec;
use core::fmt;

/// Bit 7 of the frame type byte: sent to every board (4.6.1).
pub const BROADCAST_FLAG: u8 = 0x80;
/// Bytes around the payload: length, type, address, CRC.
pub const OVERHEAD: usize = 10;
/// `USER_PAYLOAD_SIZE` (4.5): at most 100 bytes after the address.
pub const MAX_PAYLOAD: usize = 100;
/// The shortest frame (a ping, 4.6.2).
pub const MIN_LEN: usize = OVERHEAD;
/// The longest frame.
pub const MAX_LEN: usize = OVERHEAD + MAX_PAYLOAD;

/// A board's 6-byte address.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Address(pub [u8; 6]);

impl Address {
    /// The address broadcast frames carry on the power line (all ones).
    pub const BROADCAST: Address = Address([0xFF; 6]);

    /// Reads 12 hex digits (separators allowed, as [`crate::hex`] reads).
    pub fn parse(text: &str) -> Result<Address, AddressError> {
        let bytes = crate::hex::parse(text).map_err(|_| AddressError(text.len()))?;
        let arr: [u8; 6] = bytes.try_into().map_err(|_| AddressError(text.len()))?;
        Ok(Address(arr))
    }

    /// The address as a 48-bit number.
    pub fn to_u64(self) -> u64 {
        self.0.iter().fold(0, |v, b| v << 8 | *b as u64)
    }

    /// The address of a 48-bit number (the low 48 bits).
    pub fn from_u64(v: u64) -> Address {
        let b = v.to_be_bytes();
        Address([b[2], b[3], b[4], b[5], b[6], b[7]])
    }
}

/// Lowercase, 12 hex digits (`0080e1000001`): how JSON, the CLI and the
/// console write addresses.
impl fmt::Display for Address {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|b| write!(f, "{b:02x}"))
    }
}

/// An address that is not 12 hex digits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AddressError(pub usize);

impl fmt::Display for AddressError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a board address is 6 bytes: 12 hex digits such as 0080e1000001")
    }
}

/// `APP_fstype_t` (4.5). Unknown values are preserved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrameType {
    /// APP_DATA_FRAME (00h): user data; HID ballast commands (Appendix A).
    Data,
    /// APP_SERVICE_FRAME (01h): service commands (4.6.4).
    Service,
    /// APP_PING_FRAME (02h) (4.6.2).
    Ping,
    /// APP_ERROR_FRAME (03h) (4.6.3).
    Error,
    /// APP_PROGRAMMING_FRAME (04h).
    Programming,
    /// APP_ACK_FRAME (05h).
    Ack,
    /// APP_MIB_FRAME (06h).
    Mib,
    /// Any other value of bits 0-6.
    Unknown(u8),
}

/// The seed's names, index = value.
pub const FRAME_TYPE_NAMES: &[&str] = &[
    "APP_DATA_FRAME",
    "APP_SERVICE_FRAME",
    "APP_PING_FRAME",
    "APP_ERROR_FRAME",
    "APP_PROGRAMMING_FRAME",
    "APP_ACK_FRAME",
    "APP_MIB_FRAME",
];

impl FrameType {
    /// The type of bits 0-6 of a type byte.
    pub fn from_byte(b: u8) -> FrameType {
        match b & !BROADCAST_FLAG {
            0 => FrameType::Data,
            1 => FrameType::Service,
            2 => FrameType::Ping,
            3 => FrameType::Error,
            4 => FrameType::Programming,
            5 => FrameType::Ack,
            6 => FrameType::Mib,
            v => FrameType::Unknown(v),
        }
    }

    /// Its value (bits 0-6).
    pub fn byte(self) -> u8 {
        match self {
            FrameType::Data => 0,
            FrameType::Service => 1,
            FrameType::Ping => 2,
            FrameType::Error => 3,
            FrameType::Programming => 4,
            FrameType::Ack => 5,
            FrameType::Mib => 6,
            FrameType::Unknown(v) => v & !BROADCAST_FLAG,
        }
    }

    /// The seed's name (`APP_SERVICE_FRAME`), `None` for an unknown type.
    pub fn name(self) -> Option<&'static str> {
        FRAME_TYPE_NAMES.get(self.byte() as usize).copied()
    }
}

/// One application frame, whatever carries it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AppFrame {
    /// Frame type.
    pub frame_type: FrameType,
    /// BROADCAST_FLAG.
    pub broadcast: bool,
    /// The remote board: target of a request, source of an answer.
    pub address: Address,
    /// What follows the address (service command and data, HID data,
    /// error code, ...), at most [`MAX_PAYLOAD`] bytes.
    pub payload: Vec<u8>,
}

/// Why bytes are not an application frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    /// Fewer bytes than the length byte says, or than a frame needs.
    Truncated,
    /// The length byte is outside 10..=110.
    BadLength(u8),
    /// The CRC does not match.
    BadCrc {
        /// As received.
        received: u16,
        /// As computed.
        computed: u16,
    },
    /// The payload is longer than 100 bytes (emitting).
    TooLong(usize),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::Truncated => f.write_str("the frame is shorter than its length byte says"),
            FrameError::BadLength(l) => write!(
                f,
                "length byte {l} is not a frame length ({MIN_LEN}..={MAX_LEN})"
            ),
            FrameError::BadCrc { received, computed } => write!(
                f,
                "CRC-16 is {received:04X}h, the bytes give {computed:04X}h"
            ),
            FrameError::TooLong(n) => write!(
                f,
                "a payload of {n} bytes is longer than the {MAX_PAYLOAD} bytes a frame carries"
            ),
        }
    }
}

impl AppFrame {
    /// A unicast frame.
    pub fn new(frame_type: FrameType, address: Address, payload: Vec<u8>) -> AppFrame {
        AppFrame {
            frame_type,
            broadcast: false,
            address,
            payload,
        }
    }

    /// The type byte: type value with BROADCAST_FLAG.
    pub fn type_byte(&self) -> u8 {
        self.frame_type.byte() | if self.broadcast { BROADCAST_FLAG } else { 0 }
    }

    /// The frame as the USART carries it, CRC included.
    pub fn emit(&self) -> Result<Vec<u8>, FrameError> {
        if self.payload.len() > MAX_PAYLOAD {
            return Err(FrameError::TooLong(self.payload.len()));
        }
        let len = OVERHEAD + self.payload.len();
        let mut out = Vec::with_capacity(len);
        out.push(len as u8);
        out.push(self.type_byte());
        out.extend_from_slice(&self.address.0);
        out.extend_from_slice(&self.payload);
        let crc = crc16(&out);
        out.extend_from_slice(&crc.to_be_bytes());
        Ok(out)
    }

    /// Reads one whole frame (exactly `bytes`, as the length byte says).
    /// A wrong CRC is an error; [`AppFrame::parse_unchecked`] keeps it.
    pub fn parse(bytes: &[u8]) -> Result<AppFrame, FrameError> {
        let (frame, received) = AppFrame::parse_unchecked(bytes)?;
        let computed = crc16(&bytes[..bytes.len() - 2]);
        if received != computed {
            return Err(FrameError::BadCrc { received, computed });
        }
        Ok(frame)
    }

    /// Reads one frame without checking its CRC; returns the CRC as
    /// received, so that a sniffer can show a damaged frame.
    pub fn parse_unchecked(bytes: &[u8]) -> Result<(AppFrame, u16), FrameError> {
        let &len = bytes.first().ok_or(FrameError::Truncated)?;
        let l = len as usize;
        if !(MIN_LEN..=MAX_LEN).contains(&l) {
            return Err(FrameError::BadLength(len));
        }
        if bytes.len() < l {
            return Err(FrameError::Truncated);
        }
        let b = &bytes[..l];
        let mut address = [0; 6];
        address.copy_from_slice(&b[2..8]);
        let frame = AppFrame {
            frame_type: FrameType::from_byte(b[1]),
            broadcast: b[1] & BROADCAST_FLAG != 0,
            address: Address(address),
            payload: b[8..l - 2].to_vec(),
        };
        Ok((frame, u16::from_be_bytes([b[l - 2], b[l - 1]])))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::ToString;

    #[test]
    fn ping_is_ten_bytes_and_round_trips() {
        let f = AppFrame::new(
            FrameType::Ping,
            Address([0, 0x80, 0xE1, 0, 0, 1]),
            Vec::new(),
        );
        let b = f.emit().unwrap();
        assert_eq!(b.len(), 10);
        assert_eq!(b[0], 10);
        assert_eq!(AppFrame::parse(&b), Ok(f));
    }

    #[test]
    fn wrong_crc_and_lengths_are_refused_in_words() {
        let mut b = AppFrame::new(FrameType::Ping, Address::default(), Vec::new())
            .emit()
            .unwrap();
        b[9] ^= 1;
        assert!(matches!(
            AppFrame::parse(&b),
            Err(FrameError::BadCrc { .. })
        ));
        assert_eq!(AppFrame::parse(&[9]), Err(FrameError::BadLength(9)));
        assert_eq!(AppFrame::parse(&[12, 0]), Err(FrameError::Truncated));
        assert_eq!(AppFrame::parse(&[]), Err(FrameError::Truncated));
    }

    #[test]
    fn addresses_read_and_print_as_twelve_hex_digits() {
        let a = Address::parse("00:80:E1:00:00:2a").unwrap();
        assert_eq!(a.to_string(), "0080e100002a");
        assert_eq!(Address::from_u64(a.to_u64()), a);
        assert!(Address::parse("0080e1").is_err());
    }
}
