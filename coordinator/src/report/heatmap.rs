//! Heat maps of a signed quantity over a regular grid, e.g. a
//! time-frequency residual map (x: time in s, y: frequency in Hz, z:
//! measured minus simulated spectral level). Colours follow a diverging
//! blue-white-red scale symmetric about zero with a colour bar; missing
//! cells (NaN) are grey. The cells are drawn as one inline PNG (one pixel
//! per cell, at most [`MAX_CELLS_X`] x [`MAX_CELLS_Y`]; larger grids are
//! reduced by keeping, per block, the value of largest magnitude).

use super::axis::Axis;
use super::colour::{diverging_rgb, hex};
use super::frame::{draw_frame, FrameSpec, LegendItem, PlotSize, Swatch, TICK_PX};
use super::png::png_rgb_base64;
use super::svg::{Anchor, Stroke, Svg, TextStyle};
use super::ReportError;

/// Most cells drawn along x; more are reduced.
pub const MAX_CELLS_X: usize = 1200;
/// Most cells drawn along y; more are reduced.
pub const MAX_CELLS_Y: usize = 600;

/// A heat map on a regular grid of cell centres.
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap {
    /// Title over the map.
    pub title: String,
    /// x axis label with units, e.g. "time (s)".
    pub x_label: String,
    /// y axis label with units, e.g. "frequency (Hz)".
    pub y_label: String,
    /// Colour bar label with units, e.g. "residual (dB)".
    pub z_label: String,
    /// Cell centres along x: finite, increasing, evenly spaced (n_x).
    pub x: Vec<f64>,
    /// Cell centres along y: finite, increasing, evenly spaced (n_y).
    pub y: Vec<f64>,
    /// Values, one column per x: `z[ix][iy]`, shape (n_x, n_y); NaN = missing.
    pub z: Vec<Vec<f64>>,
    /// Colour scale runs over ±`z_limit`; `None` uses the largest |z|.
    pub z_limit: Option<f64>,
    /// Size of the drawing.
    pub size: PlotSize,
}

/// Draw `map` as a standalone SVG element.
pub fn heatmap(map: &Heatmap) -> Result<String, ReportError> {
    map.size.check(&map.title)?;
    let (x_lo, x_hi) = extent(&map.title, "x", &map.x)?;
    let (y_lo, y_hi) = extent(&map.title, "y", &map.y)?;
    check_shape(map)?;
    let limit = colour_limit(map)?;
    let (nx, ny, cells) = reduce(&map.z, map.y.len());
    let has_gaps = cells.iter().any(|v| !v.is_finite());
    let legend: Vec<LegendItem> = if has_gaps {
        vec![LegendItem {
            label: "missing".into(),
            swatch: Swatch::Box { colour: "#bebebe", opacity: 1.0 },
        }]
    } else {
        vec![]
    };
    let spec = FrameSpec {
        title: &map.title,
        x_label: &map.x_label,
        y_label: &map.y_label,
        legend: &legend,
        size: map.size,
        extra_bottom: 0.0,
        extra_right: 86.0,
    };
    let mut svg = Svg::new(map.size.width_px as f64, map.size.height_px as f64, &map.title);
    let (x, y) =
        draw_frame(&mut svg, &spec, Axis::exact(x_lo, x_hi, 8), Axis::exact(y_lo, y_hi, 6), true);
    let mut rgb = Vec::with_capacity(3 * nx * ny);
    for iy in (0..ny).rev() {
        for ix in 0..nx {
            rgb.extend_from_slice(&diverging_rgb(cells[ix * ny + iy] / limit));
        }
    }
    let (left, right, top, bottom) = (x.px_lo, x.px_hi, y.px_hi, y.px_lo);
    let image = png_rgb_base64(nx as u32, ny as u32, &rgb)
        .map_err(|message| ReportError::Image { plot: map.title.clone(), message })?;
    svg.png(left, top, right - left, bottom - top, &image);
    svg.rect(left, top, right - left, bottom - top, "none", 1.0, Some(Stroke::solid("#444", 1.0)));
    colour_bar(&mut svg, right + 18.0, top, bottom, limit, &map.z_label);
    Ok(svg.finish())
}

/// Outer edges of evenly spaced cell centres `c`.
fn extent(plot: &str, axis: &str, c: &[f64]) -> Result<(f64, f64), ReportError> {
    let bad = |i: usize, v: f64, expected: &str| ReportError::BadValue {
        plot: plot.to_string(),
        key: format!("{axis}[{i}]"),
        value: v,
        expected: expected.to_string(),
    };
    if c.is_empty() {
        return Err(ReportError::Empty {
            plot: plot.to_string(),
            what: format!("no {axis} cells"),
        });
    }
    if let Some(i) = c.iter().position(|v| !v.is_finite()) {
        return Err(bad(i, c[i], "finite"));
    }
    if c.len() == 1 {
        let half = if c[0] == 0.0 { 0.5 } else { c[0].abs() * 0.5 };
        return Ok((c[0] - half, c[0] + half));
    }
    let step = (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64;
    for i in 1..c.len() {
        let expected = c[0] + step * i as f64;
        if c[i] <= c[i - 1] || (c[i] - expected).abs() > 1e-3 * step.abs() {
            return Err(bad(i, c[i], &format!("evenly spaced and increasing, about {expected}")));
        }
    }
    Ok((c[0] - step / 2.0, c[c.len() - 1] + step / 2.0))
}

fn check_shape(map: &Heatmap) -> Result<(), ReportError> {
    let mismatch = |what: String, expected, found| ReportError::LengthMismatch {
        plot: map.title.clone(),
        what,
        expected,
        found,
    };
    if map.z.len() != map.x.len() {
        return Err(mismatch("z columns".into(), map.x.len(), map.z.len()));
    }
    for (i, col) in map.z.iter().enumerate() {
        if col.len() != map.y.len() {
            return Err(mismatch(format!("z[{i}]"), map.y.len(), col.len()));
        }
    }
    Ok(())
}

/// The colour scale's half-range: the caller's, or the largest |z|.
fn colour_limit(map: &Heatmap) -> Result<f64, ReportError> {
    if let Some(l) = map.z_limit {
        if !(l.is_finite() && l > 0.0) {
            return Err(ReportError::BadValue {
                plot: map.title.clone(),
                key: "z_limit".into(),
                value: l,
                expected: "finite and > 0".into(),
            });
        }
        return Ok(l);
    }
    let max = map
        .z
        .iter()
        .flatten()
        .filter(|v| v.is_finite())
        .fold(None, |m: Option<f64>, v| Some(m.map_or(v.abs(), |m| m.max(v.abs()))));
    match max {
        None => {
            Err(ReportError::Empty { plot: map.title.clone(), what: "no finite z value".into() })
        }
        Some(m) if m > 0.0 => Ok(m),
        Some(_) => Ok(1.0),
    }
}

/// Cells reduced to at most MAX_CELLS_X x MAX_CELLS_Y by keeping the value of
/// largest magnitude per block; returns (n_x, n_y, cells[ix * n_y + iy]).
fn reduce(z: &[Vec<f64>], ny: usize) -> (usize, usize, Vec<f64>) {
    let (bx, by) = (z.len().div_ceil(MAX_CELLS_X), ny.div_ceil(MAX_CELLS_Y));
    let (nx_out, ny_out) = (z.len().div_ceil(bx), ny.div_ceil(by));
    let mut out = vec![f64::NAN; nx_out * ny_out];
    for (ix, col) in z.iter().enumerate() {
        for (iy, &v) in col.iter().enumerate() {
            let cell = &mut out[(ix / bx) * ny_out + iy / by];
            if v.is_finite() && (cell.is_nan() || v.abs() > cell.abs()) {
                *cell = v;
            }
        }
    }
    (nx_out, ny_out, out)
}

/// The colour bar from `top` to `bottom` at `x0`, ticks over ±`limit`.
fn colour_bar(svg: &mut Svg, x0: f64, top: f64, bottom: f64, limit: f64, label: &str) {
    const STEPS: usize = 48;
    let h = (bottom - top) / STEPS as f64;
    for k in 0..STEPS {
        let t = 1.0 - 2.0 * (k as f64 + 0.5) / STEPS as f64;
        svg.rect(x0, top + k as f64 * h, 14.0, h + 0.5, &hex(diverging_rgb(t)), 1.0, None);
    }
    svg.rect(x0, top, 14.0, bottom - top, "none", 1.0, Some(Stroke::solid("#444", 1.0)));
    let axis = Axis::exact(-limit, limit, 4).placed(bottom, top);
    for t in axis.ticks.iter().filter(|t| !t.label.is_empty()) {
        let Some(p) = axis.map(t.value) else { continue };
        svg.line(x0 + 14.0, p, x0 + 18.0, p, Stroke::solid("#444", 1.0));
        svg.text(x0 + 21.0, p + 4.0, &t.label, TextStyle::new(TICK_PX, Anchor::Start));
    }
    let style = TextStyle { rotate_deg: 90.0, ..TextStyle::new(TICK_PX + 1.0, Anchor::Middle) };
    svg.text(x0 + 62.0, (top + bottom) / 2.0, label, style);
}

#[cfg(test)]
mod tests {
    use super::super::wellformed::check_svg;
    use super::*;

    fn map(nx: usize, ny: usize) -> Heatmap {
        Heatmap {
            title: "residual map".into(),
            x_label: "time (s)".into(),
            y_label: "frequency (Hz)".into(),
            z_label: "residual (dB)".into(),
            x: (0..nx).map(|i| 0.5 * i as f64).collect(),
            y: (0..ny).map(|j| 0.25 + 0.5 * j as f64).collect(),
            z: (0..nx).map(|i| (0..ny).map(|j| (i as f64 - j as f64) / 10.0).collect()).collect(),
            z_limit: None,
            size: PlotSize::default(),
        }
    }

    #[test]
    fn draws_a_png_and_a_colour_bar() {
        let svg = heatmap(&map(40, 20)).unwrap();
        check_svg(&svg).unwrap();
        assert!(svg.contains("data:image/png;base64,iVBORw0KGgo"), "PNG signature in base64");
        assert!(svg.contains("residual (dB)"));
    }

    #[test]
    fn missing_cells_get_a_legend_entry() {
        let mut m = map(5, 5);
        m.z[2][3] = f64::NAN;
        assert!(heatmap(&m).unwrap().contains(">missing<"));
    }

    #[test]
    fn bad_shapes_and_grids_are_errors() {
        let mut m = map(5, 5);
        m.z[4].pop();
        assert_eq!(
            heatmap(&m).unwrap_err().to_string(),
            "residual map: z[4]: lengths differ (5 expected, 4 found)"
        );
        let mut m = map(5, 5);
        m.x[3] = 7.0;
        assert!(matches!(heatmap(&m), Err(ReportError::BadValue { ref key, .. }) if key == "x[3]"));
        let mut m = map(5, 5);
        m.z = vec![vec![f64::NAN; 5]; 5];
        assert!(matches!(heatmap(&m), Err(ReportError::Empty { .. })));
        assert!(matches!(heatmap(&map(0, 5)), Err(ReportError::Empty { .. })));
    }

    #[test]
    fn reduction_keeps_the_largest_magnitude() {
        let mut z = vec![vec![0.1; 3]; 2500];
        z[1234][1] = -9.0;
        let (nx, ny, cells) = reduce(&z, 3);
        assert_eq!((nx, ny), (834, 3));
        assert_eq!(cells.iter().copied().fold(0.0, f64::min), -9.0);
    }
}
