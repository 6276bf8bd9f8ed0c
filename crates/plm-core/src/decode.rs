//! The named-field view of stream elements: what `plm decode` prints as
//! JSON Lines and what the console's traffic inspector shows, exports and
//! imports. One object per element:
//!
//! - `kind`: `frame`, `ack`, `nak`, `status` or `garbage`;
//! - `hex`: the element's bytes exactly as on the wire;
//! - frames: `stx`, `length`, `code`, `command` (the manual's name, `null`
//!   for an unknown code), `checksum`, `checksum_ok`, and `fields` named
//!   after the manual's labels in snake_case;
//! - `error` when the data does not fit the command, `reason` for garbage;
//! - ST7580: `warning` when UM0932 forbids what a frame that decodes says
//!   (a request from the modem or a confirm, error or indication from the
//!   host under `--from`, a BIO_ResetConfirm whose data is not 00h, a data
//!   request the modem refuses, by `st7580::validate::check_request`);
//! - ST7580: `repeat: true` on a frame with STX 03h (the modem's repeat,
//!   UM0932 3.2.7), and `after_t_ack: true` on the host's ACK that the
//!   capture shows came after that repeat had started, so after T_ACK (the
//!   original had no ACK or NAK before its repeat): the reason the modem
//!   repeated, for someone debugging their own host code.
//!
//! What differs between the chips is answered by the chip's module, chosen
//! once from the dialect ([`Chip::new`]): [`st7580`] (MIB_ReadConfirm named
//! by the request before it; DL payloads carrying application frames)
//! and [`st7570`] (the access layer the frames are read in, named in
//! `layer`; MIB frames that carry their index). Frames from the ST7570's
//! power line itself are [`decode_line`]'s ([`LineDecoded`]).

pub mod app;
#[cfg(feature = "st7570")]
mod st7570;
#[cfg(feature = "st7570")]
mod st7570_line;
mod st7580;

#[cfg(feature = "st7570")]
pub use st7570_line::{decode_line, LineDecoded};

use crate::hex;
use crate::json::{json_record, Json, Object};
use crate::link::{Dialect, Element, GarbageReason, LocalFrame, Source, StreamDecoder};
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use app::AppDecoded;

/// One decoded element, ready to serialise as a JSON line.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded {
    /// `frame`, `ack`, `nak`, `status` or `garbage`.
    pub kind: String,
    /// Who sent it, when known (`host` or `modem`).
    pub from: Option<String>,
    /// The bytes as on the wire, lowercase hex.
    pub hex: String,
    /// STX byte (frames).
    pub stx: Option<u8>,
    /// Length byte as sent (frames).
    pub length: Option<u8>,
    /// Command code (frames).
    pub code: Option<u8>,
    /// The manual's command name; `null` for a code it does not define.
    pub command: Option<Json>,
    /// The access layer a frame was read in, or a status message gives
    /// (`PHY` or `MAC`; ST7570 only).
    pub layer: Option<String>,
    /// The checksum as received (frames).
    pub checksum: Option<u16>,
    /// Whether the checksum is right (frames).
    pub checksum_ok: Option<bool>,
    /// Named fields (frames, status messages).
    pub fields: Option<Object>,
    /// Why the data could not be decoded, or what the modem will refuse.
    pub error: Option<String>,
    /// Why bytes are garbage: `unexpected` or `truncated`.
    pub reason: Option<String>,
    /// ST7580: a frame with STX 03h, the repeat of the frame before it
    /// (UM0932 3.2.7).
    pub repeat: Option<bool>,
    /// ST7580: an ACK that came after the modem had started repeating the
    /// frame it answers, so after T_ACK (UM0932 3.2.7); known only from a
    /// capture of both directions.
    pub after_t_ack: Option<bool>,
    /// ST7580: what UM0932 forbids of a frame that still decodes (a code
    /// sent the wrong way, a BIO_ResetConfirm whose data is not 00h, a
    /// data request the modem refuses); several are joined by "; ".
    pub warning: Option<String>,
}

// The object `plm decode` prints, and the console exports and imports.
json_record!(Decoded {
    kind,
    from,
    hex,
    stx,
    length,
    code,
    command,
    layer,
    checksum,
    checksum_ok,
    fields,
    error,
    reason,
    repeat,
    after_t_ack,
    warning,
});

// An application frame in this decoder's shape lives beside the shape, so
// that `decode::app`, which `decode` uses for the frames a DL frame carries,
// uses nothing of `decode`.
impl AppDecoded {
    /// The same element in the modem decoder's shape, so that one traffic
    /// inspector (and its export) shows both: `from` is who sent it
    /// (`host` or `board`); the command is the frame's name, the checksum
    /// its CRC-16, and the address, frame type, broadcast flag and
    /// direction lead its fields.
    pub fn to_decoded(&self, from: &str) -> Decoded {
        let mut fields = Object::new();
        let mut put = |k: &str, v: Option<Json>| {
            if let Some(v) = v {
                fields.insert(k.to_string(), v);
            }
        };
        put("address", self.address.clone().map(Json::String));
        put("destination", self.destination.clone().map(Json::String));
        put("source", self.source.clone().map(Json::String));
        put("frame_type", self.frame_type.clone());
        put("broadcast", self.broadcast.map(Json::Bool));
        put("direction", self.direction.clone().map(Json::String));
        if let Some(f) = &self.fields {
            fields.extend(f.clone());
        }
        Decoded {
            kind: self.kind.clone(),
            from: Some(from.to_string()),
            hex: self.hex.clone(),
            stx: None,
            length: self.length,
            code: None,
            command: self.command.clone().or_else(|| self.frame_type.clone()),
            layer: None,
            checksum: self.crc,
            checksum_ok: self.crc_ok,
            fields: Some(fields),
            error: self.error.clone(),
            reason: None,
            repeat: None,
            after_t_ack: None,
            warning: None,
        }
    }
}

pub(crate) fn put_hex(map: &mut Object, key: &str, bytes: &[u8]) {
    map.insert(key, Json::String(hex::encode(bytes)));
}

/// The chip whose host interface is decoded, with the context its frames
/// need that a single frame lacks.
#[derive(Debug, Clone)]
enum Chip {
    St7580(st7580::Context),
    #[cfg(feature = "st7570")]
    St7570(st7570::Context),
    /// The ST7570 without its names (plm-core built without the `st7570`
    /// feature, as the console is until it speaks the chip): frames,
    /// status messages and the rest at the link level only.
    #[cfg(not(feature = "st7570"))]
    Unnamed,
}

impl Chip {
    /// The one place where the dialect picks the chip's decoding.
    fn new(dialect: Dialect) -> Chip {
        match dialect {
            Dialect::St7580 => Chip::St7580(st7580::Context::default()),
            #[cfg(feature = "st7570")]
            Dialect::St7570 => Chip::St7570(st7570::Context::default()),
            #[cfg(not(feature = "st7570"))]
            Dialect::St7570 => Chip::Unnamed,
        }
    }

    /// Command name, layer, fields and error of a frame sent by `from`.
    fn frame(&mut self, from: Source, frame: &LocalFrame, d: &mut Decoded) {
        match self {
            Chip::St7580(c) => c.frame(from, frame, d),
            #[cfg(feature = "st7570")]
            Chip::St7570(c) => c.frame(from, frame, d),
            #[cfg(not(feature = "st7570"))]
            Chip::Unnamed => {
                let _ = (from, frame, d);
            }
        }
    }

    /// Fields (and layer) of a status message: its bytes after `?`.
    fn status(&mut self, data: &[u8], d: &mut Decoded) {
        match self {
            Chip::St7580(_) => st7580::status(data, d),
            #[cfg(feature = "st7570")]
            Chip::St7570(c) => c.status(data, d),
            #[cfg(not(feature = "st7570"))]
            Chip::Unnamed => {
                let _ = (data, d);
            }
        }
    }
}

/// Decodes a host-interface stream into [`Decoded`] elements, keeping the
/// context a single frame lacks: for the ST7580 the index of a pending
/// MIB_ReadRequest, which names the object of the following
/// MIB_ReadConfirm; for the ST7570 the access layer (and operating mode)
/// the last status message or MIB 00A1h frame set.
#[derive(Debug, Clone)]
pub struct Decoder {
    dialect: Dialect,
    source: Source,
    stream: StreamDecoder,
    chip: Chip,
    /// ST7580: the last frame with STX 02h had no ACK or NAK before its
    /// repeat came: the next ACK is late.
    ack_overdue: bool,
    /// ST7580: the last frame with STX 02h, and whether an ACK or NAK
    /// followed it.
    last_first: Option<(LocalFrame, bool)>,
}

impl Decoder {
    /// A decoder of bytes sent by `source`.
    pub fn new(dialect: Dialect, source: Source) -> Self {
        Decoder {
            dialect,
            source,
            stream: StreamDecoder::new(dialect, source),
            chip: Chip::new(dialect),
            ack_overdue: false,
            last_first: None,
        }
    }

    /// Names the object of MIB_ReadConfirm frames when the request is not
    /// in the input (a capture of the modem side only). ST7580 only: an
    /// ST7570 CMD_ReadDBConfirm carries its INDEX.
    pub fn assume_mib_read(&mut self, index: u8) {
        if let Chip::St7580(c) = &mut self.chip {
            c.assume_mib_read(index);
        }
    }

    /// Reads every ST7570 frame in `layer`, whatever status messages and
    /// MIB 00A1h frames in the input say (`plm decode --layer`). Without
    /// it the layer is PHY (the factory default of 00A1h) until the input
    /// says otherwise. No effect on an ST7580 decoder.
    #[cfg(feature = "st7570")]
    pub fn fix_layer(&mut self, layer: crate::st7570::Layer) {
        if let Chip::St7570(c) = &mut self.chip {
            c.fix_layer(layer);
        }
    }

    /// The ST7570 access layer the input has set so far (PHY, the factory
    /// default, until it says otherwise); `None` for an ST7580 decoder.
    #[cfg(feature = "st7570")]
    pub fn layer(&self) -> Option<crate::st7570::Layer> {
        match &self.chip {
            Chip::St7570(c) => Some(c.layer()),
            _ => None,
        }
    }

    /// Feeds bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.stream.push(bytes);
    }

    /// Ends the input.
    pub fn finish(&mut self) {
        self.stream.finish();
    }

    /// The next decoded element.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Option<Decoded> {
        let e = self.stream.next()?;
        Some(self.decode(&e))
    }

    /// Decodes one element (updating the context).
    pub fn decode(&mut self, e: &Element) -> Decoded {
        self.decode_from(self.source, e)
    }

    /// Decodes one element sent by `source`: for a driver that sees both
    /// directions, as the console's session does (one context for both).
    pub fn decode_from(&mut self, source: Source, e: &Element) -> Decoded {
        let mut d = Decoded {
            kind: e.kind().to_string(),
            from: match source {
                Source::Host => Some("host".into()),
                Source::Modem => Some("modem".into()),
                Source::Any => None,
            },
            hex: hex::encode(&e.to_bytes(self.dialect)),
            stx: None,
            length: None,
            code: None,
            command: None,
            layer: None,
            checksum: None,
            checksum_ok: None,
            fields: None,
            error: None,
            reason: None,
            repeat: None,
            after_t_ack: None,
            warning: None,
        };
        if self.dialect == Dialect::St7580 {
            self.repeats(e, &mut d);
        }
        match e {
            Element::Frame {
                frame,
                checksum,
                checksum_ok,
            } => {
                d.stx = Some(frame.stx.byte());
                d.length = self.dialect.length_byte(frame.data.len());
                d.code = Some(frame.code);
                d.checksum = Some(*checksum);
                d.checksum_ok = Some(*checksum_ok);
                self.chip.frame(source, frame, &mut d);
            }
            Element::Status(s) => self.chip.status(s.data(), &mut d),
            Element::Garbage { reason, .. } => {
                d.reason = Some(
                    match reason {
                        GarbageReason::Unexpected => "unexpected",
                        GarbageReason::Truncated => "truncated",
                    }
                    .into(),
                );
            }
            Element::Ack | Element::Nak => {}
        }
        d
    }
}

impl Decoder {
    /// UM0932 3.2.7: the modem repeats a frame with STX 03h once, T_ACK
    /// after it, when no ACK came. A repeat whose original had neither ACK
    /// nor NAK before it makes the next ACK a late one.
    fn repeats(&mut self, e: &Element, d: &mut Decoded) {
        match e {
            Element::Frame { frame, .. } if frame.stx == crate::link::Stx::Repeat => {
                d.repeat = Some(true);
                if let Some((first, answered)) = self.last_first.take() {
                    self.ack_overdue =
                        !answered && first.code == frame.code && first.data == frame.data;
                }
            }
            Element::Frame { frame, .. } => {
                self.last_first = Some((frame.clone(), false));
                self.ack_overdue = false;
            }
            Element::Ack | Element::Nak => {
                if let Some((_, answered)) = &mut self.last_first {
                    *answered = true;
                }
                if *e == Element::Ack && self.ack_overdue {
                    d.after_t_ack = Some(true);
                }
                self.ack_overdue = false;
            }
            _ => {}
        }
    }
}

/// Decodes a whole input at once.
pub fn decode_all(dialect: Dialect, source: Source, bytes: &[u8]) -> Vec<Decoded> {
    let mut d = Decoder::new(dialect, source);
    d.push(bytes);
    d.finish();
    core::iter::from_fn(|| d.next()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_decoder_for_both_directions_knows_who_sent_each_element() {
        // PingConfirm (UM0932 Table 11): the modem's to send, not the host's.
        let mut d = Decoder::new(Dialect::St7580, Source::Any);
        d.push(&hex::parse("02 01 2d 07 35 00").unwrap());
        let e = d.stream.next().unwrap();
        assert_eq!(d.decode(&e).warning, None);
        let host = d.decode_from(Source::Host, &e);
        assert_eq!(host.from.as_deref(), Some("host"));
        assert!(host.warning.unwrap().contains("never from the host"));
        assert_eq!(d.decode_from(Source::Modem, &e).warning, None);
    }
}
