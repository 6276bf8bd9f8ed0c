//! plm-core's JSON module against serde_json, the writer everyone else
//! uses: the same text for the same value (compact and pretty), the same
//! texts accepted and refused, the same values read, and the decoded views
//! written and read back whole.

use plm_core::decode::app::{decode_usart, AppDecoded};
use plm_core::decode::{decode_all, Decoded};
use plm_core::json::{parse, Json, Object};
use plm_core::link::{Dialect, Source};
use proptest::collection::vec;
use proptest::prelude::*;
use serde_json::Value;

/// Strings with what needs escaping: quotes, backslashes, every control
/// character, DEL, `/`, non-ASCII and astral characters.
fn text() -> impl Strategy<Value = String> {
    let c = prop_oneof![
        3 => any::<char>(),
        2 => (0u8..0x20).prop_map(char::from),
        2 => prop::sample::select(vec!['"', '\\', '/', '\u{7f}', 'é', '😀', 'a', ' ']),
    ];
    vec(c, 0..12).prop_map(|v| v.into_iter().collect())
}

/// Any serde_json value of the kinds plm-core writes: whole numbers
/// (`u64` beyond `i64` too), strings, arrays and objects in order.
fn value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::Bool),
        any::<i64>().prop_map(Value::from),
        any::<u64>().prop_map(Value::from),
        (0u8..=255).prop_map(Value::from),
        text().prop_map(Value::String),
    ];
    leaf.prop_recursive(5, 48, 6, |inner| {
        prop_oneof![
            vec(inner.clone(), 0..6).prop_map(Value::Array),
            vec((text(), inner), 0..6)
                .prop_map(|members| Value::Object(members.into_iter().collect())),
        ]
    })
}

/// The same value in plm-core's type.
fn mine(v: &Value) -> Json {
    match v {
        Value::Null => Json::Null,
        Value::Bool(b) => Json::Bool(*b),
        Value::Number(n) => match n.as_i64() {
            Some(i) => Json::Int(i),
            None => Json::Number(n.to_string()),
        },
        Value::String(s) => Json::String(s.clone()),
        Value::Array(items) => Json::Array(items.iter().map(mine).collect()),
        Value::Object(map) => {
            let mut o = Object::new();
            for (k, v) in map {
                o.insert(k.clone(), mine(v));
            }
            Json::Object(o)
        }
    }
}

/// Whether plm-core read the same value serde_json read; numbers that
/// are not whole compare with the f64 serde_json made of them, which its
/// fast parsing may round a unit or two off in the last place.
fn same(a: &Json, b: &Value) -> bool {
    match (a, b) {
        (Json::Int(i), Value::Number(n)) => n.as_i64() == Some(*i),
        (Json::Number(t), Value::Number(n)) => match t.parse::<u64>() {
            Ok(u) => n.as_u64() == Some(u),
            Err(_) => match (t.parse::<f64>(), n.as_f64()) {
                (Ok(x), Some(y)) => x == y || (x - y).abs() <= x.abs() * 1e-15,
                _ => false,
            },
        },
        (Json::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b))
        }
        (Json::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|((k, a), (l, b))| k == l && same(a, b))
        }
        _ => *a == mine(b),
    }
}

/// A text edited once: a character put in, taken out or changed, from
/// the characters that matter to JSON.
fn edited(text: String) -> impl Strategy<Value = String> {
    let c = prop::sample::select(
        "[]{}\",:\\/ \n\t0123456789-+.eEtrufalsnu\u{1}é"
            .chars()
            .collect::<Vec<_>>(),
    );
    (any::<prop::sample::Index>(), 0..3u8, c).prop_map(move |(i, how, c)| {
        let mut chars: Vec<char> = text.chars().collect();
        let i = i.index(chars.len() + 1);
        match how {
            0 => chars.insert(i, c),
            _ if i == chars.len() => chars.push(c),
            1 => {
                chars.remove(i);
            }
            _ => chars[i] = c,
        }
        chars.into_iter().collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn writes_what_serde_json_writes(v in value()) {
        let m = mine(&v);
        prop_assert_eq!(m.to_string(), serde_json::to_string(&v).unwrap());
        prop_assert_eq!(m.pretty(), serde_json::to_string_pretty(&v).unwrap());
        // `plm decode` writes through serde: the same text again.
        prop_assert_eq!(serde_json::to_string(&m).unwrap(), m.to_string());
    }

    #[test]
    fn reads_what_serde_json_writes(v in value()) {
        let m = mine(&v);
        prop_assert_eq!(parse(&serde_json::to_string(&v).unwrap()), Ok(m.clone()));
        prop_assert_eq!(parse(&serde_json::to_string_pretty(&v).unwrap()), Ok(m));
    }

    #[test]
    fn accepts_and_refuses_what_serde_json_does(t in value()
        .prop_map(|v| serde_json::to_string(&v).unwrap())
        .prop_flat_map(edited))
    {
        match (parse(&t), serde_json::from_str::<Value>(&t)) {
            (Ok(a), Ok(b)) => prop_assert!(same(&a, &b), "{t}: {a:?} / {b:?}"),
            (Err(_), Err(_)) => {}
            // serde_json refuses numbers beyond f64 (`1e400`); JSON
            // does not, and they are kept as their text.
            (Ok(_), Err(e)) if e.to_string().contains("number out of range") => {}
            (a, b) => prop_assert!(false, "{t}: {a:?} / {b:?}"),
        }
    }

    /// Any bytes at all, as a file handed to the console: read as text,
    /// then as JSON, each refusal in words (tests/hostile_files.rs has
    /// the table of damaged files).
    #[test]
    fn any_bytes_are_read_or_refused_in_words(
        bytes in vec(prop_oneof![
            prop::sample::select(b"[]{}\",:\\ 0123456789-.eu".to_vec()),
            any::<u8>(),
        ], 0..200),
    ) {
        match plm_core::file::text(&bytes) {
            Err(why) => prop_assert!(why.starts_with("the file ")),
            Ok(text) => match (parse(text), serde_json::from_str::<Value>(text)) {
                (Err(e), _) => prop_assert!(e.to_string().contains("expected")),
                (Ok(_), b) => prop_assert!(b.is_ok() || text.contains('e')),
            },
        }
    }

    #[test]
    fn decoded_elements_go_out_and_come_back_whole(
        dialect in prop_oneof![Just(Dialect::St7580), Just(Dialect::St7570)],
        bytes in vec(prop_oneof![Just(0x02u8), Just(0x03), Just(0x06), Just(0x15), Just(0x3f), any::<u8>()], 0..80),
    ) {
        for d in decode_all(dialect, Source::Modem, &bytes) {
            let j = d.to_json();
            prop_assert_eq!(serde_json::to_string(&d).unwrap(), j.to_string());
            prop_assert_eq!(parse(&j.to_string()), Ok(j.clone()));
            prop_assert_eq!(Decoded::from_json(&j), Ok(d));
        }
        for d in decode_usart(&bytes) {
            prop_assert_eq!(AppDecoded::from_json(&d.to_json()), Ok(d));
        }
    }
}

#[test]
fn nesting_stops_where_serde_json_stops() {
    for depth in [126, 127, 128, 129, 100_000] {
        let t = format!("{}{}", "[".repeat(depth), "]".repeat(depth));
        assert_eq!(
            parse(&t).is_ok(),
            serde_json::from_str::<Value>(&t).is_ok(),
            "{depth} levels"
        );
    }
}

#[test]
fn errors_say_where_and_what_was_expected() {
    let e = parse("{\"a\": 1,\n  \"b\" 2}").unwrap_err();
    assert_eq!(e.to_string(), "line 2, column 7: expected `:`, found `2`");
    let e = parse("[1, 2").unwrap_err();
    assert_eq!(
        e.to_string(),
        "line 1, column 6: expected `,` or `]`, found the end of the text"
    );
    assert_eq!(
        parse("\"tab\there\"").unwrap_err().to_string(),
        "line 1, column 5: expected `\\` before a control character, found U+0009"
    );
    assert_eq!(parse("{} x").unwrap_err().expected, "the end of the text");
    assert_eq!(parse("01").unwrap_err().column, 2);
    assert_eq!(parse("\"\\ud800\"").unwrap_err().column, 8);
}

#[test]
fn numbers_other_than_i64_are_kept_as_written() {
    for t in [
        "1.50",
        "-0",
        "1e400",
        "18446744073709551616",
        "-9223372036854775809",
    ] {
        assert_eq!(parse(t), Ok(Json::Number(t.into())));
        assert_eq!(parse(t).unwrap().to_string(), t);
    }
    assert_eq!(parse("-9223372036854775808"), Ok(Json::Int(i64::MIN)));
    assert_eq!(Json::from(u64::MAX).to_string(), u64::MAX.to_string());
    assert_eq!(
        parse("18446744073709551615").unwrap().as_u64(),
        Some(u64::MAX)
    );
}

#[test]
fn a_null_command_comes_back_as_null() {
    // An unknown code: `"command": null`, which is not "no command".
    let d = decode_all(
        Dialect::St7580,
        Source::Modem,
        &[0x02, 0x00, 0x7f, 0x7f, 0x00],
    );
    assert_eq!(d[0].command, Some(Json::Null));
    assert_eq!(Decoded::from_json(&d[0].to_json()), Ok(d[0].clone()));
}

#[test]
fn reading_an_element_says_which_key_is_wrong() {
    let read = |t: &str| Decoded::from_json(&parse(t).unwrap());
    assert_eq!(read("[]"), Err("not a JSON object".into()));
    assert_eq!(read(r#"{"hex":"06"}"#), Err("`kind` is missing".into()));
    assert_eq!(
        read(r#"{"kind":"ack","hex":"06","stx":256}"#),
        Err("`stx` must be a whole number from 0 to 255".into())
    );
    let d = read(r#"{"kind":"ack","hex":"06","stx":null,"extra":1}"#).unwrap();
    assert_eq!((d.kind.as_str(), d.stx), ("ack", None));
}
