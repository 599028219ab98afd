//! Uniform base acceleration a_g(t) = scale × record(t), linear between
//! samples, zero after the last sample (OpenSees `timeSeries Path -dt`).
//! The record CSV has header `t_s,ag_mm_s2` and rows t = k·dt (mm/s²).

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::spec::ExcitationSpec;
use super::TransientError;

/// A scaled ground-acceleration record (mm/s²) in one global DOF.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundMotion {
    /// Global DOF 1..6.
    pub dof: u8,
    /// Sample interval (s).
    pub dt_s: f64,
    /// Scaled samples (mm/s²), sample k at t = k·dt.
    pub accel_mm_s2: Vec<f64>,
}

impl GroundMotion {
    /// Reads the record an excitation block names, relative to `base_dir`.
    pub fn from_spec(spec: &ExcitationSpec, base_dir: &Path) -> Result<Self, TransientError> {
        let path = base_dir.join(&spec.record_csv);
        let bytes = std::fs::read(&path)
            .map_err(|e| TransientError::Record { path: path.clone(), message: e.to_string() })?;
        if let Some(expected) = &spec.sha256 {
            let got: String = Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect();
            if !got.eq_ignore_ascii_case(expected) {
                return Err(TransientError::Record {
                    path,
                    message: format!("sha256 {got}, expected {expected}"),
                });
            }
        }
        let text = String::from_utf8_lossy(&bytes);
        let values = parse_record(&text, spec.dt_s, &path)?;
        if values.len() != spec.npts {
            return Err(TransientError::Record {
                path,
                message: format!("{} samples, expected npts = {}", values.len(), spec.npts),
            });
        }
        Ok(GroundMotion {
            dof: spec.dof,
            dt_s: spec.dt_s,
            accel_mm_s2: values.iter().map(|a| a * spec.scale).collect(),
        })
    }

    /// a_g(t) (mm/s²): linear between samples, 0 after the record.
    pub fn accel_at(&self, t_s: f64) -> f64 {
        let x = t_s / self.dt_s;
        let k = (x + 1e-9).floor();
        let n = self.accel_mm_s2.len();
        if k < 0.0 || n == 0 {
            return 0.0;
        }
        let k = k as usize;
        if k + 1 >= n {
            return if k + 1 == n { self.accel_mm_s2[n - 1] } else { 0.0 };
        }
        let r = x - k as f64;
        if r.abs() < 1e-9 {
            return self.accel_mm_s2[k];
        }
        self.accel_mm_s2[k] * (1.0 - r) + self.accel_mm_s2[k + 1] * r
    }
}

/// Base acceleration in one or more global DOFs at once (e.g. x and y of a
/// bidirectional shaking-table run); each component acts on its own DOF.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMotion {
    /// Components, each in a distinct DOF.
    pub components: Vec<GroundMotion>,
}

impl BaseMotion {
    /// One component.
    pub fn single(g: GroundMotion) -> Self {
        BaseMotion { components: vec![g] }
    }

    /// a_g of every component at `t_s` (mm/s²), in component order.
    pub fn accel_at(&self, t_s: f64, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.components.iter().map(|g| g.accel_at(t_s)));
    }

    /// Index of the component acting on `dof`, if any.
    pub fn component_of(&self, dof: u8) -> Option<usize> {
        self.components.iter().position(|g| g.dof == dof)
    }
}

/// The acceleration column of a record CSV, checking t = k·dt.
fn parse_record(text: &str, dt_s: f64, path: &Path) -> Result<Vec<f64>, TransientError> {
    let err = |line: usize, message: String| TransientError::Record {
        path: PathBuf::from(format!("{}:{}", path.display(), line)),
        message,
    };
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let mut cols = line.split(',');
        let mut num = |what: &str| -> Result<f64, TransientError> {
            let s = cols.next().unwrap_or("").trim();
            s.parse::<f64>().map_err(|_| err(n + 1, format!("{what} {s:?} is not a number")))
        };
        let t = num("time")?;
        let a = num("acceleration")?;
        let expected = out.len() as f64 * dt_s;
        if (t - expected).abs() > 1e-6 * dt_s.max(1.0) {
            return Err(err(n + 1, format!("time {t} s, expected k·dt = {expected} s")));
        }
        out.push(a);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_linearly_and_is_zero_after_the_record() {
        let g = GroundMotion { dof: 1, dt_s: 0.01, accel_mm_s2: vec![0.0, 10.0, -10.0] };
        assert_eq!(g.accel_at(0.0), 0.0);
        assert!((g.accel_at(0.005) - 5.0).abs() < 1e-12);
        assert!((g.accel_at(0.015) - 0.0).abs() < 1e-9);
        assert_eq!(g.accel_at(0.02), -10.0);
        assert_eq!(g.accel_at(0.03), 0.0);
    }

    #[test]
    fn record_rows_must_be_on_the_time_grid() {
        let p = Path::new("r.csv");
        assert_eq!(parse_record("t_s,ag\n0,1\n0.01,2\n", 0.01, p).unwrap(), vec![1.0, 2.0]);
        assert!(parse_record("t_s,ag\n0,1\n0.02,2\n", 0.01, p).is_err());
    }
}
