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
//! - DL_DataRequest, DL_DataIndication and DL_SnifferIndication: `app` in
//!   `fields`, the application frame the DL payload carries
//!   ([`crate::decode_app`]), when it can be one.

use crate::field::{Field, Value};
use crate::hex;
use crate::json::{json_record, Json, Object};
use crate::link::{Dialect, Element, GarbageReason, Source, StreamDecoder};
use crate::st7580::fields::{indication_data, reset_data, status, tx_options};
use crate::st7580::{self, code as c, Command};
use alloc::string::{String, ToString};
use alloc::vec::Vec;

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
    checksum,
    checksum_ok,
    fields,
    error,
    reason,
});

/// A field value as JSON: numbers as numbers, enums by the manual's name,
/// bytes as lowercase hex, "no value" as null.
pub fn json_value(v: &Value) -> Json {
    match v {
        Value::Uint(n) => Json::from(*n),
        Value::Int(n) => Json::from(*n),
        Value::Flag(b) => Json::Bool(*b),
        Value::Enum { name: Some(n), .. } => Json::String((*n).to_string()),
        Value::Enum { raw, name: None } => Json::from(*raw),
        Value::Bytes(b) => Json::String(hex::encode(b)),
        Value::Absent => Json::Null,
    }
}

pub(crate) fn put_layout(map: &mut Object, layout: &'static [Field], data: &[u8]) {
    for (f, v) in crate::mib::describe(layout, data) {
        map.insert(f.name, json_value(&v));
    }
}

fn put_hex(map: &mut Object, key: &str, bytes: &[u8]) {
    map.insert(key, Json::String(hex::encode(bytes)));
}

/// Decodes a host-interface stream into [`Decoded`] elements, keeping the
/// context a single frame lacks (the index of a pending MIB_ReadRequest,
/// which names the object in the following MIB_ReadConfirm).
#[derive(Debug, Clone)]
pub struct Decoder {
    dialect: Dialect,
    source: Source,
    stream: StreamDecoder,
    pending_read: Option<u8>,
}

impl Decoder {
    /// A decoder of bytes sent by `source`.
    pub fn new(dialect: Dialect, source: Source) -> Self {
        Decoder {
            dialect,
            source,
            stream: StreamDecoder::new(dialect, source),
            pending_read: None,
        }
    }

    /// Names the object of MIB_ReadConfirm frames when the request is not
    /// in the input (a capture of the modem side only).
    pub fn assume_mib_read(&mut self, index: u8) {
        self.pending_read = Some(index);
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

    /// Decodes one element (updating the MIB read context).
    pub fn decode(&mut self, e: &Element) -> Decoded {
        let mut d = Decoded {
            kind: e.kind().to_string(),
            from: match self.source {
                Source::Host => Some("host".into()),
                Source::Modem => Some("modem".into()),
                Source::Any => None,
            },
            hex: hex::encode(&e.to_bytes(self.dialect)),
            stx: None,
            length: None,
            code: None,
            command: None,
            checksum: None,
            checksum_ok: None,
            fields: None,
            error: None,
            reason: None,
        };
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
                if self.dialect == Dialect::St7580 {
                    d.command =
                        Some(c::name(frame.code).map_or(Json::Null, |n| Json::String(n.into())));
                    let mut fields = Object::new();
                    match Command::parse(frame.code, &frame.data) {
                        Ok(cmd) => d.error = self.command_fields(&cmd, &frame.data, &mut fields),
                        Err(err) => {
                            put_hex(&mut fields, "data", &frame.data);
                            d.error = Some(err.to_string());
                        }
                    }
                    d.fields = Some(fields);
                } else {
                    let mut fields = Object::new();
                    put_hex(&mut fields, "data", &frame.data);
                    d.fields = Some(fields);
                }
            }
            Element::Status(s) => {
                let mut fields = Object::new();
                if self.dialect == Dialect::St7580 {
                    put_layout(&mut fields, status::LAYOUT, s.data());
                } else {
                    put_hex(&mut fields, "data", s.data());
                }
                d.fields = Some(fields);
            }
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

    /// Fills `f` with the named fields of `cmd`; returns what the modem
    /// would refuse about it, if anything.
    /// `data` is the frame's data field, from which the layouts read
    /// directly (nothing is re-encoded).
    fn command_fields(&mut self, cmd: &Command, data: &[u8], f: &mut Object) -> Option<String> {
        use Command::*;
        let mut problem = None;
        match cmd {
            BioResetRequest | MibWriteConfirm | MibEraseConfirm => {}
            BioResetConfirm { confirm_data } => {
                f.insert("confirm_data", Json::from(*confirm_data));
            }
            BioResetError(e) | MibWriteError(e) | MibReadError(e) | MibEraseError(e)
            | PhyDataError(e) | DlDataError(e) | SsDataError(e) => {
                f.insert(
                    "error_data",
                    e.name()
                        .map_or(Json::from(e.byte()), |n| Json::String(n.into())),
                );
            }
            BioResetIndication(r) => put_layout(f, reset_data::LAYOUT, &[r.byte()]),
            MibWriteRequest { index, data } => {
                problem = put_object(f, *index, data);
                if let Err(e) = st7580::mib::check_write(*index, data) {
                    problem = Some(alloc::format!("the modem will refuse this write: {e}"));
                }
            }
            MibReadRequest { index } | MibEraseRequest { index } => {
                f.insert("index", Json::from(*index));
                let name = st7580::mib::object(*index).map(|o| o.name);
                f.insert(
                    "object",
                    name.map_or(Json::Null, |n| Json::String(n.into())),
                );
                if matches!(cmd, MibReadRequest { .. }) {
                    self.pending_read = Some(*index);
                }
            }
            MibReadConfirm { data } => match self.pending_read.take() {
                Some(index) => problem = put_object(f, index, data),
                None => put_hex(f, "data", data),
            },
            PingRequest { data } | PingConfirm { data } | Unknown { data, .. } => {
                put_hex(f, "data", data)
            }
            PhyDataRequest(r) | DlDataRequest(r) => {
                put_tx_params(f, data, &r.params);
                put_hex(f, "payload", &r.payload);
                if matches!(cmd, DlDataRequest(_)) {
                    put_app(f, &r.payload);
                }
            }
            SsDataRequest(r) => {
                put_tx_params(f, data, &r.params);
                f.insert(tx_options::HEADER_LENGTH.name, Json::from(r.header_length));
                put_hex(f, "header_and_payload", &r.header_and_payload);
            }
            PhyDataConfirm(_) | DlDataConfirm(_) | SsDataConfirm(_) => {
                put_layout(f, st7580::fields::confirm_data::LAYOUT, data)
            }
            PhyDataIndication(i)
            | DlDataIndication(i)
            | DlSnifferIndication(i)
            | SsDataIndication(i)
            | SsSnifferIndication(i) => {
                put_layout(f, indication_data::LAYOUT, data);
                let key = match cmd {
                    PhyDataIndication(_) => "phy_payload",
                    DlDataIndication(_) => "dl_payload",
                    DlSnifferIndication(_) => "dl_payload_and_wrong_crc",
                    SsDataIndication(_) => "ss_header_and_payload",
                    _ => "ss_sdu",
                };
                put_hex(f, key, &i.payload);
                if matches!(cmd, DlDataIndication(_) | DlSnifferIndication(_)) {
                    put_app(f, &i.payload);
                }
            }
            CmdSyntaxError { error } => {
                f.insert("error", Json::from(*error));
            }
        }
        problem
    }
}

/// Index, object name and fields of a MIB value; a problem if the value
/// does not fit the object.
fn put_object(f: &mut Object, index: u8, data: &[u8]) -> Option<String> {
    f.insert("index", Json::from(index));
    let Some(o) = st7580::mib::object(index) else {
        f.insert("object", Json::Null);
        put_hex(f, "data", data);
        return Some(alloc::format!("there is no MIB object {index:02X}h"));
    };
    f.insert("object", Json::String(o.name.into()));
    put_hex(f, "data", data);
    if data.len() != o.len {
        return Some(alloc::format!(
            "{} is {} bytes long, not {}",
            o.name,
            o.len,
            data.len()
        ));
    }
    put_layout(f, o.fields, data);
    None
}

/// The application frame a DL payload carries over the power line
/// (`app::line`), under the key `app`, when the payload can be one. A
/// sniffed frame's payload still ends with its wrong DL CRC, whose length
/// the indication does not give: it shows as the last payload bytes.
fn put_app(f: &mut Object, payload: &[u8]) {
    if let Some(line) = crate::app::LineFrame::parse(payload) {
        f.insert("app", crate::decode_app::decode_line(&line).to_json());
    }
}

fn put_tx_params(f: &mut Object, bytes: &[u8], p: &st7580::TxParams) {
    put_layout(f, tx_options::LAYOUT, bytes);
    if let Some(hz) = p.tx_frequency {
        f.insert(tx_options::TX_FREQUENCY.name, Json::from(hz));
    }
    if let Some(g) = p.tx_gain {
        f.insert(tx_options::TX_GAIN.name, Json::from(g));
    }
}

/// Decodes a whole input at once.
pub fn decode_all(dialect: Dialect, source: Source, bytes: &[u8]) -> Vec<Decoded> {
    let mut d = Decoder::new(dialect, source);
    d.push(bytes);
    d.finish();
    core::iter::from_fn(|| d.next()).collect()
}
