//! Run files (`runs/*.csv`): a time column `t`, the run's input columns and
//! any sensor columns, read line by line within fixed limits.

use super::manifest::{run_path, Manifest, RunMeta};
use super::{BundleError, Limits};
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// One run's samples, units converted: inputs in m/s², accelerations in
/// m/s², displacements in mm; a missing reading is NaN.
#[derive(Debug, Clone, PartialEq)]
pub struct RunData {
    /// Run id.
    pub id: String,
    /// First time stamp, s.
    pub t0_s: f64,
    /// Sampling step, s.
    pub dt_s: f64,
    /// Floor acceleration in x, m/s².
    pub input_x_m_s2: Option<Vec<f64>>,
    /// Floor acceleration in y, m/s².
    pub input_y_m_s2: Option<Vec<f64>>,
    /// Sensor columns present in the file: (sensor id, samples in internal units).
    pub sensors: Vec<(String, Vec<f64>)>,
}

impl RunData {
    /// Number of samples.
    pub fn n_samples(&self) -> usize {
        self.input_x_m_s2.as_ref().or(self.input_y_m_s2.as_ref()).map_or(0, Vec::len)
    }
    /// Duration from first to last sample, s.
    pub fn duration_s(&self) -> f64 {
        self.dt_s * (self.n_samples().saturating_sub(1)) as f64
    }
    /// Samples of one sensor, if the run measured it.
    pub fn sensor(&self, id: &str) -> Option<&[f64]> {
        self.sensors.iter().find(|(s, _)| s == id).map(|(_, v)| v.as_slice())
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Role {
    Time,
    InputX,
    InputY,
    Sensor(usize),
}

struct Lines<R> {
    reader: R,
    path: PathBuf,
    line: usize,
    buf: Vec<u8>,
    max_line: usize,
}

impl<R: BufRead> Lines<R> {
    /// Next line that is not a comment or blank, as text, with its number.
    fn next(&mut self) -> Result<Option<(usize, String)>, BundleError> {
        loop {
            self.buf.clear();
            let n = (&mut self.reader)
                .take(self.max_line as u64 + 1)
                .read_until(b'\n', &mut self.buf)
                .map_err(|source| BundleError::Io { path: self.path.clone(), source })?;
            if n == 0 {
                return Ok(None);
            }
            self.line += 1;
            let err = |message: String| BundleError::Line {
                path: self.path.clone(),
                line: self.line,
                message,
            };
            if self.buf.last() != Some(&b'\n') && n > self.max_line {
                return Err(err(format!("line longer than the limit of {} bytes", self.max_line)));
            }
            if self.buf.contains(&0) {
                return Err(err("NUL byte: expected plain text".into()));
            }
            let text = std::str::from_utf8(&self.buf).map_err(|_| err("not UTF-8 text".into()))?;
            let text = text.trim_end_matches(['\n', '\r']);
            if text.trim().is_empty() || text.trim_start().starts_with('#') {
                continue;
            }
            return Ok(Some((self.line, text.to_string())));
        }
    }
}

/// Reads one run file named by the manifest.
pub fn read_run(
    dir: &Path,
    manifest: &Manifest,
    run: &RunMeta,
    limits: &Limits,
) -> Result<RunData, BundleError> {
    let bundle_toml = dir.join("bundle.toml");
    let path = run_path(dir, &run.file).map_err(|m| BundleError::Key {
        path: bundle_toml,
        key: format!("runs[{}].file", run.id),
        message: format!("{:?}: {m}", run.file),
    })?;
    let file = std::fs::File::open(&path)
        .map_err(|source| BundleError::Io { path: path.clone(), source })?;
    let size = file.metadata().map(|m| m.len()).unwrap_or(0);
    let too_big = || BundleError::File {
        path: path.clone(),
        message: format!("larger than the limit of {} bytes", limits.max_file_bytes),
    };
    if size > limits.max_file_bytes {
        return Err(too_big());
    }
    let reader = BufReader::new(file.take(limits.max_file_bytes + 1));
    let mut lines = Lines {
        reader,
        path: path.clone(),
        line: 0,
        buf: Vec::new(),
        max_line: limits.max_line_bytes,
    };
    let (hline, header) = lines.next()?.ok_or_else(|| BundleError::File {
        path: path.clone(),
        message: "empty: expected a header line starting with t".into(),
    })?;
    let roles = header_roles(&header, hline, manifest, run, &path, limits)?;
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); roles.len()];
    let mut line_of_row: Vec<usize> = Vec::new();
    while let Some((line, text)) = lines.next()? {
        if cols[0].len() >= limits.max_rows {
            return Err(BundleError::Line {
                path,
                line,
                message: format!("more than {} rows", limits.max_rows),
            });
        }
        parse_row(&text, line, &roles, &header, &mut cols, &path)?;
        line_of_row.push(line);
    }
    assemble(run, manifest, roles, cols, &line_of_row, &path)
}

fn header_roles(
    header: &str,
    line: usize,
    m: &Manifest,
    run: &RunMeta,
    path: &Path,
    limits: &Limits,
) -> Result<Vec<Role>, BundleError> {
    let err = |message: String| BundleError::Line { path: path.to_path_buf(), line, message };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    if names.len() > limits.max_fields {
        return Err(err(format!(
            "{} columns: more than the limit of {}",
            names.len(),
            limits.max_fields
        )));
    }
    if names[0] != "t" {
        return Err(err(format!(
            "first column is {:?}: expected \"t\" (time in seconds)",
            names[0]
        )));
    }
    let mut roles = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let role = if i == 0 {
            Role::Time
        } else if run.input_x.as_deref() == Some(*name) {
            Role::InputX
        } else if run.input_y.as_deref() == Some(*name) {
            Role::InputY
        } else if let Some(k) = m.sensors.iter().position(|s| s.id == *name) {
            Role::Sensor(k)
        } else {
            return Err(err(format!("column {} {name:?} is neither t, an input of run {} nor a listed sensor (a typo in an id?)", i + 1, run.id)));
        };
        if roles.contains(&role) {
            return Err(err(format!("column {name:?} appears twice")));
        }
        roles.push(role);
    }
    for (want, role, key) in
        [(&run.input_x, Role::InputX, "input_x"), (&run.input_y, Role::InputY, "input_y")]
    {
        if let Some(name) = want {
            if !roles.contains(&role) {
                return Err(err(format!(
                    "no column {name:?}, which run {} names as {key}",
                    run.id
                )));
            }
        }
    }
    Ok(roles)
}

fn parse_row(
    text: &str,
    line: usize,
    roles: &[Role],
    header: &str,
    cols: &mut [Vec<f64>],
    path: &Path,
) -> Result<(), BundleError> {
    let err = |message: String| BundleError::Line { path: path.to_path_buf(), line, message };
    let mut n = 0;
    for (k, field) in text.split(',').enumerate() {
        if k >= roles.len() {
            return Err(err(format!("expected {} fields, found more", roles.len())));
        }
        let field = field.trim();
        let missing = field.is_empty() || field.eq_ignore_ascii_case("nan");
        let column = || header.split(',').nth(k).unwrap_or("").trim().to_string();
        let value = if missing {
            match roles[k] {
                Role::Time => return Err(err("time t is missing: expected a number".into())),
                Role::InputX | Role::InputY => {
                    return Err(err(format!(
                        "input column {:?} has a gap: inputs must be complete",
                        column()
                    )))
                }
                Role::Sensor(_) => f64::NAN,
            }
        } else {
            let v: f64 = field
                .parse()
                .map_err(|_| err(format!("column {:?}: {field:?} is not a number", column())))?;
            if !v.is_finite() {
                return Err(err(format!("column {:?}: {field:?}: expected a finite number (empty or nan for a missing reading)", column())));
            }
            v
        };
        cols[k].push(value);
        n = k + 1;
    }
    if n != roles.len() {
        return Err(err(format!("expected {} fields, found {n}", roles.len())));
    }
    Ok(())
}

fn assemble(
    run: &RunMeta,
    m: &Manifest,
    roles: Vec<Role>,
    mut cols: Vec<Vec<f64>>,
    lines: &[usize],
    path: &Path,
) -> Result<RunData, BundleError> {
    let t = std::mem::take(&mut cols[0]);
    let (t0_s, dt_s) = check_time(&t, lines, path)?;
    let scale_in = run.input_units.to_m_s2();
    let mut data = RunData {
        id: run.id.clone(),
        t0_s,
        dt_s,
        input_x_m_s2: None,
        input_y_m_s2: None,
        sensors: Vec::new(),
    };
    for (role, mut col) in roles.into_iter().zip(cols).skip(1) {
        match role {
            Role::InputX | Role::InputY => {
                col.iter_mut().for_each(|v| *v *= scale_in);
                if role == Role::InputX {
                    data.input_x_m_s2 = Some(col);
                } else {
                    data.input_y_m_s2 = Some(col);
                }
            }
            Role::Sensor(k) => {
                let s = &m.sensors[k];
                let f = s.units.to_internal();
                col.iter_mut().for_each(|v| *v *= f);
                data.sensors.push((s.id.clone(), col));
            }
            Role::Time => {}
        }
    }
    Ok(data)
}

/// Checks that time is strictly increasing and uniform; returns (t0, dt).
fn check_time(t: &[f64], lines: &[usize], path: &Path) -> Result<(f64, f64), BundleError> {
    if t.len() < 2 {
        return Err(BundleError::File {
            path: path.to_path_buf(),
            message: format!("{} data rows: expected at least 2", t.len()),
        });
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    for k in 1..t.len() {
        let err = |message: String| BundleError::Line {
            path: path.to_path_buf(),
            line: lines[k],
            message,
        };
        let step = t[k] - t[k - 1];
        if step <= 0.0 {
            return Err(err(format!(
                "t = {} after {}: time must be strictly increasing",
                t[k],
                t[k - 1]
            )));
        }
        let tol = 1e-6 * dt + 4.0 * f64::EPSILON * t[k].abs().max(t[k - 1].abs());
        if (step - dt).abs() > tol {
            return Err(err(format!(
                "time step {step} s, expected a uniform {dt} s (relative jitter up to 1e-6)"
            )));
        }
    }
    Ok((t[0], dt))
}
