//! What the CLI tests share: the repository root and a way to run `cirrus`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root, where `data/` is.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs the `cirrus` binary from the repository root: (success, stdout, stderr).
pub fn cirrus(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
