//! Helpers shared by the subcommands: paths, command lines, timed steps.

use std::ffi::OsString;
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Errors are one-line messages for the user; `main` prints them.
pub type Result<T = ()> = std::result::Result<T, String>;

/// The workspace root (the parent of this crate's directory).
pub fn root() -> PathBuf {
    let manifest_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest_dir.parent().unwrap_or(manifest_dir).to_path_buf()
}

/// Where `cargo install` puts binaries: `$CARGO_HOME/bin`, else `~/.cargo/bin`.
fn cargo_bin_dir() -> Option<PathBuf> {
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))?;
    Some(home.join("bin"))
}

/// `PATH` for every child process: the inherited one plus cargo's bin
/// directory, so that a freshly installed trunk is found, and trunk in turn
/// finds the wasm-bindgen we installed instead of trying to download one.
fn child_path() -> Option<OsString> {
    let current = std::env::var_os("PATH").unwrap_or_default();
    let mut dirs: Vec<PathBuf> = std::env::split_paths(&current).collect();
    let bin = cargo_bin_dir()?;
    if !dirs.contains(&bin) {
        dirs.push(bin);
    }
    std::env::join_paths(dirs).ok()
}

/// A command line to run from a directory of the workspace.
#[derive(Clone, Debug)]
pub struct Cmd {
    program: String,
    args: Vec<String>,
    dir: PathBuf,
    envs: Vec<(String, String)>,
}

impl Cmd {
    /// `program` run from the workspace root.
    pub fn new(program: &str) -> Self {
        Cmd {
            program: program.to_string(),
            args: Vec::new(),
            dir: root(),
            envs: Vec::new(),
        }
    }

    /// Adds arguments.
    pub fn args<I, S>(mut self, args: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: AsRef<str>,
    {
        self.args
            .extend(args.into_iter().map(|a| a.as_ref().to_string()));
        self
    }

    /// Runs from `dir` instead of the workspace root.
    pub fn dir(mut self, dir: impl Into<PathBuf>) -> Self {
        self.dir = dir.into();
        self
    }

    /// Sets an environment variable (not shown when printed).
    pub fn env(mut self, key: &str, value: &str) -> Self {
        self.envs.push((key.to_string(), value.to_string()));
        self
    }

    /// The command, ready to spawn (for output read as it comes).
    pub fn command(&self) -> Command {
        // The `cargo` that runs us (`$CARGO`) also runs our cargo commands,
        // so that a toolchain override applies to both.
        let program = match (self.program.as_str(), std::env::var_os("CARGO")) {
            ("cargo", Some(cargo)) => cargo,
            _ => OsString::from(&self.program),
        };
        let mut command = Command::new(program);
        command.args(&self.args).current_dir(&self.dir);
        if let Some(path) = child_path() {
            command.env("PATH", path);
        }
        for (key, value) in &self.envs {
            command.env(key, value);
        }
        command
    }

    /// Runs with the terminal attached; an error unless it exits with 0.
    pub fn run(&self) -> Result {
        let status = self
            .command()
            .status()
            .map_err(|e| format!("could not start `{self}`: {e}"))?;
        if status.success() {
            Ok(())
        } else {
            let code = status
                .code()
                .map_or("a signal".to_string(), |c| c.to_string());
            Err(format!("`{self}` failed (exit status {code})"))
        }
    }

    /// Its standard output, or `None` when it cannot start or fails.
    pub fn output(&self) -> Option<String> {
        let output = self.command().stderr(Stdio::null()).output().ok()?;
        output
            .status
            .success()
            .then(|| String::from_utf8_lossy(&output.stdout).into_owned())
    }
}

/// Shell-like, ready to paste at the workspace root.
impl fmt::Display for Cmd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let words: Vec<String> = std::iter::once(&self.program)
            .chain(&self.args)
            .map(|w| {
                if w.is_empty() || w.contains(char::is_whitespace) {
                    format!("'{w}'")
                } else {
                    w.clone()
                }
            })
            .collect();
        let line = words.join(" ");
        match self.dir.strip_prefix(root()) {
            Ok(rel) if rel.as_os_str().is_empty() => f.write_str(&line),
            Ok(rel) => write!(f, "(cd {} && {line})", rel.display()),
            Err(_) => write!(f, "(cd {} && {line})", self.dir.display()),
        }
    }
}

/// One timed step of `cargo xtask test` or `cargo xtask bench`.
pub struct Step {
    /// Short name for headers and the summary.
    pub name: String,
    /// The command a user runs to repeat just this step.
    pub rerun: String,
    action: Box<dyn Fn() -> Result>,
}

impl Step {
    /// A step that runs one command line.
    pub fn cmd(name: &str, cmd: Cmd) -> Self {
        let rerun = cmd.to_string();
        Step::new(name, &rerun, move || cmd.run())
    }

    /// A step that runs some xtask code; `rerun` says how to repeat it.
    pub fn new(name: &str, rerun: &str, action: impl Fn() -> Result + 'static) -> Self {
        Step {
            name: name.to_string(),
            rerun: rerun.to_string(),
            action: Box::new(action),
        }
    }
}

/// Runs `steps` in order, stopping at the first failure, then prints a
/// summary table. `task` names the subcommand in messages.
pub fn run_steps(task: &str, steps: &[Step], dry_run: bool) -> Result {
    let mut results: Vec<(&Step, &str, Duration)> = Vec::new();
    let mut failure = None;
    for (i, step) in steps.iter().enumerate() {
        println!();
        println!("==> {task} [{}/{}]: {}", i + 1, steps.len(), step.name);
        println!("    $ {}", step.rerun);
        if dry_run {
            results.push((step, "dry run", Duration::ZERO));
            continue;
        }
        let start = Instant::now();
        let outcome = (step.action)();
        let took = start.elapsed();
        match outcome {
            Ok(()) => results.push((step, "ok", took)),
            Err(e) => {
                results.push((step, "FAILED", took));
                failure = Some((step, e));
                break;
            }
        }
    }
    for step in &steps[results.len()..] {
        results.push((step, "not run", Duration::ZERO));
    }

    let width = steps.iter().map(|s| s.name.len()).max().unwrap_or(0).max(4);
    println!();
    println!("{task}: summary");
    println!("    {:<width$}  {:<8}  time", "step", "result");
    let mut total = Duration::ZERO;
    for (step, result, took) in &results {
        total += *took;
        println!(
            "    {:<width$}  {result:<8}  {}",
            step.name,
            fmt_duration(*took)
        );
    }
    println!(
        "    {:<width$}  {:<8}  {}",
        "total",
        "",
        fmt_duration(total)
    );

    match failure {
        None if dry_run => {
            println!("{task}: dry run, {} steps listed, none run", steps.len());
            Ok(())
        }
        None => {
            println!("{task}: all {} steps passed", steps.len());
            Ok(())
        }
        Some((step, e)) => Err(format!(
            "{task} failed at step `{}`: {e}\nre-run that step with:\n    {}",
            step.name, step.rerun
        )),
    }
}

/// `0.4s`, `12.0s`, `3m07s`.
pub fn fmt_duration(d: Duration) -> String {
    let secs = d.as_secs_f64();
    if secs < 60.0 {
        format!("{secs:.1}s")
    } else {
        let whole = d.as_secs();
        format!("{}m{:02}s", whole / 60, whole % 60)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_naturally() {
        assert_eq!(fmt_duration(Duration::from_millis(420)), "0.4s");
        assert_eq!(fmt_duration(Duration::from_secs(187)), "3m07s");
    }

    #[test]
    fn commands_print_ready_to_paste_from_the_root() {
        let cmd = Cmd::new("cargo").args(["fmt", "--all", "--", "--check"]);
        assert_eq!(cmd.to_string(), "cargo fmt --all -- --check");
        let npm = Cmd::new("npm").args(["test"]).dir(root().join("tests/e2e"));
        assert_eq!(npm.to_string(), "(cd tests/e2e && npm test)");
    }

    #[test]
    fn steps_stop_at_the_first_failure() {
        use std::cell::Cell;
        use std::rc::Rc;
        let ran = Rc::new(Cell::new(0));
        let (a, b) = (ran.clone(), ran.clone());
        let steps = [
            Step::new("one", "x one", move || {
                a.set(a.get() + 1);
                Err("broken".to_string())
            }),
            Step::new("two", "x two", move || {
                b.set(b.get() + 1);
                Ok(())
            }),
        ];
        let err = run_steps("t", &steps, false).unwrap_err();
        assert_eq!(ran.get(), 1, "the step after a failure must not run");
        assert!(err.contains("`one`") && err.contains("x one"), "{err}");
    }
}
