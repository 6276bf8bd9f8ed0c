//! A MIB configuration profile: the values of a chip's writable MIB
//! objects, saved to and loaded from a JSON file (`{"format": …, "chip":
//! "ST7580", "objects": {"01": "014ff0…"}}`, values as lowercase hex). The
//! Modem view saves and loads it; what it reads is checked here, object
//! by object as a MIB write request would be (docs/protocol-notes.md,
//! "Files read").

use crate::chip::{self, Chip};
use crate::json::{self, Json};
use crate::link::Dialect;
use crate::mib::Object;
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

/// What a saved profile file says it is.
pub const FORMAT: &str = "plm-console MIB profile";

/// Whether a profile holds `o`: an object written with its value (not a
/// counter a write resets, ST7570 UM 6.5).
pub fn holds(o: &&Object) -> bool {
    o.access.write && o.write.is_none()
}

/// The objects of `chip` a profile holds.
pub fn objects(chip: &dyn Chip) -> impl Iterator<Item = &'static Object> {
    chip.mib().iter().filter(holds)
}

/// A MIB index as profiles and messages write it: two hex digits for the
/// ST7580's one-byte indexes (UM0932 Table 52), four for the ST7570's
/// (`00A1`, ST7570 UM 6.5).
pub fn index_text(dialect: Dialect, index: u16) -> String {
    match dialect {
        Dialect::St7580 => format!("{index:02X}"),
        _ => format!("{index:04X}"),
    }
}

/// The profile of `chip` with the values `value` gives for its objects
/// (those without one are left out).
pub fn to_json<'a>(chip: &dyn Chip, value: impl Fn(u16) -> Option<&'a [u8]>) -> String {
    let mut objects = json::Object::new();
    for o in self::objects(chip) {
        if let Some(v) = value(o.index) {
            objects.insert(
                index_text(chip.dialect(), o.index).to_ascii_lowercase(),
                Json::String(crate::hex::encode(v)),
            );
        }
    }
    let mut profile = json::Object::new();
    profile.insert("format", Json::from(FORMAT));
    profile.insert("chip", Json::from(chip.name()));
    profile.insert("objects", Json::Object(objects));
    Json::Object(profile).pretty()
}

/// Reads a profile file for `chip`: its objects' indexes and values, every
/// value checked as a MIB write request would be; the first problem
/// refuses the whole file, in words.
pub fn parse(chip: &dyn Chip, text: &str) -> Result<Vec<(u16, Vec<u8>)>, String> {
    let v = json::parse(text).map_err(|e| format!("not JSON ({e})"))?;
    if v.get("format").and_then(Json::as_str) != Some(FORMAT) {
        return Err(format!("not a profile: \"format\" must be \"{FORMAT}\""));
    }
    let name = chip.name();
    if v.get("chip").and_then(Json::as_str) != Some(name) {
        return Err(format!("the profile is not for the {name}"));
    }
    let objects = v
        .get("objects")
        .and_then(Json::as_object)
        .ok_or("the profile has no \"objects\"")?;
    let mut out = Vec::new();
    for (key, value) in objects {
        let index = u16::from_str_radix(key, 16)
            .map_err(|_| format!("\"{key}\" is not a MIB index in hex"))?;
        let hex = value
            .as_str()
            .ok_or_else(|| format!("object {key}: the value must be a hex string"))?;
        let data = crate::hex::parse(hex).map_err(|e| format!("object {key}: {e}"))?;
        let at = index_text(chip.dialect(), index);
        let o = chip::object(chip, index)
            .filter(holds)
            .ok_or_else(|| format!("object {at}h: not a writable object of the {name}"))?;
        o.check_write(&data)
            .map_err(|e| format!("object {at}h: {e}"))?;
        out.push((index, data));
    }
    if out.is_empty() {
        return Err("the profile has no objects".to_string());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::st7580::mib::{index, object};
    use alloc::vec;

    fn text_of(chip: &dyn Chip, values: &[(u16, Vec<u8>)]) -> String {
        to_json(chip, |i| {
            values.iter().find(|(x, _)| *x == i).map(|(_, v)| &v[..])
        })
    }

    #[test]
    fn profiles_save_writable_objects_and_load_them_checked() {
        let chip = crate::chip::St7580::default();
        let phy = index::PHY_CONFIG as u16;
        let values = vec![
            (phy, object(index::PHY_CONFIG).unwrap().default.to_vec()),
            (index::FIRMWARE_VERSION as u16, vec![0, 0x42, 0, 0x97]),
        ];
        let text = text_of(&chip, &values);
        assert!(text.contains("\"01\": \"014ff0"), "{text}");
        let back = parse(&chip, &text).unwrap();
        assert_eq!(back, [(phy, values[0].1.clone())]);
        let bad = text.replace("014ff0", "030d40");
        assert_eq!(
            parse(&chip, &bad),
            Err("object 01h: high_frequency: 200000 is out of range: 3000 to 148500 Hz".into())
        );
        assert!(parse(&chip, "{}").unwrap_err().starts_with("not a profile"));
    }

    /// A profile cut short, with a byte changed anywhere, or not UTF-8
    /// text, is refused in words (or, changed where the value stays
    /// valid, read and checked as any profile), never a panic.
    #[test]
    fn a_damaged_profile_is_refused_in_words() {
        let chip = crate::chip::St7580::default();
        let mut values: Vec<(u16, Vec<u8>)> = Vec::new();
        for i in [index::PHY_CONFIG, index::MODEM_CONFIG] {
            values.push((i as u16, object(i).unwrap().default.to_vec()));
        }
        let text = text_of(&chip, &values).into_bytes();
        let read = |b: &[u8]| crate::file::text(b).and_then(|t| parse(&chip, t));
        assert!(read(&text).is_ok());
        for n in 0..text.len() {
            assert!(read(&text[..n]).unwrap_err().len() > 15, "cut at {n}");
        }
        for i in 0..text.len() {
            for bit in [0x01, 0x20, 0x80] {
                let mut b = text.clone();
                b[i] ^= bit;
                if let Err(why) = read(&b) {
                    assert!(why.len() > 15, "{why}");
                }
            }
        }
        let utf16: Vec<u8> = text.iter().flat_map(|&b| [b, 0]).collect();
        assert!(read(&[&[0xFE, 0xFF][..], &utf16].concat())
            .unwrap_err()
            .contains("UTF-16"));
        assert!(read(&utf16).unwrap_err().contains("NUL byte"));
    }

    /// Issue 12: the ST7570's profile files come from the same code, read
    /// its MIB (16-bit indexes, Table 71), leave out the counters a write
    /// resets, and refuse a profile of the other chip.
    #[test]
    fn an_st7570_profile_holds_its_configuration_objects_only() {
        use crate::st7570::mib::{index as i7570, object as o7570};
        let chip = crate::chip::St7570::default();
        let mut values: Vec<(u16, Vec<u8>)> = Vec::new();
        for o in chip.mib() {
            values.push((o.index, o.default.to_vec()));
        }
        let text = text_of(&chip, &values);
        assert!(text.contains("\"chip\": \"ST7570\""), "{text}");
        assert!(text.contains("\"00a1\": "), "{text}");
        let back = parse(&chip, &text).unwrap();
        assert!(back.iter().all(|(i, _)| {
            let o = o7570(*i).unwrap();
            o.access.write && o.write.is_none()
        }));
        assert!(back.iter().any(|(i, _)| *i == i7570::PLC_CONFIGURATION));
        assert!(parse(&crate::chip::St7580::default(), &text)
            .unwrap_err()
            .contains("not for the ST7580"));
        // A value the chip would refuse refuses the whole file.
        let tic = o7570(i7570::TIC_REPEATER).unwrap();
        let bad = text.replace(
            &format!("\"000b\": \"{}\"", crate::hex::encode(tic.default)),
            "\"000b\": \"0102\"",
        );
        assert_ne!(bad, text);
        assert!(parse(&chip, &bad).unwrap_err().starts_with("object 000Bh:"));
    }
}
