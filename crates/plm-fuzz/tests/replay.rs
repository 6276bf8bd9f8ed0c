//! Replays every fuzz target's seeds (`fuzz/seeds/<target>/`, made from
//! the golden vectors), the corpus its fuzzing grew (`fuzz/corpus/`) and
//! every crash it found (`fuzz/regressions/`), through the same target
//! bodies the libFuzzer binaries run. No open-ended fuzzing: the same files, the same
//! verdict, every time.

use plm_fuzz::TARGETS;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The files of `dir`, sorted; none when it does not exist.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(entries) => entries
            .map(|e| e.expect("a readable directory entry").path())
            .filter(|p| p.is_file())
            .collect(),
        Err(_) => Vec::new(),
    };
    out.sort();
    out
}

/// Runs `target` on each input; the names of those that panicked.
fn replay(target: fn(&[u8]), inputs: impl IntoIterator<Item = (String, Vec<u8>)>) -> Vec<String> {
    let mut failed = Vec::new();
    for (name, bytes) in inputs {
        if catch_unwind(AssertUnwindSafe(|| target(&bytes))).is_err() {
            failed.push(name);
        }
    }
    failed
}

/// The files' bytes; a file gone since it was listed (a fuzzer running
/// meanwhile replaces corpus files by smaller ones) is skipped.
fn read(paths: Vec<PathBuf>) -> impl Iterator<Item = (String, Vec<u8>)> {
    paths.into_iter().filter_map(|p| match std::fs::read(&p) {
        Ok(bytes) => Some((p.display().to_string(), bytes)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => panic!("{}: {e}", p.display()),
    })
}

#[test]
fn every_seed_corpus_file_and_crash_found_replays_without_panic() {
    let fuzz = root().join("fuzz");
    let mut failed = Vec::new();
    for (name, target) in TARGETS {
        let seeds = files(&fuzz.join("seeds").join(name));
        assert!(!seeds.is_empty(), "fuzz/seeds/{name}/ has no input");
        for dir in ["seeds", "corpus", "regressions"] {
            failed.extend(replay(*target, read(files(&fuzz.join(dir).join(name)))));
        }
    }
    assert!(
        failed.is_empty(),
        "these inputs panic:\n{}",
        failed.join("\n")
    );
}

#[test]
fn the_seeds_made_now_from_the_golden_vectors_replay_without_panic() {
    let seeds = plm_fuzz::seeds::all(&root()).expect("the golden vectors read");
    for (name, _) in TARGETS {
        assert!(
            seeds.iter().any(|(t, _, _)| t == name),
            "no seed for the {name} target"
        );
    }
    let mut failed = Vec::new();
    for (target, name, bytes) in seeds {
        let f = plm_fuzz::target(target).expect("a seed's target exists");
        failed.extend(replay(f, [(format!("{target}/{name}"), bytes)]));
    }
    assert!(
        failed.is_empty(),
        "these seeds panic:\n{}",
        failed.join("\n")
    );
}

#[test]
fn every_target_has_a_libfuzzer_binary_and_no_binary_lacks_a_target() {
    let manifest =
        std::fs::read_to_string(root().join("fuzz/Cargo.toml")).expect("fuzz/Cargo.toml");
    let bins: Vec<&str> = manifest
        .lines()
        .filter_map(|l| l.trim().strip_prefix("name = \""))
        .filter_map(|l| l.strip_suffix('"'))
        .filter(|n| *n != "plm-fuzz-targets")
        .collect();
    let names: Vec<&str> = TARGETS.iter().map(|(n, _)| *n).collect();
    assert_eq!(
        bins, names,
        "fuzz/Cargo.toml's [[bin]]s and plm_fuzz::TARGETS"
    );
    for name in names {
        let source = root().join("fuzz/fuzz_targets").join(format!("{name}.rs"));
        let text = std::fs::read_to_string(&source).expect("a target's binary source");
        assert!(
            text.contains(&format!("plm_fuzz::targets::{name}(")),
            "{} calls plm_fuzz::targets::{name}",
            source.display()
        );
    }
}

#[test]
fn a_target_that_panics_is_caught_by_the_replay() {
    fn panics(_: &[u8]) {
        panic!("found");
    }
    let failed = replay(panics, [("x".to_string(), vec![1])]);
    assert_eq!(failed, ["x"]);
}
