//! `cargo xtask fuzz [TARGET] [--time S]`: coverage-guided fuzzing of the
//! decoders, parsers and link engines with libFuzzer through cargo-fuzz,
//! without sanitizers, on the stable toolchain. The target bodies are
//! `crates/plm-fuzz` (whose test replays the corpus in `cargo xtask
//! test`); the binaries are `fuzz/`. libFuzzer reads `fuzz/seeds/` and
//! `fuzz/regressions/`, and keeps the inputs that reach new code in
//! `fuzz/corpus/<target>/`. A crash is copied into
//! `fuzz/regressions/<target>/`, where the replay test keeps running it.

use crate::util::{fmt_duration, root, Cmd, Result};
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Seconds each target runs when `--time` is not given.
pub const DEFAULT_SECONDS: u64 = 60;

/// When the coverage is noted (seconds into a target's run), besides its end.
const CHECKPOINTS: [u64; 6] = [10, 60, 300, 600, 1800, 3600];

/// What one target's run showed.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
struct Report {
    target: String,
    seconds: u64,
    execs: Option<u64>,
    /// The last `cov:` and `ft:` libFuzzer printed.
    last: Option<(u64, u64)>,
    /// (seconds, cov, ft) at each checkpoint reached.
    over_time: Vec<(u64, u64, u64)>,
    crashes: Vec<String>,
}

/// `cov: N ft: M` of a libFuzzer status line (`#1234 pulse cov: ...`).
fn coverage(line: &str) -> Option<(u64, u64)> {
    if !line.starts_with('#') {
        return None;
    }
    let number_after = |key: &str| -> Option<u64> {
        let at = line.find(key)? + key.len();
        line[at..].split_whitespace().next()?.parse().ok()
    };
    Some((number_after("cov: ")?, number_after("ft: ")?))
}

/// The executions of libFuzzer's final statistics line.
fn executions(line: &str) -> Option<u64> {
    line.strip_prefix("stat::number_of_executed_units:")?
        .trim()
        .parse()
        .ok()
}

/// Whether a line of libFuzzer's is worth showing: not the stream of new
/// inputs, which says nothing a person reads.
fn shown(line: &str) -> bool {
    !(line.starts_with('#') && (line.contains("\tNEW ") || line.contains("\tREDUCE ")))
        && !line.starts_with("\tNEW_FUNC")
}

/// Runs `target` (all targets in turn when `None`) for `seconds` each.
pub fn run(target: Option<&str>, seconds: u64) -> Result {
    let root = root();
    cargo_fuzz()?;
    Cmd::new("cargo")
        .args(["run", "-q", "-p", "plm-fuzz", "--bin", "plm-fuzz-seed"])
        .run()?;
    let listed = fuzz_cmd(&root, &["list"])
        .output()
        .ok_or("`cargo fuzz list` failed")?;
    let all: Vec<&str> = listed.split_whitespace().collect();
    let targets: Vec<&str> = match target {
        None => all.clone(),
        Some(t) if all.contains(&t) => vec![t],
        Some(t) => {
            return Err(format!(
                "no fuzz target `{t}` (there are: {})",
                all.join(", ")
            ))
        }
    };
    println!(
        "fuzz: building {} target(s) without sanitizers",
        targets.len()
    );
    fuzz_cmd(&root, &["build", "-s", "none"]).run()?;
    let mut reports = Vec::new();
    for t in targets {
        println!("fuzz: {t} for {seconds} s");
        reports.push(run_target(&root, t, seconds)?);
    }
    println!("\nfuzz: summary");
    for r in &reports {
        println!("{}", summary(r));
    }
    let crashed: Vec<&str> = reports
        .iter()
        .filter(|r| !r.crashes.is_empty())
        .map(|r| r.target.as_str())
        .collect();
    if crashed.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "crashes found in {} (kept in fuzz/regressions/; `cargo test -p plm-fuzz` replays them)",
            crashed.join(", ")
        ))
    }
}

/// cargo-fuzz, installed if missing.
fn cargo_fuzz() -> Result {
    if Cmd::new("cargo")
        .args(["fuzz", "--version"])
        .output()
        .is_some()
    {
        return Ok(());
    }
    let install = Cmd::new("cargo").args(["install", "cargo-fuzz"]);
    println!("fuzz: cargo-fuzz not found, installing: {install}");
    install.run()
}

/// `cargo fuzz ARGS`, its build in `fuzz/target` (away from the
/// workspace's, which it would otherwise rebuild with instrumentation).
fn fuzz_cmd(root: &Path, args: &[&str]) -> Cmd {
    Cmd::new("cargo").args(["fuzz"]).args(args).env(
        "CARGO_TARGET_DIR",
        &root.join("fuzz/target").to_string_lossy(),
    )
}

fn run_target(root: &Path, target: &str, seconds: u64) -> Result<Report> {
    let corpus = format!("fuzz/corpus/{target}");
    let seeds = format!("fuzz/seeds/{target}");
    let regressions = format!("fuzz/regressions/{target}");
    let artifacts = root.join("fuzz/artifacts").join(target);
    for dir in [root.join(&corpus), root.join(&regressions)] {
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let before = files(&artifacts);
    let time = format!("-max_total_time={seconds}");
    let cmd = fuzz_cmd(
        root,
        &[
            "run",
            "-s",
            "none",
            target,
            &corpus,
            &seeds,
            &regressions,
            "--",
            &time,
            "-print_final_stats=1",
            "-timeout=10",
        ],
    );
    let mut child = cmd
        .command()
        .stdout(Stdio::inherit())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("could not start `{cmd}`: {e}"))?;
    let start = Instant::now();
    let mut report = Report {
        target: target.to_string(),
        ..Report::default()
    };
    let stderr = child.stderr.take().ok_or("no stderr from cargo fuzz")?;
    for line in BufReader::new(stderr).lines() {
        let line = line.map_err(|e| format!("reading cargo fuzz: {e}"))?;
        let at = start.elapsed().as_secs();
        if let Some((cov, ft)) = coverage(&line) {
            for c in CHECKPOINTS.iter().filter(|&&c| c <= at) {
                if !report.over_time.iter().any(|(s, _, _)| s == c) {
                    report.over_time.push((*c, cov, ft));
                }
            }
            report.last = Some((cov, ft));
        }
        if let Some(n) = executions(&line) {
            report.execs = Some(n);
        }
        if shown(&line) {
            eprintln!("{line}");
        }
    }
    let status = child.wait().map_err(|e| format!("`{cmd}`: {e}"))?;
    report.seconds = start.elapsed().as_secs();
    for found in files(&artifacts)
        .into_iter()
        .filter(|f| !before.contains(f))
    {
        let into = root.join(&regressions).join(&found);
        std::fs::copy(artifacts.join(&found), &into)
            .map_err(|e| format!("{}: {e}", into.display()))?;
        report.crashes.push(found);
    }
    if !status.success() && report.crashes.is_empty() {
        return Err(format!("`{cmd}` failed and left no crash input"));
    }
    Ok(report)
}

/// The names of the files in `dir` (none when it does not exist).
fn files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default()
}

fn summary(r: &Report) -> String {
    let count = |n: Option<u64>| n.map_or("?".to_string(), |n| n.to_string());
    let (cov, ft) = r.last.map_or((None, None), |(c, f)| (Some(c), Some(f)));
    let mut line = format!(
        "  {:<16} {:>7} {:>12} execs  cov {:>5} ft {:>6}",
        r.target,
        fmt_duration(Duration::from_secs(r.seconds)),
        count(r.execs),
        count(cov),
        count(ft),
    );
    let curve: Vec<String> = r
        .over_time
        .iter()
        .map(|(s, c, f)| format!("{s} s: {c}/{f}"))
        .collect();
    if !curve.is_empty() {
        line.push_str(&format!("  (cov/ft at {})", curve.join(", ")));
    }
    line.push_str(&match r.crashes.len() {
        0 => "  no crash".to_string(),
        _ => format!("  CRASHES: {}", r.crashes.join(", ")),
    });
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_give_coverage_and_the_final_stats_executions() {
        let pulse =
            "#65536\tpulse  cov: 1118 ft: 5249 corp: 780/21Kb lim: 97 exec/s: 10084 rss: 41Mb";
        assert_eq!(coverage(pulse), Some((1118, 5249)));
        assert_eq!(
            coverage("#12\tINITED cov: 4 ft: 5 corp: 1/1b"),
            Some((4, 5))
        );
        assert_eq!(
            coverage("INFO: Loaded 1 modules (5042 inline 8-bit counters)"),
            None
        );
        assert_eq!(
            executions("stat::number_of_executed_units: 1234567"),
            Some(1_234_567)
        );
        assert_eq!(executions("stat::average_exec_per_sec:     10084"), None);
    }

    #[test]
    fn new_inputs_are_not_shown_but_pulses_and_crashes_are() {
        assert!(!shown("#110750\tREDUCE cov: 1118 ft: 5248 corp: 779/21Kb"));
        assert!(!shown("#2\tNEW    cov: 5 ft: 6 corp: 2/2b"));
        assert!(!shown("\tNEW_FUNC[1/10]: 0x55778fa063a1"));
        assert!(shown("#65536\tpulse  cov: 1118 ft: 5249"));
        assert!(shown("==123== ERROR: libFuzzer: deadly signal"));
        assert!(shown(
            "thread '<unnamed>' panicked at crates/plm-core/src/json.rs:1:1:"
        ));
    }

    #[test]
    fn the_summary_says_runs_coverage_over_time_and_crashes() {
        let r = Report {
            target: "json_lines".into(),
            seconds: 75,
            execs: Some(900_000),
            last: Some((1200, 5400)),
            over_time: vec![(10, 1000, 4000), (60, 1180, 5300)],
            crashes: vec!["crash-abc".into()],
        };
        let line = summary(&r);
        assert!(line.contains("json_lines"), "{line}");
        assert!(line.contains("900000 execs"), "{line}");
        assert!(line.contains("cov  1200 ft   5400"), "{line}");
        assert!(line.contains("10 s: 1000/4000, 60 s: 1180/5300"), "{line}");
        assert!(line.contains("CRASHES: crash-abc"), "{line}");
        let quiet = summary(&Report {
            crashes: vec![],
            ..r
        });
        assert!(quiet.ends_with("no crash"), "{quiet}");
    }
}
