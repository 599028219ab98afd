//! Run files (`runs/*.csv`): a time column `t`, the run's input columns and
//! any sensor columns, read row by row through the shared CSV reader
//! ([`worker::csv_rows`]: quotes, a byte-order mark, CRLF, `#` comments)
//! within fixed limits.

use super::files::open_regular;
use super::manifest::{run_path, Manifest, RunMeta};
use super::ranges::{check_range, DT_S, TIME_S};
use super::{BundleError, Limits};
use csv::StringRecord;
use std::io::{BufReader, Read};
use std::path::Path;
use worker::csv_rows::{CsvError, CsvLimits, CsvRows};

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
    /// Numbers held while reading it: samples times columns, time included.
    pub fn n_values(&self) -> u64 {
        let columns =
            [&self.input_x_m_s2, &self.input_y_m_s2].iter().filter(|c| c.is_some()).count()
                + self.sensors.len()
                + 1;
        (self.n_samples() * columns) as u64
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
    let file = open_regular(&path, limits.max_file_bytes)?;
    let reader = BufReader::new(file.take(limits.max_file_bytes + 1));
    let mut rows = CsvRows::new(reader, csv_limits(limits), true);
    let (hline, header) = match rows.next_row().map_err(|e| csv_error(&path, e))? {
        Some((line, record)) => (line, record.clone()),
        None => {
            return Err(BundleError::File {
                path: path.clone(),
                message: "empty: expected a header line starting with t".into(),
            })
        }
    };
    let roles = header_roles(&header, hline, manifest, run, &path)?;
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); roles.len()];
    let mut line_of_row: Vec<usize> = Vec::new();
    while let Some((line, record)) = rows.next_row().map_err(|e| csv_error(&path, e))? {
        if cols[0].len() >= limits.max_rows {
            return Err(BundleError::Line {
                path,
                line,
                message: format!("more than {} rows", limits.max_rows),
            });
        }
        if ((cols[0].len() + 1) * roles.len()) as u64 > limits.max_values {
            return Err(BundleError::Line { path, line, message: values_message(limits) });
        }
        parse_row(record, line, &roles, &header, &mut cols, &path)?;
        line_of_row.push(line);
    }
    assemble(run, manifest, roles, cols, &line_of_row, &path)
}

/// Why a run is refused for the bundle's memory bound.
fn values_message(limits: &Limits) -> String {
    format!(
        "more than the {} numbers left of the bundle's limit (Limits::max_values, 8 bytes each; \
         all run files together, a file named by several runs counted each time)",
        limits.max_values
    )
}

/// The shared reader's bounds from a bundle's limits.
pub(super) fn csv_limits(limits: &Limits) -> CsvLimits {
    CsvLimits { max_line_bytes: limits.max_line_bytes, max_fields: limits.max_fields }
}

/// A shared-reader error as a bundle error naming the file and line.
pub(super) fn csv_error(path: &Path, e: CsvError) -> BundleError {
    let path = path.to_path_buf();
    match (e.line(), e) {
        (_, CsvError::Io { source }) => BundleError::Io { path, source },
        (line, e) => BundleError::Line { path, line: line.unwrap_or(0), message: e.to_string() },
    }
}

fn header_roles(
    header: &StringRecord,
    line: usize,
    m: &Manifest,
    run: &RunMeta,
    path: &Path,
) -> Result<Vec<Role>, BundleError> {
    let err = |message: String| BundleError::Line { path: path.to_path_buf(), line, message };
    let names: Vec<&str> = header.iter().collect();
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
    record: &StringRecord,
    line: usize,
    roles: &[Role],
    header: &StringRecord,
    cols: &mut [Vec<f64>],
    path: &Path,
) -> Result<(), BundleError> {
    let err = |message: String| BundleError::Line { path: path.to_path_buf(), line, message };
    let mut n = 0;
    if record.len() > roles.len() {
        return Err(err(format!("expected {} fields, found more ({})", roles.len(), record.len())));
    }
    for (k, field) in record.iter().enumerate() {
        let missing = field.is_empty() || field.eq_ignore_ascii_case("nan");
        let column = || header.get(k).unwrap_or("").to_string();
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
            if roles[k] == Role::Time {
                check_range(&TIME_S, v).map_err(|m| err(format!("column \"t\": {m}")))?;
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
        // Growth by doubling leaves up to half a column unused; the bundle's
        // memory bound counts what is held.
        col.shrink_to_fit();
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
    if dt > 0.0 {
        check_range(&DT_S, dt).map_err(|m| BundleError::File {
            path: path.to_path_buf(),
            message: format!("time step dt = {m}"),
        })?;
    }
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
