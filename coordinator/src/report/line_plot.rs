//! Line plots of series y(x): time histories (measured vs simulated),
//! spectra (log axes), backbone curves. Missing readings (NaN or infinite
//! values) break the line; on a log axis non-positive values are treated as
//! missing. Series longer than [`MAX_POINTS_PER_SERIES`] are decimated by
//! min/max buckets ([`decimate_min_max`]) so every peak is still drawn; the
//! axis ranges always come from the full data.

use super::axis::{data_range, Scale};
use super::colour::series_colour;
use super::decimate::decimate_min_max;
use super::frame::{axis_for, draw_frame, FrameSpec, LegendItem, PlotSize, Swatch};
use super::svg::{PathData, Stroke, Svg};
use super::ReportError;

/// Most points drawn per series; longer series are decimated.
pub const MAX_POINTS_PER_SERIES: usize = 4000;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A solid line.
    Solid,
    /// A dashed line.
    Dashed,
    /// Dots, no line.
    Points,
}

/// One named series of (x, y) pairs, same length; NaN marks a missing reading.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text, e.g. "measured A13".
    pub name: String,
    /// Abscissae (in the units of the plot's x label).
    pub x: Vec<f64>,
    /// Ordinates (in the units of the plot's y label).
    pub y: Vec<f64>,
    /// Line or points.
    pub style: SeriesStyle,
}

/// A line plot: title, axis labels with units, series, scales, size.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePlot {
    /// Title over the plot.
    pub title: String,
    /// x axis label with units, e.g. "time (s)".
    pub x_label: String,
    /// y axis label with units, e.g. "acceleration (m/s²)".
    pub y_label: String,
    /// The series, drawn in order (later on top), coloured by position.
    pub series: Vec<Series>,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Size of the drawing.
    pub size: PlotSize,
}

/// Draw `plot` as a standalone SVG element.
pub fn line_plot(plot: &LinePlot) -> Result<String, ReportError> {
    plot.size.check(&plot.title)?;
    let scale = |log: bool| if log { Scale::Log10 } else { Scale::Linear };
    let (sx, sy) = (scale(plot.log_x), scale(plot.log_y));
    let mut pairs: Vec<(f64, f64)> = Vec::new();
    for s in &plot.series {
        if s.x.len() != s.y.len() {
            return Err(ReportError::LengthMismatch {
                plot: plot.title.clone(),
                what: format!("series \"{}\" y", s.name),
                expected: s.x.len(),
                found: s.y.len(),
            });
        }
        pairs.extend(
            s.x.iter()
                .zip(&s.y)
                .map(|(&x, &y)| (x, y))
                .filter(|&(x, y)| drawable(x, sx) && drawable(y, sy)),
        );
    }
    if pairs.is_empty() {
        let what =
            if plot.series.is_empty() { "no series" } else { "no series has a drawable point" };
        return Err(ReportError::Empty { plot: plot.title.clone(), what: what.to_string() });
    }
    let x = axis_for(data_range(pairs.iter().map(|p| p.0), sx), sx, 8);
    let y = axis_for(data_range(pairs.iter().map(|p| p.1), sy), sy, 6);
    let mut svg = Svg::new(plot.size.width_px as f64, plot.size.height_px as f64, &plot.title);
    let legend = legend(&plot.series);
    let spec = FrameSpec {
        title: &plot.title,
        x_label: &plot.x_label,
        y_label: &plot.y_label,
        legend: &legend,
        size: plot.size,
        extra_bottom: 0.0,
        extra_right: 0.0,
    };
    let (x, y) = draw_frame(&mut svg, &spec, x, y, true);
    for (i, s) in plot.series.iter().enumerate() {
        let (xd, yd) = decimate_min_max(&s.x, &s.y, MAX_POINTS_PER_SERIES);
        let pts = xd.iter().zip(&yd).map(|(&a, &b)| Some((x.map(a)?, y.map(b)?)));
        draw_series(&mut svg, pts, s.style, series_colour(i));
    }
    Ok(svg.finish())
}

/// Whether `v` can be placed on an axis of `scale`.
fn drawable(v: f64, scale: Scale) -> bool {
    v.is_finite() && (scale == Scale::Linear || v > 0.0)
}

fn legend(series: &[Series]) -> Vec<LegendItem> {
    series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let colour = series_colour(i);
            let swatch = match s.style {
                SeriesStyle::Solid => Swatch::Line { colour, dash: None },
                SeriesStyle::Dashed => Swatch::Line { colour, dash: Some("6 4") },
                SeriesStyle::Points => Swatch::Dot { colour },
            };
            LegendItem { label: s.name.clone(), swatch }
        })
        .collect()
}

fn draw_series(
    svg: &mut Svg,
    pts: impl Iterator<Item = Option<(f64, f64)>>,
    style: SeriesStyle,
    colour: &str,
) {
    match style {
        SeriesStyle::Points => {
            for (px, py) in pts.flatten() {
                svg.circle(px, py, 2.5, colour, None);
            }
        }
        SeriesStyle::Solid | SeriesStyle::Dashed => {
            let mut d = PathData::default();
            pts.for_each(|p| d.point(p));
            let dash = (style == SeriesStyle::Dashed).then_some("6 4");
            svg.path(&d.into_string(), Stroke { colour, width: 1.5, dash });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::wellformed::check_svg;
    use super::*;

    fn plot(series: Vec<Series>) -> LinePlot {
        LinePlot {
            title: "run18 <A13>".into(),
            x_label: "time (s)".into(),
            y_label: "acceleration (m/s²)".into(),
            series,
            log_x: false,
            log_y: false,
            size: PlotSize::default(),
        }
    }

    fn series(name: &str, x: Vec<f64>, y: Vec<f64>) -> Series {
        Series { name: name.into(), x, y, style: SeriesStyle::Solid }
    }

    #[test]
    fn draws_title_labels_and_legend_escaped() {
        let svg =
            line_plot(&plot(vec![series("measured & filtered", vec![0.0, 1.0], vec![0.0, 2.0])]))
                .unwrap();
        check_svg(&svg).unwrap();
        assert!(svg.contains("run18 &lt;A13&gt;"));
        assert!(svg.contains("acceleration (m/s²)"));
        assert!(svg.contains("measured &amp; filtered"));
    }

    #[test]
    fn empty_input_is_an_error_not_a_panic() {
        let err = line_plot(&plot(vec![])).unwrap_err();
        assert_eq!(err.to_string(), "run18 <A13>: nothing to draw (no series)");
        let err = line_plot(&plot(vec![series("a", vec![], vec![])])).unwrap_err();
        assert!(matches!(err, ReportError::Empty { .. }));
        let err = line_plot(&plot(vec![series("a", vec![f64::NAN], vec![1.0])])).unwrap_err();
        assert!(matches!(err, ReportError::Empty { .. }));
    }

    #[test]
    fn length_mismatch_names_the_series() {
        let err = line_plot(&plot(vec![series("base", vec![0.0, 1.0], vec![0.0])])).unwrap_err();
        assert_eq!(
            err.to_string(),
            "run18 <A13>: series \"base\" y: lengths differ (2 expected, 1 found)"
        );
    }

    #[test]
    fn nan_gap_splits_the_path() {
        let y = vec![1.0, 2.0, f64::NAN, 3.0, 4.0];
        let svg = line_plot(&plot(vec![series("m", (0..5).map(f64::from).collect(), y)])).unwrap();
        let d = svg.split("<path d=\"").nth(1).unwrap().split('"').next().unwrap();
        assert_eq!(d.matches('M').count(), 2, "{d}");
        assert_eq!(d.matches('L').count(), 2, "{d}");
    }

    #[test]
    fn constant_series_and_single_point_draw() {
        let svg = line_plot(&plot(vec![series("c", vec![0.0, 1.0, 2.0], vec![5.0; 3])])).unwrap();
        check_svg(&svg).unwrap();
        let svg = line_plot(&plot(vec![series("p", vec![1.0], vec![1.0])])).unwrap();
        assert!(svg.contains("h0"), "a lone point is drawn as a dot");
    }

    #[test]
    fn huge_series_is_decimated() {
        let n = 200_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
        let y: Vec<f64> = x.iter().map(|t| (7.0 * t).sin()).collect();
        let svg = line_plot(&plot(vec![series("m", x, y)])).unwrap();
        let d = svg.split("<path d=\"").nth(1).unwrap().split('"').next().unwrap();
        assert!(d.matches('L').count() < MAX_POINTS_PER_SERIES, "{}", d.len());
        assert!(svg.len() < 120_000, "{} bytes", svg.len());
    }

    #[test]
    fn log_axes_drop_nonpositive_values() {
        let mut p =
            plot(vec![series("psd", vec![0.0, 1.0, 10.0, 100.0], vec![0.0, 1e-3, 1e-1, 1e-5])]);
        p.log_x = true;
        p.log_y = true;
        let svg = line_plot(&p).unwrap();
        check_svg(&svg).unwrap();
        let d = svg.split("<path d=\"").nth(1).unwrap().split('"').next().unwrap();
        assert_eq!(d.matches('M').count(), 1, "{d}");
        assert_eq!(d.matches('L').count(), 2, "{d}");
    }
}
