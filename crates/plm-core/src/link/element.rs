//! What a byte stream on the host interface is made of.

use super::{Dialect, Frame, LocalFrame, ACK, NAK, STATUS_FIRST};
use alloc::vec::Vec;

/// Who sent the bytes being decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Source {
    /// The external host (the console): frames and ACK/NAK.
    Host,
    /// The modem: frames, ACK/NAK and status messages.
    Modem,
    /// Unknown: anything is recognised.
    Any,
}

impl Source {
    /// Whether this side sends status messages (only the modem does).
    pub const fn sends_status(self) -> bool {
        !matches!(self, Source::Host)
    }
}

/// A status message (UM0932 3.2.4, ST7570 UM Table 11): the bytes after
/// the leading `?`. The chip modules give the bits their meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct StatusMessage {
    bytes: [u8; 3],
    len: u8,
}

impl StatusMessage {
    /// A status message from the bytes after `?` (1 for the ST7580, 3 for
    /// the ST7570; extra bytes are ignored).
    pub fn new(dialect: Dialect, after_mark: &[u8]) -> Self {
        let len = (dialect.status_len() - 1).min(after_mark.len());
        let mut bytes = [0; 3];
        bytes[..len].copy_from_slice(&after_mark[..len]);
        StatusMessage {
            bytes,
            len: len as u8,
        }
    }

    /// The bytes after `?`.
    pub fn data(&self) -> &[u8] {
        &self.bytes[..self.len as usize]
    }

    /// The whole message as sent, `?` first.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(1 + self.len as usize);
        v.push(STATUS_FIRST);
        v.extend_from_slice(self.data());
        v
    }
}

/// Why bytes were not part of any element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GarbageReason {
    /// Bytes that start nothing known.
    Unexpected,
    /// The start of a frame that never completed (end of input, or a pause
    /// longer than T_IC, UM0932 3.2.6).
    Truncated,
}

/// One element of a host-interface byte stream.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Element {
    /// A local frame. A frame with a wrong checksum is still reported, so
    /// that an inspector shows it, and nothing is made of it.
    Frame {
        /// The frame.
        frame: LocalFrame,
        /// The checksum as received.
        checksum: u16,
        /// Whether it matched the frame.
        checksum_ok: bool,
    },
    /// ACK (06h).
    Ack,
    /// NAK (15h).
    Nak,
    /// A status message.
    Status(StatusMessage),
    /// Bytes that are none of the above.
    Garbage {
        /// The bytes.
        bytes: Vec<u8>,
        /// Why they are garbage.
        reason: GarbageReason,
    },
}

impl Element {
    /// The element of a checked frame view.
    pub fn from_frame<T: AsRef<[u8]>>(f: &Frame<T>) -> Element {
        Element::Frame {
            frame: LocalFrame::parse(f),
            checksum: f.checksum(),
            checksum_ok: f.checksum_ok(),
        }
    }

    /// The element of a frame this side emitted as `bytes` (its checksum is
    /// right by construction and is read from the last two bytes).
    pub fn emitted(frame: LocalFrame, bytes: &[u8]) -> Element {
        let n = bytes.len();
        let checksum = match bytes.get(n.saturating_sub(2)..) {
            Some([lo, hi]) => u16::from_le_bytes([*lo, *hi]),
            _ => 0,
        };
        Element::Frame {
            frame,
            checksum,
            checksum_ok: true,
        }
    }

    /// The bytes of the element exactly as they were on the wire.
    pub fn to_bytes(&self, dialect: Dialect) -> Vec<u8> {
        match self {
            Element::Frame {
                frame, checksum, ..
            } => frame
                .emit_with_checksum(dialect, Some(*checksum))
                .unwrap_or_default(),
            Element::Ack => alloc::vec![ACK],
            Element::Nak => alloc::vec![NAK],
            Element::Status(s) => s.to_bytes(),
            Element::Garbage { bytes, .. } => bytes.clone(),
        }
    }

    /// The kind as `plm decode` names it.
    pub fn kind(&self) -> &'static str {
        match self {
            Element::Frame { .. } => "frame",
            Element::Ack => "ack",
            Element::Nak => "nak",
            Element::Status(_) => "status",
            Element::Garbage { .. } => "garbage",
        }
    }
}
