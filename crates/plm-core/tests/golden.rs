//! Golden vectors from UM0932 chapters 3-4 (tests/vectors/um0932.jsonl,
//! written by tests/vectors/make_um0932.py from the manual's tables, with
//! frames built independently of plm-core).

use plm_core::decode::decode_all;
use plm_core::link::{Dialect, Source};
use serde_json::Value;

const VECTORS: &str = include_str!("../../../tests/vectors/um0932.jsonl");

fn check_subset(want: &Value, got: &Value, path: &str, errors: &mut Vec<String>) {
    match want {
        Value::Object(map) => {
            for (k, w) in map {
                let g = got.get(k).unwrap_or(&Value::Null);
                if !got.as_object().is_some_and(|o| o.contains_key(k)) && !w.is_null() {
                    errors.push(format!("{path}.{k}: missing (want {w})"));
                    continue;
                }
                check_subset(w, g, &format!("{path}.{k}"), errors);
            }
        }
        _ if want != got => errors.push(format!("{path}: want {want}, got {got}")),
        _ => {}
    }
}

#[test]
fn every_um0932_vector_decodes_as_the_manual_says() {
    let mut failures = Vec::new();
    let mut count = 0;
    for line in VECTORS.lines().filter(|l| !l.trim().is_empty()) {
        let v: Value = serde_json::from_str(line).expect("vector line is JSON");
        let name = v["name"].as_str().unwrap();
        let source = match v["from"].as_str() {
            Some("host") => Source::Host,
            Some("modem") => Source::Modem,
            _ => Source::Any,
        };
        let bytes = plm_core::hex::parse(v["hex"].as_str().unwrap()).unwrap();
        let got: Vec<Value> = decode_all(Dialect::St7580, source, &bytes)
            .iter()
            .map(|d| serde_json::to_value(d).unwrap())
            .collect();
        let want = v["expect"].as_array().unwrap();
        let mut errors = Vec::new();
        if got.len() != want.len() {
            errors.push(format!(
                "{} elements, want {}: {got:?}",
                got.len(),
                want.len()
            ));
        } else {
            for (i, (w, g)) in want.iter().zip(&got).enumerate() {
                check_subset(w, g, &format!("[{i}]"), &mut errors);
            }
        }
        if !errors.is_empty() {
            failures.push(format!("{name} ({}): {}", v["source"], errors.join("; ")));
        }
        count += 1;
    }
    assert!(count >= 70, "only {count} vectors read");
    assert!(
        failures.is_empty(),
        "{} vectors fail:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn table_9_default_timeouts() {
    let t = plm_core::link::Timeouts::default();
    assert_eq!((t.t_ic, t.t_ack, t.t_sr), (10_000, 40_000, 200_000));
    let from_mib = plm_core::st7580::mib::MibObject::factory_default(0x09)
        .unwrap()
        .timeouts()
        .unwrap();
    assert_eq!(from_mib, t, "MIB 09h factory default C8280Ah is Table 9");
}

#[test]
fn table_52_defaults_pass_the_chip_validation_and_round_trip() {
    for o in plm_core::st7580::mib::OBJECTS {
        assert_eq!(o.default.len(), o.len, "{}", o.name);
        o.check_value(o.default)
            .unwrap_or_else(|e| panic!("{}: {e}", o.name));
        let typed = plm_core::st7580::mib::MibObject::decode(o.index as u8, o.default).unwrap();
        assert_eq!(typed.encode(), o.default, "{}", o.name);
    }
}

#[test]
fn table_10_to_15_codes_are_all_distinct_and_named() {
    use plm_core::st7580::code::{CommandType, ALL};
    assert_eq!(ALL.len(), 30);
    let mut codes: Vec<u8> = ALL.iter().map(|c| c.0).collect();
    codes.sort();
    codes.dedup();
    assert_eq!(codes.len(), 30);
    let count = |t| ALL.iter().filter(|c| c.2 == t).count();
    assert_eq!(count(CommandType::Request), 8, "Table 10");
    assert_eq!(count(CommandType::Confirm), 8, "Table 11");
    assert_eq!(count(CommandType::Error), 8, "Table 12");
    assert_eq!(count(CommandType::Indication), 6, "Table 15");
}

/// ST7570 UM sections 8.1 and 9: worked examples with exact bytes. Only the
/// link layer (length counts command + data + checksum) is checked here;
/// the ST7570 commands come with their own issue.
#[test]
fn st7570_worked_examples_frame_and_checksum() {
    use plm_core::link::{Element, StreamDecoder};
    let examples = [
        // 8.1 CMD_WriteDBRequest, checksum 7E.02h
        (
            "02 13 41 A1.00 09 00 10 10.21.01 44.F7.00 00.00.00 02 01 7E.02",
            0x41,
            16,
            0x027E,
        ),
        // 8.1 CMD_WriteDBConfirm, checksum 7F.02h
        (
            "02 13 42 A1.00 09 00 10 10.21.01 44.F7.00 00.00.00 02 01 7F.02",
            0x42,
            16,
            0x027F,
        ),
    ];
    let mut phy = String::from("02 29 51 ");
    for b in 0..0x26u8 {
        phy.push_str(&format!("{b:02x} "));
    }
    phy.push_str("39 03"); // 9: CMD_DataRequest, P_SDU 00h..25h, checksum 39.03h
    let phy_example = (phy.as_str(), 0x51, 38, 0x0339);
    for (hex, code, data_len, sum) in examples.iter().copied().chain([phy_example]) {
        let bytes = plm_core::hex::parse(hex).unwrap();
        let els = StreamDecoder::decode_all(Dialect::St7570, Source::Host, &bytes);
        assert_eq!(els.len(), 1, "{hex}");
        let Element::Frame {
            frame,
            checksum,
            checksum_ok,
        } = &els[0]
        else {
            panic!("{hex}: {els:?}")
        };
        assert!(checksum_ok, "{hex}");
        assert_eq!(
            (frame.code, frame.data.len(), *checksum),
            (code, data_len, sum)
        );
        assert_eq!(
            frame.emit(Dialect::St7570).unwrap(),
            bytes,
            "re-emitted bytes"
        );
    }
}
