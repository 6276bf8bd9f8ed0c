//! Byte-by-byte receiver shared by both link engines: assembles frames,
//! ACK/NAK and status messages, and applies T_IC (UM0932 3.2.6): after a
//! pause longer than T_IC inside an element, the bytes so far are dropped.

use super::{
    Dialect, Element, Frame, FrameError, GarbageReason, Source, StatusMessage, ACK, NAK,
    STATUS_FIRST,
};
use crate::time::{Duration, Instant};
use alloc::vec::Vec;

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
        let reason = match self.partial {
            Partial::Garbage => GarbageReason::Unexpected,
            _ => GarbageReason::Truncated,
        };
        if !self.buf.is_empty() {
            out.push(Element::Garbage {
                bytes: core::mem::take(&mut self.buf),
                reason,
            });
        }
        self.partial = Partial::None;
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
                    Ok(f) => {
                        out.push(Element::from_frame(&f));
                        self.buf.clear();
                        self.partial = Partial::None;
                    }
                    Err(FrameError::Truncated { .. }) => {}
                    Err(_) => {
                        // An impossible length byte: not a frame after all.
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
}
