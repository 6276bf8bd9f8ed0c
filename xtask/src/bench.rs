//! `cargo xtask bench`: the performance figures of docs/architecture.md
//! ("Performance and size"), measured by programs that print their own
//! results (never by timed tests).

use crate::serve;
use crate::util::{root, run_steps, Cmd, Result, Step};

/// One benchmark: a program that prints its figures, and the source file
/// whose absence means it is not written yet.
struct Bench {
    name: &'static str,
    /// Relative to the workspace root; any one of them will do.
    sources: &'static [&'static str],
    cmd: Cmd,
    /// Whether it measures the release console in `dist/`, which is then
    /// built first (once).
    needs_dist: bool,
}

/// Append new benchmarks here (link latency, command rate, RFU, size...).
fn benches() -> Vec<Bench> {
    vec![
        Bench {
            name: "decoder throughput (native)",
            sources: &[
                "crates/plm-core/examples/bench_decode.rs",
                "crates/plm-core/examples/bench_decode/main.rs",
            ],
            cmd: Cmd::new("cargo").args([
                "run",
                "--profile",
                "bench-native",
                "-p",
                "plm-core",
                "--example",
                "bench_decode",
            ]),
            needs_dist: false,
        },
        Bench {
            name: "simulator speed, MIB-read rate, reads behind a USB-UART latency timer (native)",
            sources: &["crates/plm-sim/examples/bench_sim.rs"],
            cmd: Cmd::new("cargo").args([
                "run",
                "--profile",
                "bench-native",
                "-p",
                "plm-sim",
                "--example",
                "bench_sim",
            ]),
            needs_dist: false,
        },
        Bench {
            name: "street: discover and read 12, 100 and 500 lamps, sweep 500 (simulated s per wall s), firmware update (native)",
            sources: &["crates/plm-sim/examples/bench_street.rs"],
            cmd: Cmd::new("cargo").args([
                "run",
                "--profile",
                "bench-native",
                "-p",
                "plm-sim",
                "--example",
                "bench_street",
            ]),
            needs_dist: false,
        },
        Bench {
            name: "plm sim: T_REQ to status message through RFC 2217 on loopback (native)",
            sources: &["crates/plm-cli/examples/bench_sim_latency.rs"],
            cmd: Cmd::new("cargo").args([
                "run",
                "--profile",
                "bench-native",
                "-p",
                "plm-cli",
                "--example",
                "bench_sim_latency",
            ]),
            needs_dist: false,
        },
        Bench {
            name: "ST7570: 50-node S-FSK network with repeaters, simulated s per wall s (native)",
            sources: &["crates/plm-sim/examples/bench_st7570.rs"],
            cmd: Cmd::new("cargo").args([
                "run",
                "--profile",
                "bench-native",
                "-p",
                "plm-sim",
                "--example",
                "bench_st7570",
            ]),
            needs_dist: false,
        },
        Bench {
            name:
                "console in Chromium: ACK latency, MIB-read rate, Street view with 500 lamps (frame time, simulated s per wall s), size",
            sources: &["tests/e2e/bench.mjs"],
            cmd: Cmd::new("node").args(["tests/e2e/bench.mjs"]),
            needs_dist: true,
        },
    ]
}

/// How the release console is built into `dist/`.
const DIST: &str = "cargo xtask dist";

/// Runs every benchmark; all must exist.
pub fn run() -> Result {
    let root = root();
    let benches = benches();
    let missing: Vec<String> = benches
        .iter()
        .filter(|b| !b.sources.iter().any(|s| root.join(s).exists()))
        .map(|b| {
            format!(
                "`{}` is not written yet: {} is missing",
                b.name, b.sources[0]
            )
        })
        .collect();
    if !missing.is_empty() {
        return Err(format!("cannot bench: {}", missing.join("; ")));
    }
    println!(
        "bench: {} benchmark(s); each prints its own figures",
        benches.len()
    );
    let mut steps = Vec::new();
    for b in benches {
        if b.needs_dist && !steps.iter().any(|s: &Step| s.rerun == DIST) {
            steps.push(Step::new(
                "console release build (dist/)",
                DIST,
                serve::dist,
            ));
        }
        steps.push(Step::cmd(b.name, b.cmd));
    }
    run_steps("bench", &steps, false)
}
