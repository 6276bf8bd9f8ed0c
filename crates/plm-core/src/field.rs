//! Declarative field layouts: where a named value sits in a byte string.
//!
//! Every table of the seeds that splits bytes into labelled fields (UM0932
//! Tables 8, 19, 35-39, 45, 48, 53-62) is written once as a `&[Field]`.
//! The typed codecs read and write through these descriptions, the generic
//! decoder prints them, console forms are rendered from them and the
//! simulator validates with them: a bit position is never written twice.

use alloc::string::String;
use alloc::vec::Vec;
use core::fmt;

/// Byte order of a multi-byte field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// Most significant byte first (UM0932 data fields, see protocol notes).
    MsbFirst,
    /// Least significant byte first (ST7570 sub-fields, checksums).
    LsbFirst,
}

/// What a field's bits mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An unsigned number.
    Uint,
    /// A two's complement signed number.
    Int,
    /// A yes/no bit (1 = yes).
    Flag,
    /// A value chosen from a list; the index is the raw value. An empty name
    /// marks a value the seed does not define: it is preserved, shown as a
    /// number and refused by validation.
    Enum(&'static [&'static str]),
    /// Opaque bytes (keys, payloads), printed as hex.
    Bytes,
}

/// One labelled field of a layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// The seed's label in snake_case (`high_frequency`), used as JSON key.
    pub name: &'static str,
    /// The seed's label as printed in the manual (`High frequency`).
    pub label: &'static str,
    /// First byte of the field.
    pub offset: usize,
    /// Number of bytes the field spans (for [`Kind::Bytes`]: 0 = to the end).
    pub size: usize,
    /// For a field narrower than its bytes: (lowest bit, width).
    pub bits: Option<(u8, u8)>,
    /// What the value means.
    pub kind: Kind,
    /// Byte order when `size > 1`.
    pub order: Order,
    /// Unit of a number (`Hz`, `ms`, `13 µs`), empty when none.
    pub unit: &'static str,
    /// Smallest value the chip accepts (numbers only).
    pub min: i64,
    /// Largest value the chip accepts (numbers only).
    pub max: i64,
    /// Whether the host may set it (false for reserved and unused bits).
    pub settable: bool,
    /// A raw value that means "no value" (UM0932 Table 39: SNR 255 for
    /// FSK frames); it reads as [`Value::Absent`].
    pub absent: Option<&'static Absent>,
    /// How the seed reads the raw number in its unit (ST7570 UM 3.6.1:
    /// S0 in dBµV is the raw value / 100); `None` when the number is read
    /// as it is.
    pub scale: Option<&'static Scale>,
}

/// A raw value that means "no value" ([`Field::absent`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Absent {
    /// The raw value.
    pub raw: u64,
    /// When set, `raw` means "no value" only while this other field of
    /// the same bytes holds this value (Table 39: SNR 255 has no meaning
    /// for FSK frames only; for PSK frames it is -1 dB).
    pub only_while: Option<(&'static Field, i64)>,
}

/// A raw number read in the seed's unit: `raw × factor` `unit`, given to
/// `decimals` places (ST7570 UM 3.6.1, Equations 1 and 2).
#[derive(Debug, Clone, Copy)]
pub struct Scale {
    /// The unit of the reading (`dBµV`, `dB`).
    pub unit: &'static str,
    /// The reading of one raw step.
    pub factor: f64,
    /// Decimal places the reading is given to (at most 9).
    pub decimals: u8,
}

impl PartialEq for Scale {
    fn eq(&self, other: &Scale) -> bool {
        self.unit == other.unit
            && self.factor.to_bits() == other.factor.to_bits()
            && self.decimals == other.decimals
    }
}

impl Eq for Scale {}

impl Scale {
    /// The reading of `raw`.
    pub fn of(&self, raw: i64) -> f64 {
        raw as f64 * self.factor
    }

    /// The reading of `raw` as decimal text with [`Scale::decimals`]
    /// places, rounded half away from zero (`6646` at 0.01 is `66.46`).
    /// Written out rather than through float formatting, which would cost
    /// the console's wasm two algorithms and their tables.
    pub fn text(&self, raw: i64) -> String {
        let decimals = self.decimals.min(9) as u32;
        let step = 10u64.pow(decimals);
        let v = self.of(raw);
        // Non-negative and below 2^53: `as` truncates, + 0.5 rounds.
        let scaled = (if v < 0.0 { -v } else { v }) * step as f64 + 0.5;
        let scaled = scaled as u64;
        let sign = if v < 0.0 && scaled != 0 { "-" } else { "" };
        match decimals {
            0 => alloc::format!("{sign}{scaled}"),
            d => alloc::format!(
                "{sign}{}.{:0width$}",
                scaled / step,
                scaled % step,
                width = d as usize
            ),
        }
    }
}

/// A decoded field value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Value {
    /// An unsigned number.
    Uint(u32),
    /// A signed number.
    Int(i32),
    /// A yes/no bit.
    Flag(bool),
    /// An enumerated value: its raw number and the seed's name, if defined.
    Enum {
        /// The raw value.
        raw: u8,
        /// The seed's name for it (`Q-PSK`), `None` for an undefined value.
        name: Option<&'static str>,
    },
    /// Opaque bytes.
    Bytes(Vec<u8>),
    /// The field holds its "no value" marker.
    Absent,
}

impl Value {
    /// The value as a plain number, for numbers, flags and enums.
    pub fn as_i64(&self) -> Option<i64> {
        match *self {
            Value::Uint(v) => Some(v as i64),
            Value::Int(v) => Some(v as i64),
            Value::Flag(v) => Some(v as i64),
            Value::Enum { raw, .. } => Some(raw as i64),
            Value::Bytes(_) | Value::Absent => None,
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Uint(v) => write!(f, "{v}"),
            Value::Int(v) => write!(f, "{v}"),
            Value::Flag(v) => write!(f, "{v}"),
            Value::Enum { name: Some(n), .. } => f.write_str(n),
            Value::Enum { raw, name: None } => write!(f, "{raw} (undefined)"),
            Value::Bytes(b) => f.write_str(&crate::hex::encode(b)),
            Value::Absent => f.write_str("no value"),
        }
    }
}

/// Why a value does not fit a field, in words for the user.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldError {
    /// The field's snake_case name.
    pub field: &'static str,
    /// What is wrong and what is allowed.
    pub reason: String,
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

impl Field {
    const fn base(
        name: &'static str,
        label: &'static str,
        offset: usize,
        size: usize,
        kind: Kind,
    ) -> Field {
        Field {
            name,
            label,
            offset,
            size,
            bits: None,
            kind,
            order: Order::MsbFirst,
            unit: "",
            min: 0,
            max: 0,
            settable: true,
            absent: None,
            scale: None,
        }
    }

    /// An unsigned number filling `size` whole bytes.
    pub const fn uint(
        name: &'static str,
        label: &'static str,
        offset: usize,
        size: usize,
    ) -> Field {
        let mut f = Field::base(name, label, offset, size, Kind::Uint);
        f.max = (1i64 << (8 * size)) - 1;
        f
    }

    /// A signed number filling `size` whole bytes.
    pub const fn int(name: &'static str, label: &'static str, offset: usize, size: usize) -> Field {
        let mut f = Field::base(name, label, offset, size, Kind::Int);
        f.min = -(1i64 << (8 * size - 1));
        f.max = (1i64 << (8 * size - 1)) - 1;
        f
    }

    /// Opaque bytes; `size` 0 runs to the end of the data.
    pub const fn bytes(
        name: &'static str,
        label: &'static str,
        offset: usize,
        size: usize,
    ) -> Field {
        Field::base(name, label, offset, size, Kind::Bytes)
    }

    /// An unsigned number in bits `lo .. lo+width` of byte `offset`.
    pub const fn bits_uint(
        name: &'static str,
        label: &'static str,
        offset: usize,
        lo: u8,
        width: u8,
    ) -> Field {
        let mut f = Field::base(name, label, offset, 1, Kind::Uint);
        f.bits = Some((lo, width));
        f.max = (1i64 << width) - 1;
        f
    }

    /// A yes/no bit.
    pub const fn flag(name: &'static str, label: &'static str, offset: usize, bit: u8) -> Field {
        let mut f = Field::base(name, label, offset, 1, Kind::Flag);
        f.bits = Some((bit, 1));
        f.max = 1;
        f
    }

    /// An enumerated value in bits `lo .. lo+width` of byte `offset`.
    pub const fn enumeration(
        name: &'static str,
        label: &'static str,
        offset: usize,
        lo: u8,
        width: u8,
        names: &'static [&'static str],
    ) -> Field {
        let mut f = Field::base(name, label, offset, 1, Kind::Enum(names));
        f.bits = Some((lo, width));
        f.max = names.len() as i64 - 1;
        f
    }

    /// A reserved or unused bit range: decoded, preserved, never set by forms.
    pub const fn reserved(
        name: &'static str,
        label: &'static str,
        offset: usize,
        lo: u8,
        width: u8,
    ) -> Field {
        let mut f = Field::bits_uint(name, label, offset, lo, width);
        f.settable = false;
        f
    }

    /// The same field with a unit.
    pub const fn unit(mut self, unit: &'static str) -> Field {
        self.unit = unit;
        self
    }

    /// The same field read in the seed's unit through `scale` (the raw
    /// number keeps [`Field::unit`]).
    pub const fn scaled(mut self, scale: &'static Scale) -> Field {
        self.scale = Some(scale);
        self
    }

    /// The same field with the range the chip accepts.
    pub const fn range(mut self, min: i64, max: i64) -> Field {
        self.min = min;
        self.max = max;
        self
    }

    /// The same field with a raw value that means "no value".
    pub const fn absent_when(mut self, absent: &'static Absent) -> Field {
        self.absent = Some(absent);
        self
    }

    /// The same field with another byte order.
    pub const fn order(mut self, order: Order) -> Field {
        self.order = order;
        self
    }

    /// The same field narrowed to bits `lo .. lo+width` of its bytes read
    /// as one number (ST7570 UM Table 38: the 24-bit ADDRESS holds SA in
    /// b23..b12 and DA in b11..b0).
    pub const fn within(mut self, lo: u8, width: u8) -> Field {
        self.bits = Some((lo, width));
        self.min = 0;
        self.max = (1i64 << width) - 1;
        self
    }

    /// The same field `by` bytes further on: one description of a sub-field
    /// that several tables place at different offsets (ST7570 UM Tables 17
    /// and 18 put S0..N1 at byte 0 and at byte 1).
    pub const fn shifted(mut self, by: usize) -> Field {
        self.offset += by;
        self
    }

    /// Number of bytes this field needs in `data` (to its last byte).
    pub fn end(&self) -> usize {
        self.offset + self.size
    }

    fn raw(&self, data: &[u8]) -> Option<u64> {
        let bytes = data.get(self.offset..self.offset + self.size)?;
        let mut v: u64 = 0;
        match self.order {
            Order::MsbFirst => bytes.iter().for_each(|b| v = v << 8 | *b as u64),
            Order::LsbFirst => bytes.iter().rev().for_each(|b| v = v << 8 | *b as u64),
        }
        if let Some((lo, width)) = self.bits {
            v = (v >> lo) & ((1u64 << width) - 1);
        }
        Some(v)
    }

    /// Reads the field as a number (flags and enums as their raw value).
    /// `None` if `data` is too short or the field holds bytes.
    pub fn get(&self, data: &[u8]) -> Option<i64> {
        let raw = self.raw(data)?;
        Some(match self.kind {
            Kind::Int => {
                let bits = self.bits.map_or(8 * self.size as u32, |(_, w)| w as u32);
                let shift = 64 - bits;
                ((raw << shift) as i64) >> shift
            }
            Kind::Bytes => return None,
            _ => raw as i64,
        })
    }

    /// Reads the field as a typed [`Value`]; `None` if `data` is too short.
    pub fn read(&self, data: &[u8]) -> Option<Value> {
        if self.absent.is_some_and(|a| {
            self.raw(data) == Some(a.raw)
                && a.only_while
                    .is_none_or(|(other, value)| other.get(data) == Some(value))
        }) {
            return Some(Value::Absent);
        }
        Some(match self.kind {
            Kind::Bytes => {
                let rest = data.get(self.offset..)?;
                let bytes = if self.size == 0 {
                    rest
                } else {
                    rest.get(..self.size)?
                };
                Value::Bytes(bytes.to_vec())
            }
            Kind::Uint => Value::Uint(self.get(data)? as u32),
            Kind::Int => Value::Int(self.get(data)? as i32),
            Kind::Flag => Value::Flag(self.get(data)? != 0),
            Kind::Enum(names) => {
                let raw = self.get(data)? as u8;
                let name = names.get(raw as usize).copied().filter(|n| !n.is_empty());
                Value::Enum { raw, name }
            }
        })
    }

    /// The reading of a number value in the seed's unit, as decimal text
    /// ([`Scale::text`]); `None` for a field without a [`Scale`] and for
    /// values that are not numbers.
    pub fn reading(&self, v: &Value) -> Option<String> {
        let scale = self.scale?;
        match v {
            Value::Uint(_) | Value::Int(_) => Some(scale.text(v.as_i64()?)),
            _ => None,
        }
    }

    /// The unit a value of this field is shown in: its [`Scale`]'s when
    /// it has one, else [`Field::unit`].
    pub fn shown_unit(&self) -> &'static str {
        self.scale.map_or(self.unit, |s| s.unit)
    }

    /// A value of this field in words with its unit, for people: `66.46
    /// dBµV` (a scaled number), `86000 Hz`, `Q-PSK`, `no value`.
    pub fn show(&self, v: &Value) -> String {
        let text = self.reading(v).unwrap_or_else(|| alloc::format!("{v}"));
        match (self.shown_unit(), v) {
            ("", _)
            | (_, Value::Enum { .. } | Value::Flag(_) | Value::Bytes(_) | Value::Absent) => text,
            (unit, _) => alloc::format!("{text} {unit}"),
        }
    }

    /// Writes a number into the field, leaving the other bits of its bytes
    /// untouched. Values are truncated to the field's width; call
    /// [`Field::check`] first to refuse them instead.
    pub fn set(&self, data: &mut [u8], value: i64) {
        let Some(bytes) = data.get_mut(self.offset..self.offset + self.size) else {
            return;
        };
        let mut word: u64 = 0;
        match self.order {
            Order::MsbFirst => bytes.iter().for_each(|b| word = word << 8 | *b as u64),
            Order::LsbFirst => bytes
                .iter()
                .rev()
                .for_each(|b| word = word << 8 | *b as u64),
        }
        let (lo, width) = self.bits.unwrap_or((0, 8 * self.size as u8));
        let mask = if width >= 64 {
            u64::MAX
        } else {
            (1u64 << width) - 1
        } << lo;
        word = (word & !mask) | (((value as u64) << lo) & mask);
        let n = bytes.len();
        for (i, b) in bytes.iter_mut().enumerate() {
            let shift = match self.order {
                Order::MsbFirst => 8 * (n - 1 - i),
                Order::LsbFirst => 8 * i,
            };
            *b = (word >> shift) as u8;
        }
    }

    /// Checks that `value` is one the chip accepts for this field.
    pub fn check(&self, value: i64) -> Result<(), FieldError> {
        if let Kind::Enum(names) = self.kind {
            let defined = usize::try_from(value)
                .ok()
                .and_then(|i| names.get(i))
                .is_some_and(|n| !n.is_empty() && *n != "Reserved");
            if !defined {
                return Err(FieldError {
                    field: self.name,
                    reason: alloc::format!("{value} is not one of {}", self.allowed()),
                });
            }
            return Ok(());
        }
        if !self.settable && value != 0 {
            return Err(FieldError {
                field: self.name,
                reason: alloc::format!("{} bits must be 0, not {value}", self.label),
            });
        }
        if value < self.min || value > self.max {
            return Err(FieldError {
                field: self.name,
                reason: alloc::format!(
                    "{value} is out of range: {} to {}{}",
                    self.min,
                    self.max,
                    self.unit_suffix()
                ),
            });
        }
        Ok(())
    }

    fn unit_suffix(&self) -> String {
        if self.unit.is_empty() {
            String::new()
        } else {
            alloc::format!(" {}", self.unit)
        }
    }

    /// The allowed values in words (`0 = B-PSK, 1 = Q-PSK, ...`).
    pub fn allowed(&self) -> String {
        match self.kind {
            Kind::Enum(names) => {
                let mut s = String::new();
                for (i, n) in names.iter().enumerate() {
                    if n.is_empty() || *n == "Reserved" {
                        continue;
                    }
                    if !s.is_empty() {
                        s.push_str(", ");
                    }
                    let _ = fmt::write(&mut s, format_args!("{i} = {n}"));
                }
                s
            }
            _ => alloc::format!("{} to {}{}", self.min, self.max, self.unit_suffix()),
        }
    }
}

/// The names of a byte-wide enumeration whose defined values are sparse
/// (ST7570 UM Table 43: 00h..06h and FFh = LP_OK), indexed by raw value;
/// the values not listed have an empty name (undefined, refused).
pub const fn sparse_names(pairs: &[(u8, &'static str)]) -> [&'static str; 256] {
    let mut names = [""; 256];
    let mut i = 0;
    while i < pairs.len() {
        names[pairs[i].0 as usize] = pairs[i].1;
        i += 1;
    }
    names
}

/// Checks every settable field of `layout` in `data`; the first error wins.
pub fn validate(layout: &[Field], data: &[u8]) -> Result<(), FieldError> {
    for f in layout {
        if matches!(f.kind, Kind::Bytes) {
            continue;
        }
        if let Some(v) = f.get(data) {
            f.check(v)?;
        }
    }
    Ok(())
}

/// Finds a field of a layout by name.
pub fn find(layout: &'static [Field], name: &str) -> Option<&'static Field> {
    layout.iter().find(|f| f.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: &[&str] = &["zero", "one", "", "Reserved"];

    #[test]
    fn reads_and_writes_bits_without_touching_neighbours() {
        let f = Field::bits_uint("x", "X", 0, 3, 2);
        let mut d = [0b1110_0111u8];
        assert_eq!(f.get(&d), Some(0));
        f.set(&mut d, 3);
        assert_eq!(d[0], 0b1111_1111);
        f.set(&mut d, 1);
        assert_eq!(d[0], 0b1110_1111);
    }

    #[test]
    fn multi_byte_orders_and_sign() {
        let be = Field::int("z", "Z", 0, 2);
        let le = Field::uint("u", "U", 0, 2).order(Order::LsbFirst);
        let mut d = [0xFF, 0xFE];
        assert_eq!(be.get(&d), Some(-2));
        assert_eq!(le.get(&d), Some(0xFEFF));
        be.set(&mut d, -300);
        assert_eq!(d, [0xFE, 0xD4]);
        assert_eq!(be.get(&d), Some(-300));
        assert_eq!(be.get(&[1]), None, "short data is None, not a panic");
    }

    #[test]
    fn enums_refuse_undefined_and_reserved_values() {
        let f = Field::enumeration("e", "E", 0, 0, 2, NAMES);
        assert!(f.check(1).is_ok());
        assert!(f.check(2).is_err());
        assert!(f.check(3).is_err());
        assert_eq!(f.read(&[2]), Some(Value::Enum { raw: 2, name: None }));
        assert_eq!(f.allowed(), "0 = zero, 1 = one");
    }

    #[test]
    fn narrowed_multi_byte_fields_and_shifts() {
        // ST7570 UM 10.4.2: ADDRESS 00.1C.00h = SA 001h, DA C00h.
        let sa = Field::uint("sa", "SA", 0, 3).within(12, 12);
        let da = Field::uint("da", "DA", 0, 3).within(0, 12);
        let mut d = [0x00, 0x1C, 0x00];
        assert_eq!((sa.get(&d), da.get(&d)), (Some(0x001), Some(0xC00)));
        assert_eq!(sa.max, 0xFFF);
        sa.set(&mut d, 0xC00);
        da.set(&mut d, 0x001);
        assert_eq!(d, [0xC0, 0x00, 0x01]);
        let s0 = Field::uint("s0", "S0", 0, 3)
            .order(Order::LsbFirst)
            .shifted(1);
        assert_eq!(s0.get(&[0x01, 0xDF, 0x28, 0x00]), Some(0x28DF));
    }

    #[test]
    fn sparse_names_leave_gaps_undefined() {
        const N: [&str; 256] = sparse_names(&[(0x00, "LP_TU"), (0xFF, "LP_OK")]);
        let f = Field::enumeration("c", "C", 0, 0, 8, &N);
        assert!(f.check(0xFF).is_ok());
        assert!(f.check(0x01).is_err());
        assert_eq!(f.allowed(), "0 = LP_TU, 255 = LP_OK");
    }

    #[test]
    fn scaled_numbers_read_in_their_unit() {
        const HUNDREDTHS: Scale = Scale {
            unit: "dBµV",
            factor: 0.01,
            decimals: 2,
        };
        let f = Field::uint("s0", "S0", 0, 3)
            .order(Order::LsbFirst)
            .unit("0.01 dBµV")
            .scaled(&HUNDREDTHS);
        // ST7570 UM 9 step 2: S0 F6.19.00h = 6646 = 66.46 dBµV.
        let v = f.read(&[0xF6, 0x19, 0x00]).unwrap();
        assert_eq!(f.reading(&v).as_deref(), Some("66.46"));
        assert_eq!(f.show(&v), "66.46 dBµV");
        assert_eq!(f.shown_unit(), "dBµV");
        assert_eq!(HUNDREDTHS.text(0), "0.00");
        assert_eq!(HUNDREDTHS.text(5), "0.05");
        assert_eq!(HUNDREDTHS.text(-1250), "-12.50");
        assert_eq!(HUNDREDTHS.text(0xFF_FFFF), "167772.15");
        let thirds = Scale {
            unit: "x",
            factor: 1.0 / 3.0,
            decimals: 0,
        };
        assert_eq!(thirds.text(2), "1");
        assert_eq!(thirds.text(-2), "-1");
        assert_eq!(thirds.text(-1), "0");
        // Not scaled: as it is, with the raw unit.
        let hz = Field::uint("hz", "Hz", 0, 2).unit("Hz");
        let v = hz.read(&[0x01, 0x00]).unwrap();
        assert_eq!((hz.reading(&v), hz.show(&v)), (None, "256 Hz".into()));
        let e = Field::enumeration("e", "E", 0, 0, 2, NAMES).unit("Hz");
        assert_eq!(e.show(&e.read(&[1]).unwrap()), "one");
    }

    #[test]
    fn ranges_are_enforced_with_a_reason() {
        let f = Field::uint("hz", "Hz", 0, 3)
            .range(3000, 148_500)
            .unit("Hz");
        let e = f.check(200_000).unwrap_err();
        assert_eq!(e.reason, "200000 is out of range: 3000 to 148500 Hz");
    }
}
