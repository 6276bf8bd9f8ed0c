//! The stream decoder: splits a byte stream (a capture, a sniffed line, a
//! pasted hex dump) into frames, ACK/NAK, status messages and garbage.
//!
//! It has no notion of time, so it cannot use T_IC to delimit frames as the
//! link engines do (UM0932 3.2.6). Instead it resynchronises by content:
//! a frame whose checksum is wrong is reported as such *unless* a frame
//! with a right checksum starts inside it, in which case the bytes before
//! that frame are garbage. The same rule guards multi-byte status messages.
//! The result does not depend on how the input is chunked.

use super::{
    Dialect, Element, Frame, FrameError, GarbageReason, Source, StatusMessage, ACK, NAK,
    STATUS_FIRST,
};
use alloc::collections::VecDeque;
use alloc::vec::Vec;

/// Incremental decoder of one direction (or both) of a host interface.
#[derive(Debug, Clone)]
pub struct StreamDecoder {
    dialect: Dialect,
    source: Source,
    buf: Vec<u8>,
    pos: usize,
    garbage: Vec<u8>,
    out: VecDeque<Element>,
    finished: bool,
}

/// What starts at a position of the buffer.
enum Probe {
    /// A whole frame of `len` bytes with a right checksum.
    Valid(usize),
    /// A whole frame with a wrong checksum.
    BadChecksum(usize),
    /// Could be a frame, more bytes are needed to know.
    NeedMore,
    /// Not a frame.
    No,
}

impl StreamDecoder {
    /// A decoder for `dialect`, reading bytes sent by `source`.
    pub fn new(dialect: Dialect, source: Source) -> Self {
        StreamDecoder {
            dialect,
            source,
            buf: Vec::new(),
            pos: 0,
            garbage: Vec::new(),
            out: VecDeque::new(),
            finished: false,
        }
    }

    /// Feeds bytes. Elements become available from [`StreamDecoder::next`]
    /// as soon as they are certain.
    pub fn push(&mut self, bytes: &[u8]) {
        if self.pos > 0 && self.pos * 2 >= self.buf.len() {
            self.buf.drain(..self.pos);
            self.pos = 0;
        }
        self.buf.extend_from_slice(bytes);
        self.run();
    }

    /// Declares the end of the input: whatever is left becomes elements.
    pub fn finish(&mut self) {
        self.finished = true;
        self.run();
        self.flush_garbage(GarbageReason::Unexpected);
    }

    /// The next decoded element, if one is complete.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Option<Element> {
        self.out.pop_front()
    }

    /// Decodes a whole input at once.
    pub fn decode_all(dialect: Dialect, source: Source, bytes: &[u8]) -> Vec<Element> {
        let mut d = StreamDecoder::new(dialect, source);
        d.push(bytes);
        d.finish();
        d.out.into_iter().collect()
    }

    fn probe(&self, at: usize) -> Probe {
        let b = &self.buf[at..];
        match Frame::new_checked(b, self.dialect) {
            Ok(f) if f.checksum_ok() => Probe::Valid(f.total_len()),
            Ok(f) => Probe::BadChecksum(f.total_len()),
            Err(FrameError::Truncated { .. }) if !self.finished => Probe::NeedMore,
            Err(_) => Probe::No,
        }
    }

    /// Looks for a valid frame starting in `from..to`: `Ok(Some(q))` found at
    /// q, `Ok(None)` none, `Err(())` cannot tell yet.
    fn valid_frame_within(&self, from: usize, to: usize) -> Result<Option<usize>, ()> {
        let mut need_more = false;
        for q in from..to.min(self.buf.len()) {
            if !self.dialect.is_stx(self.buf[q]) {
                continue;
            }
            match self.probe(q) {
                Probe::Valid(_) if !need_more => return Ok(Some(q)),
                Probe::Valid(_) | Probe::NeedMore => need_more = true,
                _ => {}
            }
        }
        if need_more || (to > self.buf.len() && !self.finished) {
            Err(())
        } else {
            Ok(None)
        }
    }

    fn emit(&mut self, e: Element) {
        self.flush_garbage(GarbageReason::Unexpected);
        self.out.push_back(e);
    }

    fn flush_garbage(&mut self, reason: GarbageReason) {
        if !self.garbage.is_empty() {
            let bytes = core::mem::take(&mut self.garbage);
            self.out.push_back(Element::Garbage { bytes, reason });
        }
    }

    fn run(&mut self) {
        while self.pos < self.buf.len() {
            let p = self.pos;
            let first = self.buf[p];
            if self.dialect.is_stx(first) {
                match self.probe(p) {
                    Probe::Valid(n) => {
                        self.take_frame(p, n);
                        continue;
                    }
                    Probe::BadChecksum(n) => match self.valid_frame_within(p + 1, p + n) {
                        Ok(Some(q)) => {
                            self.garbage.extend_from_slice(&self.buf[p..q]);
                            self.pos = q;
                            continue;
                        }
                        Ok(None) => {
                            self.take_frame(p, n);
                            continue;
                        }
                        Err(()) => return,
                    },
                    Probe::NeedMore => return,
                    Probe::No
                        if self.finished
                            && Frame::new_checked(&self.buf[p..], self.dialect)
                                .is_err_and(|e| matches!(e, FrameError::Truncated { .. })) =>
                    {
                        // A frame cut off by the end of the input: report
                        // it whole as truncated, unless a frame hides in it.
                        match self.valid_frame_within(p + 1, self.buf.len()) {
                            Ok(Some(q)) => {
                                self.garbage.extend_from_slice(&self.buf[p..q]);
                                self.pos = q;
                            }
                            _ => {
                                self.flush_garbage(GarbageReason::Unexpected);
                                self.garbage.extend_from_slice(&self.buf[p..]);
                                self.pos = self.buf.len();
                                self.flush_garbage(GarbageReason::Truncated);
                            }
                        }
                        continue;
                    }
                    Probe::No => {}
                }
            } else if first == ACK {
                self.pos += 1;
                self.emit(Element::Ack);
                continue;
            } else if first == NAK {
                self.pos += 1;
                self.emit(Element::Nak);
                continue;
            } else if first == STATUS_FIRST && self.source.sends_status() {
                let n = self.dialect.status_len();
                if p + n > self.buf.len() {
                    if !self.finished {
                        return;
                    }
                } else {
                    match self.valid_frame_within(p + 1, p + n) {
                        Err(()) => return,
                        Ok(Some(_)) => {}
                        Ok(None) => {
                            let s = StatusMessage::new(self.dialect, &self.buf[p + 1..p + n]);
                            self.pos += n;
                            self.emit(Element::Status(s));
                            continue;
                        }
                    }
                }
            }
            self.garbage.push(first);
            self.pos += 1;
        }
    }

    fn take_frame(&mut self, p: usize, n: usize) {
        let e = match Frame::new_checked(&self.buf[p..p + n], self.dialect) {
            Ok(f) => Element::from_frame(&f),
            Err(_) => return,
        };
        self.pos = p + n;
        self.emit(e);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::LocalFrame;
    use alloc::vec;

    fn ping() -> Vec<u8> {
        LocalFrame::new(0x2C, vec![1, 2, 3])
            .emit(Dialect::St7580)
            .unwrap()
    }

    #[test]
    fn splits_frames_acks_status_and_garbage() {
        let mut bytes = vec![0x3F, 0x08, 0x06];
        bytes.extend(ping());
        bytes.extend([0x15, 0xAA, 0xBB]);
        let els = StreamDecoder::decode_all(Dialect::St7580, Source::Modem, &bytes);
        let kinds: Vec<_> = els.iter().map(Element::kind).collect();
        assert_eq!(kinds, ["status", "ack", "frame", "nak", "garbage"]);
        assert_eq!(
            els[4],
            Element::Garbage {
                bytes: vec![0xAA, 0xBB],
                reason: GarbageReason::Unexpected
            }
        );
    }

    #[test]
    fn host_side_never_sends_status() {
        let els = StreamDecoder::decode_all(Dialect::St7580, Source::Host, &[0x3F, 0x08]);
        assert_eq!(
            els,
            vec![Element::Garbage {
                bytes: vec![0x3F, 0x08],
                reason: GarbageReason::Unexpected
            }]
        );
    }

    #[test]
    fn a_bad_checksum_frame_is_reported_once() {
        let mut f = ping();
        let last = f.len() - 1;
        f[last] ^= 0xFF;
        let els = StreamDecoder::decode_all(Dialect::St7580, Source::Any, &f);
        assert_eq!(els.len(), 1);
        assert!(matches!(
            els[0],
            Element::Frame {
                checksum_ok: false,
                ..
            }
        ));
    }

    #[test]
    fn a_valid_frame_inside_a_bad_candidate_wins() {
        // 02 FF looks like the start of a 260-byte frame; the ping after it
        // must still be found.
        let mut bytes = vec![0x02, 0xFF];
        bytes.extend(ping());
        bytes.extend(vec![0u8; 300]);
        let els = StreamDecoder::decode_all(Dialect::St7580, Source::Any, &bytes);
        assert!(matches!(&els[0], Element::Garbage { bytes, .. } if bytes == &[0x02, 0xFF]));
        assert!(
            matches!(&els[1], Element::Frame { checksum_ok: true, frame, .. } if frame.code == 0x2C)
        );
    }

    #[test]
    fn truncated_frame_at_end_of_input() {
        let f = ping();
        let els = StreamDecoder::decode_all(Dialect::St7580, Source::Any, &f[..4]);
        assert_eq!(
            els,
            vec![Element::Garbage {
                bytes: f[..4].to_vec(),
                reason: GarbageReason::Truncated
            }]
        );
    }

    #[test]
    fn chunking_does_not_change_the_result() {
        let mut bytes = vec![0x3F, 0x02, 0x02, 0xFF, 0x06];
        bytes.extend(ping());
        bytes.extend([0x03, 0x01]);
        let whole = StreamDecoder::decode_all(Dialect::St7580, Source::Modem, &bytes);
        let mut d = StreamDecoder::new(Dialect::St7580, Source::Modem);
        for b in &bytes {
            d.push(core::slice::from_ref(b));
        }
        d.finish();
        let chunked: Vec<_> = core::iter::from_fn(|| d.next()).collect();
        assert_eq!(whole, chunked);
    }

    #[test]
    fn st7570_nak_code_and_control_bytes_inside_elements() {
        // ST7570 UM 5.2.1: CMD_IS_Indication's code is the NAK byte; ACK,
        // NAK, `?` and STX bytes sit inside frames and status messages.
        let is_ind = LocalFrame::new(NAK, vec![0x01, ACK, NAK, STATUS_FIRST, 0x02]);
        let mut bytes = vec![STATUS_FIRST, 0x02, ACK, NAK, NAK];
        bytes.extend(is_ind.emit(Dialect::St7570).unwrap());
        bytes.push(ACK);
        let els = StreamDecoder::decode_all(Dialect::St7570, Source::Modem, &bytes);
        let kinds: Vec<_> = els.iter().map(Element::kind).collect();
        assert_eq!(kinds, ["status", "nak", "frame", "ack"]);
        assert!(
            matches!(&els[2], Element::Frame { frame, checksum_ok: true, .. } if *frame == is_ind)
        );
        // From the host, `?` starts nothing, and 03h is no STX.
        let els = StreamDecoder::decode_all(Dialect::St7570, Source::Host, &[0x3F, 0x03, NAK]);
        assert_eq!(
            els,
            vec![
                Element::Garbage {
                    bytes: vec![0x3F, 0x03],
                    reason: GarbageReason::Unexpected
                },
                Element::Nak
            ]
        );
    }
}
