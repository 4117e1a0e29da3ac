//! Running the `sagcal` binary from a test (included with `#[path]`).

use std::path::Path;
use std::process::{Command, Output};

/// Run `sagcal ARGS` in `dir`.
pub fn sagcal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

/// The path of a built-in robot file, `robots/NAME.toml`.
pub fn robot(name: &str) -> String {
    format!("{}/robots/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}
