//! The declarative MIB description: every object of both chips with its
//! name, index, length, access, factory default and field layout. Console
//! forms are rendered from it, the decoder prints with it and the simulator
//! validates with it; nothing about a MIB object is described twice.

use crate::field::{self, Field, FieldError, Value};
use alloc::vec::Vec;
use core::fmt;

pub use crate::st7580::mib::OBJECTS as ST7580;

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

    /// As the manual writes it: `R`, `R/W`, `R/E`.
    pub fn label(self) -> &'static str {
        match (self.write, self.erase) {
            (true, _) => "R/W",
            (_, true) => "R/E",
            _ => "R",
        }
    }
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

    /// The checks the chip applies to a MIB_WriteRequest of this object.
    pub fn check_write(&self, data: &[u8]) -> Result<(), MibError> {
        if !self.access.write {
            return Err(MibError::NotWritable(self.name));
        }
        self.check_value(data)
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
