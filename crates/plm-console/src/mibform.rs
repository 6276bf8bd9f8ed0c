//! The form model of a MIB object, read from plm-core's declarative
//! description (`plm_core::mib::Object` and its `Field`s): what each input
//! shows, and the value a filled-in form makes, checked field by field as
//! the chip would check it before anything is sent. No object has a form
//! of its own: the Modem view renders every one from this.

use plm_core::field::{Field, Kind};
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
}
