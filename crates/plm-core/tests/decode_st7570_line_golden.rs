//! The line decoder's JSON of every ST7570 line vector (tests/vectors/
//! st7570_line.jsonl, written by tests/vectors/make_st7570_line.py from
//! the layout and FCS forms in docs/protocol-notes.md): long MAC frames,
//! subframes and PHY frames with their FCS form named (the catalogue form
//! this project sends, Gurux's over the pad bytes or without them), and a
//! frame no form explains flagged, exactly as `plm decode --chip st7570
//! --line` prints them.

use plm_core::decode::decode_line;
use serde_json::Value;

const VECTORS: &str = include_str!("../../../tests/vectors/st7570_line.jsonl");

/// Where `got` differs from the vector's `expect`, in words.
fn differences(got: &Value, want: &Value) -> Vec<String> {
    let mut errors = Vec::new();
    for (k, w) in want.as_object().expect("expect is an object") {
        match k.as_str() {
            "error_starts" => {
                let prefix = w.as_str().unwrap();
                if !got["error"].as_str().is_some_and(|e| e.starts_with(prefix)) {
                    errors.push(format!(
                        "error {}, want it to start {prefix:?}",
                        got["error"]
                    ));
                }
            }
            "error_mentions" => {
                for m in w.as_array().unwrap() {
                    let m = m.as_str().unwrap();
                    if !got["error"].as_str().is_some_and(|e| e.contains(m)) {
                        errors.push(format!("error {}, want it to name {m}", got["error"]));
                    }
                }
            }
            // null: the member is absent.
            _ => {
                let g = got.get(k).unwrap_or(&Value::Null);
                if g != w {
                    errors.push(format!("{k} {g}, want {w}"));
                }
            }
        }
    }
    errors
}

#[test]
fn every_line_vector_decodes_with_its_fcs_form() {
    let mut failures = Vec::new();
    let mut forms = Vec::new();
    for line in VECTORS.lines().filter(|l| !l.trim().is_empty()) {
        let v: Value = serde_json::from_str(line).unwrap();
        let bytes = plm_core::hex::parse(v["hex"].as_str().unwrap()).unwrap();
        let got = serde_json::to_value(decode_line(&bytes)).unwrap();
        assert_eq!(got["hex"], v["hex"]);
        let errors = differences(&got, &v["expect"]);
        if !errors.is_empty() {
            failures.push(format!("{}: {}", v["name"], errors.join("; ")));
        }
        forms.push(got["fcs_form"].as_str().unwrap_or("none").to_string());
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    for form in ["catalogue", "gurux", "gurux_without_pad", "none"] {
        assert!(forms.iter().any(|f| f == form), "no vector in form {form}");
    }
}
