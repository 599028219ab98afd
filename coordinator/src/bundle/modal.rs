//! `modal.csv`: identified natural frequencies, `mode,freq_hz,std_hz`.

use super::manifest::read_text;
use super::{BundleError, Limits};
use std::path::Path;

/// One identified mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalEntry {
    /// Mode number (1-based).
    pub mode: u32,
    /// Frequency, Hz.
    pub freq_hz: f64,
    /// One-sigma uncertainty, Hz; `None` when unknown (0 or empty).
    pub std_hz: Option<f64>,
}

/// Reads and checks `modal.csv`.
pub fn read_modal(path: &Path, limits: &Limits) -> Result<Vec<ModalEntry>, BundleError> {
    let text = read_text(path, limits.max_file_bytes.min(16 << 20))?;
    let mut out: Vec<ModalEntry> = Vec::new();
    let mut header_seen = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let err = |message: String| BundleError::Line { path: path.to_path_buf(), line, message };
        let l = raw.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        if !header_seen {
            if f != ["mode", "freq_hz", "std_hz"] {
                return Err(err(format!("header {l:?}: expected \"mode,freq_hz,std_hz\"")));
            }
            header_seen = true;
            continue;
        }
        if f.len() != 3 {
            return Err(err(format!("expected 3 fields, found {}", f.len())));
        }
        let mode: u32 = f[0]
            .parse()
            .map_err(|_| err(format!("mode {:?}: expected a whole number >= 1", f[0])))?;
        let freq_hz: f64 =
            f[1].parse().map_err(|_| err(format!("freq_hz {:?} is not a number", f[1])))?;
        if mode == 0 || !(freq_hz.is_finite() && freq_hz > 0.0) {
            return Err(err(format!(
                "mode {mode}, freq_hz {freq_hz}: expected mode >= 1 and a frequency > 0"
            )));
        }
        let std_hz = if f[2].is_empty() {
            None
        } else {
            let s: f64 =
                f[2].parse().map_err(|_| err(format!("std_hz {:?} is not a number", f[2])))?;
            if !(s.is_finite() && s >= 0.0) {
                return Err(err(format!("std_hz {s}: expected >= 0 (0 or empty: unknown)")));
            }
            (s > 0.0).then_some(s)
        };
        if out.iter().any(|e| e.mode == mode) {
            return Err(err(format!("mode {mode} listed twice")));
        }
        out.push(ModalEntry { mode, freq_hz, std_hz });
    }
    if !header_seen {
        return Err(BundleError::File {
            path: path.to_path_buf(),
            message: "empty: expected the header mode,freq_hz,std_hz".into(),
        });
    }
    out.sort_by_key(|e| e.mode);
    Ok(out)
}
