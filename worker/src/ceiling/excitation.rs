//! `[model.excitation]` of the `ceiling` kind: the base input of every run,
//! either the seed's exponential sine sweep (6 → 0.8 Hz with 2 s cosine
//! ramps, seed 4.2.3; `fe::ceiling::SineSweep`) or a recorded accelerogram
//! read from CSV in g or m/s². Output: an [`fe::ceiling::BaseInput`] in m/s².
//!
//! A record file is comma-separated with one header line, read through the
//! shared CSV reader ([`crate::csv_rows`]: quotes, a byte-order mark, CRLF);
//! `#` starts a comment line. Its first column is time (s), uniformly sampled (relative
//! jitter up to 1e-6 of the step); the acceleration columns are chosen by
//! name (`column_x`, `column_y`) or, by default, the second column for `x`
//! or `y` and the second and third for `xy`.

use std::path::PathBuf;

use crate::csv_rows::{CsvError, CsvLimits, CsvRows};
use csv::StringRecord;
use fe::ceiling::{sine_sweep, BaseInput, SineSweep};
use serde::Deserialize;

/// Standard gravity (m/s²).
pub const G_M_S2: f64 = 9.80665;

/// Which horizontal components the base moves in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shaking {
    /// Along x only.
    X,
    /// Along y only.
    Y,
    /// Along x and y at once.
    Xy,
}

/// Units of a record file's acceleration columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum RecordUnits {
    /// Multiples of standard gravity.
    #[serde(rename = "g")]
    G,
    /// m/s².
    #[serde(rename = "m/s2")]
    MPerS2,
}

impl RecordUnits {
    /// Factor to m/s².
    pub fn to_m_s2(self) -> f64 {
        match self {
            RecordUnits::G => G_M_S2,
            RecordUnits::MPerS2 => 1.0,
        }
    }
}

/// `[model.excitation]`, tagged by `type`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Excitation {
    /// The seed's exponential sine sweep with cosine ramps.
    SineSweep {
        /// Peak base acceleration (g).
        pga_g: f64,
        /// Duration (s).
        duration_s: f64,
        /// Sample interval (s), default 0.005.
        #[serde(default = "default_dt_s")]
        dt_s: f64,
        /// Shaking direction.
        direction: Shaking,
        /// Start frequency (Hz), default 6.
        #[serde(default = "default_f_start_hz")]
        f_start_hz: f64,
        /// End frequency (Hz), default 0.8.
        #[serde(default = "default_f_end_hz")]
        f_end_hz: f64,
        /// Cosine ramp at each end (s), default 2.
        #[serde(default = "default_ramp_s")]
        ramp_s: f64,
    },
    /// A recorded accelerogram.
    Record {
        /// The CSV file, relative to the study file (the coordinator replaces
        /// it by `csv`; a worker reads it relative to its working directory).
        #[serde(default)]
        file: Option<PathBuf>,
        /// The CSV text itself.
        #[serde(default)]
        csv: Option<String>,
        /// Units of the acceleration columns.
        units: RecordUnits,
        /// Shaking direction.
        direction: Shaking,
        /// Factor applied to the record (default 1).
        #[serde(default = "one")]
        scale: f64,
        /// Column of the x acceleration (default: by position).
        #[serde(default)]
        column_x: Option<String>,
        /// Column of the y acceleration (default: by position).
        #[serde(default)]
        column_y: Option<String>,
    },
}

fn default_dt_s() -> f64 {
    0.005
}
fn default_f_start_hz() -> f64 {
    6.0
}
fn default_f_end_hz() -> f64 {
    0.8
}
fn default_ramp_s() -> f64 {
    2.0
}
fn one() -> f64 {
    1.0
}

/// Why an excitation cannot be built; `key` is the offending option.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("model.excitation{}{key}: {message}", if key.is_empty() { "" } else { "." })]
pub struct ExcitationError {
    /// Option name under `[model.excitation]`.
    pub key: String,
    /// What is wrong and what was expected.
    pub message: String,
}

fn err<T>(key: &str, message: String) -> Result<T, ExcitationError> {
    Err(ExcitationError { key: key.into(), message })
}

impl Excitation {
    /// Parses `[model.excitation]` (as JSON), naming the offending key: an
    /// unknown `type`, `units` or `direction` value, or a missing or unknown key.
    pub fn from_json(v: &serde_json::Value) -> Result<Self, ExcitationError> {
        let Some(obj) = v.as_object() else {
            return err("type", format!("{v}: expected a table with a `type`"));
        };
        match obj.get("type").and_then(|t| t.as_str()) {
            Some("sine-sweep" | "record") => {}
            Some(t) => return err("type", format!("{t:?}: expected \"sine-sweep\" or \"record\"")),
            None => return err("type", "missing: expected \"sine-sweep\" or \"record\"".into()),
        }
        check_value::<RecordUnits>(obj, "units", "\"g\" or \"m/s2\"")?;
        check_value::<Shaking>(obj, "direction", "\"x\", \"y\" or \"xy\"")?;
        serde_json::from_value(v.clone()).or_else(|e| err("", e.to_string()))
    }

    /// The base input in m/s².
    pub fn base_input(&self) -> Result<BaseInput, ExcitationError> {
        match self {
            Excitation::SineSweep {
                pga_g,
                duration_s,
                dt_s,
                direction,
                f_start_hz,
                f_end_hz,
                ramp_s,
            } => {
                let sweep = SineSweep {
                    f_start_hz: *f_start_hz,
                    f_end_hz: *f_end_hz,
                    duration_s: *duration_s,
                    amplitude_m_s2: pga_g * G_M_S2,
                    ramp_s: *ramp_s,
                };
                check_sweep(*pga_g, &sweep, *dt_s)?;
                let a = sine_sweep(&sweep, *dt_s);
                Ok(split(*direction, *dt_s, a.clone(), a))
            }
            Excitation::Record { file, csv, units, direction, scale, column_x, column_y } => {
                if !scale.is_finite() {
                    return err("scale", format!("{scale}: expected a finite number"));
                }
                let text = record_text(file, csv)?;
                let factor = scale * units.to_m_s2();
                let cols = Columns { direction: *direction, x: column_x, y: column_y };
                let (dt_s, x, y) = read_record(&text, &cols)?;
                let conv = |v: Vec<f64>| v.into_iter().map(|a| a * factor).collect();
                Ok(split(*direction, dt_s, conv(x), conv(y)))
            }
        }
    }
}

/// Refuses a sweep whose sizes are not positive, whose ramps overlap, or
/// whose step resolves its highest frequency by fewer than 10 samples.
fn check_sweep(pga_g: f64, s: &SineSweep, dt_s: f64) -> Result<(), ExcitationError> {
    positive("pga_g", pga_g)?;
    positive("duration_s", s.duration_s)?;
    positive("dt_s", dt_s)?;
    positive("f_start_hz", s.f_start_hz)?;
    positive("f_end_hz", s.f_end_hz)?;
    let ramp_s = s.ramp_s;
    if !(ramp_s >= 0.0 && 2.0 * ramp_s <= s.duration_s) {
        return err("ramp_s", format!("{ramp_s}: expected 0 <= ramp_s <= duration_s / 2"));
    }
    if dt_s * 2.0 > s.duration_s {
        return err("dt_s", format!("{dt_s}: expected at most duration_s / 2"));
    }
    let f_max = s.f_start_hz.max(s.f_end_hz);
    if dt_s * f_max > 0.1 {
        return err(
            "dt_s",
            format!("{dt_s} s: expected at least 10 samples per cycle at {f_max} Hz"),
        );
    }
    Ok(())
}

/// A record's CSV text: the file's, or the inline text (exactly one given).
fn record_text(file: &Option<PathBuf>, csv: &Option<String>) -> Result<String, ExcitationError> {
    match (file, csv) {
        (None, Some(text)) => Ok(text.clone()),
        (Some(path), None) => std::fs::read_to_string(path)
            .or_else(|e| err("file", format!("{}: cannot read it ({e})", path.display()))),
        _ => err("file", "expected exactly one of `file` or `csv`".into()),
    }
}

/// Refuses a present `key` whose value is not one of `expected`.
fn check_value<T: serde::de::DeserializeOwned>(
    obj: &serde_json::Map<String, serde_json::Value>,
    key: &str,
    expected: &str,
) -> Result<(), ExcitationError> {
    match obj.get(key) {
        Some(v) if serde_json::from_value::<T>(v.clone()).is_err() => {
            err(key, format!("{v}: expected {expected}"))
        }
        _ => Ok(()),
    }
}

fn positive(key: &str, v: f64) -> Result<(), ExcitationError> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        err(key, format!("{v}: expected a finite number > 0"))
    }
}

/// Keeps the components that `direction` names.
pub fn split(direction: Shaking, dt_s: f64, x: Vec<f64>, y: Vec<f64>) -> BaseInput {
    let (x, y) = match direction {
        Shaking::X => (Some(x), None),
        Shaking::Y => (None, Some(y)),
        Shaking::Xy => (Some(x), Some(y)),
    };
    BaseInput { dt_s, x_m_s2: x, y_m_s2: y }
}

/// Which columns of a record hold the components (default: x the 2nd, y
/// the 2nd alone or the 3rd under `xy`).
pub struct Columns<'a> {
    /// Components to read.
    pub direction: Shaking,
    /// Name of the x column, if not the default.
    pub x: &'a Option<String>,
    /// Name of the y column, if not the default.
    pub y: &'a Option<String>,
}

/// Parses a record: (dt_s, x column, y column) in file units; a component
/// the direction does not use comes back empty.
pub fn read_record(
    text: &str,
    cols: &Columns<'_>,
) -> Result<(f64, Vec<f64>, Vec<f64>), ExcitationError> {
    let mut rows = CsvRows::new(text.as_bytes(), CsvLimits::default(), true);
    let Some((_, header)) = rows.next_row().map_err(csv_err)? else {
        return err("file", "the record is empty: expected a header line and samples".into());
    };
    let header: Vec<String> = header.iter().map(str::to_string).collect();
    let names: Vec<&str> = header.iter().map(String::as_str).collect();
    let (ix, iy) = component_columns(&names, cols)?;
    let (mut t, mut x, mut y) = (Vec::new(), Vec::new(), Vec::new());
    while let Some((line, row)) = rows.next_row().map_err(csv_err)? {
        let fields = record_fields(line, row, names.len())?;
        t.push(record_number(&names, &fields, line, 0)?);
        if let Some(i) = ix {
            x.push(record_number(&names, &fields, line, i)?);
        }
        if let Some(i) = iy {
            y.push(record_number(&names, &fields, line, i)?);
        }
    }
    Ok((uniform_step(&t)?, x, y))
}

/// The header positions of the x and y columns that `cols.direction` uses.
fn component_columns(
    names: &[&str],
    cols: &Columns<'_>,
) -> Result<(Option<usize>, Option<usize>), ExcitationError> {
    Ok(match cols.direction {
        Shaking::X => (Some(column_index(names, "column_x", cols.x, 1)?), None),
        Shaking::Y => (None, Some(column_index(names, "column_y", cols.y, 1)?)),
        Shaking::Xy => (
            Some(column_index(names, "column_x", cols.x, 1)?),
            Some(column_index(names, "column_y", cols.y, 2)?),
        ),
    })
}

/// The position of column `name` (option `key`) in `names`, else the `default` position.
fn column_index(
    names: &[&str],
    key: &str,
    name: &Option<String>,
    default: usize,
) -> Result<usize, ExcitationError> {
    match name {
        Some(n) => match names.iter().position(|h| h == n) {
            Some(i) => Ok(i),
            None => {
                err(key, format!("no column `{n}` in the record (columns: {})", names.join(", ")))
            }
        },
        None if default < names.len() => Ok(default),
        None => err(
            "file",
            format!("the record has {} columns: expected at least {}", names.len(), default + 1),
        ),
    }
}

/// A shared-reader error as an error of option `file`, with its line.
fn csv_err(e: CsvError) -> ExcitationError {
    let message = match e.line() {
        Some(line) => format!("line {line}: {e}"),
        None => e.to_string(),
    };
    ExcitationError { key: "file".into(), message }
}

/// The trimmed fields of record line `line`, refused unless there are `expected`.
fn record_fields(
    line: usize,
    row: &StringRecord,
    expected: usize,
) -> Result<Vec<&str>, ExcitationError> {
    let fields: Vec<&str> = row.iter().collect();
    if fields.len() != expected {
        return err("file", format!("line {line}: {} fields, expected {expected}", fields.len()));
    }
    Ok(fields)
}

/// The finite number in field `i` of record line `line` (columns `names`).
fn record_number(
    names: &[&str],
    fields: &[&str],
    line: usize,
    i: usize,
) -> Result<f64, ExcitationError> {
    match fields[i].parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => err(
            "file",
            format!("line {line}, column `{}`: {:?} is not a finite number", names[i], fields[i]),
        ),
    }
}

/// The sampling step of a strictly increasing, uniform time column.
fn uniform_step(t: &[f64]) -> Result<f64, ExcitationError> {
    if t.len() < 2 {
        return err("file", format!("{} samples: expected at least 2", t.len()));
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    if dt <= 0.0 {
        return err("file", "the time column does not increase".into());
    }
    for (k, w) in t.windows(2).enumerate() {
        if ((w[1] - w[0]) - dt).abs() > 1e-6 * dt {
            return err(
                "file",
                format!(
                    "time step {} → {} is {} s: expected uniform {dt} s",
                    k + 1,
                    k + 2,
                    w[1] - w[0]
                ),
            );
        }
    }
    Ok(dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(text: &str, units: RecordUnits, direction: Shaking) -> Excitation {
        Excitation::Record {
            file: None,
            csv: Some(text.into()),
            units,
            direction,
            scale: 2.0,
            column_x: None,
            column_y: None,
        }
    }

    #[test]
    fn record_in_g_is_scaled_to_m_s2() {
        let text = "t,ax,ay\n# comment\n0,0,0\n0.01,0.1,-0.2\n0.02,0.0,0.3\n";
        let b = record(text, RecordUnits::G, Shaking::Xy).base_input().unwrap();
        assert!((b.dt_s - 0.01).abs() < 1e-15);
        let x = b.x_m_s2.unwrap();
        let y = b.y_m_s2.unwrap();
        assert!((x[1] - 0.2 * G_M_S2).abs() < 1e-12 && (y[2] - 0.6 * G_M_S2).abs() < 1e-12);
        // By default `y` alone reads the second column; `column_y` names another.
        let b = record(text, RecordUnits::MPerS2, Shaking::Y).base_input().unwrap();
        assert!(b.x_m_s2.is_none() && (b.y_m_s2.unwrap()[1] - 0.2).abs() < 1e-15);
        let mut r = record(text, RecordUnits::MPerS2, Shaking::Y);
        if let Excitation::Record { column_y, .. } = &mut r {
            *column_y = Some("ay".into());
        }
        assert!((r.base_input().unwrap().y_m_s2.unwrap()[1] + 0.4).abs() < 1e-15);
    }

    #[test]
    fn record_defects_name_the_line() {
        let e = record("t,a\n0,0\n0.01,x\n", RecordUnits::G, Shaking::X).base_input().unwrap_err();
        assert!(e.to_string().contains("line 3") && e.key == "file", "{e}");
        let e = record("t,a\n0,0\n0.01,1\n0.03,1\n", RecordUnits::G, Shaking::X)
            .base_input()
            .unwrap_err();
        assert!(e.to_string().contains("uniform"), "{e}");
        let e = record("t,a\n0,0\n0.01,1\n", RecordUnits::G, Shaking::Xy).base_input().unwrap_err();
        assert!(e.to_string().contains("at least 3"), "{e}");
    }

    #[test]
    fn sweep_peaks_at_its_pga() {
        let s = Excitation::SineSweep {
            pga_g: 0.15,
            duration_s: 10.0,
            dt_s: 0.005,
            direction: Shaking::X,
            f_start_hz: 6.0,
            f_end_hz: 0.8,
            ramp_s: 2.0,
        };
        let b = s.base_input().unwrap();
        let x = b.x_m_s2.unwrap();
        assert_eq!(x.len(), 2001);
        let peak = x.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        assert!(peak <= 0.15 * G_M_S2 + 1e-12 && peak > 0.99 * 0.15 * G_M_S2, "{peak}");
    }

    #[test]
    fn sweep_defects_name_the_key() {
        // pga_g, duration_s, dt_s, f_start_hz, ramp_s, edited by each case
        type Edit = fn(&mut [f64; 5]);
        let sweep = |edit: Edit| {
            let mut v = [0.15, 10.0, 0.005, 6.0, 2.0];
            edit(&mut v);
            Excitation::SineSweep {
                pga_g: v[0],
                duration_s: v[1],
                dt_s: v[2],
                direction: Shaking::X,
                f_start_hz: v[3],
                f_end_hz: 0.8,
                ramp_s: v[4],
            }
            .base_input()
            .unwrap_err()
        };
        let cases: [(Edit, &str, &str); 6] = [
            (|v| v[0] = 0.0, "pga_g", "finite number > 0"),
            (|v| v[1] = f64::NAN, "duration_s", "finite number > 0"),
            (|v| v[3] = -1.0, "f_start_hz", "finite number > 0"),
            (|v| v[4] = 6.0, "ramp_s", "duration_s / 2"),
            (|v| (v[1], v[2], v[4]) = (0.01, 0.006, 0.0), "dt_s", "duration_s / 2"),
            (|v| v[2] = 0.02, "dt_s", "10 samples per cycle at 6 Hz"),
        ];
        for (edit, key, expected) in cases {
            let e = sweep(edit);
            assert!(e.key == key && e.message.contains(expected), "{key}: {e}");
        }
    }

    #[test]
    fn record_needs_exactly_one_source() {
        let mut r = record("t,a\n0,0\n0.01,1\n", RecordUnits::G, Shaking::X);
        if let Excitation::Record { file, .. } = &mut r {
            *file = Some("elsewhere.csv".into());
        }
        let e = r.base_input().unwrap_err();
        assert!(e.key == "file" && e.message.contains("exactly one"), "{e}");
    }
}
