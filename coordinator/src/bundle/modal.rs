//! `modal.csv`: identified natural frequencies, `mode,freq_hz,std_hz`, read
//! through the shared CSV reader ([`worker::csv_rows`]); duplicate modes are
//! found in O(n log n) (a `BTreeSet` of the modes seen).

use super::files::open_regular;
use super::ranges::{check_range, FREQ_HZ, STD_HZ};
use super::runfile::{csv_error, csv_limits};
use super::{BundleError, Limits};
use csv::StringRecord;
use std::collections::BTreeSet;
use std::io::{BufReader, Read};
use std::path::Path;
use worker::csv_rows::CsvRows;

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

/// Largest `modal.csv` read (bytes).
const MAX_MODAL_BYTES: u64 = 16 << 20;

/// Reads and checks `modal.csv` (a regular file inside the bundle).
pub fn read_modal(path: &Path, limits: &Limits) -> Result<Vec<ModalEntry>, BundleError> {
    let max_bytes = limits.max_file_bytes.min(MAX_MODAL_BYTES);
    let file = open_regular(path, max_bytes)?;
    let mut rows = CsvRows::new(BufReader::new(file.take(max_bytes)), csv_limits(limits), true);
    let mut out: Vec<ModalEntry> = Vec::new();
    let mut seen = BTreeSet::new();
    let mut header_seen = false;
    while let Some((line, f)) = rows.next_row().map_err(|e| csv_error(path, e))? {
        let err = |message: String| BundleError::Line { path: path.to_path_buf(), line, message };
        if !header_seen {
            if f.iter().ne(["mode", "freq_hz", "std_hz"]) {
                let l = f.iter().collect::<Vec<_>>().join(",");
                return Err(err(format!("header {l:?}: expected \"mode,freq_hz,std_hz\"")));
            }
            header_seen = true;
            continue;
        }
        let entry = parse_entry(f).map_err(err)?;
        if !seen.insert(entry.mode) {
            return Err(err(format!("mode {} listed twice", entry.mode)));
        }
        out.push(entry);
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

/// One data row `mode,freq_hz,std_hz`, or what is wrong with it.
fn parse_entry(f: &StringRecord) -> Result<ModalEntry, String> {
    if f.len() != 3 {
        return Err(format!("expected 3 fields, found {}", f.len()));
    }
    let mode: u32 =
        f[0].parse().map_err(|_| format!("mode {:?}: expected a whole number >= 1", &f[0]))?;
    let freq_hz: f64 = f[1].parse().map_err(|_| format!("freq_hz {:?} is not a number", &f[1]))?;
    if mode == 0 || !(freq_hz.is_finite() && freq_hz > 0.0) {
        return Err(format!(
            "mode {mode}, freq_hz {freq_hz}: expected mode >= 1 and a frequency > 0"
        ));
    }
    check_range(&FREQ_HZ, freq_hz).map_err(|m| format!("freq_hz {m}"))?;
    let std_hz = if f[2].is_empty() {
        None
    } else {
        let s: f64 = f[2].parse().map_err(|_| format!("std_hz {:?} is not a number", &f[2]))?;
        if !(s.is_finite() && s >= 0.0) {
            return Err(format!("std_hz {s}: expected >= 0 (0 or empty: unknown)"));
        }
        check_range(&STD_HZ, s).map_err(|m| format!("std_hz {m}"))?;
        (s > 0.0).then_some(s)
    };
    Ok(ModalEntry { mode, freq_hz, std_hz })
}
