//! A frame from the ST7570's power line (IEC 61334-5-1; ST7570 UM 3.2,
//! 4.4): what `plm decode --chip st7570 --line HEX` prints, one JSON
//! object:
//!
//! - `kind`: `mac_frame`, `mac_subframes` or `phy_frames` (how the long
//!   MAC frame was carried, see [`phy_frame::decode`]), or `garbage` with
//!   `error` in words;
//! - `hex`: the bytes as given;
//! - `fi`: the subframes' frame indicator; `windows`: each PHY frame's
//!   pause or alarm window (`pause`, `alarm` or the bytes in hex);
//! - `ns`: the number of subframes; `fields`: the header by the names of
//!   Table 38 (`ic`, `cc`, `dc`, `sa`, `da` with `sa_group`/`da_group`
//!   for Table 6's groups, `pad`);
//! - `m_sdu` and the `pad_bytes`, hex; `fcs`, `fcs_ok` and `fcs_form`,
//!   the form of FCS the frame carries ([`mac::FcsForm`]: `catalogue`,
//!   `gurux` or `gurux_without_pad`); a frame whose FCS is in none of them
//!   has `fcs_ok: false`, no `fcs_form` and `error` with each form's FCS.
//!
//! The layout is [`crate::st7570::mac`]'s; nothing is read here.

use super::st7570::put_fields;
use crate::hex;
use crate::json::Object;
use crate::json::{json_record, Json};
use crate::st7570::mac;
use crate::st7570::phy_frame::{self, Window};
use alloc::string::{String, ToString};
use alloc::vec::Vec;

/// A line frame, ready to serialise as a JSON line.
#[derive(Debug, Clone, PartialEq)]
pub struct LineDecoded {
    /// `mac_frame`, `mac_subframes`, `phy_frames` or `garbage`.
    pub kind: String,
    /// The bytes as given, lowercase hex.
    pub hex: String,
    /// FI of the subframes (subframes and PHY frames).
    pub fi: Option<u16>,
    /// The pause or alarm window of each PHY frame.
    pub windows: Option<Json>,
    /// NS: the number of subframes.
    pub ns: Option<u8>,
    /// The header's fields by name.
    pub fields: Option<Object>,
    /// The M_sdu, lowercase hex.
    pub m_sdu: Option<String>,
    /// The pad bytes as received, lowercase hex.
    pub pad_bytes: Option<String>,
    /// The FCS as received.
    pub fcs: Option<u32>,
    /// Whether the FCS is the frame's in one of the known forms.
    pub fcs_ok: Option<bool>,
    /// The form it is in (`catalogue`, `gurux`, `gurux_without_pad`).
    pub fcs_form: Option<String>,
    /// Why the bytes are not a frame, in words.
    pub error: Option<String>,
}

// The object `plm decode --chip st7570 --line` prints.
json_record!(LineDecoded {
    kind,
    hex,
    fi,
    windows,
    ns,
    fields,
    m_sdu,
    pad_bytes,
    fcs,
    fcs_ok,
    fcs_form,
    error,
});

fn window(w: Window) -> Json {
    Json::String(match w {
        Window::Pause => "pause".to_string(),
        Window::Alarm => "alarm".to_string(),
        Window::Other(v) => hex::encode(&v.to_be_bytes()[1..]),
    })
}

/// Decodes a long MAC frame, MAC subframes or PHY frames from the line.
/// A frame whose FCS is in no known form is shown with `fcs_ok: false`;
/// bytes that are none of the three are `garbage` with the reason.
pub fn decode_line(bytes: &[u8]) -> LineDecoded {
    let mut d = LineDecoded {
        kind: "garbage".to_string(),
        hex: hex::encode(bytes),
        fi: None,
        windows: None,
        ns: None,
        fields: None,
        m_sdu: None,
        pad_bytes: None,
        fcs: None,
        fcs_ok: None,
        fcs_form: None,
        error: None,
    };
    let line = match phy_frame::decode(bytes) {
        Ok(line) => line,
        Err(e) => {
            d.error = Some(e.to_string());
            return d;
        }
    };
    let frame = match line.frame() {
        Ok(f) => f,
        Err(e) => {
            d.error = Some(e.to_string());
            return d;
        }
    };
    d.kind = line.kind.name().to_string();
    d.fi = line.fi;
    if !line.windows.is_empty() {
        d.windows = Some(Json::Array(
            line.windows.iter().map(|w| window(*w)).collect::<Vec<_>>(),
        ));
    }
    d.ns = Some(frame.ns() as u8);
    let mut fields = Object::new();
    put_fields(&mut fields, mac::fields::HEADER, frame.bytes());
    d.fields = Some(fields);
    d.m_sdu = Some(hex::encode(frame.m_sdu()));
    d.pad_bytes = Some(hex::encode(frame.pad()));
    d.fcs = Some(frame.fcs());
    match frame.fcs_form() {
        Ok(form) => {
            d.fcs_ok = Some(true);
            d.fcs_form = Some(form.name().to_string());
        }
        Err(e) => {
            d.fcs_ok = Some(false);
            d.error = Some(e.to_string());
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    // UM 10.3.1's request on the line (docs/protocol-notes.md, "ST7570:
    // MAC and PHY frames on the line").
    const SEED_10_3: &str =
        "6c6c00c000010000 0102030405060708090a0b0c0d0e0f10111213141516171819ff3b89";

    #[test]
    fn the_seed_frame_by_name() {
        let bytes = hex::parse(SEED_10_3).unwrap();
        let j = decode_line(&bytes).to_json();
        let text = j.to_string();
        assert_eq!(
            text,
            "{\"kind\":\"mac_frame\",\"hex\":\"6c6c00c0000100000102030405060708090a0b0c0d0e0f10111213141516171819ff3b89\",\
             \"ns\":1,\"fields\":{\"ic\":0,\"cc\":0,\"dc\":0,\"sa\":3072,\"da\":1,\"pad\":0},\
             \"m_sdu\":\"000102030405060708090a0b0c0d0e0f10111213141516171819\",\"pad_bytes\":\"\",\
             \"fcs\":16726921,\"fcs_ok\":true,\"fcs_form\":\"catalogue\"}"
        );
    }

    #[test]
    fn damage_and_garbage_in_words() {
        let mut bytes = hex::parse(SEED_10_3).unwrap();
        bytes[12] ^= 0x10;
        let d = decode_line(&bytes);
        assert_eq!((d.fcs_ok, d.fcs), (Some(false), Some(0xFF3B89)));
        assert!(d.error.unwrap().starts_with("bad FCS"));
        let d = decode_line(&bytes[..20]);
        assert_eq!(d.kind, "garbage");
        assert_eq!(
            d.error.as_deref(),
            Some("20 bytes is not a long MAC frame: it is 36 bytes per subframe, 1 to 7 subframes")
        );
        let d = decode_line(&bytes[2..22]);
        assert_eq!(
            d.error.as_deref(),
            Some("20 bytes is not a whole number of 38-byte subframes")
        );
    }
}
