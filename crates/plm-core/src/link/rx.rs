//! Byte-by-byte receiver shared by both link engines: assembles frames,
//! ACK/NAK and status messages, and applies T_IC (UM0932 3.2.6): after a
//! pause longer than T_IC inside an element, the bytes so far are dropped.
//!
//! A frame that cannot be right (its checksum is wrong, or T_IC ended it
//! short) is also searched for a later STX, as [`super::StreamDecoder`]
//! does for captures: when a frame that can still be right starts there,
//! the bytes before it are garbage and reception goes on from that STX.
//! A USB-UART adapter that holds bytes back (FTDI's latency timer: 16 ms)
//! delivers the stalled tail of a frame and the modem's repeat in one
//! burst; without this, an 02h or 03h in the tail swallows the repeat.
//! See docs/protocol-notes.md, "Known limits of the host interface".

use super::{
    Dialect, Element, Frame, FrameError, GarbageReason, Source, StatusMessage, ACK, NAK,
    STATUS_FIRST,
};
use crate::time::{Duration, Instant};
use alloc::vec::Vec;

/// Whether `e` is a frame cut short: its STX and length came, T_IC ended
/// it before the length was complete (UM0932 3.2.6). The receiving side
/// answers it with NAK (3.2.7, 3.2.8: "In other cases, it answers with a
/// NAK"), except where [`Dialect::modem_naks_cut_frame`] says otherwise.
pub(crate) fn is_cut_frame(dialect: Dialect, e: &Element) -> bool {
    matches!(e, Element::Garbage { bytes, reason: GarbageReason::Truncated }
        if bytes.first().is_some_and(|&b| dialect.is_stx(b)))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Partial {
    None,
    Frame,
    Status,
    Garbage,
}

#[derive(Debug, Clone)]
pub(crate) struct Receiver {
    dialect: Dialect,
    peer: Source,
    buf: Vec<u8>,
    partial: Partial,
    /// Bytes at the start of `buf` already reported in a frame with a
    /// wrong checksum: the frame being received started inside it.
    reported: usize,
    last_byte_at: Instant,
    /// When the first byte of the element being received, or of the last
    /// one completed, arrived.
    started_at: Instant,
}

impl Receiver {
    pub(crate) fn new(dialect: Dialect, peer: Source) -> Self {
        Receiver {
            dialect,
            peer,
            buf: Vec::new(),
            partial: Partial::None,
            reported: 0,
            last_byte_at: 0,
            started_at: 0,
        }
    }

    /// Whether a frame or status message is being received.
    pub(crate) fn busy(&self) -> bool {
        matches!(self.partial, Partial::Frame | Partial::Status)
    }

    /// When the first byte of the element completed last (or being
    /// received) arrived: the host tells the ST7570's repeat from a new
    /// frame by it.
    pub(crate) fn started_at(&self) -> Instant {
        self.started_at
    }

    /// When the partial element must be dropped (or, for garbage, reported).
    pub(crate) fn deadline(&self, t_ic: Duration) -> Option<Instant> {
        (self.partial != Partial::None).then(|| self.last_byte_at + t_ic)
    }

    /// Ends the partial element if T_IC has passed.
    pub(crate) fn timeout(&mut self, now: Instant, t_ic: Duration, out: &mut Vec<Element>) {
        if self.partial != Partial::None && now >= self.last_byte_at + t_ic {
            self.flush(out);
        }
    }

    fn flush(&mut self, out: &mut Vec<Element>) {
        if self.partial == Partial::Frame {
            if self.reported > 0 && self.resync_at(false).is_none() {
                self.afresh(self.last_byte_at, out);
                return self.flush(out);
            }
            // Cut short by T_IC: a whole right frame may start inside.
            if let Some(q) = self.resync_at(false) {
                self.restart_at(q, out);
                return self.flush(out);
            }
        }
        let reason = match self.partial {
            Partial::Frame | Partial::Status => GarbageReason::Truncated,
            _ => GarbageReason::Unexpected,
        };
        self.garbage(reason, out);
    }

    /// The frame started inside a bad one is no frame either: the bytes
    /// that came after the bad one are received afresh.
    fn afresh(&mut self, at: Instant, out: &mut Vec<Element>) {
        let rest = self.buf.split_off(self.reported.min(self.buf.len()));
        self.clear();
        for b in rest {
            self.push(at, b, 0, out);
        }
    }

    /// Reports the bytes not reported yet as garbage; nothing is partial.
    fn garbage(&mut self, reason: GarbageReason, out: &mut Vec<Element>) {
        let bytes = self.buf.split_off(self.reported.min(self.buf.len()));
        if !bytes.is_empty() {
            out.push(Element::Garbage { bytes, reason });
        }
        self.clear();
    }

    fn clear(&mut self) {
        self.buf.clear();
        self.reported = 0;
        self.partial = Partial::None;
    }

    /// Where, after its STX, a frame starts in the partial frame that is
    /// whole with a right checksum, or (`incomplete`) not whole yet.
    fn resync_at(&self, incomplete: bool) -> Option<usize> {
        (1..self.buf.len()).find(|&q| {
            self.dialect.is_stx(self.buf[q])
                && match Frame::new_checked(&self.buf[q..], self.dialect) {
                    Ok(f) => f.checksum_ok(),
                    Err(e) => incomplete && matches!(e, FrameError::Truncated { .. }),
                }
        })
    }

    /// After a whole frame that cannot be right (its first `reported`
    /// bytes already reported): goes on from the first STX inside it
    /// where a frame whole and right, or not whole yet, starts. False if
    /// there is none.
    fn resync_bad(&mut self, now: Instant, out: &mut Vec<Element>) -> bool {
        let Some(q) = self.resync_at(true) else {
            return false;
        };
        if q > self.reported {
            out.push(Element::Garbage {
                bytes: self.buf[self.reported..q].to_vec(),
                reason: GarbageReason::Unexpected,
            });
        }
        self.buf.drain(..q);
        self.reported = self.reported.saturating_sub(q);
        self.started_at = now;
        if let Ok(f) = Frame::new_checked(&self.buf[..], self.dialect) {
            out.push(Element::from_frame(&f));
            self.reported = self.reported.max(f.total_len());
            self.afresh(now, out);
        }
        true
    }

    /// Reports the bytes before `q` as garbage and receives the rest again
    /// as if they had arrived with the last byte.
    fn restart_at(&mut self, q: usize, out: &mut Vec<Element>) {
        let rest = self.buf.split_off(q);
        self.garbage(GarbageReason::Unexpected, out);
        for b in rest {
            self.push(self.last_byte_at, b, 0, out);
        }
    }

    /// Takes one byte received at `now`; completed elements go to `out`.
    pub(crate) fn push(&mut self, now: Instant, byte: u8, t_ic: Duration, out: &mut Vec<Element>) {
        if self.partial != Partial::None && now > self.last_byte_at + t_ic {
            self.flush(out);
        }
        self.last_byte_at = now;
        match self.partial {
            Partial::Frame => {
                self.buf.push(byte);
                match Frame::new_checked(&self.buf[..], self.dialect) {
                    Ok(f) if f.checksum_ok() => {
                        out.push(Element::from_frame(&f));
                        self.clear();
                    }
                    // A frame that cannot be right: one still coming may
                    // have started inside it (the stall above).
                    Ok(f) if self.reported == 0 => {
                        out.push(Element::from_frame(&f));
                        self.reported = self.buf.len();
                        if !self.resync_bad(now, out) {
                            self.clear();
                        }
                    }
                    // Started inside a bad frame, and wrong too.
                    Ok(_) => {
                        if !self.resync_bad(now, out) {
                            self.afresh(now, out);
                        }
                    }
                    Err(FrameError::Truncated { .. }) => {}
                    Err(_) => {
                        // An impossible length byte: not a frame after all.
                        self.buf.drain(..self.reported);
                        self.reported = 0;
                        self.partial = Partial::Garbage;
                    }
                }
            }
            Partial::Status => {
                self.buf.push(byte);
                if self.buf.len() == self.dialect.status_len() {
                    out.push(Element::Status(StatusMessage::new(
                        self.dialect,
                        &self.buf[1..],
                    )));
                    self.buf.clear();
                    self.partial = Partial::None;
                }
            }
            Partial::None | Partial::Garbage => {
                let starts = if self.dialect.is_stx(byte) {
                    Some(Partial::Frame)
                } else if byte == STATUS_FIRST && self.peer.sends_status() {
                    Some(Partial::Status)
                } else if byte == ACK || byte == NAK {
                    Some(Partial::None)
                } else {
                    None
                };
                match starts {
                    None => {
                        self.partial = Partial::Garbage;
                        self.buf.push(byte);
                    }
                    Some(next) => {
                        self.flush(out);
                        match next {
                            Partial::None => out.push(if byte == ACK {
                                Element::Ack
                            } else {
                                Element::Nak
                            }),
                            p => {
                                self.partial = p;
                                self.started_at = now;
                                self.buf.push(byte);
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::LocalFrame;
    use alloc::vec;

    /// ST7570 UM 5.2.1: 15h is NAK and CMD_IS_Indication's code, and 06h,
    /// 15h, 3Fh and 02h may sit inside frames and status messages. What a
    /// byte means depends on where the receiver is, never on its value.
    #[test]
    fn st7570_bytes_mean_what_their_place_says() {
        let is_ind = LocalFrame::new(NAK, vec![0x01, ACK, NAK, STATUS_FIRST, 0x02]);
        let mut bytes = vec![STATUS_FIRST, 0x02, ACK, NAK, NAK];
        bytes.extend(is_ind.emit(Dialect::St7570).unwrap());
        bytes.push(ACK);
        let mut rx = Receiver::new(Dialect::St7570, Source::Modem);
        let mut out = Vec::new();
        for (i, b) in bytes.iter().enumerate() {
            rx.push(i as Instant * 100, *b, 1_000, &mut out);
        }
        let kinds: Vec<_> = out.iter().map(Element::kind).collect();
        assert_eq!(kinds, ["status", "nak", "frame", "ack"]);
        assert_eq!(
            out[0],
            Element::Status(StatusMessage::new(Dialect::St7570, &[0x02, ACK, NAK]))
        );
        assert!(
            matches!(&out[2], Element::Frame { frame, checksum_ok: true, .. } if *frame == is_ind)
        );
        // The frame began at its STX, the 6th byte.
        assert_eq!(rx.started_at(), 500);
    }

    #[test]
    fn st7570_impossible_length_is_not_a_frame() {
        // Length 02h < 3 (UM Table 10): garbage, and the NAK after it is
        // still a NAK.
        let mut rx = Receiver::new(Dialect::St7570, Source::Modem);
        let mut out = Vec::new();
        for b in [0x02, 0x02, 0x90, NAK] {
            rx.push(0, b, 1_000, &mut out);
        }
        assert_eq!(
            out,
            vec![
                Element::Garbage {
                    bytes: vec![0x02, 0x02, 0x90],
                    reason: GarbageReason::Unexpected
                },
                Element::Nak
            ]
        );
    }

    /// The stall of "Known limits": the tail of a frame and the modem's
    /// repeat in one burst. `repeat` is `03 03 2D 11 22 33 ..`.
    fn burst(tail: &[u8]) -> (Vec<Element>, LocalFrame) {
        let repeat = LocalFrame {
            stx: crate::link::Stx::Repeat,
            ..LocalFrame::new(0x2D, vec![0x11, 0x22, 0x33])
        };
        let mut bytes = tail.to_vec();
        bytes.extend(repeat.emit(Dialect::St7580).unwrap());
        let mut rx = Receiver::new(Dialect::St7580, Source::Modem);
        let mut out = Vec::new();
        for b in bytes {
            rx.push(0, b, 10_000, &mut out);
        }
        rx.timeout(10_000, 10_000, &mut out);
        (out, repeat)
    }

    #[test]
    fn a_frame_cut_short_gives_up_the_repeat_inside_it() {
        // The tail's 02h announces 40h bytes: T_IC ends it, and the
        // whole right frame inside is taken; the rest is no cut frame.
        let (out, repeat) = burst(&[0x11, 0x02, 0x40, 0x96]);
        assert_eq!(out.len(), 3, "{out:?}");
        assert_eq!(
            out[1],
            Element::Garbage {
                bytes: vec![0x02, 0x40, 0x96],
                reason: GarbageReason::Unexpected
            }
        );
        assert!(
            matches!(&out[2], Element::Frame { frame, checksum_ok: true, .. } if *frame == repeat)
        );
    }

    #[test]
    fn a_frame_with_a_wrong_checksum_gives_up_the_repeat_starting_inside_it() {
        // The tail's 02h announces 1 byte: that frame ends two bytes into
        // the repeat, checksum wrong (reported, so NAKed); the repeat
        // that started inside it is received on.
        let (out, repeat) = burst(&[0x02, 0x01, 0xAA, 0xBB]);
        assert_eq!(out.len(), 2, "{out:?}");
        assert!(matches!(
            &out[0],
            Element::Frame {
                checksum_ok: false,
                ..
            }
        ));
        assert!(
            matches!(&out[1], Element::Frame { frame, checksum_ok: true, .. } if *frame == repeat)
        );
    }
}
