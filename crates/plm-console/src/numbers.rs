//! How the page writes times and numbers, and reads numbers typed in
//! forms: written out rather than through std's float formatting and
//! parsing, which cost the page's wasm more (docs/console.md, "Size").

use plm_core::time::Instant;

/// A time on the transport's clock as seconds with µs (`12.345678 s`).
pub fn seconds(at: Instant) -> String {
    format!("{}.{:06} s", at / 1_000_000, at % 1_000_000)
}

/// A duration as milliseconds (`3.2 ms`).
pub fn millis(us: u64) -> String {
    format!("{} ms", fixed(us as f64 / 1_000.0, 1))
}

/// `v` with `decimals` digits after the point (0-6), rounded half away
/// from zero: `fixed(2.25, 1)` is `2.3`. Written out, like [`decimal`],
/// because std's exact float formatting costs the console's wasm more
/// than this does.
pub fn fixed(v: f64, decimals: u32) -> String {
    if !v.is_finite() {
        return "–".to_string();
    }
    let scale = 10u64.pow(decimals.min(6));
    let scaled = (v.abs() * scale as f64).round() as u64;
    let sign = if v < 0.0 && scaled != 0 { "-" } else { "" };
    let whole = scaled / scale;
    match decimals.min(6) {
        0 => format!("{sign}{whole}"),
        d => format!(
            "{sign}{whole}.{:0width$}",
            scaled % scale,
            width = d as usize
        ),
    }
}

/// A decimal number typed in a form (`-12`, `3.5`, `+0.25`; at most 9
/// digits after the point), or `None`. Written out because std's `f64`
/// parser brings a 10 KiB table of powers of five into the console's wasm,
/// and a form needs none of its range.
pub fn decimal(text: &str) -> Option<f64> {
    let t = text.trim();
    let (negative, t) = match t.as_bytes().first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    let (whole, fraction) = t.split_once('.').unwrap_or((t, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if whole.len() + fraction.len() == 0 || whole.len() > 9 || fraction.len() > 9 {
        return None;
    }
    if !digits(whole) || !digits(fraction) {
        return None;
    }
    let number = |s: &str| s.bytes().fold(0u64, |n, b| n * 10 + u64::from(b - b'0'));
    let v = number(whole) as f64 + number(fraction) as f64 / 10f64.powi(fraction.len() as i32);
    Some(if negative { -v } else { v })
}

/// Lowercase hex as spaced byte pairs (`02 00 2c`).
pub fn spaced(hex: &str) -> String {
    let mut s = String::with_capacity(hex.len() * 3 / 2);
    for (i, c) in hex.chars().enumerate() {
        if i > 0 && i % 2 == 0 {
            s.push(' ');
        }
        s.push(c);
    }
    s
}

/// Seconds in a day.
pub const DAY: f64 = 86_400.0;

/// A local clock time as `HH:MM:SS`, or `HH:MM` when `step` is whole
/// minutes.
pub fn clock_label(t: f64, step: f64) -> String {
    let s = (t.floor() as i64).rem_euclid(DAY as i64);
    let hm = format!("{:02}:{:02}", s / 3600, s / 60 % 60);
    // Whole minutes, tested without `%` on floats (libm's fmod and the
    // 128-bit division under it, 2 KB of the page's code for this test).
    if step >= 60.0 && (step / 60.0).trunc() * 60.0 == step {
        hm
    } else {
        format!("{hm}:{:02}", s % 60)
    }
}

/// Seconds to add to a time since the Unix epoch for this computer's
/// local clock (0 natively: the tests' clock is UTC).
pub fn zone_offset() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        -js_sys::Date::new_0().get_timezone_offset() * 60.0
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        assert_eq!(seconds(12_000_345), "12.000345 s");
        assert_eq!(millis(3_249), "3.2 ms");
        assert_eq!(fixed(2.25, 1), "2.3");
        assert_eq!(fixed(-0.04, 1), "0.0");
        assert_eq!(fixed(-7.5, 0), "-8");
        assert_eq!(fixed(56.0, 1), "56.0");
        assert_eq!(fixed(0.125, 2), "0.13");
        assert_eq!(spaced("02002c"), "02 00 2c");
        assert_eq!(decimal(" 42 "), Some(42.0));
        assert_eq!(decimal("-3.25"), Some(-3.25));
        assert_eq!(decimal("+.5"), Some(0.5));
        assert_eq!(decimal("7."), Some(7.0));
        for bad in ["", "-", ".", "1e3", "4o", "1.2.3", "0x10", "1234567890"] {
            assert_eq!(decimal(bad), None, "{bad:?}");
        }
    }
}
