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

/// docs/cli.md's `plm sim` section and `plm sim --help` name the same
/// options, each with the same range or values where the help gives one.
#[test]
fn docs_and_help_name_the_same_options() {
    let out = Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["sim", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    let docs =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/cli.md")).unwrap();
    let section = docs
        .split("\n# `plm sim`")
        .nth(1)
        .expect("docs/cli.md has a `plm sim` section")
        .split("\n# ")
        .next()
        .unwrap();
    // An option of the help is a line starting with `--name` (after
    // `-h, ` for help itself).
    let in_help: Vec<&str> = help
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("--"))
        .filter_map(|l| l.split([' ', '<']).next())
        .filter(|name| *name != "help")
        .collect();
    assert!(in_help.len() >= 11, "{in_help:?}");
    // An option of the docs is a list item starting with `` `--name ``.
    let in_docs: Vec<&str> = section
        .lines()
        .filter_map(|l| l.strip_prefix("- `--"))
        .filter_map(|l| l.split([' ', '`']).next())
        .collect();
    let mut a = in_help.clone();
    let mut b = in_docs.clone();
    a.sort();
    b.sort();
    assert_eq!(a, b, "options of plm sim --help, then of docs/cli.md");
    for (name, words) in [
        ("serve", "1-64"),
        ("nodes", "1-64"),
        ("street", "1-500"),
        ("lamp-failures", "0-60"),
        ("peers", "follow|factory"),
        ("listen", "127.0.0.1:7580"),
        ("loss", "1 excluded"),
    ] {
        let item = section
            .split(&format!("\n- `--{name}"))
            .nth(1)
            .unwrap_or_else(|| panic!("--{name} in the docs"));
        let item = item.split("\n- ").next().unwrap();
        assert!(item.contains(words), "docs, --{name}: {item}");
        let entry = help
            .split("\n      --")
            .find(|e| {
                e.strip_prefix(name)
                    .is_some_and(|r| r.starts_with([' ', '\n']))
            })
            .unwrap_or_else(|| panic!("--{name} in the help"));
        for word in words.split('|') {
            assert!(entry.contains(word), "help, --{name}: {entry}");
        }
    }
}

#[test]
fn street_and_echo_flags_are_refused_with_chip_st7570() {
    for flag in [
        &["--street", "3"][..],
        &["--board"],
        &["--peers", "factory"],
        &["--cold-lamps"],
        &["--uniform-lamps"],
        &["--lamp-failures", "1"],
    ] {
        let args = [&["--chip", "st7570"][..], flag].concat();
        let err = refused(&args);
        assert!(
            err.contains(flag[0]) && err.contains("cannot be used with --chip st7570"),
            "{args:?}: {err}"
        );
    }
    let err = refused(&["--chip", "st7570", "--serve", "3", "--nodes", "2"]);
    assert!(
        err.contains("--nodes 2") && err.contains("--serve 3"),
        "{err}"
    );
}

#[test]
fn alarms_need_st7570_servers() {
    let err = refused(&["--alarms", "5"]);
    assert!(err.contains("--alarms needs --chip st7570"), "{err}");
    let err = refused(&["--chip", "st7570", "--nodes", "1", "--alarms", "5"]);
    assert!(err.contains("no Server raises one"), "{err}");
    let err = refused(&["--chip", "st7570", "--alarms", "0"]);
    assert!(err.contains("--alarms"), "{err}");
}

#[test]
fn factory_servers_need_st7570_servers() {
    let err = refused(&["--factory-servers"]);
    assert!(
        err.contains("--factory-servers needs --chip st7570"),
        "{err}"
    );
    let err = refused(&["--chip", "st7570", "--nodes", "1", "--factory-servers"]);
    assert!(err.contains("there is no Server"), "{err}");
}

#[test]
fn a_loss_that_is_not_a_probability_below_1_is_refused_in_words() {
    for p in ["1", "1.5", "-0.1", "NaN", "five percent"] {
        let err = refused(&["--board", "--loss", p]);
        assert!(
            err.contains(&format!("'{p}' is not a loss probability")),
            "--loss {p}: {err}"
        );
    }
}

/// The help and the docs give the line model's capture margin.
#[test]
fn no_capture_names_the_models_margin() {
    let margin = format!("{} dB or more", plm_sim::line::CAPTURE_DB);
    let out = Command::new(env!("CARGO_BIN_EXE_plm"))
        .args(["sim", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    let docs =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/cli.md")).unwrap();
    for (what, text) in [("help", help), ("docs/cli.md", docs)] {
        let entry = text.rsplit("--no-capture").next().unwrap_or("");
        assert!(
            entry.split("--seed").next().unwrap().contains(&margin),
            "{what}: --no-capture should say {margin}"
        );
    }
}

#[test]
fn no_capture_is_refused_with_chip_st7570() {
    let err = refused(&["--chip", "st7570", "--no-capture"]);
    assert!(
        err.contains("--no-capture cannot be used with --chip st7570"),
        "{err}"
    );
}
