//! `plm sim --loss P` and `--no-capture` on a street (the other lines:
//! `sim_rfc2217.rs`): what the server says of its line, and a lossy line
//! that a board's requests and answers do not cross, beside the same
//! street without loss where they do.

mod common;

use common::Server;
use std::process::{Command, Output};

/// `plm board status` of lamp 1 through `server`.
fn status(server: &Server) -> Output {
    Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["board", "--port", &format!("rfc2217://{}", server.addr)])
        .args(["status", "0080e1000001"])
        .output()
        .expect("plm runs")
}

fn street(args: &[&str]) -> Server {
    let base = ["--board", "--street", "1", "--listen", "127.0.0.1:0"];
    Server::start(&[&base[..], args].concat())
}

#[test]
fn a_street_loses_frames_with_loss() {
    let clean = street(&[]);
    let mut lossy = street(&["--loss", "0.99", "--no-capture"]);
    let said = lossy.lines_up_to("powers on");
    assert!(
        said.iter()
            .any(|l| l.contains("probability 0.99") && l.contains("--loss")),
        "{said:?}"
    );
    assert!(said.iter().any(|l| l.contains("--no-capture")), "{said:?}");
    // Side by side: the lossy street takes its attempts' timeouts.
    let lossy_status = std::thread::spawn(move || (status(&lossy), lossy));
    let out = status(&clean);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // An attempt gets through when the request and its answer both
    // cross, 1 time in 10 000: of its 3 attempts, none does.
    let (out, _lossy) = lossy_status.join().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("did not answer"), "{err}");
}

#[test]
fn a_plain_street_says_nothing_of_its_line() {
    let mut server = street(&[]);
    let said = server.lines_up_to("powers on");
    assert!(
        !said
            .iter()
            .any(|l| l.contains("--loss") || l.contains("--no-capture")),
        "{said:?}"
    );
}
