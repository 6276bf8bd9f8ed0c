//! JSON values, written and read the way `plm decode`, the console's
//! exports and its imports need: objects keep their keys in order, the
//! writer puts out exactly the bytes serde_json writes for the same value
//! (compact and pretty), and the parser is strict (RFC 8259) and says in
//! words where and what it expected.
//!
//! Written here rather than taken from serde_json because the console's
//! size budget (350 KiB gzipped, docs/console.md "Size") does not fit
//! serde_json's generic code; `tests/json_props.rs` holds this module to
//! serde_json's output byte for byte.
//!
//! Numbers: plm-core writes whole numbers ([`Json::Int`]), and the
//! decimal text of a field read in its unit ([`crate::field::Scale::text`]).
//! Any other number read from a file is kept as its text
//! ([`Json::Number`]) and written back as read, so no float formatting is
//! needed.

mod parse;
mod record;

pub use parse::{parse, ParseError};
pub(crate) use record::{json_record, Member};

use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

/// A JSON value.
#[derive(Debug, Clone, PartialEq)]
pub enum Json {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A whole number that an `i64` holds.
    Int(i64),
    /// Any other number (a fraction, an exponent, a whole number beyond
    /// `i64`), as its JSON text.
    Number(String),
    /// A string.
    String(String),
    /// An array.
    Array(Vec<Json>),
    /// An object, keys in order.
    Object(Object),
}

/// The members of a JSON object in order; a key appears once.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Object(Vec<(String, Json)>);

impl Object {
    /// An empty object.
    pub fn new() -> Self {
        Object(Vec::new())
    }

    /// Sets `key` to `value`: a key already there keeps its place (as
    /// serde_json's ordered map does), a new one goes last.
    pub fn insert(&mut self, key: impl Into<String>, value: Json) {
        let key = key.into();
        match self.0.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => *v = value,
            None => self.0.push((key, value)),
        }
    }

    /// The value of `key`.
    pub fn get(&self, key: &str) -> Option<&Json> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// Takes `key` out, keeping the order of the others.
    pub fn remove(&mut self, key: &str) -> Option<Json> {
        let i = self.0.iter().position(|(k, _)| k == key)?;
        Some(self.0.remove(i).1)
    }

    /// Sets every member of `other` in turn ([`Object::insert`]).
    pub fn extend(&mut self, other: Object) {
        for (k, v) in other.0 {
            self.insert(k, v);
        }
    }

    /// The members in order.
    pub fn iter(&self) -> impl Iterator<Item = (&String, &Json)> {
        self.0.iter().map(|(k, v)| (k, v))
    }

    /// How many members.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there is no member.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<'a> IntoIterator for &'a Object {
    type Item = (&'a String, &'a Json);
    type IntoIter = core::iter::Map<
        core::slice::Iter<'a, (String, Json)>,
        fn(&'a (String, Json)) -> (&'a String, &'a Json),
    >;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter().map(|(k, v)| (k, v))
    }
}

impl Json {
    /// The string, if this is one.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Json::String(s) => Some(s),
            _ => None,
        }
    }

    /// The number, if this is a whole number from 0 to `u64::MAX`.
    pub fn as_u64(&self) -> Option<u64> {
        match self {
            Json::Int(n) => u64::try_from(*n).ok(),
            Json::Number(text) => text.parse().ok(),
            _ => None,
        }
    }

    /// The number, if this is a whole number an `i64` holds.
    pub fn as_i64(&self) -> Option<i64> {
        match self {
            Json::Int(n) => Some(*n),
            _ => None,
        }
    }

    /// The object, if this is one.
    pub fn as_object(&self) -> Option<&Object> {
        match self {
            Json::Object(o) => Some(o),
            _ => None,
        }
    }

    /// The value of `key`, if this is an object that has it.
    pub fn get(&self, key: &str) -> Option<&Json> {
        self.as_object()?.get(key)
    }

    /// The text with two-space indents, as `serde_json::to_string_pretty`
    /// writes it. ([`ToString::to_string`] gives the compact text.)
    pub fn pretty(&self) -> String {
        let mut out = String::new();
        self.write(&mut out, Some(0));
        out
    }

    /// Appends the text to `out`: compact with `indent` `None`, else
    /// pretty at that depth.
    fn write(&self, out: &mut String, indent: Option<usize>) {
        match self {
            Json::Null => out.push_str("null"),
            Json::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
            Json::Int(n) => out.push_str(&n.to_string()),
            Json::Number(text) => out.push_str(text),
            Json::String(s) => write_string(out, s),
            Json::Array(items) => write_members(out, indent, '[', ']', items.iter(), |out, v| {
                v.write(out, indent.map(|i| i + 1))
            }),
            Json::Object(o) => write_members(out, indent, '{', '}', o.iter(), |out, (k, v)| {
                write_string(out, k);
                out.push_str(if indent.is_some() { ": " } else { ":" });
                v.write(out, indent.map(|i| i + 1));
            }),
        }
    }
}

/// Brackets around members separated by commas; pretty: each member on
/// its own line one level in, the closing bracket on its own line, and
/// nothing between the brackets of an empty one (serde_json's
/// `PrettyFormatter`).
fn write_members<T>(
    out: &mut String,
    indent: Option<usize>,
    open: char,
    close: char,
    members: impl Iterator<Item = T>,
    mut write: impl FnMut(&mut String, T),
) {
    out.push(open);
    let mut any = false;
    for m in members {
        if any {
            out.push(',');
        }
        if let Some(i) = indent {
            newline(out, i + 1);
        }
        write(out, m);
        any = true;
    }
    if let (Some(i), true) = (indent, any) {
        newline(out, i);
    }
    out.push(close);
}

fn newline(out: &mut String, depth: usize) {
    out.push('\n');
    for _ in 0..depth {
        out.push_str("  ");
    }
}

/// A string in quotes, escaped as serde_json escapes: `"` and `\`, the
/// short escapes `\b \t \n \f \r`, other control characters as `\u00xx`
/// (lowercase hex); everything else, `/` and non-ASCII included, as is.
fn write_string(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\u{8}' => out.push_str("\\b"),
            '\t' => out.push_str("\\t"),
            '\n' => out.push_str("\\n"),
            '\u{c}' => out.push_str("\\f"),
            '\r' => out.push_str("\\r"),
            c if (c as u32) < 0x20 => {
                out.push_str("\\u00");
                out.push_str(&crate::hex::encode(&[c as u8]));
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

/// The compact text, as `serde_json::to_string` writes it.
impl fmt::Display for Json {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut out = String::new();
        self.write(&mut out, None);
        f.write_str(&out)
    }
}

impl From<bool> for Json {
    fn from(b: bool) -> Self {
        Json::Bool(b)
    }
}

impl From<&str> for Json {
    fn from(s: &str) -> Self {
        Json::String(s.into())
    }
}

impl From<String> for Json {
    fn from(s: String) -> Self {
        Json::String(s)
    }
}

impl From<Object> for Json {
    fn from(o: Object) -> Self {
        Json::Object(o)
    }
}

macro_rules! from_int {
    ($($t:ty),*) => {$(
        impl From<$t> for Json {
            fn from(n: $t) -> Self {
                Json::Int(n.into())
            }
        }
    )*};
}
from_int!(u8, u16, u32, i8, i16, i32, i64);

/// Beyond `i64::MAX` the number is kept as its text.
impl From<u64> for Json {
    fn from(n: u64) -> Self {
        i64::try_from(n).map_or_else(|_| Json::Number(n.to_string()), Json::Int)
    }
}

impl<T: Into<Json>> From<Option<T>> for Json {
    fn from(v: Option<T>) -> Self {
        v.map_or(Json::Null, Into::into)
    }
}

/// `plm decode` serialises through serde (feature `serde`); the value
/// goes out member by member, so serde_json writes the same text as
/// [`Json`]'s own writer.
#[cfg(feature = "serde")]
impl serde::Serialize for Json {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{SerializeMap, SerializeSeq};
        match self {
            Json::Null => s.serialize_unit(),
            Json::Bool(b) => s.serialize_bool(*b),
            Json::Int(n) => s.serialize_i64(*n),
            // Whole numbers beyond i64 stay exact; other numbers (never
            // made by plm-core) go out as the nearest f64.
            Json::Number(text) => match text.parse::<u64>() {
                Ok(n) => s.serialize_u64(n),
                Err(_) => s.serialize_f64(text.parse().unwrap_or(f64::NAN)),
            },
            Json::String(v) => s.serialize_str(v),
            Json::Array(items) => {
                let mut seq = s.serialize_seq(Some(items.len()))?;
                for v in items {
                    seq.serialize_element(v)?;
                }
                seq.end()
            }
            Json::Object(o) => {
                let mut map = s.serialize_map(Some(o.len()))?;
                for (k, v) in o {
                    map.serialize_entry(k, v)?;
                }
                map.end()
            }
        }
    }
}
