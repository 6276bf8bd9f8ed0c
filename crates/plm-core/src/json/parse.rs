//! The strict JSON parser (RFC 8259): one value, whitespace around it,
//! nothing else. Errors name the line and column, what was expected and
//! what was found, for a user who opened the wrong file.

use super::{Json, Object};
use alloc::string::String;
use alloc::vec::Vec;
use core::fmt;

/// Arrays and objects nested deeper than this are refused rather than
/// risking the stack; serde_json refuses the 128th level too.
const MAX_DEPTH: usize = 127;

/// Numbers longer than this are refused: a number kept as its text
/// ([`Json::Number`]) is never that long in a file plm-core wrote, and a
/// file of one ten-megabyte number is not a traffic log (RFC 8259 section
/// 9 lets a parser limit numbers).
const MAX_NUMBER: usize = 100;

/// Where a text stops being JSON, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParseError {
    /// Line, from 1.
    pub line: usize,
    /// Column in characters, from 1.
    pub column: usize,
    /// What would have been JSON there (`a value`, `` `,` or `]` ``).
    pub expected: &'static str,
    /// What is there instead: a character in backquotes, a control
    /// character by its code point (`U+0009`), or `the end of the text`.
    pub found: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {}, column {}: expected {}, found {}",
            self.line, self.column, self.expected, self.found
        )
    }
}

/// Reads one JSON value.
pub fn parse(text: &str) -> Result<Json, ParseError> {
    let mut p = Parser { text, pos: 0 };
    let v = p.value(0)?;
    p.skip_whitespace();
    if p.pos < text.len() {
        return Err(p.error("the end of the text"));
    }
    Ok(v)
}

struct Parser<'a> {
    text: &'a str,
    /// Byte offset of the next character.
    pos: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    fn error(&self, expected: &'static str) -> ParseError {
        // Byte by byte rather than through `matches` and `rsplit`, whose
        // searchers are 1 KB of the console's wasm for this one use.
        let before = &self.text[..self.pos];
        let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
        let start = before
            .bytes()
            .rposition(|b| b == b'\n')
            .map_or(0, |i| i + 1);
        let column = before[start..].chars().count() + 1;
        let found = match self.text[self.pos..].chars().next() {
            // Control characters and invisible ones (a byte order mark).
            Some(c) if c.is_control() || c == '\u{feff}' => {
                alloc::format!("U+{:04X}", u32::from(c))
            }
            Some(c) => alloc::format!("`{c}`"),
            None => "the end of the text".into(),
        };
        ParseError {
            line,
            column,
            expected,
            found,
        }
    }

    fn skip_whitespace(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.pos += 1;
        }
    }

    /// Consumes `b` after whitespace, or says it was expected.
    fn expect(&mut self, b: u8, expected: &'static str) -> Result<(), ParseError> {
        self.skip_whitespace();
        if self.peek() != Some(b) {
            return Err(self.error(expected));
        }
        self.pos += 1;
        Ok(())
    }

    fn value(&mut self, depth: usize) -> Result<Json, ParseError> {
        self.skip_whitespace();
        match self.peek() {
            Some(b'n') => self.literal("null", Json::Null),
            Some(b't') => self.literal("true", Json::Bool(true)),
            Some(b'f') => self.literal("false", Json::Bool(false)),
            Some(b'"') => Ok(Json::String(self.string()?)),
            Some(b'-' | b'0'..=b'9') => self.number(),
            Some(b'[' | b'{') if depth == MAX_DEPTH => {
                Err(self.error("at most 127 nested arrays and objects"))
            }
            Some(b'[') => self.array(depth + 1),
            Some(b'{') => self.object(depth + 1),
            _ => Err(self.error("a value")),
        }
    }

    fn literal(&mut self, word: &'static str, v: Json) -> Result<Json, ParseError> {
        for &b in word.as_bytes() {
            if self.peek() != Some(b) {
                return Err(self.error(word));
            }
            self.pos += 1;
        }
        Ok(v)
    }

    fn array(&mut self, depth: usize) -> Result<Json, ParseError> {
        self.pos += 1;
        let mut items = Vec::new();
        self.skip_whitespace();
        if self.peek() == Some(b']') {
            self.pos += 1;
            return Ok(Json::Array(items));
        }
        loop {
            items.push(self.value(depth)?);
            self.skip_whitespace();
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b']') => {
                    self.pos += 1;
                    return Ok(Json::Array(items));
                }
                _ => return Err(self.error("`,` or `]`")),
            }
        }
    }

    fn object(&mut self, depth: usize) -> Result<Json, ParseError> {
        self.pos += 1;
        let mut members = Vec::new();
        self.skip_whitespace();
        if self.peek() == Some(b'}') {
            self.pos += 1;
            return Ok(Json::Object(Object::new()));
        }
        loop {
            self.skip_whitespace();
            if self.peek() != Some(b'"') {
                return Err(self.error("a key in double quotes"));
            }
            let key = self.string()?;
            self.expect(b':', "`:`")?;
            members.push((key, self.value(depth)?));
            self.skip_whitespace();
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {
                    self.pos += 1;
                    return Ok(Json::Object(Object(once_each(members))));
                }
                _ => return Err(self.error("`,` or `}`")),
            }
        }
    }

    /// `-? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE] [+-]? [0-9]+)?`
    fn number(&mut self) -> Result<Json, ParseError> {
        let start = self.pos;
        if self.peek() == Some(b'-') {
            self.pos += 1;
        }
        match self.peek() {
            Some(b'0') => self.pos += 1,
            Some(b'1'..=b'9') => self.digits(),
            _ => return Err(self.error("a digit")),
        }
        let mut whole = true;
        if self.peek() == Some(b'.') {
            self.pos += 1;
            self.digits_after("a digit after `.`")?;
            whole = false;
        }
        if matches!(self.peek(), Some(b'e' | b'E')) {
            self.pos += 1;
            if matches!(self.peek(), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            self.digits_after("a digit in the exponent")?;
            whole = false;
        }
        if matches!(self.peek(), Some(b'0'..=b'9')) {
            // A digit after a leading 0 (`01`).
            return Err(self.error("the end of the number (no digit after a leading 0)"));
        }
        let text = &self.text[start..self.pos];
        if text.len() > MAX_NUMBER {
            self.pos = start;
            return Err(self.error("a number of at most 100 characters"));
        }
        Ok(match text.parse::<i64>() {
            // `-0` is not how an i64 is written: keep it as text.
            Ok(n) if whole && text != "-0" => Json::Int(n),
            _ => Json::Number(text.into()),
        })
    }

    fn digits(&mut self) {
        while matches!(self.peek(), Some(b'0'..=b'9')) {
            self.pos += 1;
        }
    }

    fn digits_after(&mut self, expected: &'static str) -> Result<(), ParseError> {
        if !matches!(self.peek(), Some(b'0'..=b'9')) {
            return Err(self.error(expected));
        }
        self.digits();
        Ok(())
    }

    /// A string from its opening quote.
    fn string(&mut self) -> Result<String, ParseError> {
        self.pos += 1;
        let mut out = String::new();
        loop {
            // Runs of plain characters are copied as they are: every byte
            // that ends one is ASCII, so the slices are whole characters.
            let run = self.pos;
            while matches!(self.peek(), Some(b) if b != b'"' && b != b'\\' && b >= 0x20) {
                self.pos += 1;
            }
            out.push_str(&self.text[run..self.pos]);
            match self.peek() {
                Some(b'"') => {
                    self.pos += 1;
                    return Ok(out);
                }
                Some(b'\\') => {
                    self.pos += 1;
                    out.push(self.escape()?);
                }
                Some(_) => return Err(self.error("`\\` before a control character")),
                None => return Err(self.error("the closing `\"`")),
            }
        }
    }

    /// The character of an escape, after its `\`.
    fn escape(&mut self) -> Result<char, ParseError> {
        let c = match self.peek() {
            Some(b'"') => '"',
            Some(b'\\') => '\\',
            Some(b'/') => '/',
            Some(b'b') => '\u{8}',
            Some(b'f') => '\u{c}',
            Some(b'n') => '\n',
            Some(b'r') => '\r',
            Some(b't') => '\t',
            Some(b'u') => {
                self.pos += 1;
                return self.unicode_escape();
            }
            _ => return Err(self.error("an escape: one of `\"\\/bfnrt` or `u`")),
        };
        self.pos += 1;
        Ok(c)
    }

    /// `XXXX` after `\u`, and the low half after a high surrogate.
    fn unicode_escape(&mut self) -> Result<char, ParseError> {
        let high = self.hex4()?;
        let code = match high {
            0xD800..=0xDBFF => {
                if !self.text[self.pos..].starts_with("\\u") {
                    return Err(self.error("`\\u` and the low surrogate after a high one"));
                }
                self.pos += 2;
                let at = self.pos;
                let low = self.hex4()?;
                if !(0xDC00..=0xDFFF).contains(&low) {
                    self.pos = at;
                    return Err(self.error("a low surrogate (DC00 to DFFF)"));
                }
                0x10000 + ((high - 0xD800) << 10) + (low - 0xDC00)
            }
            0xDC00..=0xDFFF => {
                self.pos -= 4;
                return Err(self.error("a high surrogate before a low one"));
            }
            other => other,
        };
        // Whole surrogate pairs and non-surrogates are always characters.
        char::from_u32(code).ok_or_else(|| self.error("a character"))
    }

    fn hex4(&mut self) -> Result<u32, ParseError> {
        let mut n = 0;
        for _ in 0..4 {
            let d = match self.peek() {
                Some(b @ b'0'..=b'9') => b - b'0',
                Some(b @ b'a'..=b'f') => b - b'a' + 10,
                Some(b @ b'A'..=b'F') => b - b'A' + 10,
                _ => return Err(self.error("4 hex digits after `\\u`")),
            };
            n = n * 16 + u32::from(d);
            self.pos += 1;
        }
        Ok(n)
    }
}

/// An object's members with each key once: a key given twice keeps its
/// first place and its last value, as serde_json reads it. Sorted rather
/// than looked up member by member, so that an object of a million keys
/// (a hostile file) takes as long as sorting them, not a million squared.
fn once_each(mut members: Vec<(String, Json)>) -> Vec<(String, Json)> {
    // By key, members with the same key in the order they came.
    let mut order: Vec<usize> = (0..members.len()).collect();
    heap_sort(&mut order, |a, b| (&members[a].0, a) < (&members[b].0, b));
    let mut keep = alloc::vec![true; members.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && members[order[j + 1]].0 == members[order[i]].0 {
            j += 1;
            keep[order[j]] = false;
        }
        if j > i {
            let last = core::mem::replace(&mut members[order[j]].1, Json::Null);
            members[order[i]].1 = last;
        }
        i = j + 1;
    }
    members
        .into_iter()
        .zip(keep)
        .filter_map(|(m, keep)| keep.then_some(m))
        .collect()
}

/// `items` in the order `before` says (a strict order: no two items
/// equal), in O(n log n) whatever they are. Written out: std's sorts bring
/// 7.6 KB of code into the console's wasm for this one use
/// (docs/console.md, "Size").
fn heap_sort(items: &mut [usize], before: impl Fn(usize, usize) -> bool) {
    let sift = |items: &mut [usize], mut root: usize, end: usize| loop {
        let mut child = 2 * root + 1;
        if child >= end {
            return;
        }
        if child + 1 < end && before(items[child], items[child + 1]) {
            child += 1;
        }
        if !before(items[root], items[child]) {
            return;
        }
        items.swap(root, child);
        root = child;
    };
    for root in (0..items.len() / 2).rev() {
        sift(items, root, items.len());
    }
    for end in (1..items.len()).rev() {
        items.swap(0, end);
        sift(items, 0, end);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::ToString;

    #[test]
    fn heap_sort_orders_every_arrangement_as_std_does() {
        // Every length to 9 in a few arrangements each, and a long one.
        let mut seed = 1u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as usize
        };
        for len in (0..10).chain([1000]) {
            for _ in 0..20 {
                let keys: Vec<usize> = (0..len).map(|_| next() % 4).collect();
                let mut order: Vec<usize> = (0..len).collect();
                heap_sort(&mut order, |a, b| (keys[a], a) < (keys[b], b));
                let mut expected: Vec<usize> = (0..len).collect();
                expected.sort_by_key(|&i| keys[i]);
                assert_eq!(order, expected, "{keys:?}");
            }
        }
    }

    #[test]
    fn a_key_given_twice_keeps_its_first_place_and_last_value() {
        let parsed = parse(r#"{"b":1,"a":2,"b":3,"c":4,"a":5,"a":6}"#).unwrap();
        assert_eq!(parsed.to_string(), r#"{"b":3,"a":6,"c":4}"#);
        assert_eq!(parse(r#"{"x":1}"#).unwrap().to_string(), r#"{"x":1}"#);
    }
}
