//! The two host-interface dialects. Everything that differs between the
//! ST7580 and the ST7570 at the link level is answered here, once: frame
//! layout, status length, how long the host waits for the status message,
//! and when and how the modem repeats a frame.

use super::{StatusMessage, Stx, Timeouts};
use crate::time::{wire_time, Duration, Instant};

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

    /// How long the host waits for the status message after pulling T_REQ
    /// low, and again after each byte the modem sends meanwhile (it may be
    /// sending a frame of its own first: the modem is master).
    pub const fn status_wait(self, t: &Timeouts) -> Duration {
        match self {
            // UM0932 3.2.8: "as soon as the ST7580 is not busy"; no T_POLL,
            // so the host allows the T_SR it allows for its own STX.
            Dialect::St7580 => t.t_sr,
            // ST7570 UM 5.2.2: "answers within the T_POLL delay".
            Dialect::St7570 => t.t_poll,
        }
    }

    /// The STX of the modem's repeat of a frame.
    pub const fn repeat_stx(self) -> Stx {
        match self {
            Dialect::St7580 => Stx::Repeat, // UM0932 3.2.7: STX 03h
            Dialect::St7570 => Stx::First,  // ST7570 UM Table 10: 02h only
        }
    }

    /// What the modem does about the host's answer to a frame it sent.
    /// The modem waits T_ACK for an answer; [`Answer::Silence`] is that
    /// wait running out.
    pub const fn modem_reaction(self, answer: Answer, t: &Timeouts) -> Reaction {
        match (self, answer) {
            (_, Answer::Ack) => Reaction::Delivered,
            // UM0932 3.2.7: on NAK, any other frame or no answer within
            // T_ACK, repeat once "after a delay corresponding to T_ACK":
            // the repeat goes when T_ACK from the frame's end has run out.
            (Dialect::St7580, Answer::Nak | Answer::Other) => Reaction::Wait,
            (Dialect::St7580, Answer::Silence) => Reaction::Repeat { after: 0 },
            // ST7570 UM 5.2.2: "In the case of an NAK response ... repeats
            // the frame only once after a delay corresponding to T_WBC. A
            // missed response ... or a framing error when an ACK character
            // is awaited is considered as an acknowledgment."
            (Dialect::St7570, Answer::Nak) => Reaction::Repeat { after: t.t_wbc },
            (Dialect::St7570, Answer::Other | Answer::Silence) => Reaction::Delivered,
        }
    }

    /// When the first byte of the modem's repeat of a frame the host has
    /// accepted can arrive at the host (inclusive bounds): `end` is when
    /// the frame's last byte arrived, `answered` when the host's ACK had
    /// left its UART, `baud` the UART's rate. A frame with the same command
    /// and data and [`Dialect::repeat_stx`] whose first byte arrives in the
    /// window is that repeat (the modem took a damaged ACK for a NAK, or
    /// for the ST7580 missed it), not a new frame.
    pub fn repeat_window(
        self,
        t: &Timeouts,
        end: Instant,
        answered: Instant,
        baud: u32,
    ) -> (Instant, Instant) {
        let char_time = wire_time(1, baud);
        match self {
            // The repeat leaves T_ACK after the frame's end; STX 03h already
            // tells it apart, so the window only has to be generous: twice
            // T_ACK.
            Dialect::St7580 => (end, end + 2 * t.t_ack + char_time),
            // The repeat leaves T_WBC after the modem has the "NAK", that
            // is when the host's answer has left; up to T_WBC late. A new
            // frame sent right after a received ACK comes before.
            Dialect::St7570 => {
                let from = answered + t.t_wbc + char_time;
                (from, from + t.t_wbc)
            }
        }
    }

    /// Bits of the status message's first data byte that mean "not now":
    /// the status does not confirm the data channel's availability
    /// (UM0932 3.2.5, 3.2.8). ST7580: Table 8 bits 1 and 2, a power line
    /// frame being transmitted or received. ST7570: none; Table 11 has no
    /// such bit and its BUSY is the PHY layer's state (docs/protocol-notes.md,
    /// "ST7570: link").
    pub const fn not_now_bits(self) -> u8 {
        match self {
            Dialect::St7580 => 0b0000_0110,
            Dialect::St7570 => 0,
        }
    }

    /// Whether `status` says "not now" ([`Dialect::not_now_bits`]).
    pub fn not_now(self, status: &StatusMessage) -> bool {
        status
            .data()
            .first()
            .is_some_and(|b| b & self.not_now_bits() != 0)
    }

    /// Whether the modem answers a host frame cut short by T_IC with NAK
    /// (UM0932 3.2.8: "In other cases, it answers with a NAK"). The
    /// ST7570 answers it with a CMD_SyntaxError frame instead (ST7570 UM
    /// 5.3.26: "the value declared in the length field has not been
    /// respected"; NAK only for a wrong checksum), which its model sends
    /// on [`super::device::DeviceEvent::FrameCut`].
    pub const fn modem_naks_cut_frame(self) -> bool {
        matches!(self, Dialect::St7580)
    }

    /// Short name, as the CLI spells it.
    pub const fn name(self) -> &'static str {
        match self {
            Dialect::St7580 => "st7580",
            Dialect::St7570 => "st7570",
        }
    }
}

/// The host's answer to a modem frame, as the modem sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// ACK (06h) after the frame's last byte.
    Ack,
    /// NAK (15h) after the frame's last byte.
    Nak,
    /// Anything else: a damaged character, a frame.
    Other,
    /// Nothing within T_ACK.
    Silence,
}

/// What the modem does about an [`Answer`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reaction {
    /// The frame is delivered (acknowledged, or counted as such).
    Delivered,
    /// Nothing yet: the outcome comes with T_ACK.
    Wait,
    /// Repeat the frame once, `after` this long; the repeat is delivered
    /// whatever comes back.
    Repeat {
        /// Delay before the repeat.
        after: Duration,
    },
}
