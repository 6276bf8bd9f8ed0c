//! The fuzz targets of PLM Console, written once: each is a plain function
//! of arbitrary bytes that feeds one decoder, parser or engine and checks
//! what it must never do (panic, loop, lose an export on re-import).
//!
//! The libFuzzer binaries (`fuzz/fuzz_targets/`, built by `cargo xtask
//! fuzz`) call [`targets`]; `tests/replay.rs` replays every file of
//! `fuzz/seeds/<target>/` ([`seeds`]), `fuzz/corpus/<target>/` (what
//! fuzzing kept) and `fuzz/regressions/<target>/` (every crash found)
//! through the same functions, so a crash once found stays a regression
//! test.

pub mod input;
pub mod seeds;
pub mod targets;

/// A target body: any bytes in, a panic when it finds something.
pub type Target = fn(&[u8]);

/// Every target by name: the name of its libFuzzer binary and of its
/// corpus and regression directories.
pub const TARGETS: &[(&str, Target)] = &[
    ("st7580_host", targets::st7580_host),
    ("st7570_host", targets::st7570_host),
    ("steval_usart", targets::steval_usart),
    ("app_frame", targets::app_frame),
    ("st7570_mac", targets::st7570_mac),
    ("json_lines", targets::json_lines),
    ("rfu_image", targets::rfu_image),
    ("saved_campaign", targets::saved_campaign),
    ("pole_list", targets::pole_list),
    ("rfc2217", targets::rfc2217),
    ("host_engine", targets::host_engine),
    ("device_engine", targets::device_engine),
];

/// The target called `name`.
pub fn target(name: &str) -> Option<Target> {
    TARGETS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
}
