//! `plm board discover` finds a whole street at the size of a real one
//! (issue 26, "Must show"): the real binary, as a child process, against
//! the real `plm sim --board --street N` over RFC 2217. Simulated time
//! runs at wall-clock speed, so the line time of a discovery is its wall
//! time; both are printed (`cargo test -- --nocapture`).
//!
//! Every lamp of the street must be printed once, with its address
//! (`plm_sim::board::street_address`), and no other board.

mod common;

use common::Server;
use plm_sim::board::street_address;
use serde_json::Value;
use std::collections::BTreeSet;
use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What one `plm board` run printed, and how it ended.
struct Done {
    code: Option<i32>,
    out: String,
    err: String,
    wall: Duration,
}

/// `plm <args>` to its end, killed (and the test failed) after `limit`:
/// a guard against a run that never ends, not a measure.
fn plm(args: &[String], limit: Duration) -> Done {
    let started = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("plm runs");
    let read = |mut from: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            from.read_to_string(&mut text).expect("UTF-8 output");
            text
        })
    };
    let out = read(Box::new(child.stdout.take().unwrap()));
    let err = read(Box::new(child.stderr.take().unwrap()));
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "plm {args:?} still running after {limit:?}; stderr: {}",
                err.join().unwrap()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Done {
        code,
        out: out.join().unwrap(),
        err: err.join().unwrap(),
        wall: started.elapsed(),
    }
}

/// `plm sim --board --street <lamps>`, then `plm board discover --guess
/// <lamps> --json` against it: every lamp found, each printed once.
fn discover_whole_street(lamps: usize, limit: Duration) {
    let n = lamps.to_string();
    let mut server = Server::start(&["--board", "--street", &n, "--listen", "127.0.0.1:0"]);
    assert!(
        server.banner.contains(&format!("{lamps} lamps")),
        "{}",
        server.banner
    );
    let args: Vec<String> = [
        "board",
        "--port",
        &format!("rfc2217://{}", server.addr),
        "--json",
        "discover",
        "--guess",
        &n,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let done = plm(&args, limit);
    assert_eq!(done.code, Some(0), "exit code; stderr: {}", done.err);

    let printed: Vec<String> = done
        .out
        .lines()
        .map(|l| {
            let v: Value =
                serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON ({e}): {l}"));
            assert_eq!(v["firmware"], "1.4", "{v}");
            v["address"]
                .as_str()
                .unwrap_or_else(|| panic!("no address in {v}"))
                .to_string()
        })
        .collect();
    let found: BTreeSet<String> = printed.iter().cloned().collect();
    assert_eq!(found.len(), printed.len(), "a board printed twice");
    let street: BTreeSet<String> = (1..=lamps).map(|i| street_address(i).to_string()).collect();
    let missed: Vec<&String> = street.difference(&found).collect();
    let strangers: Vec<&String> = found.difference(&street).collect();
    assert!(
        missed.is_empty() && strangers.is_empty(),
        "{} of {lamps} lamps found; missed {missed:?}; not of the street {strangers:?}; \
         stderr: {}",
        found.len(),
        done.err
    );
    let summary = format!("{lamps} boards found in");
    let report = done
        .err
        .lines()
        .find(|l| l.contains(&summary))
        .unwrap_or_else(|| panic!("no {summary:?} in stderr: {}", done.err));
    println!(
        "street of {lamps}: `plm board discover` took {:.1} s wall (the line's time: the \
         simulation runs in real time); it says: {report}",
        done.wall.as_secs_f64()
    );
    server.line_containing("disconnected");
    server.interrupt();
}

#[test]
fn a_street_of_100_lamps_is_discovered_whole() {
    discover_whole_street(100, Duration::from_secs(120));
}

#[test]
fn a_street_of_500_lamps_is_discovered_whole() {
    discover_whole_street(500, Duration::from_secs(300));
}
