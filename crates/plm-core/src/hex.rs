//! Hex text, the way people paste frames: `02 00 2c 2c 00`, `02.00.2C`,
//! `02:00:2c`, `02002c` all mean the same bytes.

use alloc::string::String;
use alloc::vec::Vec;
use core::fmt;

/// Why a hex text could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum HexError {
    /// A character that is neither a hex digit nor a separator.
    BadChar {
        /// The character.
        ch: char,
        /// Its position (in characters) in the text.
        at: usize,
    },
    /// An odd number of hex digits in a run without separators.
    OddDigits {
        /// Position of the run.
        at: usize,
    },
}

impl fmt::Display for HexError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HexError::BadChar { ch, at } => {
                write!(f, "'{ch}' at position {at} is not a hex digit")
            }
            HexError::OddDigits { at } => write!(
                f,
                "odd number of hex digits in the group at position {at}: write bytes as two digits"
            ),
        }
    }
}

fn is_separator(c: char) -> bool {
    c.is_whitespace() || matches!(c, '.' | ':' | ',' | '-' | '_')
}

/// Parses hex text. Separators (whitespace, `.`, `:`, `,`, `-`, `_`) may
/// appear between bytes; an optional `h` suffix after a group (`02h`) and a
/// `0x` prefix before one are accepted, as the manuals write both.
pub fn parse(text: &str) -> Result<Vec<u8>, HexError> {
    let mut out = Vec::new();
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if is_separator(chars[i]) {
            i += 1;
            continue;
        }
        let start = i;
        if chars[i] == '0' && matches!(chars.get(i + 1), Some('x' | 'X')) {
            i += 2;
        }
        let digits_start = i;
        while i < chars.len() && chars[i].is_ascii_hexdigit() {
            i += 1;
        }
        let digits = &chars[digits_start..i];
        if i < chars.len() && matches!(chars[i], 'h' | 'H') {
            i += 1;
        }
        if i < chars.len() && !is_separator(chars[i]) {
            return Err(HexError::BadChar {
                ch: chars[i],
                at: i,
            });
        }
        if digits.is_empty() {
            return Err(HexError::BadChar {
                ch: chars[start],
                at: start,
            });
        }
        if !digits.len().is_multiple_of(2) {
            return Err(HexError::OddDigits { at: start });
        }
        for pair in digits.chunks(2) {
            let hi = pair[0].to_digit(16).unwrap_or(0) as u8;
            let lo = pair[1].to_digit(16).unwrap_or(0) as u8;
            out.push(hi << 4 | lo);
        }
    }
    Ok(out)
}

/// Lowercase hex without separators, as `plm decode` prints byte strings.
pub fn encode(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 2);
    for b in bytes {
        let _ = fmt::write(&mut s, format_args!("{b:02x}"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_separators_people_use() {
        let want = alloc::vec![0x02, 0x00, 0x2c, 0x2c, 0x00];
        for text in [
            "02 00 2c 2c 00",
            "02.00.2C.2C.00",
            "02:00:2c:2c:00",
            "02002c2c00",
            "02h 00h 2Ch 2ch 00h",
            "0x02 0x00 0x2c2c00",
        ] {
            assert_eq!(parse(text).unwrap(), want, "{text}");
        }
    }

    #[test]
    fn refuses_what_is_not_hex() {
        assert_eq!(parse("02 zz"), Err(HexError::BadChar { ch: 'z', at: 3 }));
        assert_eq!(parse("020"), Err(HexError::OddDigits { at: 0 }));
        assert_eq!(encode(&[0xAB, 0x01]), "ab01");
    }
}
