//! The board's USART: application frames back to back, no T_REQ and no
//! ACK/NAK of the modem's host interface (STEVAL-IHP007V1 UM 4.6). The
//! stream decoder finds frames by their length byte and CRC-16 and
//! resynchronises after garbage: a byte that does not start a frame with
//! a right CRC is set aside and the search goes on from the next byte, so
//! a damaged frame costs only itself.

use super::crc::crc16;
use super::frame::{AppFrame, MAX_LEN, MIN_LEN};
use alloc::collections::VecDeque;
use alloc::vec::Vec;

/// One element of a USART stream.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UsartElement {
    /// A frame whose CRC is right.
    Frame {
        /// The frame.
        frame: AppFrame,
        /// Its bytes as on the wire.
        bytes: Vec<u8>,
    },
    /// Bytes that are a frame by their length but whose CRC is wrong.
    BadCrc {
        /// The frame as read.
        frame: AppFrame,
        /// Its bytes.
        bytes: Vec<u8>,
    },
    /// Bytes that are no frame.
    Garbage(Vec<u8>),
}

impl UsartElement {
    /// The bytes as on the wire.
    pub fn bytes(&self) -> &[u8] {
        match self {
            UsartElement::Frame { bytes, .. } | UsartElement::BadCrc { bytes, .. } => bytes,
            UsartElement::Garbage(b) => b,
        }
    }
}

/// The stream decoder of a board USART.
#[derive(Debug, Clone, Default)]
pub struct UsartDecoder {
    buf: VecDeque<u8>,
    garbage: Vec<u8>,
    out: VecDeque<UsartElement>,
}

impl UsartDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Feeds bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend(bytes);
        self.scan(false);
    }

    /// The line went quiet: a frame begun cannot be completed, so what is
    /// buffered is searched again from its second byte.
    pub fn idle(&mut self) {
        self.scan(true);
        self.flush_garbage();
    }

    /// Whether bytes wait for the rest of a frame.
    pub fn is_partial(&self) -> bool {
        !self.buf.is_empty()
    }

    /// The next element.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Option<UsartElement> {
        self.out.pop_front()
    }

    /// Decodes a whole capture.
    pub fn decode_all(bytes: &[u8]) -> Vec<UsartElement> {
        let mut d = UsartDecoder::new();
        d.push(bytes);
        d.idle();
        core::iter::from_fn(|| d.next()).collect()
    }

    fn scan(&mut self, idle: bool) {
        loop {
            let Some(&len) = self.buf.front() else { return };
            let l = len as usize;
            if (MIN_LEN..=MAX_LEN).contains(&l) && self.buf.len() >= l {
                let bytes: Vec<u8> = self.buf.iter().take(l).copied().collect();
                let crc = u16::from_be_bytes([bytes[l - 2], bytes[l - 1]]);
                if crc == crc16(&bytes[..l - 2]) {
                    self.flush_garbage();
                    self.buf.drain(..l);
                    if let Ok((frame, _)) = AppFrame::parse_unchecked(&bytes) {
                        self.out.push_back(UsartElement::Frame { frame, bytes });
                    }
                    continue;
                }
            } else if (MIN_LEN..=MAX_LEN).contains(&l) && !idle {
                return; // wait for the rest
            }
            let b = self.buf.pop_front().expect("front exists");
            self.garbage.push(b);
        }
    }

    /// Set-aside bytes become one element: a frame with a wrong CRC when
    /// their own length byte spans them exactly, garbage otherwise.
    fn flush_garbage(&mut self) {
        if self.garbage.is_empty() {
            return;
        }
        let bytes = core::mem::take(&mut self.garbage);
        let el = match AppFrame::parse_unchecked(&bytes) {
            Ok((frame, _)) if bytes[0] as usize == bytes.len() => {
                UsartElement::BadCrc { frame, bytes }
            }
            _ => UsartElement::Garbage(bytes),
        };
        self.out.push_back(el);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::frame::{Address, FrameType};

    fn ping(n: u8) -> Vec<u8> {
        AppFrame::new(FrameType::Ping, Address([0, 0, 0, 0, 0, n]), Vec::new())
            .emit()
            .unwrap()
    }

    #[test]
    fn resynchronises_after_garbage_and_a_damaged_frame() {
        let mut bytes = alloc::vec![0xFF, 0x0C, 0x01];
        let mut bad = ping(1);
        bad[5] ^= 0x10;
        bytes.extend_from_slice(&bad);
        bytes.extend_from_slice(&ping(2));
        let els = UsartDecoder::decode_all(&bytes);
        let frames: Vec<_> = els
            .iter()
            .filter_map(|e| match e {
                UsartElement::Frame { frame, .. } => Some(frame.address.0[5]),
                _ => None,
            })
            .collect();
        assert_eq!(frames, [2]);
        let all: Vec<u8> = els.iter().flat_map(|e| e.bytes().to_vec()).collect();
        assert_eq!(all, bytes, "no byte is lost");
    }

    #[test]
    fn a_damaged_frame_alone_is_shown_as_a_frame_with_a_wrong_crc() {
        let mut bad = ping(1);
        bad[9] ^= 1;
        let els = UsartDecoder::decode_all(&bad);
        assert!(
            matches!(els.as_slice(), [UsartElement::BadCrc { .. }]),
            "{els:?}"
        );
    }

    #[test]
    fn frames_split_across_pushes_are_joined() {
        let p = ping(3);
        let mut d = UsartDecoder::new();
        d.push(&p[..4]);
        assert!(d.next().is_none());
        d.push(&p[4..]);
        assert!(matches!(d.next(), Some(UsartElement::Frame { .. })));
    }
}
