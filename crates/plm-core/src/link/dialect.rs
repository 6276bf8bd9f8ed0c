//! The two host-interface dialects. Everything that differs between the
//! ST7580 and the ST7570 at the link level is answered here, once.

/// Which chip's host-interface rules apply.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// UM0932: length counts the data field only; STX 02h or 03h (repeat);
    /// 2-byte status message.
    St7580,
    /// ST7570 UM Table 10: length counts command + data + checksum (3..250);
    /// STX 02h only; 4-byte status message.
    St7570,
}

impl Dialect {
    /// Bytes of a status message, including the leading `?`.
    pub const fn status_len(self) -> usize {
        match self {
            Dialect::St7580 => 2, // UM0932 Table 8
            Dialect::St7570 => 4, // ST7570 UM Table 11
        }
    }

    /// Whether `byte` starts a local frame in this dialect.
    pub const fn is_stx(self, byte: u8) -> bool {
        match self {
            // UM0932 Table 6: 02h, or 03h for the modem's single repeat (3.2.7).
            Dialect::St7580 => byte == 0x02 || byte == 0x03,
            Dialect::St7570 => byte == 0x02,
        }
    }

    /// Largest data field a local frame can carry.
    pub const fn max_data(self) -> usize {
        match self {
            Dialect::St7580 => 255, // UM0932 Table 6
            Dialect::St7570 => 247, // ST7570 UM Table 10
        }
    }

    /// Data field length announced by a length byte, `None` when the length
    /// byte is impossible in this dialect.
    pub const fn data_len(self, length: u8) -> Option<usize> {
        match self {
            Dialect::St7580 => Some(length as usize),
            Dialect::St7570 => {
                if length >= 3 && length <= 250 {
                    Some(length as usize - 3)
                } else {
                    None
                }
            }
        }
    }

    /// The length byte for a data field of `data_len` bytes.
    pub const fn length_byte(self, data_len: usize) -> Option<u8> {
        if data_len > self.max_data() {
            return None;
        }
        Some(match self {
            Dialect::St7580 => data_len as u8,
            Dialect::St7570 => (data_len + 3) as u8,
        })
    }

    /// Total bytes on the wire of a frame with `data_len` data bytes:
    /// STX, length, command, data, 2 checksum bytes.
    pub const fn frame_len(data_len: usize) -> usize {
        data_len + 5
    }

    /// Short name, as the CLI spells it.
    pub const fn name(self) -> &'static str {
        match self {
            Dialect::St7580 => "st7580",
            Dialect::St7570 => "st7570",
        }
    }
}
