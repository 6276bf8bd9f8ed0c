//! `cargo xtask setup`: installs what the other subcommands need.
//!
//! Idempotent: every step first checks what is there and says so in one
//! line, and installs only what is missing or of the wrong version.

use crate::util::{root, Cmd, Result};
use std::fs;
use std::path::Path;
use std::time::SystemTime;

/// Trunk 0.22 needs a newer rustc than the workspace's 1.95.
pub const TRUNK_VERSION: &str = "0.21.14";
const WASM_TARGET: &str = "wasm32-unknown-unknown";
/// Debian's Chromium, which every browser test drives.
pub const CHROMIUM: &str = "/usr/bin/chromium";
/// Debian's ChromeDriver, through which wasm-bindgen-test-runner drives it.
pub const CHROMEDRIVER: &str = "/usr/bin/chromedriver";

/// Runs every setup step; with `dry_run`, only says what it would do.
pub fn run(dry_run: bool) -> Result {
    let root = root();
    wasm_target(dry_run)?;
    trunk(dry_run)?;
    wasm_bindgen_cli(&root, dry_run)?;
    chromium(dry_run)?;
    browser_test_packages(&root, dry_run)
}

/// Prints the decision for `what` and, unless `dry_run`, runs `cmd`.
fn install(what: &str, why: &str, cmd: &Cmd, dry_run: bool) -> Result {
    if dry_run {
        println!("setup: {what} ... {why}, would run: {cmd}");
        return Ok(());
    }
    println!("setup: {what} ... {why}, installing: {cmd}");
    cmd.run()
}

fn already(what: &str) -> Result {
    println!("setup: {what} ... already installed");
    Ok(())
}

fn wasm_target(dry_run: bool) -> Result {
    let what = format!("{WASM_TARGET} target");
    let installed = Cmd::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .ok_or("`rustup target list --installed` failed; is rustup installed?")?;
    if installed.lines().any(|l| l.trim() == WASM_TARGET) {
        return already(&what);
    }
    let cmd = Cmd::new("rustup").args(["target", "add", WASM_TARGET]);
    install(&what, "missing", &cmd, dry_run)
}

/// The version a tool reports as `<name> <version>` on `--version`.
fn tool_version(program: &str) -> Option<String> {
    let out = Cmd::new(program).args(["--version"]).output()?;
    out.split_whitespace().nth(1).map(str::to_string)
}

/// Installs `program` at exactly `version` with `cmd`, unless it is there.
fn exact_tool(what: &str, program: &str, version: &str, cmd: &Cmd, dry_run: bool) -> Result {
    let why = match tool_version(program) {
        Some(found) if found == version => return already(what),
        Some(found) => format!("found {found}"),
        None => "not found".to_string(),
    };
    install(what, &why, cmd, dry_run)?;
    if dry_run {
        return Ok(());
    }
    // A different version earlier on PATH would shadow the one just built.
    match tool_version(program) {
        Some(found) if found == version => Ok(()),
        found => Err(format!(
            "installed {what}, but `{program} --version` reports {}; \
             put ~/.cargo/bin first on PATH",
            found.as_deref().unwrap_or("nothing")
        )),
    }
}

fn trunk(dry_run: bool) -> Result {
    let cmd = Cmd::new("cargo").args(["install", "trunk", "--version", TRUNK_VERSION, "--locked"]);
    let what = format!("trunk {TRUNK_VERSION}");
    exact_tool(&what, "trunk", TRUNK_VERSION, &cmd, dry_run)
}

fn wasm_bindgen_cli(root: &Path, dry_run: bool) -> Result {
    let version = wasm_bindgen_version(root)?;
    // Not `--locked`: its lock file pins a dependency the registry no
    // longer has.
    let cmd = Cmd::new("cargo").args(["install", "wasm-bindgen-cli", "--version", &version]);
    let what = format!("wasm-bindgen-cli {version}");
    exact_tool(&what, "wasm-bindgen", &version, &cmd, dry_run)
}

/// The wasm-bindgen library version the workspace builds with. Trunk refuses
/// a CLI of any other version, so the CLI must match it exactly.
fn wasm_bindgen_version(root: &Path) -> Result<String> {
    let lock = fs::read_to_string(root.join("Cargo.lock")).unwrap_or_default();
    if let Some(v) = locked_version(&lock, "wasm-bindgen") {
        return Ok(v);
    }
    let manifest = fs::read_to_string(root.join("Cargo.toml"))
        .map_err(|e| format!("cannot read the workspace Cargo.toml: {e}"))?;
    pinned_version(&manifest, "wasm-bindgen").ok_or_else(|| {
        "cannot tell which wasm-bindgen-cli to install: Cargo.lock has no wasm-bindgen \
         and the workspace Cargo.toml does not pin `wasm-bindgen = \"=x.y.z\"`"
            .to_string()
    })
}

/// The version of `package` in a Cargo.lock (the first one, if several).
fn locked_version(lock: &str, package: &str) -> Option<String> {
    let name_line = format!("name = \"{package}\"");
    let mut lines = lock.lines().map(str::trim);
    lines.find(|l| *l == name_line)?;
    let version = lines.next()?.strip_prefix("version")?.trim_start();
    quoted(version.strip_prefix('=')?)
}

/// The exact version pinned as `package = "=x.y.z"` (or in a table with
/// `version = "=x.y.z"`) in a Cargo.toml; `None` unless it is exact.
fn pinned_version(manifest: &str, package: &str) -> Option<String> {
    manifest.lines().find_map(|line| {
        let rest = line.trim().strip_prefix(package)?.trim_start();
        let value = rest.strip_prefix('=')?.trim_start();
        let value = match value.strip_prefix('{') {
            Some(table) => table
                .split_once("version")?
                .1
                .trim_start()
                .strip_prefix('=')?,
            None => value,
        };
        let version = quoted(value)?;
        let version = version.strip_prefix('=').unwrap_or(&version);
        let exact = version.split('.').count() == 3
            && version
                .split('.')
                .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
        exact.then(|| version.to_string())
    })
}

/// The content of the first `"..."` in `s`.
fn quoted(s: &str) -> Option<String> {
    let (_, rest) = s.split_once('"')?;
    let (inner, _) = rest.split_once('"')?;
    Some(inner.to_string())
}

fn chromium(dry_run: bool) -> Result {
    let what = "chromium and chromium-driver (browser tests)";
    let missing: Vec<&str> = [("chromium", CHROMIUM), ("chromium-driver", CHROMEDRIVER)]
        .into_iter()
        .filter(|(_, path)| !Path::new(path).exists())
        .map(|(package, _)| package)
        .collect();
    if missing.is_empty() {
        return already(what);
    }
    let by_hand = format!("sudo apt-get install -y {}", missing.join(" "));
    if !is_root() {
        println!("setup: {what} ... skipped: not root, so cannot apt-get; to install: {by_hand}");
        return Ok(());
    }
    if Cmd::new("apt-get").args(["--version"]).output().is_none() {
        println!("setup: {what} ... skipped: no apt-get (not Debian?); install Chromium and chromedriver by hand");
        return Ok(());
    }
    let cmd = Cmd::new("apt-get")
        .args(["install", "-y"])
        .args(&missing)
        .env("DEBIAN_FRONTEND", "noninteractive");
    if install(what, "missing", &cmd, dry_run).is_ok() {
        return Ok(());
    }
    // A fresh machine may have no package lists yet: refresh them, retry once.
    println!("setup: {what} ... retrying after apt-get update");
    Cmd::new("apt-get").args(["update"]).run()?;
    cmd.run()
}

fn is_root() -> bool {
    Cmd::new("id")
        .args(["-u"])
        .output()
        .is_some_and(|uid| uid.trim() == "0")
}

fn browser_test_packages(root: &Path, dry_run: bool) -> Result {
    let e2e = root.join("tests/e2e");
    let package_json = e2e.join("package.json");
    if !package_json.exists() {
        println!("setup: no browser test packages yet (tests/e2e/package.json absent)");
        return Ok(());
    }
    let what = "browser test packages (tests/e2e)";
    let lock = e2e.join("package-lock.json");
    // npm writes node_modules/.package-lock.json on every install.
    let installed = e2e.join("node_modules/.package-lock.json");
    if is_newer(&installed, &[&package_json, &lock]) {
        return already(what);
    }
    let verb = if lock.exists() { "ci" } else { "install" };
    // Playwright drives Debian's Chromium; it must not download its own.
    let cmd = Cmd::new("npm")
        .args([verb])
        .dir(&e2e)
        .env("PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD", "1");
    let why = if installed.exists() {
        "out of date"
    } else {
        "missing"
    };
    install(what, why, &cmd, dry_run)
}

/// Whether `target` exists and is no older than each of the `inputs` that exist.
fn is_newer(target: &Path, inputs: &[&Path]) -> bool {
    let mtime = |p: &Path| -> Option<SystemTime> { fs::metadata(p).ok()?.modified().ok() };
    let Some(target_time) = mtime(target) else {
        return false;
    };
    inputs
        .iter()
        .filter_map(|p| mtime(p))
        .all(|input_time| input_time <= target_time)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOCK: &str = r#"
[[package]]
name = "wasm-bindgen-backend"
version = "0.2.99"

[[package]]
name = "wasm-bindgen"
version = "0.2.130"
source = "registry+https://github.com/rust-lang/crates.io-index"
"#;

    #[test]
    fn reads_the_exact_package_from_cargo_lock() {
        assert_eq!(
            locked_version(LOCK, "wasm-bindgen").as_deref(),
            Some("0.2.130")
        );
        assert_eq!(locked_version(LOCK, "wasm-bindgen-macro"), None);
        assert_eq!(locked_version("", "wasm-bindgen"), None);
    }

    #[test]
    fn reads_an_exact_pin_from_the_workspace_manifest() {
        let manifest = "[workspace.dependencies]\n\
                        wasm-bindgen-futures = \"0.4.1\"\n\
                        wasm-bindgen = \"=0.2.130\"\n";
        assert_eq!(
            pinned_version(manifest, "wasm-bindgen").as_deref(),
            Some("0.2.130")
        );
        let table = "wasm-bindgen = { version = \"=0.2.131\", default-features = false }";
        assert_eq!(
            pinned_version(table, "wasm-bindgen").as_deref(),
            Some("0.2.131")
        );
        assert_eq!(
            pinned_version("wasm-bindgen = \"0.2\"", "wasm-bindgen"),
            None
        );
        assert_eq!(
            pinned_version("wasm-bindgen.workspace = true", "wasm-bindgen"),
            None
        );
    }

    #[test]
    fn the_real_workspace_names_a_wasm_bindgen_version() {
        let version = wasm_bindgen_version(&root()).unwrap();
        assert_eq!(version.split('.').count(), 3, "{version}");
    }

    #[test]
    fn a_missing_target_is_never_up_to_date() {
        let dir = std::env::temp_dir();
        assert!(!is_newer(&dir.join("xtask-no-such-file"), &[]));
        assert!(is_newer(&dir, &[&dir.join("xtask-no-such-input")]));
    }
}
