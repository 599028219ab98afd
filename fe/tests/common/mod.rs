//! Helpers shared by the fe tests: the verification folder and CSV readers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The shared verification folder: `CEILFARM_SHARED` if set, else the first
/// `shared/verification` found above this crate.
pub fn verification_dir() -> PathBuf {
    if let Ok(dir) = std::env::var("CEILFARM_SHARED") {
        return PathBuf::from(dir).join("verification");
    }
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .ancestors()
        .map(|a| a.join("shared").join("verification"))
        .find(|p| p.join("MODEL_FORMAT.md").is_file())
        .expect("shared/verification not found above the crate; set CEILFARM_SHARED")
}

/// Rows of a CSV file as strings (header skipped).
pub fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|s| s.trim().to_string()).collect())
        .collect()
}

/// Modal assurance criterion of two real vectors.
pub fn mac(a: &[f64], b: &[f64]) -> f64 {
    let ab: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let aa: f64 = a.iter().map(|x| x * x).sum();
    let bb: f64 = b.iter().map(|x| x * x).sum();
    ab * ab / (aa * bb)
}
