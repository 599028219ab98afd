//! Helpers shared by the end-to-end tests: run the `ceilfarm` binary, make
//! study files in temporary directories.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Path of the built `ceilfarm` binary.
pub fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_ceilfarm"))
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// The shared reference folder (`../shared` beside the repository):
/// `CEILFARM_SHARED` if set, else the first `shared/` above the repository
/// that holds `verification/MODEL_FORMAT.md`.
pub fn shared() -> PathBuf {
    if let Ok(dir) = std::env::var("CEILFARM_SHARED") {
        return PathBuf::from(dir);
    }
    repo()
        .ancestors()
        .map(|a| a.join("shared"))
        .find(|p| p.join("verification").join("MODEL_FORMAT.md").is_file())
        .expect("shared/ not found above the repository; set CEILFARM_SHARED")
}

/// Runs `ceilfarm` with arguments; returns its output.
pub fn ceilfarm(args: &[&str]) -> Output {
    Command::new(bin()).args(args).output().expect("spawn ceilfarm")
}

/// Runs `ceilfarm` and panics with its stderr unless it succeeds.
pub fn ceilfarm_ok(args: &[&str]) -> Output {
    let out = ceilfarm(args);
    assert!(
        out.status.success(),
        "ceilfarm {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Writes the shipped borehole study, edited by `edit`, into `dir`.
pub fn borehole_study(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("configs/borehole.toml")).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, edit(text)).unwrap();
    path
}

/// `&Path` as `&str` for argument lists.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}
