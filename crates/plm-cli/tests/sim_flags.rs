//! `plm sim` refuses flags that would have no effect with the others
//! given (issue 15: `--peers` was silently ignored with `--street`), in
//! words that name them, rather than serve something the user did not
//! ask for.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Runs `plm sim <args>`, which must exit at once with code 2; returns
/// what it said on stderr. A server that starts instead is stopped and
/// the test fails.
fn refused(args: &[&str]) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plm"))
        .arg("sim")
        .args(args)
        .args(["--listen", "127.0.0.1:0"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("plm runs");
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("plm sim {args:?} serves instead of refusing");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(status.code(), Some(2), "plm sim {args:?}: {err}");
    err
}

#[test]
fn line_of_modems_flags_are_refused_with_a_street() {
    for world in [
        &["--street", "3"][..],
        &["--board"],
        &["--board", "--street", "3"],
    ] {
        for flag in [
            &["--peers", "factory"][..],
            &["--serve", "2"],
            &["--nodes", "3"],
        ] {
            let args = [world, flag].concat();
            let err = refused(&args);
            assert!(
                err.contains(flag[0]) && err.contains("cannot be used with"),
                "{args:?}: {err}"
            );
        }
    }
}

#[test]
fn peers_without_peers_are_refused() {
    // Every node served: nobody echoes, so their MIB means nothing.
    for args in [
        &["--peers", "factory"][..],
        &["--serve", "2", "--peers", "follow"],
        &["--serve", "3", "--nodes", "3", "--peers", "factory"],
    ] {
        let err = refused(args);
        assert!(
            err.contains("--peers") && err.contains("--nodes"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn fewer_nodes_than_served_are_refused() {
    let err = refused(&["--serve", "3", "--nodes", "2"]);
    assert!(
        err.contains("--nodes 2") && err.contains("--serve 3"),
        "{err}"
    );
}
