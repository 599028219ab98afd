//! The recorded history of a transient run and its CSV form: header
//! `t_s,ag_mm_s2,<recorder names>`, one row per output step from t = 0.

use std::io::Write;
use std::path::Path;

use super::TransientError;

/// Recorded rows: time (s), a_g (mm/s²), then one value per recorder.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct History {
    /// Column names, starting with `t_s`, `ag_mm_s2`.
    pub columns: Vec<String>,
    /// Rows in time order.
    pub rows: Vec<Vec<f64>>,
}

impl History {
    /// The values of a named column, if present.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }
}

/// Writes a history as CSV.
pub fn write_history<W: Write>(h: &History, out: &mut W) -> std::io::Result<()> {
    writeln!(out, "{}", h.columns.join(","))?;
    let mut line = String::new();
    for r in &h.rows {
        line.clear();
        for (k, v) in r.iter().enumerate() {
            if k > 0 {
                line.push(',');
            }
            push_number(&mut line, *v);
        }
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// Shortest round-trip text of a number, in scientific notation when very
/// small or large (a plain decimal otherwise).
fn push_number(line: &mut String, v: f64) {
    use std::fmt::Write as _;
    let a = v.abs();
    let _ = if a == 0.0 || (1e-4..1e15).contains(&a) {
        write!(line, "{v}")
    } else {
        write!(line, "{v:e}")
    };
}

/// Writes a history to a CSV file (`history.csv` by convention).
pub fn write_history_csv(h: &History, path: &Path) -> Result<(), TransientError> {
    let io =
        |e: std::io::Error| TransientError::Io { path: path.to_path_buf(), message: e.to_string() };
    let f = std::fs::File::create(path).map_err(io)?;
    let mut w = std::io::BufWriter::new(f);
    write_history(h, &mut w).map_err(io)?;
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_header_and_rows() {
        let h = History {
            columns: vec!["t_s".into(), "ag_mm_s2".into(), "x".into()],
            rows: vec![vec![0.0, 0.0, 0.0], vec![0.002, 1.5, -2e-7]],
        };
        let mut out = Vec::new();
        write_history(&h, &mut out).unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), "t_s,ag_mm_s2,x\n0,0,0\n0.002,1.5,-2e-7\n");
    }
}
