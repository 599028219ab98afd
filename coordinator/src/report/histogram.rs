//! Histograms of samples as a probability density, for posterior
//! marginals: bars of the sample density, the prior range as a shaded
//! band, and vertical markers (e.g. the posterior mean, a true value).
//! Bin count by the Freedman–Diaconis rule (bin width 2 IQR n^(-1/3)),
//! clamped to 10..=60, unless the caller fixes it.

use super::axis::{data_range, Axis, Scale};
use super::colour::series_colour;
use super::frame::{axis_for, draw_frame, FrameSpec, LegendItem, PlotSize, Swatch};
use super::svg::{Stroke, Svg};
use super::ReportError;

/// A shaded range on the x axis, e.g. the prior's support or 95 % interval.
#[derive(Debug, Clone, PartialEq)]
pub struct PriorBand {
    /// Legend text, e.g. "prior (uniform 0.5–4 N/mm)".
    pub label: String,
    /// Low end (x units).
    pub low: f64,
    /// High end (x units).
    pub high: f64,
}

/// A vertical line at `x` with a legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Legend text, e.g. "posterior mean".
    pub label: String,
    /// Position (x units).
    pub x: f64,
}

/// A density histogram of samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Histogram {
    /// Title over the plot, e.g. the parameter's name.
    pub title: String,
    /// x label with units, e.g. "K_friction (N/mm)".
    pub x_label: String,
    /// Samples; non-finite ones are ignored.
    pub samples: Vec<f64>,
    /// Number of bins (1 to 500); `None` chooses by Freedman–Diaconis.
    pub bins: Option<usize>,
    /// Prior range drawn as a band.
    pub prior: Option<PriorBand>,
    /// Vertical markers.
    pub markers: Vec<Marker>,
    /// Size of the drawing.
    pub size: PlotSize,
}

/// Draw `hist` as a standalone SVG element.
pub fn histogram(hist: &Histogram) -> Result<String, ReportError> {
    hist.size.check(&hist.title)?;
    let s = finite_sorted(hist)?;
    let n_bins = bin_count(hist, &s)?;
    let (edges, density) = bin(&s, n_bins);
    let extra =
        hist.prior.iter().flat_map(|p| [p.low, p.high]).chain(hist.markers.iter().map(|m| m.x));
    let x_range = data_range(edges.iter().copied().chain(extra), Scale::Linear);
    let y_range = data_range(density.iter().copied().chain([0.0]), Scale::Linear);
    let legend = legend(hist);
    let spec = FrameSpec {
        title: &hist.title,
        x_label: &hist.x_label,
        y_label: "probability density",
        legend: &legend,
        size: hist.size,
        extra_bottom: 0.0,
        extra_right: 0.0,
    };
    let mut svg = Svg::new(hist.size.width_px as f64, hist.size.height_px as f64, &hist.title);
    let (x, y) = draw_frame(
        &mut svg,
        &spec,
        axis_for(x_range, Scale::Linear, 6),
        axis_for(y_range, Scale::Linear, 5),
        true,
    );
    if let Some(p) = &hist.prior {
        band(&mut svg, &x, &y, p);
    }
    bars(&mut svg, &x, &y, &edges, &density);
    markers(&mut svg, &x, &y, &hist.markers);
    Ok(svg.finish())
}

/// The finite samples of `hist`, sorted; an error when there are none.
fn finite_sorted(hist: &Histogram) -> Result<Vec<f64>, ReportError> {
    let mut s: Vec<f64> = hist.samples.iter().copied().filter(|v| v.is_finite()).collect();
    if s.is_empty() {
        return Err(ReportError::Empty {
            plot: hist.title.clone(),
            what: "no finite sample".into(),
        });
    }
    s.sort_by(f64::total_cmp);
    Ok(s)
}

/// One bar per bin from the x axis up to its density.
fn bars(svg: &mut Svg, x: &Axis, y: &Axis, edges: &[f64], density: &[f64]) {
    let zero = y.map(0.0).unwrap_or(y.px_lo);
    for (k, d) in density.iter().enumerate() {
        let (Some(a), Some(b), Some(top)) = (x.map(edges[k]), x.map(edges[k + 1]), y.map(*d))
        else {
            continue;
        };
        let outline = Some(Stroke::solid("#fff", 0.5));
        svg.rect(a, top, (b - a).max(1.0), zero - top, series_colour(1), 0.75, outline);
    }
}

/// A dashed vertical line per marker, coloured as its legend entry.
fn markers(svg: &mut Svg, x: &Axis, y: &Axis, markers: &[Marker]) {
    for (i, m) in markers.iter().enumerate() {
        if let Some(p) = x.map(m.x) {
            let stroke = Stroke { colour: series_colour(i + 2), width: 2.0, dash: Some("6 3") };
            svg.line(p, y.px_hi, p, y.px_lo, stroke);
        }
    }
}

fn legend(hist: &Histogram) -> Vec<LegendItem> {
    let mut items = vec![LegendItem {
        label: format!(
            "posterior ({} samples)",
            hist.samples.iter().filter(|v| v.is_finite()).count()
        ),
        swatch: Swatch::Box { colour: series_colour(1), opacity: 0.75 },
    }];
    if let Some(p) = &hist.prior {
        items.push(LegendItem {
            label: p.label.clone(),
            swatch: Swatch::Box { colour: "#009E73", opacity: 0.18 },
        });
    }
    for (i, m) in hist.markers.iter().enumerate() {
        items.push(LegendItem {
            label: m.label.clone(),
            swatch: Swatch::Line { colour: series_colour(i + 2), dash: Some("6 3") },
        });
    }
    items
}

fn band(svg: &mut Svg, x: &Axis, y: &Axis, p: &PriorBand) {
    let (Some(a), Some(b)) = (x.map(p.low.min(p.high)), x.map(p.high.max(p.low))) else { return };
    svg.rect(a, y.px_hi, (b - a).max(1.0), y.px_lo - y.px_hi, "#009E73", 0.18, None);
}

/// The bin count: the caller's (checked), or Freedman–Diaconis on sorted `s`.
fn bin_count(hist: &Histogram, s: &[f64]) -> Result<usize, ReportError> {
    if let Some(b) = hist.bins {
        if !(1..=500).contains(&b) {
            return Err(ReportError::BadValue {
                plot: hist.title.clone(),
                key: "bins".into(),
                value: b as f64,
                expected: "1 to 500".into(),
            });
        }
        return Ok(b);
    }
    let q = |p: f64| s[((s.len() - 1) as f64 * p).round() as usize];
    let (iqr, range) = (q(0.75) - q(0.25), s[s.len() - 1] - s[0]);
    let width = 2.0 * iqr / (s.len() as f64).cbrt();
    Ok(if width > 0.0 && range > 0.0 {
        ((range / width).ceil() as usize).clamp(10, 60)
    } else {
        10
    })
}

/// Bin edges (n + 1) and densities (n) of sorted `s`; a constant sample
/// gets one bin of width 1 % of its magnitude (or 1) around it.
fn bin(s: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (s[0], s[s.len() - 1]);
    if hi - lo <= lo.abs().max(hi.abs()) * 1e-12 {
        let half = if lo == 0.0 { 0.5 } else { lo.abs() * 0.005 };
        return (vec![lo - half, lo + half], vec![1.0 / (2.0 * half)]);
    }
    let width = (hi - lo) / n as f64;
    let edges: Vec<f64> = (0..=n).map(|k| lo + width * k as f64).collect();
    let mut counts = vec![0usize; n];
    for &v in s {
        counts[(((v - lo) / width) as usize).min(n - 1)] += 1;
    }
    let total = s.len() as f64 * width;
    (edges, counts.iter().map(|&c| c as f64 / total).collect())
}

#[cfg(test)]
mod tests {
    use super::super::wellformed::check_svg;
    use super::*;

    fn hist(samples: Vec<f64>) -> Histogram {
        Histogram {
            title: "K_friction".into(),
            x_label: "K_friction (N/mm)".into(),
            samples,
            bins: None,
            prior: Some(PriorBand { label: "prior range".into(), low: 0.5, high: 4.0 }),
            markers: vec![Marker { label: "posterior mean".into(), x: 2.0 }],
            size: PlotSize::default(),
        }
    }

    #[test]
    fn density_integrates_to_one() {
        let s: Vec<f64> = (0..1000).map(|i| (i as f64 * 0.618).fract() * 3.0).collect();
        let (edges, d) = bin(&s, 25);
        let area: f64 = d.iter().zip(edges.windows(2)).map(|(d, e)| d * (e[1] - e[0])).sum();
        assert!((area - 1.0).abs() < 1e-12, "{area}");
    }

    #[test]
    fn draws_bars_band_and_marker() {
        let s: Vec<f64> = (0..500).map(|i| 2.0 + ((i as f64) * 0.37).sin()).collect();
        let svg = histogram(&hist(s)).unwrap();
        check_svg(&svg).unwrap();
        assert!(svg.contains("posterior (500 samples)"));
        assert!(svg.contains("prior range") && svg.contains("posterior mean"));
    }

    #[test]
    fn constant_and_nan_samples() {
        let svg = histogram(&hist(vec![1.5, 1.5, f64::NAN])).unwrap();
        check_svg(&svg).unwrap();
        assert!(svg.contains("posterior (2 samples)"));
        let err = histogram(&hist(vec![f64::NAN])).unwrap_err();
        assert_eq!(err.to_string(), "K_friction: nothing to draw (no finite sample)");
        let mut h = hist(vec![1.0, 2.0]);
        h.bins = Some(0);
        assert_eq!(
            histogram(&h).unwrap_err().to_string(),
            "K_friction: bins = 0 (expected 1 to 500)"
        );
    }
}
