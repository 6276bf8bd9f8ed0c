//! Files people hand the console or `plm`, damaged or hostile: every
//! reader refuses in words, never panics, and takes time and memory
//! bounded by the file's size (docs/protocol-notes.md, "Files read").
//! Each reader is fed the same table: empty, a valid sample cut at every
//! length, the sample with a byte flipped at every position, oversized,
//! invalid UTF-8, UTF-16 and UTF-8 byte order marks, NUL bytes, deep
//! nesting and huge numbers (JSON), random bytes.

use plm_core::app::frame::Address;
use plm_core::app::rfu::image;
use plm_core::app::service::Release;
use plm_core::app::update::{Update, UpdateConfig};
use plm_core::decode::{decode_all, Decoded};
use plm_core::file::{self, FILE_MAX};
use plm_core::json::{self, Json};
use plm_core::link::{Dialect, Source};
use std::time::{Duration, Instant};

/// Reads a text file as the console's Traffic import and profile load do:
/// the file's text, then JSON.
fn read_json(bytes: &[u8]) -> Result<Json, String> {
    let text = file::text(bytes)?;
    json::parse(text).map_err(|e| format!("not JSON ({e})"))
}

/// Reads one line of a traffic log as an element.
fn read_element(bytes: &[u8]) -> Result<Decoded, String> {
    Decoded::from_json(&read_json(bytes)?)
}

/// An ST7580 traffic element as a JSON Lines line.
fn element_line() -> Vec<u8> {
    let frame = [0x02, 0x04, 0x00, 0x04, 0x00];
    let d = decode_all(Dialect::St7580, Source::Host, &frame);
    d[0].to_json().to_string().into_bytes()
}

/// A MIB profile as the console saves it.
fn profile() -> Vec<u8> {
    br#"{
  "format": "plm-console-profile/1",
  "chip": "ST7580",
  "objects": {
    "00": "11",
    "01": "014ff0d4c000000000"
  }
}"#
    .to_vec()
}

/// Bytes no reader could take: a xorshift stream, the same every run.
fn noise(n: usize, seed: u64) -> Vec<u8> {
    let mut x = seed | 1;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect()
}

/// The hostile table for a reader whose valid input is `sample`; every
/// case that cannot be valid must be refused in words.
fn hostile(sample: &[u8]) -> Vec<(String, Vec<u8>, bool)> {
    let mut cases: Vec<(String, Vec<u8>, bool)> = vec![
        ("empty".into(), vec![], true),
        ("oversized".into(), vec![b' '; FILE_MAX + 1], true),
        ("invalid UTF-8".into(), [sample, b"\xC3("].concat(), true),
        (
            "UTF-16 with its BOM".into(),
            [&[0xFF, 0xFE][..], &utf16(sample)].concat(),
            true,
        ),
        ("UTF-16 without a BOM".into(), utf16(sample), true),
        (
            "a NUL byte".into(),
            [&sample[..1], b"\0", &sample[1..]].concat(),
            true,
        ),
        ("random bytes".into(), noise(4096, 7), true),
    ];
    for n in 0..sample.len() {
        cases.push((format!("cut at {n}"), sample[..n].to_vec(), true));
    }
    for i in 0..sample.len() {
        for bit in [0x01, 0x20, 0x80] {
            let mut b = sample.to_vec();
            b[i] ^= bit;
            cases.push((format!("byte {i} ^ {bit:02x}"), b, false));
        }
    }
    cases
}

fn utf16(b: &[u8]) -> Vec<u8> {
    b.iter().flat_map(|&c| [c, 0]).collect()
}

/// Runs `read` over the table: refusals must say something, the cases
/// that cannot be valid must be refused, and no case may take long.
fn check<T>(what: &str, sample: &[u8], read: impl Fn(&[u8]) -> Result<T, String>) {
    assert!(read(sample).is_ok(), "{what}: the sample itself");
    for (case, bytes, must_fail) in hostile(sample) {
        let start = Instant::now();
        match read(&bytes) {
            Err(why) => assert!(why.len() > 10, "{what}, {case}: `{why}` says too little"),
            Ok(_) => assert!(!must_fail, "{what}, {case}: accepted"),
        }
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{what}, {case}: {:?}",
            start.elapsed()
        );
    }
}

#[test]
fn a_traffic_log_line_is_refused_in_words() {
    check("traffic element", &element_line(), read_element);
}

#[test]
fn a_profile_is_refused_in_words() {
    check("profile", &profile(), read_json);
}

#[test]
fn a_byte_order_mark_is_skipped_before_the_parser_and_named_by_it() {
    let with_bom = [&b"\xEF\xBB\xBF"[..], &profile()].concat();
    assert_eq!(read_json(&with_bom), read_json(&profile()));
    let e = json::parse("\u{feff}{}").unwrap_err().to_string();
    assert_eq!(e, "line 1, column 1: expected a value, found U+FEFF");
}

#[test]
fn hostile_json_is_refused_quickly() {
    let ten_mb = 10 * 1024 * 1024;
    let cases: Vec<(&str, String)> = vec![
        ("deep arrays", "[".repeat(ten_mb)),
        ("deep objects", "{\"a\":".repeat(ten_mb / 5)),
        ("a huge number", "9".repeat(ten_mb)),
        ("a huge fraction", format!("0.{}", "1".repeat(ten_mb))),
        ("a huge exponent", format!("1e{}", "9".repeat(ten_mb))),
        ("an unclosed string", format!("\"{}", "a".repeat(ten_mb))),
        ("escapes to the end", "\"\\u0000".repeat(ten_mb / 7)),
    ];
    for (case, text) in cases {
        let start = Instant::now();
        let e = json::parse(&text).unwrap_err().to_string();
        assert!(e.contains("expected"), "{case}: {e}");
        assert!(start.elapsed() < Duration::from_secs(5), "{case}");
    }
    assert!(json::parse(&"9".repeat(101))
        .unwrap_err()
        .to_string()
        .contains("at most 100"));
    assert_eq!(json::parse(&"9".repeat(100)).unwrap().as_u64(), None);
}

#[test]
fn an_object_of_many_keys_takes_as_long_as_sorting_them() {
    // 400 000 keys, duplicates among them: looked up one by one this was
    // minutes; a key given twice keeps its first place and last value.
    let keys = 400_000;
    let mut t = String::from("{");
    for i in 0..keys {
        t.push_str(&format!("\"k{}\":{i},", i % (keys / 2)));
    }
    t.pop();
    t.push('}');
    let start = Instant::now();
    let v = json::parse(&t).unwrap();
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "{:?}",
        start.elapsed()
    );
    let o = v.as_object().unwrap();
    assert_eq!(o.len(), keys / 2);
    let first = o.iter().next().unwrap();
    assert_eq!(
        (first.0.as_str(), first.1),
        ("k0", &Json::Int(keys as i64 / 2))
    );
    let ordered = json::parse(r#"{"b":1,"a":2,"b":3,"c":4,"a":5}"#).unwrap();
    assert_eq!(ordered.to_string(), r#"{"b":3,"a":5,"c":4}"#);
}

fn campaign_image() -> Vec<u8> {
    (0..1_000u32).map(|i| (i * 7) as u8).collect()
}

/// A campaign mid-way: one board announced, one silent, the broadcast
/// started.
fn saved_campaign() -> Vec<u8> {
    let a = [Address::from_u64(1), Address::from_u64(2)];
    let v = Release { major: 1, minor: 4 };
    let mut u = Update::new(9, v, campaign_image(), &a, UpdateConfig::default()).unwrap();
    let mut now = 0;
    for _ in 0..8 {
        if u.poll(now).is_some() {
            u.on_answer(now, Err("silent"));
        }
        now += 250_000;
    }
    u.save()
}

/// Resumes `saved` and, when it is taken, runs the campaign with every
/// board silent until it ends: a save that resumes must not panic later.
fn resume_and_run(saved: &[u8]) -> Result<(), String> {
    let mut u = Update::resume(campaign_image(), saved, 0)?;
    let mut now = 0;
    for _ in 0..5_000 {
        if u.is_done() {
            break;
        }
        if u.poll(now).is_some() {
            u.on_answer(now, Err("silent"));
        }
        now += 100_000;
    }
    Ok(())
}

#[test]
fn a_saved_campaign_is_refused_in_words_and_never_panics_later() {
    check("saved campaign", &saved_campaign(), resume_and_run);
}

#[test]
fn a_saved_campaign_that_does_not_fit_its_image_is_refused() {
    let saved = saved_campaign();
    // Header: magic 7, length 1, then the header; gaps 24, counts 3.
    let at = 7 + 1 + saved[7] as usize + 24 + 3;
    let mut past = saved.clone();
    past[at] = 1; // broadcast
    past[at + 1..at + 3].copy_from_slice(&500u16.to_be_bytes());
    assert!(Update::resume(campaign_image(), &past, 0)
        .unwrap_err()
        .contains("past the image's 11"));
    let mut none = saved.clone();
    let boards = at + 3 + 8;
    none[boards..boards + 2].copy_from_slice(&0u16.to_be_bytes());
    none.truncate(boards + 2);
    assert!(Update::resume(campaign_image(), &none, 0)
        .unwrap_err()
        .contains("no board"));
    // Both boards at one address.
    let mut twice = saved.clone();
    let second = boards + 2 + 6 + 3 + first_board_len(&saved[boards + 2 + 6..]);
    let first_address = saved[boards + 2..boards + 8].to_vec();
    twice[second..second + 6].copy_from_slice(&first_address);
    assert!(Update::resume(campaign_image(), &twice, 0)
        .unwrap_err()
        .contains("twice"));
}

#[test]
fn a_saved_campaign_whose_waits_or_counts_cannot_be_counted_is_refused() {
    // Found by the saved_campaign fuzz target: a gap of 2^64-1 µs
    // overflowed the time left.
    let saved = saved_campaign();
    let pacing = 7 + 1 + saved[7] as usize;
    let refused = |at: usize, value: &[u8]| {
        let mut bad = saved.clone();
        bad[pacing + at..pacing + at + value.len()].copy_from_slice(value);
        Update::resume(campaign_image(), &bad, 0).unwrap_err()
    };
    let huge = u64::MAX.to_be_bytes();
    assert!(
        refused(0, &huge).contains("gap of"),
        "{}",
        refused(0, &huge)
    );
    assert!(refused(8, &huge).contains("restart of"));
    assert!(refused(16, &huge).contains("back-off of"));
    assert!(refused(25, &[200]).contains("200 silences"));
    // Also found: a count of bytes sent near 2^64 overflowed the next segment's.
    let sent = 24 + 3 + 3;
    assert!(
        refused(sent, &huge).contains("bytes sent"),
        "{}",
        refused(sent, &huge)
    );
    let config = UpdateConfig {
        backoff: UpdateConfig::LONGEST + 1,
        ..UpdateConfig::default()
    };
    let a = [Address::from_u64(1)];
    assert!(Update::new(9, None, campaign_image(), &a, config).is_err());
}

/// The bytes after a saved board's address, tag and counters, by its tag.
fn first_board_len(b: &[u8]) -> usize {
    match b[0] {
        1 => 3 + 2 * u16::from_be_bytes([b[4], b[5]]) as usize,
        6 => 2 + u16::from_be_bytes([b[3], b[4]]) as usize,
        _ => 0,
    }
}

#[test]
fn a_firmware_image_is_refused_in_words() {
    check("firmware image", &sealed_image(), |b| {
        image::check(b).map(|_| ())
    });
}

/// An image the checker takes: a vector table of Thumb addresses into the
/// slot (the handler past the descriptor, so that no cut image is whole
/// again), then code, sealed with its descriptor.
fn sealed_image() -> Vec<u8> {
    let mut b = vec![0x5a; 600];
    b[..4].copy_from_slice(&0x2000_5000u32.to_le_bytes());
    for at in (4..image::VECTORS).step_by(4) {
        let v = if image::RESERVED.contains(&at) {
            0
        } else {
            image::LINK_BASE + 0x201
        };
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    }
    image::seal(&mut b, Release { major: 2, minor: 1 });
    b
}

#[test]
fn a_pole_list_is_refused_in_words() {
    // One pole whose name is quoted: no prefix of it is a pole list.
    check("pole list", br#"0080e1000001,"P1""#, file::poles::parse);
}

#[test]
fn a_pole_list_of_many_short_lines_is_read_quickly() {
    // The most lines the bound lets in, each checked against every one
    // before it (a duplicate, a position going back).
    let mut text = String::new();
    let mut n = 0u64;
    while text.len() + 20 < file::poles::POLE_LIST_MAX {
        text.push_str(&format!("{},{}\n", Address::from_u64(n), n % 10));
        n += 1;
    }
    let start = Instant::now();
    let poles = file::poles::parse(text.as_bytes()).expect("a list within the bound");
    assert_eq!(poles.len() as u64, n);
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "{:?}",
        start.elapsed()
    );
}
