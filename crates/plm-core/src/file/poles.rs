//! A pole list: which lamp stands on which pole, in the order of the
//! poles along the street (docs/protocol-notes.md, "Pole list"). The
//! boards know nothing of where they stand (seed 004 has no position or
//! name object), so the console takes it from a file people write.
//!
//! CSV, one pole a line: the lamp's board address (12 hex digits, as
//! [`Address::parse`] reads them), the pole's name, and optionally its
//! position in whole metres along the street. Fields are separated by
//! commas, or by semicolons when the first line has one (spreadsheets set
//! to a decimal comma write those); a field may be double-quoted (RFC 4180,
//! `""` for a quote inside), on one line. A first line whose first field
//! is `address` is a header. Blank lines are skipped.
//!
//! Refused, in words that name the line: a file larger than
//! [`POLE_LIST_MAX`], text that is not UTF-8 ([`super::text`]), a line of
//! another number of fields, an address that is not one or is the
//! broadcast address, an address listed twice, an empty name or one longer
//! than [`NAME_MAX`] characters or holding a control character, a position
//! that is not whole metres up to [`POSITION_MAX`] or that goes back along
//! the street, a list with no pole.

use crate::app::Address;
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

/// The largest pole list: 64 KiB, about 1 800 poles of 36 bytes a line;
/// the console keeps it in the browser's storage.
pub const POLE_LIST_MAX: usize = 64 * 1024;
/// The longest pole name, in characters.
pub const NAME_MAX: usize = 40;
/// The farthest position, in metres (100 km).
pub const POSITION_MAX: u32 = 100_000;

/// One pole of the list.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pole {
    /// The board of the lamp on it.
    pub address: Address,
    /// Its name, as people call it on the street (`P12`, `Rue Haute 4`).
    pub name: String,
    /// Metres from the street's start, when given.
    pub position: Option<u32>,
}

/// Reads a pole list file: the poles in the file's order (the street's).
pub fn parse(bytes: &[u8]) -> Result<Vec<Pole>, String> {
    if bytes.len() > POLE_LIST_MAX {
        return Err(format!(
            "the pole list is larger than {POLE_LIST_MAX} bytes (64 KiB), the most the console keeps"
        ));
    }
    let text = super::text(bytes)?;
    let separator = match text.lines().next() {
        Some(first) if first.contains(';') => ';',
        _ => ',',
    };
    let mut poles: Vec<Pole> = Vec::new();
    // The line each pole was on, for a duplicate's message.
    let mut lines: Vec<usize> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let fields = split(line, separator).map_err(|e| format!("line {n}: {e}"))?;
        if n == 1 && fields[0].trim().eq_ignore_ascii_case("address") {
            continue;
        }
        let pole = pole(&fields).map_err(|e| format!("line {n}: {e}"))?;
        if let Some(at) = poles.iter().position(|p| p.address == pole.address) {
            return Err(format!(
                "line {n}: lamp {} is listed on line {} already (one pole a lamp)",
                pole.address, lines[at]
            ));
        }
        let before = poles.iter().zip(&lines).rev();
        if let (Some(here), Some((p, at))) = (
            pole.position,
            before
                .filter_map(|(p, at)| p.position.map(|m| (m, at)))
                .next(),
        ) {
            if here < p {
                return Err(format!(
                    "line {n}: position {here} m is before the {p} m of line {at}: list the poles in their order along the street"
                ));
            }
        }
        poles.push(pole);
        lines.push(n);
    }
    if poles.is_empty() {
        return Err(
            "the pole list has no pole: write one line a lamp, its address, the pole's name and its position in metres (optional)"
                .to_string(),
        );
    }
    Ok(poles)
}

/// The fields of one line, unquoted.
fn split(line: &str, separator: char) -> Result<Vec<String>, String> {
    let mut fields = Vec::new();
    let mut chars = line.trim_end_matches('\r').chars().peekable();
    loop {
        let mut field = String::new();
        while chars.peek().is_some_and(|c| *c == ' ' || *c == '\t') {
            chars.next();
        }
        if chars.peek() == Some(&'"') {
            chars.next();
            loop {
                match chars.next() {
                    Some('"') if chars.peek() == Some(&'"') => {
                        chars.next();
                        field.push('"');
                    }
                    Some('"') => break,
                    Some(c) => field.push(c),
                    None => return Err("a quoted field is not closed on its line".to_string()),
                }
            }
            while chars.peek().is_some_and(|c| *c == ' ' || *c == '\t') {
                chars.next();
            }
            match chars.next() {
                None => {
                    fields.push(field);
                    return Ok(fields);
                }
                Some(c) if c == separator => {}
                Some(c) => {
                    return Err(format!(
                        "'{c}' after a quoted field: a field ends at its closing quote"
                    ))
                }
            }
        } else {
            loop {
                match chars.next() {
                    None => {
                        fields.push(field);
                        return Ok(fields);
                    }
                    Some(c) if c == separator => break,
                    Some(c) => field.push(c),
                }
            }
        }
        fields.push(field);
    }
}

/// One line's pole from its fields.
fn pole(fields: &[String]) -> Result<Pole, String> {
    if !(2..=3).contains(&fields.len()) {
        return Err(format!(
            "{} field(s); a line is the lamp's address, the pole's name and its position in metres (optional)",
            fields.len()
        ));
    }
    let text = fields[0].trim();
    let address = Address::parse(text).map_err(|e| format!("\"{text}\" is not an address: {e}"))?;
    if address == Address::BROADCAST {
        return Err(format!("{address} is the broadcast address, not a lamp's"));
    }
    let name = fields[1].trim();
    if name.is_empty() {
        return Err(format!("lamp {address} has no pole name"));
    }
    if name.chars().count() > NAME_MAX {
        return Err(format!(
            "the pole name of lamp {address} is longer than {NAME_MAX} characters"
        ));
    }
    if name.chars().any(char::is_control) {
        return Err(format!(
            "the pole name of lamp {address} holds a control character"
        ));
    }
    let position = match fields.get(2).map(|f| f.trim()) {
        None | Some("") => None,
        Some(m) => Some(
            m.parse::<u32>()
                .ok()
                .filter(|m| *m <= POSITION_MAX)
                .ok_or_else(|| {
                    format!(
                        "position \"{m}\" of lamp {address} is not whole metres from 0 to {POSITION_MAX}"
                    )
                })?,
        ),
    };
    Ok(Pole {
        address,
        name: name.to_string(),
        position,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    fn a(n: u64) -> Address {
        Address::from_u64(0x0080_e100_0000 + n)
    }

    #[test]
    fn a_list_reads_in_its_order_with_or_without_header_and_positions() {
        let poles = parse(
            b"Address,Pole,Position m\r\n0080e1000003,P1,0\r\n\r\n0080e1000001, \"Rue Haute, 2\" ,35\r\n00:80:e1:00:00:02,\"Le \"\"Grand\"\" m\xc3\xa2t\"\r\n",
        )
        .unwrap();
        assert_eq!(
            poles,
            vec![
                Pole {
                    address: a(3),
                    name: "P1".into(),
                    position: Some(0)
                },
                Pole {
                    address: a(1),
                    name: "Rue Haute, 2".into(),
                    position: Some(35)
                },
                Pole {
                    address: a(2),
                    name: "Le \"Grand\" mât".into(),
                    position: None
                },
            ]
        );
        let semi = parse(b"0080e1000001;P 1;10\n0080e1000002;P 2;\n").unwrap();
        assert_eq!(semi[1].name, "P 2");
        assert_eq!(semi[1].position, None);
    }

    #[test]
    fn each_fault_is_refused_in_words_naming_its_line() {
        let cases: &[(&[u8], &str)] = &[
            (b"", "has no pole"),
            (b"address,name\n\n", "has no pole"),
            (b"0080e1000001\n", "line 1: 1 field(s)"),
            (b"0080e1000001,P,1,x\n", "line 1: 4 field(s)"),
            (b"0080e1000001,P1\n0080e100000g,P2\n", "line 2: \"0080e100000g\" is not an address"),
            (b"0080e10001,P1\n", "12 hex digits"),
            (b"ffffffffffff,P1\n", "broadcast address"),
            (b"0080e1000001,P1\n0080e1000002,P2\n0080e1000001,P3\n", "line 3: lamp 0080e1000001 is listed on line 1 already"),
            (b"0080e1000001,  \n", "line 1: lamp 0080e1000001 has no pole name"),
            (b"0080e1000001,\"P1\n", "line 1: a quoted field is not closed"),
            (b"0080e1000001,\"P1\"x,3\n", "line 1: 'x' after a quoted field"),
            (b"0080e1000001,P\x01,3\n", "control character"),
            (b"0080e1000001,P1,12.5\n", "line 1: position \"12.5\" of lamp 0080e1000001 is not whole metres from 0 to 100000"),
            (b"0080e1000001,P1,-3\n", "not whole metres"),
            (b"0080e1000001,P1,100001\n", "not whole metres"),
            (b"0080e1000001,P1,99999999999999999999\n", "not whole metres"),
            (b"0080e1000001,P1,50\n0080e1000002,P2\n0080e1000003,P3,40\n", "line 3: position 40 m is before the 50 m of line 1"),
            (b"0080e1000001,P1\n\xff\n", "not UTF-8"),
            (b"\xff\xfe0\x000\x00", "UTF-16"),
        ];
        for (input, says) in cases {
            let e = parse(input).unwrap_err();
            assert!(
                e.contains(says),
                "{:?}: `{e}` should say `{says}`",
                core::str::from_utf8(input)
            );
        }
        let long = format!("0080e1000001,{}\n", "x".repeat(NAME_MAX + 1));
        assert!(parse(long.as_bytes())
            .unwrap_err()
            .contains("longer than 40 characters"));
        assert!(parse(format!("0080e1000001,{}\n", "é".repeat(NAME_MAX)).as_bytes()).is_ok());
    }

    #[test]
    fn a_file_over_the_bound_is_refused_before_it_is_read() {
        let mut big = Vec::new();
        let mut n = 0;
        while big.len() <= POLE_LIST_MAX {
            big.extend(format!("{},P{n}\n", a(n)).bytes());
            n += 1;
        }
        assert!(parse(&big).unwrap_err().contains("larger than 65536 bytes"));
        let fits: Vec<u8> = big[..big[..POLE_LIST_MAX]
            .iter()
            .rposition(|b| *b == b'\n')
            .unwrap()
            + 1]
            .to_vec();
        assert!(parse(&fits).unwrap().len() > 1_500);
    }
}
