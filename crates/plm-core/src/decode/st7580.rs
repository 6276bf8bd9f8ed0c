//! The ST7580 side of the decoder (UM0932 3.3-4): the fields of every
//! command, the status message of Table 8, MIB_ReadConfirm named by the
//! MIB_ReadRequest before it, and the application frame a DL payload
//! carries ([`crate::decode::app`]) under `app` in `fields`.

use super::{put_hex, Decoded};
use crate::field_json::put_layout;
use crate::json::{Json, Object};
use crate::link::{LocalFrame, Source};
use crate::st7580::code::CommandType;
use crate::st7580::fields::{indication_data, reset_data, status as status_fields, tx_options};
use crate::st7580::{self, code as c, validate, Command};
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

/// What an ST7580 frame needs from the frames before it.
#[derive(Debug, Clone, Default)]
pub(super) struct Context {
    /// The index of the last MIB_ReadRequest, which names the object of
    /// the MIB_ReadConfirm that follows.
    pending_read: Option<u8>,
}

/// The fields of a status message (UM0932 Table 8).
pub(super) fn status(data: &[u8], d: &mut Decoded) {
    let mut fields = Object::new();
    put_layout(&mut fields, status_fields::LAYOUT, data);
    d.fields = Some(fields);
}

impl Context {
    /// See [`super::Decoder::assume_mib_read`].
    pub(super) fn assume_mib_read(&mut self, index: u8) {
        self.pending_read = Some(index);
    }

    /// Command name, fields, error and warning of a frame sent by `from`.
    pub(super) fn frame(&mut self, from: Source, frame: &LocalFrame, d: &mut Decoded) {
        d.command = Some(c::name(frame.code).map_or(Json::Null, |n| Json::String(n.into())));
        let mut fields = Object::new();
        let mut warnings = Vec::new();
        warnings.extend(direction(from, frame.code));
        match Command::parse(frame.code, &frame.data) {
            Ok(cmd) => {
                d.error = self.command_fields(&cmd, &frame.data, &mut fields);
                warnings.extend(forbidden(&cmd));
            }
            Err(err) => {
                put_hex(&mut fields, "data", &frame.data);
                d.error = Some(err.to_string());
            }
        }
        d.fields = Some(fields);
        d.warning = (!warnings.is_empty()).then(|| warnings.join("; "));
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

/// A code sent the wrong way (UM0932 3.3, Tables 10-15): the host sends
/// requests only, the modem everything else.
fn direction(from: Source, code: u8) -> Option<String> {
    let t = c::command_type(code)?;
    let name = c::name(code)?;
    match (from, t) {
        (Source::Modem, CommandType::Request) => Some(format!(
            "{name} is a request: only the host sends it (UM0932 Table 10)"
        )),
        (Source::Host, CommandType::Request) | (Source::Any, _) | (Source::Modem, _) => None,
        (Source::Host, _) => Some(format!(
            "{name} comes from the ST7580, never from the host (UM0932 Tables 11, 12, 15)"
        )),
    }
}

/// What UM0932 forbids in a command that parses: a BIO_ResetConfirm whose
/// data is not 00h (3.3.2), a data request the modem refuses
/// (`validate::check_request`, the simulated modem's rule). The DL CRC
/// length is not in the stream: 1 byte, the option that fits the most, so
/// that only what every configuration refuses is said.
fn forbidden(cmd: &Command) -> Option<String> {
    match cmd {
        Command::BioResetConfirm { confirm_data } if *confirm_data != 0 => Some(format!(
            "BIO_ResetConfirm data is always 00h, not {confirm_data:02X}h (UM0932 3.3.2)"
        )),
        Command::PhyDataRequest(_) | Command::DlDataRequest(_) | Command::SsDataRequest(_) => {
            validate::check_request(cmd, 1).err().map(|r| {
                let cause = r.cause.name().unwrap_or("an error");
                format!("the modem will refuse this request with {cause}: {r}")
            })
        }
        _ => None,
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
        f.insert(
            "app",
            crate::decode::app::decode_line_frame(&line).to_json(),
        );
    }
}

fn put_tx_params(f: &mut Object, bytes: &[u8], p: &st7580::TxParams) {
    put_layout(f, tx_options::LAYOUT, bytes);
    if let Some(hz) = p.tx_frequency {
        f.insert(tx_options::TX_FREQUENCY.name, Json::from(hz));
    }
    if let Some(g) = p.tx_gain {
        put_layout(f, tx_options::GAIN_BYTE, &[g]);
    }
}
