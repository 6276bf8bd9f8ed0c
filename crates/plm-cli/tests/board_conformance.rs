//! `plm board conformance` end to end: the real binary against the real
//! `plm sim --board`, whose lamps keep every rule of the board protocol
//! (docs/board-protocol.md), then against streets whose lamps each break
//! one rule (`plm sim --break RULE`): that rule, and only that one, is
//! reported failed, in words, with exit code 1.

mod common;

use common::Server;
use plm_sim::board::street_address;
use serde_json::Value;
use std::process::{Command, Output};

fn street(breach: Option<&str>) -> Server {
    let mut args = vec!["--board", "--street", "1", "--listen", "127.0.0.1:0"];
    if let Some(b) = breach {
        args.extend(["--break", b]);
    }
    Server::start(&args)
}

fn conformance(server: &Server, json: bool) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_plm"));
    c.args(["board", "--port", &format!("rfc2217://{}", server.addr)]);
    if json {
        c.arg("--json");
    }
    c.args(["conformance", &street_address(1).to_string()])
        .output()
        .expect("plm runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Every rule passes against a simulated lamp, each on a line of its own
/// in words; exit 0.
#[test]
fn a_simulated_lamp_keeps_every_rule() {
    let server = street(None);
    let out = conformance(&server, false);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 9, "{stdout}");
    assert!(lines.iter().all(|l| l.starts_with("pass  ")), "{stdout}");
    for words in [
        "firmware 1.4, stack 2.0",
        "answered again in session",
        "IDLE, reason ABORTED",
        "it still runs 1.4",
    ] {
        assert!(stdout.contains(words), "no {words:?} in\n{stdout}");
    }
    assert!(stderr.contains("9 of 9 rules passed"), "{stderr}");
    server.interrupt();
}

/// For each rule, a street whose lamp breaks it: that rule fails with
/// words, no other rule fails, exit 1. The streets run side by side.
#[test]
fn a_lamp_that_breaks_a_rule_fails_that_rule_alone() {
    let rules: Vec<&str> = plm_sim::breach::BREACHES.iter().map(|b| b.0).collect();
    let runs: Vec<_> = rules
        .iter()
        .map(|&rule| {
            std::thread::spawn(move || {
                let server = street(Some(rule));
                assert!(server.banner.contains("rfc2217://"), "{}", server.banner);
                let out = conformance(&server, true);
                server.interrupt();
                (rule, out)
            })
        })
        .collect();
    for run in runs {
        let (rule, out) = run.join().unwrap();
        let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
        assert_eq!(out.status.code(), Some(1), "{rule}: {stdout}\n{stderr}");
        let verdicts: Vec<Value> = stdout
            .lines()
            .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("not JSON ({e}): {l}")))
            .collect();
        assert_eq!(verdicts.len(), 9, "{rule}: {stdout}");
        let failed: Vec<&str> = verdicts
            .iter()
            .filter(|v| v["result"] == "failed")
            .map(|v| v["rule"].as_str().unwrap())
            .collect();
        assert_eq!(failed, [rule], "{rule}: {stdout}");
        let broken = verdicts.iter().find(|v| v["rule"] == rule).unwrap();
        let words = broken["words"].as_str().unwrap();
        assert!(words.len() > 20, "{rule}: no words: {broken}");
        assert!(
            verdicts.iter().all(|v| v["result"] == "passed"
                || v["rule"] == rule
                || v["result"] == "not checked"),
            "{rule}: {stdout}"
        );
        assert!(stderr.contains("1 failed"), "{rule}: {stderr}");
    }
}

/// An unknown rule to break is refused in words, and so is `--break`
/// without a street's lamps to break it.
#[test]
fn an_unknown_rule_to_break_is_refused() {
    let refused = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_plm"))
            .arg("sim")
            .args(args)
            .args(["--listen", "127.0.0.1:0"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        text(&out.stderr)
    };
    let err = refused(&["--board", "--break", "everything"]);
    assert!(err.contains("not a rule to break"), "{err}");
    assert!(err.contains("discovery-ack"), "{err}");
    let err = refused(&["--break", "status"]);
    assert!(err.contains("need a street of lamps"), "{err}");
    let err = refused(&["--chip", "st7570", "--break", "status"]);
    assert!(
        err.contains("--break cannot be used with --chip st7570"),
        "{err}"
    );
}
