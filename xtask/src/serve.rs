//! `cargo xtask serve` and `cargo xtask dist`: the console through Trunk.

use crate::setup;
use crate::util::{root, Cmd, Result};

/// Trunk's own default port.
pub const DEFAULT_PORT: u16 = 8080;

/// Serves the console with live reload on 127.0.0.1 (WebSerial needs a
/// secure context; 127.0.0.1 counts as one, a LAN address does not).
pub fn serve(port: u16, release: bool) -> Result {
    require_console()?;
    setup::run(false)?;
    let mut cmd = trunk().args([
        "serve",
        "--address",
        "127.0.0.1",
        "--port",
        &port.to_string(),
    ]);
    if release {
        cmd = cmd.args(["--release"]);
    }
    println!();
    println!("serve: the console will be at http://127.0.0.1:{port}/ (Ctrl-C to stop)");
    println!(
        "serve: its Content-Security-Policy allows inline scripts and ws: for Trunk's loader and \
         live reload; `cargo xtask dist` builds the strict page (docs/console.md)"
    );
    println!("serve: $ {cmd}");
    cmd.run()
}

/// Builds the release console into `dist/`.
pub fn dist() -> Result {
    require_console()?;
    setup::run(false)?;
    build_dist()?;
    println!("dist: the console is in {}", root().join("dist").display());
    Ok(())
}

/// `trunk build --release --dist dist`, without setup (the caller did it).
pub fn build_dist() -> Result {
    require_console()?;
    let cmd = trunk().args(["build", "--release", "--dist", "dist"]);
    println!("dist: $ {cmd}");
    cmd.run()?;
    // The wasm-bindgen glue and the service worker, minified (with their
    // integrity hashes in index.html): tests/e2e/minify-dist.mjs.
    let script = root().join("tests/e2e/minify-dist.mjs");
    let minify = Cmd::new("node").args([script.to_string_lossy().as_ref()]);
    println!("dist: $ {minify}");
    minify.run()
}

/// Trunk, told not to look for its own updates: the machine may have no
/// network beyond the package registries. The `wasm-opt` that index.html
/// asks for (`data-wasm-opt`) is npm's `binaryen`, installed by setup with
/// the browser test packages: Debian's is too old, and Trunk would
/// otherwise try to download one.
fn trunk() -> Cmd {
    let tools = root().join("tests/e2e/node_modules/.bin");
    let path = std::env::var_os("PATH").unwrap_or_default();
    let dirs = std::iter::once(tools).chain(std::env::split_paths(&path));
    let path = std::env::join_paths(dirs)
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_else(|_| path.to_string_lossy().into_owned());
    Cmd::new("trunk")
        .env("TRUNK_SKIP_VERSION_CHECK", "true")
        .env("PATH", &path)
}

fn require_console() -> Result {
    if root().join("index.html").exists() {
        Ok(())
    } else {
        Err("the console is not built yet: index.html is missing (issue 4)".to_string())
    }
}
