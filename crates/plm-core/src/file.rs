//! Files people hand the console or `plm` (traffic logs, MIB profiles,
//! saved campaigns, firmware images): the size they may have, and their
//! bytes as text, checked once here before any parser sees them
//! (docs/protocol-notes.md, "Files read").
//!
//! A file larger than [`FILE_MAX`] is refused before it is read (the
//! console asks the browser for its size first, `plm` reads one byte past
//! the cap), so neither memory nor time depends on what someone hands in.
//! Text must be UTF-8: a UTF-8 byte order mark is skipped (editors on
//! Windows write one), UTF-16 and UTF-32 (told by their byte order marks),
//! bytes that are not UTF-8 and NUL bytes are refused, each in words that
//! say where.
//!
//! [`poles`]: the pole list, which lamp stands where along the street;
//! [`profile`]: a MIB configuration profile.

pub mod poles;
pub mod profile;

use alloc::format;
use alloc::string::String;

/// The largest file read: 16 MiB. A traffic log many times what the
/// console keeps (5 000 elements, about 1 MiB as JSON Lines) fits; a
/// firmware image (60 KiB) or a profile (a few KiB) is far below it.
pub const FILE_MAX: usize = 16 * 1024 * 1024;

/// Refuses a file of `len` bytes when it is larger than [`FILE_MAX`]
/// (the message does not repeat `len`: a reader that stops one byte past
/// the cap does not know the whole size).
pub fn check_size(len: u64) -> Result<(), String> {
    if len > FILE_MAX as u64 {
        return Err(format!(
            "the file is larger than {FILE_MAX} bytes (16 MiB), the most the console and plm read"
        ));
    }
    Ok(())
}

/// The text of a file's `bytes`: UTF-8, its byte order mark (if any)
/// skipped. Refused in words when the file is too large, is UTF-16 or
/// UTF-32, is not UTF-8 (the offset of the first bad byte), or holds a
/// NUL byte (a binary file, or text in a 16-bit encoding without a mark).
pub fn text(bytes: &[u8]) -> Result<&str, String> {
    check_size(bytes.len() as u64)?;
    let wide = |enc: &str| {
        format!("the file is {enc} text: save it as UTF-8 (the console and plm read UTF-8 only)")
    };
    if bytes.starts_with(&[0xFF, 0xFE, 0, 0]) || bytes.starts_with(&[0, 0, 0xFE, 0xFF]) {
        return Err(wide("UTF-32"));
    }
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(wide("UTF-16"));
    }
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = core::str::from_utf8(bytes).map_err(|e| {
        format!(
            "the file is not UTF-8 text: byte {} (from 0) cannot start or continue a character",
            e.valid_up_to()
        )
    })?;
    if let Some(at) = text.bytes().position(|b| b == 0) {
        return Err(format!(
            "the file holds a NUL byte at byte {at} (from 0): a binary file, or text that is not UTF-8"
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    #[test]
    fn text_is_utf8_and_nothing_else() {
        assert_eq!(text(b"{}"), Ok("{}"));
        assert_eq!(text(b"\xEF\xBB\xBF{}"), Ok("{}"));
        assert_eq!(text(b""), Ok(""));
        assert!(text(b"\xFF\xFE{\0}\0").unwrap_err().contains("UTF-16"));
        assert!(text(b"\xFE\xFF\0{\0}").unwrap_err().contains("UTF-16"));
        assert!(text(b"\xFF\xFE\0\0{\0\0\0").unwrap_err().contains("UTF-32"));
        assert_eq!(
            text(b"ab\xC3(").unwrap_err(),
            "the file is not UTF-8 text: byte 2 (from 0) cannot start or continue a character"
        );
        assert!(text(b"{\0}").unwrap_err().contains("NUL byte at byte 1"));
        let big = vec![b' '; FILE_MAX + 1];
        assert!(text(&big).unwrap_err().contains("16 MiB"));
        assert!(text(&big[1..]).is_ok());
        assert!(check_size(u64::MAX).is_err());
    }
}
