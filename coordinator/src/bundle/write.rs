//! Writing a bundle: `bundle.toml`, one CSV per run in the units the
//! manifest declares, and `modal.csv`.

use super::{Bundle, BundleError};
use crate::study::format_value;
use std::io::Write;
use std::path::Path;

fn io(path: &Path) -> impl Fn(std::io::Error) -> BundleError + '_ {
    move |source| BundleError::Io { path: path.to_path_buf(), source }
}

/// Writes `bundle` into `dir` (created if needed); values are converted back
/// from internal units to the units each column declares.
pub fn write_bundle(bundle: &Bundle, dir: &Path) -> Result<(), BundleError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let m = &bundle.manifest;
    let toml_path = dir.join("bundle.toml");
    let text = toml::to_string(m)
        .map_err(|e| BundleError::File { path: toml_path.clone(), message: e.to_string() })?;
    std::fs::write(&toml_path, text).map_err(io(&toml_path))?;
    for (meta, run) in m.runs.iter().zip(&bundle.runs) {
        let path = dir.join(&meta.file);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        let mut f = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io(&path))?);
        let mut header = vec!["t".to_string()];
        let mut columns: Vec<(Vec<f64>, f64)> = Vec::new();
        let k_in = meta.input_units.to_m_s2();
        for (name, col) in [(&meta.input_x, &run.input_x_m_s2), (&meta.input_y, &run.input_y_m_s2)]
        {
            if let (Some(name), Some(col)) = (name, col) {
                header.push(name.clone());
                columns.push((col.clone(), k_in));
            }
        }
        for (id, col) in &run.sensors {
            let s = m.sensors.iter().find(|s| &s.id == id).ok_or_else(|| BundleError::Key {
                path: toml_path.clone(),
                key: format!("sensors ({id})"),
                message: format!(
                    "run {} has data for sensor {id}, which the manifest does not list",
                    meta.id
                ),
            })?;
            header.push(id.clone());
            columns.push((col.clone(), s.units.to_internal()));
        }
        writeln!(f, "{}", header.join(",")).map_err(io(&path))?;
        for k in 0..run.n_samples() {
            let mut row = vec![format_value(run.t0_s + k as f64 * run.dt_s)];
            for (col, scale) in &columns {
                let v = col[k] / scale;
                row.push(if v.is_nan() { String::new() } else { format_value(v) });
            }
            writeln!(f, "{}", row.join(",")).map_err(io(&path))?;
        }
        f.flush().map_err(io(&path))?;
    }
    if let Some(modal) = &bundle.modal {
        let path = dir.join("modal.csv");
        let mut text = String::from("mode,freq_hz,std_hz\n");
        for e in modal {
            text += &format!(
                "{},{},{}\n",
                e.mode,
                e.freq_hz,
                e.std_hz.map(|s| s.to_string()).unwrap_or_default()
            );
        }
        std::fs::write(&path, text).map_err(io(&path))?;
    }
    Ok(())
}
