//! The decoder's JSON of every ST7570 golden vector (tests/vectors/
//! st7570.jsonl, written from the manual by tests/vectors/make_st7570.py):
//! kind, code, command, checksum and the manual's fields, a MIB object's
//! among them, exactly as `plm decode --chip st7570 --layer L --from S`
//! prints them.

use plm_core::decode::Decoder;
use plm_core::link::{Dialect, Source};
use plm_core::st7570::Layer;
use serde_json::Value;

const VECTORS: &str = include_str!("../../../tests/vectors/st7570.jsonl");

#[test]
fn every_vector_decodes_to_the_manuals_fields() {
    let mut failures = Vec::new();
    let mut count = 0;
    for line in VECTORS.lines().filter(|l| !l.trim().is_empty()) {
        let v: Value = serde_json::from_str(line).unwrap();
        let name = v["name"].as_str().unwrap();
        let (source, from) = match v["from"].as_str() {
            Some("host") => (Source::Host, "host"),
            _ => (Source::Modem, "modem"),
        };
        let layer = match v["layer"].as_str() {
            Some("mac") => Layer::Mac,
            _ => Layer::Phy,
        };
        let mut d = Decoder::new(Dialect::St7570, source);
        d.fix_layer(layer);
        d.push(&plm_core::hex::parse(v["hex"].as_str().unwrap()).unwrap());
        d.finish();
        let got: Vec<Value> = std::iter::from_fn(|| d.next())
            .map(|e| serde_json::to_value(&e).unwrap())
            .collect();
        let want = v["expect"].as_array().unwrap();
        if got.len() != want.len() {
            failures.push(format!(
                "{name}: {} elements, want {}",
                got.len(),
                want.len()
            ));
            continue;
        }
        for (g, w) in got.iter().zip(want) {
            count += 1;
            let mut errors = Vec::new();
            for key in ["kind", "code", "command", "checksum_ok", "checksum"] {
                if let Some(wv) = w.get(key) {
                    if g.get(key) != Some(wv) {
                        errors.push(format!("{key} {:?}, want {wv}", g.get(key)));
                    }
                }
            }
            if g["from"] != from {
                errors.push(format!("from {}", g["from"]));
            }
            if w["kind"] == "frame" && g["layer"] != layer.name() {
                errors.push(format!("layer {}", g["layer"]));
            }
            for part in ["fields", "object"] {
                let Some(wf) = w.get(part).and_then(Value::as_object) else {
                    continue;
                };
                for (k, wv) in wf {
                    if g["fields"].get(k) != Some(wv) {
                        errors.push(format!("{part}.{k} {:?}, want {wv}", g["fields"].get(k)));
                    }
                }
            }
            if !errors.is_empty() {
                failures.push(format!("{name}: {}", errors.join("; ")));
            }
        }
    }
    assert!(count >= 120, "only {count} elements checked");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
