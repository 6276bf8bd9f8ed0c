//! The named-field view of the street-light board's application frames
//! (STEVAL-IHP007V1 UM 4.5-4.6, Appendix A): what `plm decode --board`
//! prints as JSON Lines and what the console's traffic inspector shows for
//! a board USART, and the `app` key of a DL frame that carries a
//! [`LineFrame`]. One object per element:
//!
//! - `kind`: `frame` or `garbage`; `hex`: the bytes as on the wire;
//! - frames: `length` (the length byte, USART frames only), `code` (the
//!   frame type value, bits 0-6), `frame_type` (the seed's name, `null`
//!   for a type it does not define), `broadcast`, `address` (USART) or
//!   `destination` and `source` (power line), `command` (the seed's name
//!   of the service command, HID command or frame type), `direction`
//!   (`request` or `reply`, where the bytes tell), `fields` named after the
//!   seed, `crc` and `crc_ok` (USART frames only: on the power line the DL
//!   CRC protects the frame);
//! - `error`, in words, when the payload does not fit its frame type.
//!
//! Field names, offsets and units come from the one description in
//! [`crate::app::service`] and [`crate::app::hid`]; nothing is listed here.

use crate::app::hid::{self, Hid};
use crate::app::service::{self, Service};
use crate::app::{AppFrame, FrameType, LineFrame, Message, UsartDecoder, UsartElement};
use crate::field_json::put_layout;
use crate::hex;
use crate::json::{json_record, Json, Object};
use crate::st7580;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

/// One decoded application frame or run of garbage, ready to serialise as
/// a JSON line.
#[derive(Debug, Clone, PartialEq)]
pub struct AppDecoded {
    /// `frame` or `garbage`.
    pub kind: String,
    /// The bytes as on the wire (USART frame, or DL payload), lowercase hex.
    pub hex: String,
    /// Length byte as sent (USART frames).
    pub length: Option<u8>,
    /// Frame type value, bits 0-6 of the type byte.
    pub code: Option<u8>,
    /// The seed's name of the frame type (`APP_SERVICE_FRAME`); `null` for
    /// a type it does not define.
    pub frame_type: Option<Json>,
    /// BROADCAST_FLAG (4.6.1).
    pub broadcast: Option<bool>,
    /// The remote board (USART frames): target of a request, source of an
    /// answer; 12 lowercase hex digits.
    pub address: Option<String>,
    /// Who a line frame is for.
    pub destination: Option<String>,
    /// Who sent a line frame.
    pub source: Option<String>,
    /// The seed's name of what the frame says (`SERVICE_PLM_CLOCK_GET`,
    /// `Lamp dimming`, `APP_PING_FRAME`); `null` for an unknown type.
    pub command: Option<Json>,
    /// `request` or `reply`, when the frame tells.
    pub direction: Option<String>,
    /// Named fields.
    pub fields: Option<Object>,
    /// The CRC-16 as received (USART frames, Appendix C).
    pub crc: Option<u16>,
    /// Whether the CRC-16 is right.
    pub crc_ok: Option<bool>,
    /// Why the payload does not fit its frame type, in words.
    pub error: Option<String>,
}

// The object `plm decode --board` prints, and the `app` key of a DL frame.
json_record!(AppDecoded {
    kind,
    hex,
    length,
    code,
    frame_type,
    broadcast,
    address,
    destination,
    source,
    command,
    direction,
    fields,
    crc,
    crc_ok,
    error,
});

impl AppDecoded {
    fn new(kind: &str, bytes: &[u8]) -> Self {
        AppDecoded {
            kind: kind.into(),
            hex: hex::encode(bytes),
            length: None,
            code: None,
            frame_type: None,
            broadcast: None,
            address: None,
            destination: None,
            source: None,
            command: None,
            direction: None,
            fields: None,
            crc: None,
            crc_ok: None,
            error: None,
        }
    }

    /// Type, broadcast flag, command, direction, fields and error of a
    /// frame's type byte and payload.
    fn put_payload(&mut self, frame_type: FrameType, broadcast: bool, payload: &[u8]) {
        self.code = Some(frame_type.byte());
        self.frame_type = Some(name_or_null(frame_type.name()));
        self.broadcast = Some(broadcast);
        let mut fields = Object::new();
        match Message::parse(frame_type, payload) {
            Ok(m) => {
                self.command = Some(match m {
                    Message::Unknown { .. } => Json::Null,
                    _ => Json::String(m.name().into()),
                });
                self.direction = direction(&m).map(Into::into);
                self.error = message_fields(&m, payload, &mut fields);
            }
            Err(e) => {
                // Name what can be named: the service command of a
                // service frame whose data does not fit it.
                let name = match (frame_type, payload.first()) {
                    (FrameType::Service, Some(&c)) => service::describe(c).map(|d| d.name),
                    _ => None,
                }
                .or(frame_type.name());
                self.command = Some(name_or_null(name));
                put_hex(&mut fields, "payload", payload);
                self.error = Some(e.to_string());
            }
        }
        self.fields = Some(fields);
    }
}

fn name_or_null(name: Option<&str>) -> Json {
    name.map_or(Json::Null, |n| Json::String(n.into()))
}

fn put_hex(map: &mut Object, key: &str, bytes: &[u8]) {
    map.insert(key, Json::String(hex::encode(bytes)));
}

/// Whether a message is a request or a reply, when its bytes tell: a
/// service command's request and reply differ in length (4.6.4), a HID
/// `'g'` reply carries the value (Appendix A), pings are asked and ACKs
/// and error frames answer (4.6.2, 4.6.3). MIB frames, raw service
/// commands and user data do not tell.
fn direction(m: &Message) -> Option<&'static str> {
    let request = match m {
        Message::Service(Service::Raw { .. }) => return None,
        Message::Service(s) => s.is_request(),
        Message::Hid(Hid::Reply { .. }) => false,
        Message::Hid(_) | Message::Ping | Message::Programming { .. } => true,
        Message::Ack { .. } | Message::Error(_) => false,
        Message::Data(_) | Message::Mib { .. } | Message::Unknown { .. } => return None,
    };
    Some(if request { "request" } else { "reply" })
}

/// Fills `f` with the named fields of `m` (read from `payload`, the bytes
/// after the address); returns a problem with the value, if any.
fn message_fields(m: &Message, payload: &[u8], f: &mut Object) -> Option<String> {
    match m {
        Message::Service(s) => put_layout(f, s.layout(), payload.get(1..).unwrap_or(&[])),
        Message::Hid(h) => hid_fields(h, f),
        Message::Data(d) => put_hex(f, "data", d),
        Message::Ping => {}
        Message::Ack { frame_type, echo } => {
            // 4.6.2, 4.6.4: buffer[8] the acknowledged frame type,
            // buffer[9] the command echo.
            f.insert("frame_type", frame_type_json(*frame_type));
            f.insert("command_echo", Json::from(*echo));
        }
        Message::Error(code) => {
            // 4.6.3: user_error_code = buffer[8] << 8 | buffer[9].
            f.insert("error_code", Json::from(code.0));
            f.insert("error_name", name_or_null(code.name()));
            f.insert("meaning", Json::String(code.to_string()));
        }
        Message::Programming { group, data } => {
            put_layout(f, &[service::fields::GROUP], &[*group]);
            put_hex(f, "data", data);
        }
        Message::Mib { index, data } => {
            // The board's modem MIB object (UM0932 4), read when `data` is
            // empty (protocol notes).
            f.insert("index", Json::from(*index));
            let object = st7580::mib::object(*index);
            f.insert("object", name_or_null(object.map(|o| o.name)));
            if !data.is_empty() {
                put_hex(f, "data", data);
                match object {
                    Some(o) if o.len == data.len() => put_layout(f, o.fields, data),
                    Some(o) => {
                        return Some(alloc::format!(
                            "{} is {} bytes long, not {}",
                            o.name,
                            o.len,
                            data.len()
                        ))
                    }
                    None => return Some(alloc::format!("there is no MIB object {index:02X}h")),
                }
            }
        }
        Message::Unknown { payload, .. } => put_hex(f, "payload", payload),
    }
    None
}

/// The acknowledged frame type by the seed's name, or its value.
fn frame_type_json(t: FrameType) -> Json {
    t.name()
        .map_or(Json::from(t.byte()), |n| Json::String(n.into()))
}

/// HID fields (Appendix A), named after the seed.
fn hid_fields(h: &Hid, f: &mut Object) {
    let param_name = |p: u8| hid::param(p).map_or(Json::from(p), |d| Json::String(d.name.into()));
    match h {
        Hid::Reset(t) => {
            let name = match *t {
                hid::RESET_SOFTWARE => Json::String("Software reset".into()),
                hid::RESET_HARDWARE => Json::String("Hardware reset".into()),
                other => Json::from(other),
            };
            f.insert("reset_type", name);
        }
        Hid::Dimming(v) => {
            f.insert("dimming_value", Json::from(*v));
        }
        Hid::Get(p) => {
            f.insert("param_to_get", param_name(*p));
        }
        Hid::Reply { param, value } => {
            f.insert("param_to_get", param_name(*param));
            if let Some(d) = hid::param(*param) {
                put_layout(f, d.fields, value);
            }
        }
    }
}

/// Decodes one element of a board USART stream.
pub fn decode_element(e: &UsartElement) -> AppDecoded {
    match e {
        UsartElement::Frame { frame, bytes } => usart_frame(frame, bytes, true),
        UsartElement::BadCrc { frame, bytes } => usart_frame(frame, bytes, false),
        UsartElement::Garbage(bytes) => AppDecoded::new("garbage", bytes),
    }
}

fn usart_frame(frame: &AppFrame, bytes: &[u8], crc_ok: bool) -> AppDecoded {
    let mut d = AppDecoded::new("frame", bytes);
    d.length = bytes.first().copied();
    d.address = Some(frame.address.to_string());
    d.put_payload(frame.frame_type, frame.broadcast, &frame.payload);
    let n = bytes.len();
    d.crc = (n >= 2).then(|| u16::from_be_bytes([bytes[n - 2], bytes[n - 1]]));
    d.crc_ok = Some(crc_ok);
    d
}

/// Decodes a line frame (the DL payload that carries an application frame
/// over the power line, [`LineFrame`]).
pub fn decode_line_frame(line: &LineFrame) -> AppDecoded {
    let mut d = AppDecoded::new("frame", &line.emit());
    d.destination = Some(line.destination.to_string());
    d.source = Some(line.source.to_string());
    d.put_payload(line.frame_type, line.broadcast, &line.payload);
    d
}

/// Decodes a whole board USART capture.
pub fn decode_usart(bytes: &[u8]) -> Vec<AppDecoded> {
    UsartDecoder::decode_all(bytes)
        .iter()
        .map(decode_element)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::{Address, ErrorCode};

    const A: Address = Address([0x00, 0x80, 0xE1, 0x00, 0x00, 0x2A]);

    fn one(m: &Message) -> AppDecoded {
        let bytes = m.to(A).emit().unwrap();
        let mut v = decode_usart(&bytes);
        assert_eq!(v.len(), 1);
        v.remove(0)
    }

    #[test]
    fn a_clock_reply_reads_its_fields_from_the_service_description() {
        let d = one(&Message::Service(Service::ClockNow(service::Clock {
            hours: 12,
            minutes: 30,
            seconds: 5,
        })));
        assert_eq!(d.kind, "frame");
        assert_eq!(d.length, Some(14));
        assert_eq!(d.frame_type, Some(Json::from("APP_SERVICE_FRAME")));
        assert_eq!(d.command, Some(Json::from("SERVICE_PLM_CLOCK_GET")));
        assert_eq!(d.direction.as_deref(), Some("reply"));
        assert_eq!(d.address.as_deref(), Some("0080e100002a"));
        assert_eq!(d.crc_ok, Some(true));
        let f = d.fields.unwrap();
        assert_eq!(f.get("hours"), Some(&Json::from(12)));
        assert_eq!(f.get("minutes"), Some(&Json::from(30)));
        assert_eq!(f.get("seconds"), Some(&Json::from(5)));
    }

    #[test]
    fn error_frames_carry_number_name_and_words() {
        let d = one(&Message::Error(ErrorCode::HID_TIMEOUT));
        assert_eq!(d.direction.as_deref(), Some("reply"));
        let f = d.fields.unwrap();
        assert_eq!(f.get("error_code"), Some(&Json::from(0x12)));
        assert_eq!(
            f.get("error_name"),
            Some(&Json::from("HID board response timeout"))
        );
        assert!(f
            .get("meaning")
            .and_then(Json::as_str)
            .unwrap()
            .contains("ballast"));
        let d = one(&Message::Error(ErrorCode(0x4242)));
        assert_eq!(d.fields.unwrap().get("error_name"), Some(&Json::Null));
    }

    #[test]
    fn a_payload_that_does_not_fit_is_kept_and_explained() {
        let frame = AppFrame::new(FrameType::Service, A, alloc::vec![0x08, 1]);
        let d = decode_usart(&frame.emit().unwrap()).remove(0);
        assert_eq!(d.command, Some(Json::from("SERVICE_PLM_CLOCK_GET")));
        assert_eq!(d.fields.unwrap().get("payload"), Some(&Json::from("0801")));
        assert!(d.error.unwrap().contains("SERVICE_PLM_CLOCK_GET"));
        assert_eq!(d.direction, None);
    }

    #[test]
    fn unknown_types_are_null_and_keep_their_payload() {
        let frame = AppFrame::new(FrameType::Unknown(0x33), A, alloc::vec![1, 2]);
        let d = decode_usart(&frame.emit().unwrap()).remove(0);
        assert_eq!(d.frame_type, Some(Json::Null));
        assert_eq!(d.command, Some(Json::Null));
        assert_eq!(d.code, Some(0x33));
        assert_eq!(d.fields.unwrap().get("payload"), Some(&Json::from("0102")));
    }

    #[test]
    fn line_frames_name_both_ends_and_have_no_crc() {
        let b = Address([0, 0x80, 0xE1, 0, 0, 1]);
        let line = LineFrame::from_app(&Message::Hid(Hid::Get(hid::ALL)).to(A), b);
        let d = decode_line_frame(&line);
        assert_eq!(d.destination.as_deref(), Some("0080e100002a"));
        assert_eq!(d.source.as_deref(), Some("0080e1000001"));
        assert_eq!(d.address, None);
        assert_eq!(d.crc, None);
        assert_eq!(d.length, None);
        assert_eq!(d.command, Some(Json::from("Get HID parameter")));
        assert_eq!(
            d.fields.unwrap().get("param_to_get"),
            Some(&Json::from("GET ALL PARAMETERS"))
        );
        assert_eq!(d.hex, hex::encode(&line.emit()));
    }

    #[test]
    fn the_modem_decoder_shows_the_line_frame_a_dl_payload_carries() {
        use crate::link::{Dialect, Source};
        use crate::st7580::{Channel, Command, DataIndication, IndicationInfo, Modulation};
        let line = LineFrame::from_app(&Message::Ping.to(A), Address([0, 0, 0, 0, 0, 7]));
        let ind = |payload: Vec<u8>| {
            Command::DlDataIndication(DataIndication {
                info: IndicationInfo {
                    modulation: Modulation::BPsk,
                    rx_channel: Channel::High,
                    pga: 1,
                    snr: 10,
                    zc_delay: 0,
                },
                payload,
            })
            .to_frame()
            .emit(Dialect::St7580)
            .unwrap()
        };
        let d = crate::decode::decode_all(Dialect::St7580, Source::Modem, &ind(line.emit()));
        let app = d[0].fields.as_ref().unwrap().get("app").unwrap();
        assert_eq!(app.get("command"), Some(&Json::from("APP_PING_FRAME")));
        assert_eq!(app.get("source"), Some(&Json::from("000000000007")));
        assert_eq!(app.get("destination"), Some(&Json::from("0080e100002a")));
        // Too short to be a line frame: no `app` key.
        let d = crate::decode::decode_all(Dialect::St7580, Source::Modem, &ind(alloc::vec![1, 2]));
        assert!(d[0].fields.as_ref().unwrap().get("app").is_none());
    }

    #[test]
    fn garbage_is_only_bytes() {
        let d = decode_usart(&[0xFF, 0x01]);
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].kind, "garbage");
        assert_eq!(d[0].hex, "ff01");
        assert_eq!(d[0].fields, None);
    }
}
