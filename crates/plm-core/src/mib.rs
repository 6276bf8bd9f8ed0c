//! The declarative MIB description: what an object of either chip is (its
//! name, index, length, access, factory default and field layout); each
//! chip lists its own objects in it (`st7580::mib::OBJECTS`,
//! `st7570::mib::OBJECTS`). Console forms are rendered from it, the
//! decoder prints with it and the simulator validates with it; nothing
//! about a MIB object is described twice.

use crate::field::{self, Field, FieldError, Value};
use alloc::vec::Vec;
use core::fmt;

/// What the host may do with an object (UM0932 Table 52, R/W/E).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Access {
    /// MIB_ReadRequest allowed.
    pub read: bool,
    /// MIB_WriteRequest allowed.
    pub write: bool,
    /// MIB_EraseRequest allowed.
    pub erase: bool,
}

impl Access {
    /// R.
    pub const R: Access = Access {
        read: true,
        write: false,
        erase: false,
    };
    /// R/W.
    pub const RW: Access = Access {
        read: true,
        write: true,
        erase: false,
    };
    /// R/E.
    pub const RE: Access = Access {
        read: true,
        write: false,
        erase: true,
    };
    /// W: written, never read (ST7570 UM 6.5.29, 00A0h).
    pub const W: Access = Access {
        read: false,
        write: true,
        erase: false,
    };

    /// As the manual writes it: `R`, `R/W`, `R/E`, `W`.
    pub fn label(self) -> &'static str {
        match (self.read, self.write, self.erase) {
            (true, true, _) => "R/W",
            (false, true, _) => "W",
            (_, _, true) => "R/E",
            _ => "R",
        }
    }
}

/// Where an object may be used. The ST7570 knows some objects only in one
/// access layer (ST7570 UM 6.5: ERR_UNAVAILABLE_RESOURCE "the modem is not
/// configured as MAC") and refuses some writes in some operating modes
/// (ERR_REQUEST_NOT_ALLOWED "the modem is configured as Monitor"). The
/// ST7580 has no such limits ([`Scope::ANY`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scope {
    /// The object exists with the PHY access layer.
    pub phy: bool,
    /// The object exists with the MAC access layer.
    pub mac: bool,
    /// Operating modes in which a write is allowed: bit n is mode n of
    /// ST7570 MIB 00A1h byte 0 (0 IDLE, 1 Client, 2 Server, 3 Monitor,
    /// 4-6 Test).
    pub write_modes: u8,
}

impl Scope {
    /// Every layer, every mode.
    pub const ANY: Scope = Scope {
        phy: true,
        mac: true,
        write_modes: 0xFF,
    };
}

/// One MIB object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Object {
    /// Index (ST7580: 00h..0Ah; ST7570 indexes are 16-bit).
    pub index: u16,
    /// The manual's name (`PHY configuration`).
    pub name: &'static str,
    /// Where the seed describes it (`UM0932 4.2.2, Table 54`).
    pub section: &'static str,
    /// Length of its value in bytes.
    pub len: usize,
    /// Allowed operations.
    pub access: Access,
    /// Factory default value.
    pub default: &'static [u8],
    /// Its fields.
    pub fields: &'static [Field],
    /// The layout of a write request's data when it is not the value
    /// itself (ST7570 UM 6.5: a counter is reset by 4 PAD bytes, 0082h is
    /// written with 2 of the 3 bytes it confirms); `None` when a write
    /// carries the value.
    pub write: Option<&'static [Field]>,
    /// Where the object may be used.
    pub scope: Scope,
}

/// Why a MIB operation is refused, in words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MibError {
    /// No object has this index.
    UnknownObject(u16),
    /// The object cannot be written.
    NotWritable(&'static str),
    /// The object cannot be erased.
    NotErasable(&'static str),
    /// The object cannot be read (ST7570 00A0h is written only).
    NotReadable(&'static str),
    /// The value has the wrong length.
    WrongLength {
        /// Object name.
        object: &'static str,
        /// Its length.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// A field value is not allowed.
    Field(FieldError),
}

impl fmt::Display for MibError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MibError::UnknownObject(i) => write!(f, "there is no MIB object {i:02X}h"),
            MibError::NotWritable(n) => write!(f, "{n} is read-only"),
            MibError::NotErasable(n) => write!(f, "{n} cannot be erased"),
            MibError::NotReadable(n) => write!(f, "{n} is written only, it cannot be read"),
            MibError::WrongLength {
                object,
                expected,
                got,
            } => {
                write!(f, "{object} is {expected} bytes long, not {got}")
            }
            MibError::Field(e) => write!(f, "{e}"),
        }
    }
}

impl Object {
    /// The named values of `data` (reserved bits only when not zero).
    pub fn describe(&self, data: &[u8]) -> Vec<(&'static Field, Value)> {
        describe(self.fields, data)
    }

    /// The checks the chip applies to a MIB_WriteRequest of this object:
    /// access, then the length and fields of the write layout.
    pub fn check_write(&self, data: &[u8]) -> Result<(), MibError> {
        if !self.access.write {
            return Err(MibError::NotWritable(self.name));
        }
        let Some(layout) = self.write else {
            return self.check_value(data);
        };
        if data.len() != self.write_len() {
            return Err(MibError::WrongLength {
                object: self.name,
                expected: self.write_len(),
                got: data.len(),
            });
        }
        field::validate(layout, data).map_err(MibError::Field)
    }

    /// The layout of a write request's data.
    pub fn write_fields(&self) -> &'static [Field] {
        self.write.unwrap_or(self.fields)
    }

    /// Bytes of a write request's data.
    pub fn write_len(&self) -> usize {
        match self.write {
            Some(layout) => layout.iter().map(Field::end).max().unwrap_or(0),
            None => self.len,
        }
    }

    /// The checks the chip applies to a read request of this object.
    pub fn check_read(&self) -> Result<(), MibError> {
        if self.access.read {
            Ok(())
        } else {
            Err(MibError::NotReadable(self.name))
        }
    }

    /// Checks a value (length and every field) without regard to access.
    pub fn check_value(&self, data: &[u8]) -> Result<(), MibError> {
        if data.len() != self.len {
            return Err(MibError::WrongLength {
                object: self.name,
                expected: self.len,
                got: data.len(),
            });
        }
        field::validate(self.fields, data).map_err(MibError::Field)
    }

    /// The checks the chip applies to a MIB_EraseRequest of this object.
    pub fn check_erase(&self) -> Result<(), MibError> {
        if self.access.erase {
            Ok(())
        } else {
            Err(MibError::NotErasable(self.name))
        }
    }

    /// A field by name.
    pub fn field(&self, name: &str) -> Option<&'static Field> {
        field::find(self.fields, name)
    }
}

/// The named values of `data` under `layout`; reserved and unused bits are
/// listed only when they are not zero, so that nothing is hidden.
pub fn describe(layout: &'static [Field], data: &[u8]) -> Vec<(&'static Field, Value)> {
    layout
        .iter()
        .filter_map(|f| {
            let v = f.read(data)?;
            (f.settable || v.as_i64() != Some(0)).then_some((f, v))
        })
        .collect()
}

/// The object of a table by index.
pub fn find(objects: &'static [Object], index: u16) -> Option<&'static Object> {
    objects.iter().find(|o| o.index == index)
}
