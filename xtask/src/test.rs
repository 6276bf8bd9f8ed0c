//! `cargo xtask test`: setup, then every test suite, stopping at the first
//! failure. `.ci/run` runs exactly this.

use crate::util::{root, run_steps, Cmd, Result, Step};
use crate::{circles, serve, setup};

/// Runs every suite; with `dry_run`, lists them (and the setup plan) only;
/// with `no_setup`, trusts that the tools are already there.
pub fn run(dry_run: bool, no_setup: bool) -> Result {
    let mut steps = Vec::new();
    if !no_setup {
        steps.push(Step::new("setup", "cargo xtask setup", || {
            setup::run(false)
        }));
    }
    if dry_run && !no_setup {
        // Show the setup plan now; the step list then only names it.
        setup::run(true)?;
    }
    steps.extend(suites());
    run_steps("test", &steps, dry_run)
}

fn cargo(args: &[&str]) -> Cmd {
    Cmd::new("cargo").args(args)
}

/// The suites, in order from cheapest to dearest; later ones are added as
/// their crates and directories appear.
fn suites() -> Vec<Step> {
    let root = root();
    let mut steps = vec![
        Step::new("module circles", "cargo xtask circles", circles::run),
        Step::cmd("format", cargo(&["fmt", "--all", "--", "--check"])),
        Step::cmd(
            "clippy",
            cargo(&[
                "clippy",
                "--workspace",
                "--all-targets",
                "--",
                "-D",
                "warnings",
            ]),
        ),
        Step::cmd("tests", cargo(&["test", "--workspace", "--all-targets"])),
        Step::cmd("doc tests", cargo(&["test", "--workspace", "--doc"])),
        Step::cmd(
            "plm-core and plm-sim on wasm32",
            cargo(&[
                "build",
                "-p",
                "plm-core",
                "-p",
                "plm-sim",
                "--target",
                "wasm32-unknown-unknown",
            ]),
        ),
    ];

    if root.join("crates/plm-console").exists() {
        // The console's browser-only code (WebSerial, its tests) exists on
        // wasm32 alone, so it is linted there too.
        steps.push(Step::cmd(
            "plm-console on wasm32 (clippy)",
            cargo(&[
                "clippy",
                "-p",
                "plm-console",
                "--target",
                "wasm32-unknown-unknown",
                "--all-targets",
                "--",
                "-D",
                "warnings",
            ]),
        ));
        // wasm-bindgen-test suites of both transports, in headless Chromium
        // through ChromeDriver (both from `cargo xtask setup`); the runner
        // is `.cargo/config.toml`'s, from the pinned wasm-bindgen-cli.
        let console = root.join("crates/plm-console");
        let browser = cargo(&[
            "test",
            "-p",
            "plm-console",
            "--target",
            "wasm32-unknown-unknown",
            "--tests",
        ])
        .env("CHROMEDRIVER", setup::CHROMEDRIVER)
        .env(
            "WASM_BINDGEN_TEST_WEBDRIVER_JSON",
            &console.join("webdriver.json").to_string_lossy(),
        )
        .env("WASM_BINDGEN_TEST_TIMEOUT", "180");
        steps.push(Step::cmd("console transports in Chromium", browser));
    } else {
        println!("test: no console wasm build yet (crates/plm-console absent)");
    }

    if root.join("tests/e2e/package.json").exists() {
        steps.push(Step::new("dist", "cargo xtask dist", serve::build_dist));
        let e2e = Cmd::new("npm").args(["test"]).dir(root.join("tests/e2e"));
        steps.push(Step::cmd("browser end-to-end", e2e));
    } else {
        println!("test: no browser end-to-end tests yet (tests/e2e/package.json absent)");
    }
    steps
}
