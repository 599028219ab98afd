//! Writing modal results: `eigen.csv` (`mode,f_hz`), `modeshapes.csv`
//! (`mode,node,x_mm,y_mm,phi_x,phi_y,phi_z`, mass-normalised translations of
//! every node with a free DOF) and `modal.csv` (participation and effective
//! masses in x, y).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::ModalResult;
use crate::assembly::Structure;

/// A file that could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {source}")]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// The cause.
    pub source: std::io::Error,
}

/// The text of `eigen.csv`.
pub fn eigen_csv(res: &ModalResult) -> String {
    let mut s = String::from("mode,f_hz\n");
    for (k, f) in res.freq_hz.iter().enumerate() {
        let _ = writeln!(s, "{},{:.12e}", k + 1, f);
    }
    s
}

/// The text of `modeshapes.csv`.
pub fn modeshapes_csv(st: &Structure, res: &ModalResult) -> String {
    let mut s = String::from("mode,node,x_mm,y_mm,phi_x,phi_y,phi_z\n");
    for (k, phi) in res.shapes.iter().enumerate() {
        for (n, eqs) in st.dofs.eqs.iter().enumerate() {
            if eqs.iter().all(Option::is_none) {
                continue;
            }
            let xyz = st.dofs.coords_mm[n];
            let v = [0, 1, 2].map(|d| eqs[d].map_or(0.0, |e| phi[e]));
            let id = st.dofs.node_ids[n];
            let _ = writeln!(
                s,
                "{},{id},{},{},{:.10e},{:.10e},{:.10e}",
                k + 1,
                xyz[0],
                xyz[1],
                v[0],
                v[1],
                v[2]
            );
        }
    }
    s
}

/// The text of `modal.csv`: participation factors, effective masses, dominant direction.
pub fn modal_csv(res: &ModalResult) -> String {
    let mut s = String::from(
        "mode,f_hz,gamma_x,gamma_y,meff_x_t,meff_y_t,meff_x_ratio,meff_y_ratio,dominant\n",
    );
    for k in 0..res.freq_hz.len() {
        let (g, m, t) = (res.participation[k], res.effective_mass_t[k], res.total_mass_t);
        let ratio = |d: usize| if t[d] > 0.0 { m[d] / t[d] } else { 0.0 };
        let _ = writeln!(
            s,
            "{},{:.12e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6},{:.6},{}",
            k + 1,
            res.freq_hz[k],
            g[0],
            g[1],
            m[0],
            m[1],
            ratio(0),
            ratio(1),
            res.dominant(k)
        );
    }
    s
}

/// Writes the three CSV files into `dir` (created if missing).
pub fn write_modal(dir: &Path, st: &Structure, res: &ModalResult) -> Result<(), WriteError> {
    let err = |path: PathBuf| move |source| WriteError { path, source };
    std::fs::create_dir_all(dir).map_err(err(dir.to_path_buf()))?;
    for (name, text) in [
        ("eigen.csv", eigen_csv(res)),
        ("modeshapes.csv", modeshapes_csv(st, res)),
        ("modal.csv", modal_csv(res)),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(err(path.clone()))?;
    }
    Ok(())
}
