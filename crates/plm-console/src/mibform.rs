//! The form model of a MIB object, read from plm-core's declarative
//! description (`plm_core::mib::Object` and its `Field`s): what each input
//! shows, and the value a filled-in form makes, checked field by field as
//! the chip would check it before anything is sent. No object has a form
//! of its own: the Modem view renders every one from this.

use plm_core::chip::Chip;
use plm_core::field::{Field, Kind};
use plm_core::json::{self, Json};
use plm_core::link::Dialect;
use plm_core::mib::Object;

/// Texts by field name: what a form's inputs hold, or what is wrong with
/// each. A list (an object has a handful of fields): a map type of its
/// own would bring its own copy of the tree code into the console's wasm.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Texts(Vec<(&'static str, String)>);

impl Texts {
    /// The text of field `name`.
    pub fn get(&self, name: &str) -> Option<&String> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, t)| t)
    }

    /// Sets the text of field `name`.
    pub fn insert(&mut self, name: &'static str, text: String) {
        match self.0.iter_mut().find(|(n, _)| *n == name) {
            Some(entry) => entry.1 = text,
            None => self.0.push((name, text)),
        }
    }

    /// Every field's text, in the order set.
    pub fn iter(&self) -> impl Iterator<Item = &(&'static str, String)> {
        self.0.iter()
    }

    /// Whether field `name` has a text.
    pub fn contains_key(&self, name: &str) -> bool {
        self.get(name).is_some()
    }

    /// Fields with a text.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether no field has a text.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// MIB values read from the modem, by object index (a list, for the same
/// reason as [`Texts`]; the ST7570's indexes are 16-bit).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MibValues(Vec<(u16, Vec<u8>)>);

impl MibValues {
    /// The value of object `index`, if read.
    pub fn get(&self, index: &u16) -> Option<&Vec<u8>> {
        self.0.iter().find(|(i, _)| i == index).map(|(_, v)| v)
    }

    /// Keeps the value of object `index`.
    pub fn insert(&mut self, index: u16, value: Vec<u8>) {
        self.remove(index);
        self.0.push((index, value));
    }

    /// Forgets the value of object `index`.
    pub fn remove(&mut self, index: u16) {
        self.0.retain(|(i, _)| *i != index);
    }

    /// Whether object `index` was read.
    pub fn contains_key(&self, index: &u16) -> bool {
        self.get(index).is_some()
    }
}

impl std::ops::Index<&u16> for MibValues {
    type Output = Vec<u8>;

    /// The value of object `index`; panics if it was not read (tests).
    fn index(&self, index: &u16) -> &Vec<u8> {
        self.get(index).expect("a value for this object")
    }
}

impl std::ops::Index<&str> for Texts {
    type Output = String;

    /// The text of field `name`; panics if it has none (tests).
    fn index(&self, name: &str) -> &String {
        self.get(name).expect("a text for this field")
    }
}

impl FromIterator<(&'static str, String)> for Texts {
    fn from_iter<I: IntoIterator<Item = (&'static str, String)>>(it: I) -> Self {
        let mut t = Texts::default();
        for (n, v) in it {
            t.insert(n, v);
        }
        t
    }
}

/// The text an input shows for a field of `data`: numbers in decimal,
/// enums and flags as their raw value, bytes as hex.
pub fn input_text(field: &Field, data: &[u8]) -> String {
    match field.kind {
        Kind::Bytes => match field.read(data) {
            Some(plm_core::field::Value::Bytes(b)) => plm_core::hex::encode(&b),
            _ => String::new(),
        },
        _ => field.get(data).map(|v| v.to_string()).unwrap_or_default(),
    }
}

/// A field's value in words, with its unit (`86000 Hz`, `Q-PSK`, `66.46
/// dBµV`: [`Field::show`]).
pub fn show(field: &Field, data: &[u8]) -> String {
    match field.read(data) {
        None => "–".to_string(),
        Some(v) => field.show(&v),
    }
}

/// The fields a person sets: not reserved or unused bits.
pub fn editable(object: &'static Object) -> impl Iterator<Item = &'static Field> {
    object.fields.iter().filter(|f| f.settable)
}

/// The fields whose values differ between `a` and `b`.
pub fn differences(object: &'static Object, a: &[u8], b: &[u8]) -> Vec<&'static Field> {
    object
        .fields
        .iter()
        .filter(|f| f.read(a) != f.read(b))
        .collect()
}

/// Why a form cannot be sent: reasons by field name, and one for the
/// object as a whole.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Problems {
    /// Field name to the reason, in words.
    pub fields: Texts,
    /// A reason that is no one field's (length, reserved bits of the base).
    pub object: Option<String>,
}

fn number(text: &str) -> Result<i64, String> {
    let t = text.trim();
    let parsed = match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(hex) => i64::from_str_radix(hex, 16),
        None => t.parse::<i64>(),
    };
    parsed.map_err(|_| {
        if t.is_empty() {
            "enter a value".to_string()
        } else {
            format!("\"{t}\" is not a whole number")
        }
    })
}

/// Puts one input into `data`, checked as the chip checks the field.
fn apply(field: &Field, text: &str, data: &mut [u8]) -> Result<(), String> {
    if let Kind::Bytes = field.kind {
        let bytes = plm_core::hex::parse(text).map_err(|e| e.to_string())?;
        let want = if field.size == 0 {
            data.len().saturating_sub(field.offset)
        } else {
            field.size
        };
        if bytes.len() != want {
            return Err(format!(
                "{want} bytes (as {} hex digits) are needed, not {}",
                2 * want,
                bytes.len()
            ));
        }
        data[field.offset..field.offset + want].copy_from_slice(&bytes);
        return Ok(());
    }
    let v = number(text)?;
    field.check(v).map_err(|e| e.reason)?;
    field.set(data, v);
    Ok(())
}

/// The value the form makes: `base` (the value last read, or the factory
/// default) with every input applied. Reserved bits keep the base's.
/// Every field's problem is reported, not only the first, and the whole
/// value is then checked as a MIB_WriteRequest would be.
pub fn build(object: &'static Object, base: &[u8], inputs: &Texts) -> Result<Vec<u8>, Problems> {
    let mut data = base.to_vec();
    data.resize(object.len, 0);
    let mut problems = Problems::default();
    for f in editable(object) {
        let Some(text) = inputs.get(f.name) else {
            continue;
        };
        if let Err(why) = apply(f, text, &mut data) {
            problems.fields.insert(f.name, why);
        }
    }
    if problems.fields.is_empty() {
        if let Err(e) = object.check_value(&data) {
            match e {
                plm_core::mib::MibError::Field(fe) => {
                    problems.fields.insert(fe.field, fe.reason);
                }
                other => problems.object = Some(other.to_string()),
            }
        }
    }
    if problems.fields.is_empty() && problems.object.is_none() {
        Ok(data)
    } else {
        Err(problems)
    }
}

/// What a saved profile file says it is.
pub const PROFILE_FORMAT: &str = "plm-console MIB profile";

/// The objects a profile holds: those written with their value (not the
/// counters a write resets, ST7570 UM 6.5).
fn in_profile(o: &&Object) -> bool {
    o.access.write && o.write.is_none()
}

/// The objects of `chip` a profile holds.
pub fn profile_objects(chip: &dyn Chip) -> impl Iterator<Item = &'static Object> {
    chip.mib().iter().filter(in_profile)
}

/// Whether a write of `object` resets it rather than setting the value
/// the form shows (ST7570 UM 6.5: a counter is reset by PAD bytes).
pub fn write_resets(object: &Object) -> bool {
    object.write.is_some_and(|w| {
        w.iter()
            .any(|f| object.fields.iter().all(|g| g.name != f.name))
    })
}

/// The data of the write request for the value a form made: the value
/// itself, the part of it the write layout carries (ST7570 0082h is
/// written with 2 of the 3 bytes it confirms), or the write layout's
/// zeros for an object a write resets.
pub fn write_data(object: &Object, value: &[u8]) -> Vec<u8> {
    match object.write {
        None => value.to_vec(),
        Some(_) if write_resets(object) => vec![0; object.write_len()],
        Some(_) => value[..object.write_len().min(value.len())].to_vec(),
    }
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

/// A configuration profile of `chip`: values of its writable MIB objects,
/// saved to and loaded from a JSON file (`{"format":…, "chip":"ST7580",
/// "objects": {"01": "014ff0…"}}`, values as lowercase hex).
pub fn profile_json(chip: &dyn Chip, values: &MibValues) -> String {
    let mut objects = json::Object::new();
    for o in chip.mib().iter().filter(in_profile) {
        if let Some(v) = values.get(&o.index) {
            objects.insert(
                index_text(chip.dialect(), o.index).to_ascii_lowercase(),
                Json::String(plm_core::hex::encode(v)),
            );
        }
    }
    let mut profile = json::Object::new();
    profile.insert("format", Json::from(PROFILE_FORMAT));
    profile.insert("chip", Json::from(chip.name()));
    profile.insert("objects", Json::Object(objects));
    Json::Object(profile).pretty()
}

/// Reads a profile file for `chip`; every value is checked as a MIB write
/// request would be, and the first problem refuses the whole file.
pub fn parse_profile(chip: &dyn Chip, text: &str) -> Result<Vec<(u16, Vec<u8>)>, String> {
    let v = json::parse(text).map_err(|e| format!("not JSON ({e})"))?;
    if v.get("format").and_then(Json::as_str) != Some(PROFILE_FORMAT) {
        return Err(format!(
            "not a profile: \"format\" must be \"{PROFILE_FORMAT}\""
        ));
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
        let data = plm_core::hex::parse(hex).map_err(|e| format!("object {key}: {e}"))?;
        let at = index_text(chip.dialect(), index);
        let o = plm_core::chip::object(chip, index)
            .filter(in_profile)
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
    use plm_core::st7580::mib::{index, object, phy_config};

    fn inputs(object: &'static Object, data: &[u8]) -> Texts {
        editable(object)
            .map(|f| (f.name, input_text(f, data)))
            .collect()
    }

    #[test]
    fn every_object_round_trips_its_default_through_the_form() {
        for o in plm_core::st7580::mib::OBJECTS {
            let got = build(o, o.default, &inputs(o, o.default));
            assert_eq!(got.as_deref(), Ok(o.default), "{}", o.name);
        }
    }

    #[test]
    fn a_changed_frequency_lands_in_its_bytes() {
        let o = object(index::PHY_CONFIG).unwrap();
        let mut i = inputs(o, o.default);
        i.insert("high_frequency", "110000".into());
        let data = build(o, o.default, &i).unwrap();
        assert_eq!(&data[..3], &[0x01, 0xAD, 0xB0]);
        assert_eq!(phy_config::HIGH_FREQUENCY.get(&data), Some(110_000));
        assert_eq!(
            differences(o, o.default, &data),
            [&phy_config::HIGH_FREQUENCY]
        );
        assert_eq!(show(&phy_config::HIGH_FREQUENCY, &data), "110000 Hz");
    }

    #[test]
    fn out_of_range_and_malformed_inputs_are_refused_with_reasons() {
        let o = object(index::PHY_CONFIG).unwrap();
        let mut i = inputs(o, o.default);
        i.insert("high_frequency", "200000".into());
        i.insert("tx_gain", "forty".into());
        i.insert("psk_preamble_length", "7".into());
        let p = build(o, o.default, &i).unwrap_err();
        assert_eq!(
            p.fields.get("high_frequency").map(String::as_str),
            Some("200000 is out of range: 3000 to 148500 Hz")
        );
        assert_eq!(
            p.fields.get("tx_gain").map(String::as_str),
            Some("\"forty\" is not a whole number")
        );
        assert!(p.fields["psk_preamble_length"].starts_with("7 is not one of 0 = 16 bit"));
    }

    #[test]
    fn the_key_must_be_sixteen_bytes_and_reserved_bits_of_the_base_are_refused() {
        let key = object(index::SS_KEY).unwrap();
        let mut i = inputs(key, key.default);
        i.insert("ss_key", "00112233".into());
        let p = build(key, key.default, &i).unwrap_err();
        assert_eq!(
            p.fields["ss_key"],
            "16 bytes (as 32 hex digits) are needed, not 4"
        );
        let mc = object(index::MODEM_CONFIG).unwrap();
        let p = build(mc, &[0x31], &inputs(mc, &[0x31])).unwrap_err();
        assert_eq!(p.fields["reserved"], "Reserved bits must be 0, not 1");
    }

    #[test]
    fn profiles_save_writable_objects_and_load_them_checked() {
        let chip = plm_core::chip::St7580::default();
        let phy = index::PHY_CONFIG as u16;
        let mut values = MibValues::default();
        values.insert(phy, object(index::PHY_CONFIG).unwrap().default.to_vec());
        values.insert(index::FIRMWARE_VERSION as u16, vec![0, 0x42, 0, 0x97]);
        let text = profile_json(&chip, &values);
        assert!(text.contains("\"01\": \"014ff0"), "{text}");
        let back = parse_profile(&chip, &text).unwrap();
        assert_eq!(back, [(phy, values[&phy].clone())]);
        let bad = text.replace("014ff0", "030d40");
        assert_eq!(
            parse_profile(&chip, &bad),
            Err("object 01h: high_frequency: 200000 is out of range: 3000 to 148500 Hz".into())
        );
        assert!(parse_profile(&chip, "{}")
            .unwrap_err()
            .starts_with("not a profile"));
    }

    /// A profile cut short, with a byte changed anywhere, or not UTF-8
    /// text, is refused in words (or, changed where the value stays
    /// valid, read and checked as any profile), never a panic.
    #[test]
    fn a_damaged_profile_is_refused_in_words() {
        let chip = plm_core::chip::St7580::default();
        let mut values = MibValues::default();
        for i in [index::PHY_CONFIG, index::MODEM_CONFIG] {
            values.insert(i as u16, object(i).unwrap().default.to_vec());
        }
        let text = profile_json(&chip, &values).into_bytes();
        let read = |b: &[u8]| plm_core::file::text(b).and_then(|t| parse_profile(&chip, t));
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
        use plm_core::st7570::mib::{index as i7570, object as o7570};
        let chip = plm_core::chip::St7570::default();
        let mut values = MibValues::default();
        for o in chip.mib() {
            values.insert(o.index, o.default.to_vec());
        }
        let text = profile_json(&chip, &values);
        assert!(text.contains("\"chip\": \"ST7570\""), "{text}");
        assert!(text.contains("\"00a1\": "), "{text}");
        let back = parse_profile(&chip, &text).unwrap();
        assert!(back.iter().all(|(i, _)| {
            let o = o7570(*i).unwrap();
            o.access.write && !write_resets(o)
        }));
        assert!(back.iter().any(|(i, _)| *i == i7570::PLC_CONFIGURATION));
        assert!(parse_profile(&plm_core::chip::St7580::default(), &text)
            .unwrap_err()
            .contains("not for the ST7580"));
        // A value the chip would refuse refuses the whole file.
        let tic = o7570(i7570::TIC_REPEATER).unwrap();
        let bad = text.replace(
            &format!("\"000b\": \"{}\"", plm_core::hex::encode(tic.default)),
            "\"000b\": \"0102\"",
        );
        assert_ne!(bad, text);
        assert!(parse_profile(&chip, &bad)
            .unwrap_err()
            .starts_with("object 000Bh:"));
    }
}
