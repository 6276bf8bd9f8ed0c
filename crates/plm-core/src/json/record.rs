//! Structs written as JSON objects, one member per field: what serde's
//! derive did for [`crate::decode::Decoded`] and
//! [`crate::decode::app::AppDecoded`], written out once in
//! [`json_record!`].

use super::{Json, Object};
use alloc::format;
use alloc::string::String;

/// A struct field as a member of its JSON object.
pub(crate) trait Member: Sized {
    /// Sets `key` in `o`, or leaves it out (a `None`).
    fn put(&self, key: &'static str, o: &mut Object);
    /// Reads the member `key`; `v` is `None` when the object lacks it.
    fn take(v: Option<&Json>, key: &'static str) -> Result<Self, String>;
}

/// A value a field holds.
pub(crate) trait Scalar: Sized {
    /// What the JSON value must be, in words.
    const WHAT: &'static str;
    fn to_json(&self) -> Json;
    fn from_json(v: &Json) -> Option<Self>;
}

impl Scalar for String {
    const WHAT: &'static str = "a string";
    fn to_json(&self) -> Json {
        Json::String(self.clone())
    }
    fn from_json(v: &Json) -> Option<Self> {
        v.as_str().map(Into::into)
    }
}

impl Scalar for bool {
    const WHAT: &'static str = "true or false";
    fn to_json(&self) -> Json {
        Json::Bool(*self)
    }
    fn from_json(v: &Json) -> Option<Self> {
        match v {
            Json::Bool(b) => Some(*b),
            _ => None,
        }
    }
}

impl Scalar for u8 {
    const WHAT: &'static str = "a whole number from 0 to 255";
    fn to_json(&self) -> Json {
        Json::from(*self)
    }
    fn from_json(v: &Json) -> Option<Self> {
        v.as_i64()?.try_into().ok()
    }
}

impl Scalar for u16 {
    const WHAT: &'static str = "a whole number from 0 to 65535";
    fn to_json(&self) -> Json {
        Json::from(*self)
    }
    fn from_json(v: &Json) -> Option<Self> {
        v.as_i64()?.try_into().ok()
    }
}

impl Scalar for u32 {
    const WHAT: &'static str = "a whole number from 0 to 4294967295";
    fn to_json(&self) -> Json {
        Json::from(*self)
    }
    fn from_json(v: &Json) -> Option<Self> {
        v.as_i64()?.try_into().ok()
    }
}

impl Scalar for Object {
    const WHAT: &'static str = "an object";
    fn to_json(&self) -> Json {
        Json::Object(self.clone())
    }
    fn from_json(v: &Json) -> Option<Self> {
        v.as_object().cloned()
    }
}

/// Any value, `null` included: a `command` of `null` says the code is
/// unknown, which is not the same as no `command` at all.
impl Scalar for Json {
    const WHAT: &'static str = "a value";
    fn to_json(&self) -> Json {
        self.clone()
    }
    fn from_json(v: &Json) -> Option<Self> {
        Some(v.clone())
    }
}

/// A field every object has.
impl Member for String {
    fn put(&self, key: &'static str, o: &mut Object) {
        o.insert(key, self.to_json());
    }
    fn take(v: Option<&Json>, key: &'static str) -> Result<Self, String> {
        let v = v.ok_or_else(|| format!("`{key}` is missing"))?;
        Scalar::from_json(v).ok_or_else(|| format!("`{key}` must be {}", Self::WHAT))
    }
}

/// A field left out when `None`; read as `None` when missing or `null`
/// (unless `null` is a value of the field).
impl<T: Scalar> Member for Option<T> {
    fn put(&self, key: &'static str, o: &mut Object) {
        if let Some(v) = self {
            o.insert(key, v.to_json());
        }
    }
    fn take(v: Option<&Json>, key: &'static str) -> Result<Self, String> {
        match v {
            None => Ok(None),
            Some(v) => match T::from_json(v) {
                Some(x) => Ok(Some(x)),
                None if *v == Json::Null => Ok(None),
                None => Err(format!("`{key}` must be {}", T::WHAT)),
            },
        }
    }
}

/// `to_json` and `from_json` of a struct, from the list of its fields in
/// the order they are written: each under its own name, `None`s left
/// out, as serde's derive wrote them. The struct literal in `from_json`
/// makes the compiler check that the list names every field once. With
/// the `serde` feature, `Serialize` goes through `to_json`, so that
/// `plm decode` and the console write the same bytes.
macro_rules! json_record {
    ($name:ident { $($field:ident),* $(,)? }) => {
        impl $name {
            /// This as a JSON object: every field under its own name, in
            /// a fixed order, those that are `None` left out.
            pub fn to_json(&self) -> $crate::json::Json {
                let mut o = $crate::json::Object::new();
                $( $crate::json::Member::put(&self.$field, stringify!($field), &mut o); )*
                $crate::json::Json::Object(o)
            }

            /// Reads back what [`Self::to_json`] writes. Keys it does not
            /// know are ignored; a missing or `null` optional field is
            /// `None`; the error says which key is missing or wrong.
            pub fn from_json(v: &$crate::json::Json) -> Result<Self, ::alloc::string::String> {
                let o = v.as_object().ok_or("not a JSON object")?;
                Ok($name {
                    $( $field: $crate::json::Member::take(
                        o.get(stringify!($field)),
                        stringify!($field),
                    )?, )*
                })
            }
        }

        #[cfg(feature = "serde")]
        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                self.to_json().serialize(s)
            }
        }
    };
}
pub(crate) use json_record;
