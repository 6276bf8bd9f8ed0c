//! `cargo xtask`: the project's task runner (alias in `.cargo/config.toml`).
//!
//! Every subcommand that needs tools installs them first (`setup`), so a
//! fresh machine needs only Rust and `cargo xtask serve` or `cargo xtask test`.

mod bench;
mod circles;
#[cfg(test)]
mod doc_toc;
mod fuzz;
mod serve;
mod setup;
mod test;
mod util;

use std::process::ExitCode;
use util::Result;

const USAGE: &str = "\
usage: cargo xtask <command> [options]

commands:
  setup [--dry-run]          install what is missing: wasm32 target, trunk,
                             wasm-bindgen-cli, Chromium, browser test packages
  serve [--port N] [--release]
                             serve the console at http://127.0.0.1:N/ (default 8080)
  test [--dry-run] [--no-setup]
                             setup, then every test suite; stops at the first failure
  bench                      run the benchmarks; each prints its own figures
  circles                    fail on a module circle in any crate (a -> b -> a)
  fuzz [TARGET] [--time S]   fuzz TARGET (all in turn when none) for S seconds
                             each (default 60); crashes go to fuzz/regressions/
  dist                       build the release console into dist/
  help                       this text
";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match dispatch(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn dispatch(args: &[String]) -> Result {
    let Some((command, rest)) = args.split_first() else {
        eprint!("{USAGE}");
        return Err("no command given".to_string());
    };
    if rest.iter().any(|a| a == "-h" || a == "--help") {
        print!("{USAGE}");
        return Ok(());
    }
    match command.as_str() {
        "setup" => {
            let opts = Options::parse(rest, &["--dry-run"], &[])?;
            setup::run(opts.has("--dry-run"))
        }
        "test" => {
            let opts = Options::parse(rest, &["--dry-run", "--no-setup"], &[])?;
            test::run(opts.has("--dry-run"), opts.has("--no-setup"))
        }
        "serve" => {
            let opts = Options::parse(rest, &["--release"], &["--port"])?;
            let port = match opts.value("--port") {
                None => serve::DEFAULT_PORT,
                Some(p) => p
                    .parse()
                    .ok()
                    .filter(|&port: &u16| port != 0)
                    .ok_or_else(|| format!("--port wants a number from 1 to 65535, not `{p}`"))?,
            };
            serve::serve(port, opts.has("--release"))
        }
        "dist" => {
            Options::parse(rest, &[], &[])?;
            serve::dist()
        }
        "fuzz" => {
            let (target, rest) = match rest.split_first() {
                Some((t, more)) if !t.starts_with('-') => (Some(t.as_str()), more),
                _ => (None, rest),
            };
            let opts = Options::parse(rest, &[], &["--time"])?;
            let seconds =
                match opts.value("--time") {
                    None => fuzz::DEFAULT_SECONDS,
                    Some(s) => s.parse().ok().filter(|&s: &u64| s != 0).ok_or_else(|| {
                        format!("--time wants a whole number of seconds, not `{s}`")
                    })?,
                };
            fuzz::run(target, seconds)
        }
        "bench" => {
            Options::parse(rest, &[], &[])?;
            bench::run()
        }
        "circles" => {
            Options::parse(rest, &[], &[])?;
            circles::run()
        }
        "help" | "-h" | "--help" => {
            print!("{USAGE}");
            Ok(())
        }
        other => {
            eprint!("{USAGE}");
            Err(format!("unknown command `{other}`"))
        }
    }
}

/// The few options the subcommands take: flags and `--name value` /
/// `--name=value` options. Anything else is an error.
struct Options {
    flags: Vec<String>,
    values: Vec<(String, String)>,
}

impl Options {
    fn parse(args: &[String], flags: &[&str], options: &[&str]) -> Result<Self> {
        let mut parsed = Options {
            flags: Vec::new(),
            values: Vec::new(),
        };
        let mut args = args.iter();
        while let Some(arg) = args.next() {
            let (name, inline) = match arg.split_once('=') {
                Some((n, v)) => (n, Some(v.to_string())),
                None => (arg.as_str(), None),
            };
            if flags.contains(&name) && inline.is_none() {
                parsed.flags.push(name.to_string());
            } else if options.contains(&name) {
                let value = match inline {
                    Some(v) => v,
                    None => args
                        .next()
                        .cloned()
                        .ok_or_else(|| format!("{name} needs a value"))?,
                };
                parsed.values.push((name.to_string(), value));
            } else {
                return Err(format!(
                    "unexpected argument `{arg}` (see `cargo xtask help`)"
                ));
            }
        }
        Ok(parsed)
    }

    fn has(&self, flag: &str) -> bool {
        self.flags.iter().any(|f| f == flag)
    }

    fn value(&self, name: &str) -> Option<&str> {
        self.values
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}
