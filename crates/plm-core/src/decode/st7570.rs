//! The ST7570 side of the decoder (ST7570 UM 5.2.1, 5.3, 6): every frame
//! read in an access layer, with the layouts of [`crate::st7570::layout`];
//! status messages by their row of Table 11; MIB frames with their object
//! named and its fields; requests checked as the modem checks them.
//!
//! The layer (and what the modem refuses) is context a frame lacks: it
//! comes from the last status message (LAYER, MODE), from MIB 00A1h
//! written or read (Access layer mode, Operating mode) and 0000h (FIMA,
//! LIMA), or from [`super::Decoder::fix_layer`], which wins.

use super::{put_hex, Decoded};
use crate::field::{Field, Value};
use crate::field_json::put_value;
use crate::json::{Json, Object};
use crate::link::{LocalFrame, Source};
use crate::mib::Object as MibObject;
use crate::st7570::mib::{self, index, PlcConfiguration};
use crate::st7570::{self, code as c, fields as f, status, validate, Command, Group, Layer};
use alloc::format;
use alloc::string::{String, ToString};

/// An operating mode no status message or 00A1h frame has told yet:
/// [`validate::check_write`] checks no mode then.
const MODE_UNKNOWN: u8 = 0xFF;

/// What an ST7570 frame needs from the frames before it.
#[derive(Debug, Clone)]
pub(super) struct Context {
    /// The modem's configuration as far as the input told it: the layer
    /// frames are read in, the operating mode, FIMA and LIMA.
    modem: validate::Context,
    /// Whether the input (or the user) has said which layer.
    layer_known: bool,
    /// The layer was given by the user: the input does not change it.
    layer_fixed: bool,
    /// The configuration before the last CMD_WriteDBRequest, restored if
    /// CMD_WriteDBError answers it.
    before_write: Option<validate::Context>,
}

impl Default for Context {
    /// PHY, the factory default of 00A1h (Table 137); mode, FIMA and LIMA
    /// unknown, so that nothing is refused on a guess.
    fn default() -> Self {
        Context {
            modem: validate::Context {
                layer: Layer::Phy,
                mode: MODE_UNKNOWN,
                fima: 0,
                lima: 0xFFF,
            },
            layer_known: false,
            layer_fixed: false,
            before_write: None,
        }
    }
}

impl Context {
    /// The layer frames are read in now.
    pub(super) fn layer(&self) -> Layer {
        self.modem.layer
    }

    /// See [`super::Decoder::fix_layer`].
    pub(super) fn fix_layer(&mut self, layer: Layer) {
        self.modem.layer = layer;
        self.layer_known = true;
        self.layer_fixed = true;
    }

    /// Command name, layer, fields and error of a frame sent by `from`.
    pub(super) fn frame(&mut self, from: Source, frame: &LocalFrame, d: &mut Decoded) {
        let (code, data, layer) = (frame.code, &frame.data[..], self.modem.layer);
        d.command = Some(c::name(code).map_or(Json::Null, |n| Json::String(n.into())));
        d.layer = Some(layer.name().into());
        let mut fields = Object::new();
        match Command::parse(code, data, layer) {
            Ok(cmd) => {
                match st7570::layout(code, layer, from, data) {
                    Some(layout) => put_fields(&mut fields, layout, data),
                    None => put_hex(&mut fields, "data", data),
                }
                let problem = put_object(&cmd, &mut fields);
                d.error = self.refusal(&cmd).or(problem);
                // A frame with a wrong checksum is NAKed, not acted on.
                if d.checksum_ok == Some(true) {
                    self.follow(&cmd);
                }
            }
            Err(err) => {
                put_hex(&mut fields, "data", data);
                d.error = Some(err.to_string());
            }
        }
        d.fields = Some(fields);
    }

    /// The fields of a status message (its row of Table 11), and the
    /// layer and mode it gives.
    pub(super) fn status(&mut self, data: &[u8], d: &mut Decoded) {
        let mut fields = Object::new();
        for (field, v) in status::describe(data) {
            put_value(&mut fields, field, &v);
        }
        if let Some(s) = st7570::Status::parse(data) {
            // Bits set where the row has a fixed 0: shown, never dropped.
            for (i, b) in s.stray.iter().enumerate().filter(|(_, b)| **b != 0) {
                fields.insert(format!("stray_byte_{}", i + 1), Json::from(*b));
            }
            if !self.layer_fixed {
                self.modem.layer = s.layer();
                self.layer_known = true;
            }
            self.modem.mode = s.mode;
        }
        d.fields = Some(fields);
    }

    /// What the modem will refuse about a request, in words with the code
    /// it answers (MIB error of Table 70, or LM_SE of Table 43).
    fn refusal(&self, cmd: &Command) -> Option<String> {
        let what = match cmd {
            Command::WriteDbRequest { .. } => "write",
            Command::ReadDbRequest { .. } => "read",
            Command::PhyDataRequest { .. } | Command::MacDataRequest(_) => "frame",
            _ => return None,
        };
        // Before the input says which layer, no object is refused for it:
        // every object exists with the MAC layer.
        let ctx = validate::Context {
            layer: if self.layer_known {
                self.modem.layer
            } else {
                Layer::Mac
            },
            ..self.modem
        };
        let (code, reason) = validate::check_request(cmd, &ctx).err()?;
        let name = match what {
            "frame" => f::MAC_CONFIRM_CODES[code as usize],
            _ => f::MIB_ERRORS[code as usize],
        };
        Some(format!(
            "the modem will refuse this {what}: {reason} ({name})"
        ))
    }

    /// Takes in what a correct frame says about the modem's configuration.
    fn follow(&mut self, cmd: &Command) {
        match cmd {
            Command::WriteDbRequest { index, data } => {
                self.before_write = Some(self.modem);
                self.apply(*index, data);
            }
            Command::WriteDbError { .. } => {
                if let Some(before) = self.before_write.take() {
                    let layer = self.modem.layer;
                    self.modem = before;
                    if self.layer_fixed {
                        self.modem.layer = layer;
                    }
                }
            }
            Command::WriteDbConfirm { index, data } | Command::ReadDbConfirm { index, data } => {
                self.before_write = None;
                self.apply(*index, data);
            }
            _ => {}
        }
    }

    /// The value of a MIB object, as far as it configures what is decoded
    /// and refused: 00A1h (layer, mode) and 0000h (FIMA, LIMA).
    fn apply(&mut self, object: u16, data: &[u8]) {
        match (object, mib::object(object)) {
            (index::PLC_CONFIGURATION, Some(o)) if data.len() == o.len => {
                let p = PlcConfiguration::decode(data);
                if let (Some(layer), false) = (p.layer(), self.layer_fixed) {
                    self.modem.layer = layer;
                    self.layer_known = true;
                }
                self.modem.mode = p.operating_mode;
            }
            (index::FIMA_LIMA, Some(o)) if data.len() == o.len => {
                self.modem.fima = u16::from_le_bytes([data[0], data[1]]);
                self.modem.lima = u16::from_le_bytes([data[2], data[3]]);
            }
            _ => {}
        }
    }
}

/// The named values of `data` under `layout`; a 12-bit field is a MAC
/// address (Table 5), and one of Table 6's groups is also named, under
/// `<field>_group` (`"da": 4095, "da_group": "BROADCAST"`).
pub(super) fn put_fields(map: &mut Object, layout: &'static [Field], data: &[u8]) {
    for (field, v) in crate::mib::describe(layout, data) {
        let group = match (&v, field.max) {
            (Value::Uint(a), 0xFFF) => u16::try_from(*a).ok().and_then(Group::of),
            _ => None,
        };
        put_value(map, field, &v);
        if let Some(g) = group {
            map.insert(
                format!("{}_group", field.name),
                Json::String(g.name().into()),
            );
        }
    }
}

/// The object of a MIB frame (41h, 42h, 90h, 91h) by name, and the
/// fields of the value it carries; a problem if there is no such object
/// or the value does not fit it. A write request's problems are the
/// modem's refusal ([`Context::refusal`]).
fn put_object(cmd: &Command, map: &mut Object) -> Option<String> {
    let (index, data) = match cmd {
        Command::ReadDbRequest { index } => (*index, None),
        Command::WriteDbRequest { index, data }
        | Command::WriteDbConfirm { index, data }
        | Command::ReadDbConfirm { index, data } => (*index, Some(&data[..])),
        _ => return None,
    };
    let request = matches!(
        cmd,
        Command::ReadDbRequest { .. } | Command::WriteDbRequest { .. }
    );
    let Some(o) = mib::object(index) else {
        map.insert("object", Json::Null);
        return (!request).then(|| format!("there is no MIB object {index:04X}h"));
    };
    map.insert("object", Json::String(o.name.into()));
    let data = data?;
    match value_layout(o, cmd, data.len()) {
        Some(layout) => {
            put_fields(map, layout, data);
            None
        }
        None if request => None,
        None => Some(format!(
            "{} is {} bytes long, not {}",
            o.name,
            o.len,
            data.len()
        )),
    }
}

/// The layout of the data a MIB frame carries: a write request's is the
/// object's write layout (6.5: a counter is reset by PAD bytes), a read
/// confirm's the value; a write confirm gives back the request's data or,
/// for the objects written with other bytes, the value (6.5.7, 6.5.25).
fn value_layout(o: &MibObject, cmd: &Command, len: usize) -> Option<&'static [Field]> {
    let write = (len == o.write_len()).then(|| o.write_fields());
    let value = (len == o.len).then_some(o.fields);
    match cmd {
        Command::WriteDbRequest { .. } => write,
        Command::ReadDbConfirm { .. } => value,
        _ => value.or(write),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;
    use crate::link::Dialect;

    fn decode(
        source: Source,
        frames: &[Command],
        layer: Option<Layer>,
    ) -> alloc::vec::Vec<Decoded> {
        let mut d = Decoder::new(Dialect::St7570, source);
        if let Some(l) = layer {
            d.fix_layer(l);
        }
        for cmd in frames {
            d.push(&cmd.to_frame().emit(Dialect::St7570).unwrap());
        }
        d.finish();
        core::iter::from_fn(|| d.next()).collect()
    }

    fn plc(layer: Layer, mode: u8) -> alloc::vec::Vec<u8> {
        let mut p =
            PlcConfiguration::decode(mib::object(index::PLC_CONFIGURATION).unwrap().default);
        p.access_layer_mode = layer.access_layer_mode();
        p.operating_mode = mode;
        p.encode()
    }

    #[test]
    fn every_twelve_bit_field_is_a_mac_address() {
        // The group rule of put_fields relies on it.
        let mut layouts: alloc::vec::Vec<&[Field]> = mib::OBJECTS
            .iter()
            .flat_map(|o| [o.fields, o.write_fields()])
            .collect();
        for code in c::ALL {
            for layer in [Layer::Phy, Layer::Mac] {
                for data in [
                    &[1u8; 15][..],
                    &[2; 6],
                    &[4; 6],
                    &[5; 6],
                    &[0; 4],
                    &[0; 5],
                    &[0; 10],
                    &[0; 17],
                ] {
                    layouts.extend(st7570::layout(code.code, layer, Source::Modem, data));
                }
            }
        }
        const ADDRESSES: &[&str] = &[
            "sa",
            "da",
            "add",
            "add1",
            "add2",
            "fima",
            "lima",
            "local_mac_add",
            "init_mac_add",
        ];
        for field in layouts.into_iter().flatten().filter(|f| f.max == 0xFFF) {
            assert!(
                ADDRESSES.contains(&field.name) || field.name.starts_with("mac_group_address"),
                "{} is 12 bits and no address",
                field.name
            );
        }
    }

    #[test]
    fn a_refused_00a1h_write_does_not_change_the_layer() {
        let data_request = Command::MacDataRequest(st7570::MacData {
            m_sdu: alloc::vec![1],
            ..Default::default()
        });
        let write = Command::WriteDbRequest {
            index: index::PLC_CONFIGURATION,
            data: plc(Layer::Mac, 1),
        };
        let refused = [
            write.clone(),
            Command::WriteDbError { error: 0x26 },
            data_request.clone(),
        ];
        let d = decode(Source::Any, &refused, None);
        assert_eq!(d[2].layer.as_deref(), Some("PHY"));
        let accepted = [write, data_request];
        let d = decode(Source::Any, &accepted, None);
        assert_eq!(d[1].layer.as_deref(), Some("MAC"));
        assert_eq!(d[1].error, None, "{:?}", d[1]);
        // --layer wins over what the input says.
        let d = decode(Source::Any, &accepted, Some(Layer::Phy));
        assert_eq!(d[1].layer.as_deref(), Some("PHY"));
    }

    #[test]
    fn refusals_need_a_known_layer_and_mode() {
        let local = Command::WriteDbRequest {
            index: index::LOCAL_INIT_MAC_ADD,
            data: alloc::vec![1, 0, 0, 0x0C],
        };
        // Nothing said yet: no claim about the layer.
        assert_eq!(
            decode(Source::Host, core::slice::from_ref(&local), None)[0].error,
            None
        );
        let phy = decode(
            Source::Host,
            core::slice::from_ref(&local),
            Some(Layer::Phy),
        );
        let e = phy[0].error.as_deref().unwrap();
        assert!(e.contains("ERR_UNAVAILABLE_RESOURCE"), "{e}");
        // 0015h: only a Monitor writes it; a Server (status MODE 2) cannot.
        let auto = Command::WriteDbRequest {
            index: 0x0015,
            data: alloc::vec![1],
        };
        assert_eq!(
            decode(Source::Host, core::slice::from_ref(&auto), Some(Layer::Mac))[0].error,
            None
        );
        let mut d = Decoder::new(Dialect::St7570, Source::Any);
        d.push(&[0x3F, 0x22, 0xE4, 0x80]);
        d.push(&auto.to_frame().emit(Dialect::St7570).unwrap());
        d.finish();
        let server: alloc::vec::Vec<Decoded> = core::iter::from_fn(|| d.next()).collect();
        let e = server[1].error.as_deref().unwrap();
        assert!(e.contains("ERR_REQUEST_NOT_ALLOWED"), "{e}");
    }
}
