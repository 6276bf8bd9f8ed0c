//! Writes the seed corpus (`plm_fuzz::seeds`) into `fuzz/seeds/<target>/`;
//! `cargo xtask fuzz` runs it before fuzzing (the same files each time).

use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let seeds = match plm_fuzz::seeds::all(&root) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("plm-fuzz-seed: {e}");
            return ExitCode::FAILURE;
        }
    };
    for (target, name, bytes) in &seeds {
        let dir = root.join("fuzz/seeds").join(target);
        let path = dir.join(name);
        if let Err(e) = std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&path, bytes)) {
            eprintln!("plm-fuzz-seed: {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
    }
    println!("plm-fuzz-seed: {} seeds in fuzz/seeds/", seeds.len());
    ExitCode::SUCCESS
}
