//! A layout's named fields as the members of a JSON object, the way
//! `plm decode` prints them for a modem's frames ([`crate::decode`]) and a
//! board's ([`crate::decode::app`]) alike.

use crate::field::{Field, Value};
use crate::hex;
use crate::json::{Json, Object};
use crate::mib;
use alloc::format;
use alloc::string::ToString;

/// A field value as JSON: numbers as numbers, enums by the manual's name,
/// bytes as lowercase hex, "no value" as null.
fn json_value(v: &Value) -> Json {
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

/// One field's value in `map` under its name. A number the seed reads in
/// a unit ([`Field::scale`]: S0 in dBµV) is given in that unit, and the
/// raw number beside it as `NAME_raw`.
pub(crate) fn put_value(map: &mut Object, f: &Field, v: &Value) {
    match f.reading(v) {
        Some(text) => {
            map.insert(f.name, Json::Number(text));
            map.insert(format!("{}_raw", f.name), json_value(v));
        }
        None => map.insert(f.name, json_value(v)),
    }
}

/// The named values of `data` under `layout`, in `map`.
pub(crate) fn put_layout(map: &mut Object, layout: &'static [Field], data: &[u8]) {
    for (f, v) in mib::describe(layout, data) {
        put_value(map, f, &v);
    }
}
