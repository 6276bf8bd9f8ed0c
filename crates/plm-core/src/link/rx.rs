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
}

impl Receiver {
    pub(crate) fn new(dialect: Dialect, peer: Source) -> Self {
        Receiver {
            dialect,
            peer,
            buf: Vec::new(),
            partial: Partial::None,
            last_byte_at: 0,
        }
    }

    /// Whether a frame or status message is being received.
    pub(crate) fn busy(&self) -> bool {
        matches!(self.partial, Partial::Frame | Partial::Status)
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
                                self.buf.push(byte);
                            }
                        }
                    }
                }
            }
        }
    }
}
