//! Drives one material through an imposed deformation protocol, one
//! committed step per row (set trial, then commit), as the OpenSees
//! fixtures were made with `testUniaxialMaterial` + `setStrain`.
//!
//! Protocol CSV: header `step,deformation_mm`, then one row per step.
//! Response CSV: header `deformation_mm,force_N,tangent_N_per_mm`.

use std::io::Write;
use std::path::Path;

use super::{build, MaterialError, MaterialSpec, UniaxialMaterial};

/// Why a protocol could not be read or driven.
#[derive(Debug, thiserror::Error)]
pub enum DriverError {
    /// The material failed to build or to take a step.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// File path.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The material JSON could not be parsed.
    #[error("{path}: not a material object: {message}")]
    Spec {
        /// File path.
        path: String,
        /// What serde reported.
        message: String,
    },
    /// A protocol line is malformed.
    #[error("protocol line {line}: {message}")]
    Protocol {
        /// 1-based line number in the file.
        line: usize,
        /// What was expected.
        message: String,
    },
}

/// (deformation mm, force N, tangent N/mm) of every committed step.
pub fn drive(
    spec: &MaterialSpec,
    deformations_mm: &[f64],
) -> Result<Vec<(f64, f64, f64)>, MaterialError> {
    let mut material = build(spec)?;
    drive_material(material.as_mut(), deformations_mm)
}

/// Same as [`drive`] on an existing material (its state moves on).
pub fn drive_material(
    material: &mut dyn UniaxialMaterial,
    deformations_mm: &[f64],
) -> Result<Vec<(f64, f64, f64)>, MaterialError> {
    let mut rows = Vec::with_capacity(deformations_mm.len());
    for &d in deformations_mm {
        material.set_trial(d)?;
        material.commit();
        rows.push((d, material.force(), material.tangent()));
    }
    Ok(rows)
}

/// Parses protocol CSV text (`step,deformation_mm`) into deformations (mm).
pub fn read_protocol(text: &str) -> Result<Vec<f64>, DriverError> {
    let mut lines = text.lines().enumerate();
    let header = lines.next().map(|(_, h)| h.trim()).unwrap_or("");
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = columns.iter().position(|c| *c == "deformation_mm").ok_or_else(|| {
        DriverError::Protocol {
            line: 1,
            message: format!("header {header:?} lacks the column deformation_mm"),
        }
    })?;
    let mut out = Vec::new();
    for (i, line) in lines {
        let line_no = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let field =
            line.split(',').nth(col).map(str::trim).ok_or_else(|| DriverError::Protocol {
                line: line_no,
                message: format!("expected {} columns, got {line:?}", columns.len()),
            })?;
        let d: f64 = field.parse().map_err(|_| DriverError::Protocol {
            line: line_no,
            message: format!("deformation_mm {field:?} is not a number"),
        })?;
        if !d.is_finite() {
            return Err(DriverError::Protocol {
                line: line_no,
                message: format!("deformation_mm {field:?} is not finite"),
            });
        }
        out.push(d);
    }
    Ok(out)
}

/// Reads a protocol CSV file.
pub fn read_protocol_file(path: &Path) -> Result<Vec<f64>, DriverError> {
    let text = std::fs::read_to_string(path).map_err(|e| DriverError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    read_protocol(&text)
}

/// Writes `deformation_mm,force_N,tangent_N_per_mm` rows (shortest
/// round-trip decimal form).
pub fn write_response<W: Write>(out: &mut W, rows: &[(f64, f64, f64)]) -> std::io::Result<()> {
    writeln!(out, "deformation_mm,force_N,tangent_N_per_mm")?;
    for (d, f, k) in rows {
        writeln!(out, "{d},{f},{k}")?;
    }
    Ok(())
}

/// Writes the response CSV to a file.
pub fn write_response_file(path: &Path, rows: &[(f64, f64, f64)]) -> Result<(), DriverError> {
    let io = |e: std::io::Error| DriverError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = std::io::BufWriter::new(file);
    write_response(&mut w, rows).map_err(io)?;
    w.flush().map_err(io)
}

/// Reads a material JSON object (as in the format's `materials` list; `id`
/// and unknown keys ignored).
pub fn read_material_file(path: &Path) -> Result<MaterialSpec, DriverError> {
    let text = std::fs::read_to_string(path).map_err(|e| DriverError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    serde_json::from_str(&text)
        .map_err(|e| DriverError::Spec { path: path.display().to_string(), message: e.to_string() })
}

/// `ceilfarm fe material MATERIAL.json PROTOCOL.csv --out OUT.csv`: drives
/// the material through the protocol and writes the response; returns the
/// number of steps written.
pub fn run_files(
    material_json: &Path,
    protocol_csv: &Path,
    out_csv: &Path,
) -> Result<usize, DriverError> {
    let spec = read_material_file(material_json)?;
    let d = read_protocol_file(protocol_csv)?;
    let rows = drive(&spec, &d)?;
    write_response_file(out_csv, &rows)?;
    Ok(rows.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn protocol_errors_name_the_line() {
        let err = read_protocol("step,deformation_mm\n0,0.0\n1,abc\n").unwrap_err();
        assert!(matches!(err, DriverError::Protocol { line: 3, .. }), "{err}");
        let err = read_protocol("step,d\n0,1\n").unwrap_err();
        assert!(matches!(err, DriverError::Protocol { line: 1, .. }));
    }

    #[test]
    fn drives_an_elastic_spring_and_writes_csv() {
        let d = read_protocol("step,deformation_mm\n0,0\n1,0.5\n2,-1\n").unwrap();
        let rows = drive(&MaterialSpec::Elastic { k: 4.0 }, &d).unwrap();
        assert_eq!(rows, vec![(0.0, 0.0, 4.0), (0.5, 2.0, 4.0), (-1.0, -4.0, 4.0)]);
        let mut buf = Vec::new();
        write_response(&mut buf, &rows).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert_eq!(text.lines().nth(2), Some("0.5,2,4"));
    }
}
