//! Local frames (UM0932 3.2.2 Table 6; ST7570 UM Table 10):
//! `STX | Length | Command code | Data | Checksum (LSByte first)`.

use super::Dialect;
use alloc::vec::Vec;
use core::fmt;

/// The start-of-text delimiter of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stx {
    /// 02h: a first transmission.
    First,
    /// 03h: the ST7580's single repeat of a frame the host did not
    /// acknowledge (UM0932 3.2.7).
    Repeat,
}

impl Stx {
    /// The byte on the wire.
    pub const fn byte(self) -> u8 {
        match self {
            Stx::First => 0x02,
            Stx::Repeat => 0x03,
        }
    }

    /// The delimiter for a byte, if it is one.
    pub const fn from_byte(b: u8) -> Option<Stx> {
        match b {
            0x02 => Some(Stx::First),
            0x03 => Some(Stx::Repeat),
            _ => None,
        }
    }
}

/// The local frame checksum: the 16-bit sum of every byte from the length
/// field up to the last data byte (or the command byte when there is no
/// data), UM0932 Table 6. `bytes` is that span.
pub fn checksum(bytes: &[u8]) -> u16 {
    bytes
        .iter()
        .fold(0u16, |acc, b| acc.wrapping_add(*b as u16))
}

/// Why a byte string is not a whole local frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    /// The first byte is not an STX of the dialect.
    NotStx(u8),
    /// The length byte is impossible in the dialect (ST7570: not 3..250).
    BadLength(u8),
    /// Fewer bytes than the length announces; `needed` in total.
    Truncated {
        /// Bytes the whole frame needs.
        needed: usize,
    },
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::NotStx(b) => write!(f, "{b:02x} is not a start of frame"),
            FrameError::BadLength(l) => write!(f, "length {l} is not allowed"),
            FrameError::Truncated { needed } => {
                write!(f, "frame truncated ({needed} bytes needed)")
            }
        }
    }
}

/// A zero-copy view of a local frame with checked accessors (after
/// smoltcp's `wire` packets). Construct with [`Frame::new_checked`]; the
/// accessors then never panic.
#[derive(Debug, Clone, Copy)]
pub struct Frame<T: AsRef<[u8]>> {
    buffer: T,
    dialect: Dialect,
}

impl<T: AsRef<[u8]>> Frame<T> {
    /// Checks that `buffer` starts with a whole frame of `dialect` (it may be
    /// longer: see [`Frame::total_len`]).
    pub fn new_checked(buffer: T, dialect: Dialect) -> Result<Self, FrameError> {
        let b = buffer.as_ref();
        let first = *b.first().ok_or(FrameError::Truncated { needed: 2 })?;
        if !dialect.is_stx(first) {
            return Err(FrameError::NotStx(first));
        }
        let length = *b.get(1).ok_or(FrameError::Truncated { needed: 2 })?;
        let data_len = dialect
            .data_len(length)
            .ok_or(FrameError::BadLength(length))?;
        let needed = Dialect::frame_len(data_len);
        if b.len() < needed {
            return Err(FrameError::Truncated { needed });
        }
        Ok(Frame { buffer, dialect })
    }

    fn bytes(&self) -> &[u8] {
        self.buffer.as_ref()
    }

    /// The dialect the frame was read with.
    pub fn dialect(&self) -> Dialect {
        self.dialect
    }

    /// The STX byte.
    pub fn stx(&self) -> u8 {
        self.bytes()[0]
    }

    /// The length byte as sent.
    pub fn length(&self) -> u8 {
        self.bytes()[1]
    }

    /// The command code.
    pub fn code(&self) -> u8 {
        self.bytes()[2]
    }

    fn data_len(&self) -> usize {
        self.dialect.data_len(self.length()).unwrap_or(0)
    }

    /// The data field.
    pub fn data(&self) -> &[u8] {
        &self.bytes()[3..3 + self.data_len()]
    }

    /// The checksum as received (sent LSByte first).
    pub fn checksum(&self) -> u16 {
        let at = 3 + self.data_len();
        u16::from_le_bytes([self.bytes()[at], self.bytes()[at + 1]])
    }

    /// The checksum the frame should carry.
    pub fn computed_checksum(&self) -> u16 {
        checksum(&self.bytes()[1..3 + self.data_len()])
    }

    /// Whether the received checksum is right.
    pub fn checksum_ok(&self) -> bool {
        self.checksum() == self.computed_checksum()
    }

    /// Bytes the frame occupies at the start of the buffer.
    pub fn total_len(&self) -> usize {
        Dialect::frame_len(self.data_len())
    }
}

/// Why a frame cannot be emitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EmitError {
    /// The data field is longer than the dialect allows.
    DataTooLong {
        /// The length asked for.
        len: usize,
        /// The most the dialect allows.
        max: usize,
    },
    /// STX 03h exists only in the ST7580 dialect.
    RepeatNotInDialect,
}

impl fmt::Display for EmitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EmitError::DataTooLong { len, max } => {
                write!(
                    f,
                    "data field of {len} bytes is longer than the {max} a local frame carries"
                )
            }
            EmitError::RepeatNotInDialect => {
                f.write_str("STX 03h (repeat) is only used by the ST7580")
            }
        }
    }
}

/// A local frame as values: the Repr of [`Frame`].
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct LocalFrame {
    /// Start delimiter.
    pub stx: Stx,
    /// Command code.
    pub code: u8,
    /// Data field.
    pub data: Vec<u8>,
}

impl LocalFrame {
    /// A first transmission (STX 02h) of `code` with `data`.
    pub fn new(code: u8, data: Vec<u8>) -> Self {
        LocalFrame {
            stx: Stx::First,
            code,
            data,
        }
    }

    /// Reads the frame of a checked view. The checksum is not judged here.
    pub fn parse<T: AsRef<[u8]>>(frame: &Frame<T>) -> Self {
        LocalFrame {
            stx: Stx::from_byte(frame.stx()).unwrap_or(Stx::First),
            code: frame.code(),
            data: frame.data().to_vec(),
        }
    }

    /// The frame's bytes with a correct checksum.
    pub fn emit(&self, dialect: Dialect) -> Result<Vec<u8>, EmitError> {
        let sum = self.emit_with_checksum(dialect, None)?;
        Ok(sum)
    }

    /// The frame's bytes with the given checksum (to reproduce a received
    /// frame exactly, bad checksum included), or the right one for `None`.
    pub fn emit_with_checksum(
        &self,
        dialect: Dialect,
        sum: Option<u16>,
    ) -> Result<Vec<u8>, EmitError> {
        if !dialect.is_stx(self.stx.byte()) {
            return Err(EmitError::RepeatNotInDialect);
        }
        let length = dialect
            .length_byte(self.data.len())
            .ok_or(EmitError::DataTooLong {
                len: self.data.len(),
                max: dialect.max_data(),
            })?;
        let mut out = Vec::with_capacity(Dialect::frame_len(self.data.len()));
        out.push(self.stx.byte());
        out.push(length);
        out.push(self.code);
        out.extend_from_slice(&self.data);
        let sum = sum.unwrap_or_else(|| checksum(&out[1..]));
        out.extend_from_slice(&sum.to_le_bytes());
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    #[test]
    fn ping_without_data_checksums_length_and_command() {
        // UM0932 Table 6: "up to the command byte if there is no data byte".
        let bytes = LocalFrame::new(0x2C, vec![]).emit(Dialect::St7580).unwrap();
        assert_eq!(bytes, [0x02, 0x00, 0x2C, 0x2C, 0x00]);
        let f = Frame::new_checked(&bytes[..], Dialect::St7580).unwrap();
        assert!(f.checksum_ok());
        assert_eq!(f.total_len(), 5);
    }

    #[test]
    fn checksum_is_sent_lsbyte_first() {
        let data = vec![0xFF; 4];
        let bytes = LocalFrame::new(0x2C, data).emit(Dialect::St7580).unwrap();
        // 04 + 2C + 4*FF = 0x042C
        assert_eq!(&bytes[bytes.len() - 2..], &[0x2C, 0x04]);
    }

    #[test]
    fn st7570_length_counts_command_data_and_checksum() {
        let bytes = LocalFrame::new(0x51, vec![0; 16])
            .emit(Dialect::St7570)
            .unwrap();
        assert_eq!(bytes[1], 19);
        assert_eq!(bytes.len(), 21);
        assert_eq!(
            Frame::new_checked(&[0x02, 0x02, 0x00][..], Dialect::St7570).unwrap_err(),
            FrameError::BadLength(2)
        );
    }

    #[test]
    fn accessors_refuse_short_buffers() {
        assert_eq!(
            Frame::new_checked(&[0x02, 0x03, 0x08, 0x00][..], Dialect::St7580).unwrap_err(),
            FrameError::Truncated { needed: 8 }
        );
        assert!(Frame::new_checked(&[][..], Dialect::St7580).is_err());
        assert_eq!(
            LocalFrame {
                stx: Stx::Repeat,
                code: 1,
                data: vec![]
            }
            .emit(Dialect::St7570),
            Err(EmitError::RepeatNotInDialect)
        );
        assert!(LocalFrame::new(1, vec![0; 256])
            .emit(Dialect::St7580)
            .is_err());
    }
}
