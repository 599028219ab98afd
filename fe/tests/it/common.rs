//! Helpers shared by the fe tests: the verification folder and CSV readers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use fe::generator::{Boundary, Structure};

/// A semi-free double-layer specimen of the type-C members, `lx_m` x
/// `ly_m`, on the 0.6 m module with the seed's 19 mm gap.
pub fn type_c_structure(lx_m: f64, ly_m: f64) -> Structure {
    Structure {
        length_x_m: lx_m,
        length_y_m: ly_m,
        module_m: 0.6,
        main_tee_spacing_m: 1.2,
        hanger_spacing_m: 1.2,
        hanger_length_m: 1.0,
        panel_mass_kg: 1.2,
        layers: 2,
        boundary: Boundary::SemiFree,
        nominal_gap_mm: 19.0,
        lines_from_origin: false,
        wall_members: false,
        hanger_offset_m: 0.0,
    }
}

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
