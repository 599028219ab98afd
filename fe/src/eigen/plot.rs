//! Plan view of the first mode shapes as SVG: for each mode a panel with the
//! nodes at rest (grey) and displaced by the scaled in-plane shape (blue
//! arrows), titled with the frequency. Reads a `fe run` output directory.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Why the plot could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A CSV row does not parse.
    #[error("{path}:{line}: {expected}")]
    Row {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected.
        expected: &'static str,
    },
}

/// One node of one mode: (mode, x_mm, y_mm, phi_x, phi_y).
type ShapeRow = (usize, f64, f64, f64, f64);

fn read_rows(path: &Path, cols: usize) -> Result<Vec<Vec<f64>>, PlotError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| PlotError::Io { path: path.to_path_buf(), source })?;
    let mut rows = vec![];
    for (k, line) in text.lines().enumerate().skip(1).filter(|(_, l)| !l.trim().is_empty()) {
        let v: Result<Vec<f64>, _> = line.split(',').map(|x| x.trim().parse::<f64>()).collect();
        match v {
            Ok(v) if v.len() >= cols => rows.push(v),
            _ => {
                let expected = "expected numeric columns as written by `fe run`";
                return Err(PlotError::Row { path: path.to_path_buf(), line: k + 1, expected });
            }
        }
    }
    Ok(rows)
}

/// SVG text of the first `n` modes in plan.
pub fn plan_svg(freq_hz: &[f64], shapes: &[ShapeRow], n: usize) -> String {
    let n = n.min(freq_hz.len()).max(1);
    let (w, h, pad) = (360.0, 360.0, 30.0);
    let xmax = shapes.iter().fold(1.0_f64, |m, r| m.max(r.1));
    let ymax = shapes.iter().fold(1.0_f64, |m, r| m.max(r.2));
    let scale = (w - 2.0 * pad) / xmax.max(ymax);
    let cols = n.min(3);
    let rows = n.div_ceil(cols);
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" font-family="sans-serif" font-size="13">"#,
        w * cols as f64,
        h * rows as f64
    );
    for mode in 1..=n {
        let (ox, oy) = (((mode - 1) % cols) as f64 * w, ((mode - 1) / cols) as f64 * h);
        let nodes: Vec<&ShapeRow> = shapes.iter().filter(|r| r.0 == mode).collect();
        let amp = nodes.iter().fold(0.0_f64, |m, r| m.max(r.3.hypot(r.4)));
        let k = if amp > 0.0 { 0.06 * xmax.max(ymax) / amp } else { 0.0 };
        let px = |x: f64| ox + pad + x * scale;
        let py = |y: f64| oy + h - pad - y * scale;
        let _ = write!(
            s,
            r#"<text x="{}" y="{}">mode {mode}: {:.3} Hz</text>"#,
            ox + pad,
            oy + 18.0,
            freq_hz[mode - 1]
        );
        for r in &nodes {
            let _ = write!(
                s,
                r##"<circle cx="{:.1}" cy="{:.1}" r="1.5" fill="#999"/>"##,
                px(r.1),
                py(r.2)
            );
            let _ = write!(
                s,
                r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#1f5fbf" stroke-width="1"/>"##,
                px(r.1),
                py(r.2),
                px(r.1 + k * r.3),
                py(r.2 + k * r.4)
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

/// Reads `dir/eigen.csv` and `dir/modeshapes.csv` and writes the plan SVG of the first `n` modes.
pub fn plot_modes_dir(dir: &Path, out: &Path, n: usize) -> Result<(), PlotError> {
    let freq: Vec<f64> = read_rows(&dir.join("eigen.csv"), 2)?.iter().map(|r| r[1]).collect();
    let shapes: Vec<ShapeRow> = read_rows(&dir.join("modeshapes.csv"), 7)?
        .iter()
        .map(|r| (r[0] as usize, r[2], r[3], r[4], r[5]))
        .collect();
    std::fs::write(out, plan_svg(&freq, &shapes, n))
        .map_err(|source| PlotError::Io { path: out.to_path_buf(), source })
}
