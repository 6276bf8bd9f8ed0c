//! How an application frame travels over the power line, where the seed
//! is silent (docs/protocol-notes.md, "Application frames on the power
//! line"): the payload of one ST7580 DL frame (UM0932 2.3, whose CRC
//! protects it) is
//!
//! ```text
//! [type | BROADCAST_FLAG] [destination: 6 bytes] [source: 6 bytes] [payload...]
//! ```
//!
//! Both ends are named so that a reply finds its way back and a
//! concentrator can tell its own traffic from a neighbour's. A broadcast
//! goes to [`Address::BROADCAST`] with the flag set. The USART frame's one
//! address becomes the destination on the way out and is taken from the
//! source on the way back.

use super::frame::{Address, AppFrame, FrameType, BROADCAST_FLAG, MAX_PAYLOAD};
use alloc::vec::Vec;

/// Bytes before the payload.
pub const HEADER: usize = 13;

/// An application frame on the power line.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct LineFrame {
    /// Frame type.
    pub frame_type: FrameType,
    /// BROADCAST_FLAG.
    pub broadcast: bool,
    /// Who it is for.
    pub destination: Address,
    /// Who sent it.
    pub source: Address,
    /// The application payload.
    pub payload: Vec<u8>,
}

impl LineFrame {
    /// The line frame that carries `frame` from `source` (the USART
    /// frame's address is the destination; broadcasts go to all).
    pub fn from_app(frame: &AppFrame, source: Address) -> LineFrame {
        LineFrame {
            frame_type: frame.frame_type,
            broadcast: frame.broadcast,
            destination: if frame.broadcast {
                Address::BROADCAST
            } else {
                frame.address
            },
            source,
            payload: frame.payload.clone(),
        }
    }

    /// The USART frame a receiving concentrator hands its host: the
    /// address is the source's.
    pub fn to_app(&self) -> AppFrame {
        AppFrame {
            frame_type: self.frame_type,
            broadcast: self.broadcast,
            address: self.source,
            payload: self.payload.clone(),
        }
    }

    /// Whether a board at `me` takes this frame.
    pub fn is_for(&self, me: Address) -> bool {
        self.broadcast || self.destination == me
    }

    /// The DL payload.
    pub fn emit(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(HEADER + self.payload.len());
        v.push(self.frame_type.byte() | if self.broadcast { BROADCAST_FLAG } else { 0 });
        v.extend_from_slice(&self.destination.0);
        v.extend_from_slice(&self.source.0);
        v.extend_from_slice(&self.payload);
        v
    }

    /// Reads a DL payload; `None` when it cannot be a line frame (too
    /// short or too long: not every DL frame on a line is ours).
    pub fn parse(bytes: &[u8]) -> Option<LineFrame> {
        if bytes.len() < HEADER || bytes.len() > HEADER + MAX_PAYLOAD {
            return None;
        }
        let addr = |at: usize| {
            let mut a = [0; 6];
            a.copy_from_slice(&bytes[at..at + 6]);
            Address(a)
        };
        Some(LineFrame {
            frame_type: FrameType::from_byte(bytes[0]),
            broadcast: bytes[0] & BROADCAST_FLAG != 0,
            destination: addr(1),
            source: addr(7),
            payload: bytes[HEADER..].to_vec(),
        })
    }
}
