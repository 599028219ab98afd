//! Grouped bar charts: one group of bars per category, e.g. MDL of each
//! candidate model, or baseline vs extended validation error per run.
//! Bars start at zero (negative values go down); a missing value (NaN) is
//! marked "n/a". Long category labels are slanted so they never overlap.
//! When the values are close, plot their differences (e.g. MDL minus the
//! best MDL) so the bars tell them apart.

use super::axis::{data_range, Scale};
use super::colour::series_colour;
use super::frame::{axis_for, draw_frame, FrameSpec, LegendItem, PlotSize, Swatch, TICK_PX};
use super::svg::{text_width, Anchor, Stroke, Svg, TextStyle};
use super::ReportError;

/// One named set of bars, one value per category; NaN = no value.
#[derive(Debug, Clone, PartialEq)]
pub struct BarGroup {
    /// Legend text, e.g. "extended model".
    pub name: String,
    /// One value per category (in the units of the y label).
    pub values: Vec<f64>,
}

/// A grouped bar chart.
#[derive(Debug, Clone, PartialEq)]
pub struct BarChart {
    /// Title over the chart.
    pub title: String,
    /// Label under the categories, e.g. "candidate extension".
    pub x_label: String,
    /// y axis label with units, e.g. "MDL − best MDL (nats)".
    pub y_label: String,
    /// Category names along x.
    pub categories: Vec<String>,
    /// Bar groups, coloured by position.
    pub groups: Vec<BarGroup>,
    /// A category to emphasise (bold label, outlined bars), e.g. the chosen model.
    pub highlight: Option<usize>,
    /// Size of the drawing.
    pub size: PlotSize,
}

/// Slant of long category labels (degrees).
const SLANT_DEG: f64 = 30.0;

/// Draw `chart` as a standalone SVG element.
pub fn bar_chart(chart: &BarChart) -> Result<String, ReportError> {
    chart.size.check(&chart.title)?;
    check(chart)?;
    let values = chart.groups.iter().flat_map(|g| g.values.iter().copied());
    let range = data_range(values.chain([0.0]), Scale::Linear);
    let (w, h) = (chart.size.width_px as f64, chart.size.height_px as f64);
    let slot_guess = (w - 120.0) / chart.categories.len() as f64;
    let widest = chart.categories.iter().map(|c| text_width(c, TICK_PX)).fold(0.0, f64::max);
    let slant = widest > slot_guess * 0.9;
    let extra_bottom =
        if slant { (widest * SLANT_DEG.to_radians().sin()).min(h / 4.0) } else { 0.0 };
    let legend: Vec<LegendItem> = chart
        .groups
        .iter()
        .enumerate()
        .map(|(i, g)| LegendItem {
            label: g.name.clone(),
            swatch: Swatch::Box { colour: series_colour(i + 1), opacity: 1.0 },
        })
        .collect();
    let spec = FrameSpec {
        title: &chart.title,
        x_label: &chart.x_label,
        y_label: &chart.y_label,
        legend: &legend,
        size: chart.size,
        extra_bottom,
        extra_right: 0.0,
    };
    let mut svg = Svg::new(w, h, &chart.title);
    let x = axis_for(Some((0.0, 1.0)), Scale::Linear, 2);
    let (x, y) = draw_frame(&mut svg, &spec, x, axis_for(range, Scale::Linear, 6), false);
    let slot = (x.px_hi - x.px_lo) / chart.categories.len() as f64;
    let bar_w = slot * 0.8 / chart.groups.len() as f64;
    let zero = y.map(0.0).unwrap_or(y.px_lo);
    for (c, name) in chart.categories.iter().enumerate() {
        let x0 = x.px_lo + slot * (c as f64 + 0.1);
        let emphasis = chart.highlight == Some(c);
        for (g, group) in chart.groups.iter().enumerate() {
            let slot = BarSlot { x0: x0 + bar_w * g as f64, width: bar_w, zero };
            draw_bar(&mut svg, &slot, group.values[c], &y, series_colour(g + 1), emphasis);
        }
        category_label(
            &mut svg,
            x.px_lo + slot * (c as f64 + 0.5),
            y.px_lo,
            name,
            slant,
            emphasis,
            extra_bottom,
        );
    }
    svg.line(x.px_lo, zero, x.px_hi, zero, Stroke::solid("#444", 1.0));
    Ok(svg.finish())
}

fn check(chart: &BarChart) -> Result<(), ReportError> {
    if chart.categories.is_empty() || chart.groups.is_empty() {
        let what = if chart.categories.is_empty() { "no categories" } else { "no bar groups" };
        return Err(ReportError::Empty { plot: chart.title.clone(), what: what.into() });
    }
    for g in &chart.groups {
        if g.values.len() != chart.categories.len() {
            return Err(ReportError::LengthMismatch {
                plot: chart.title.clone(),
                what: format!("group \"{}\" values", g.name),
                expected: chart.categories.len(),
                found: g.values.len(),
            });
        }
    }
    if let Some(h) = chart.highlight.filter(|&h| h >= chart.categories.len()) {
        return Err(ReportError::BadValue {
            plot: chart.title.clone(),
            key: "highlight".into(),
            value: h as f64,
            expected: format!("a category index below {}", chart.categories.len()),
        });
    }
    Ok(())
}

/// Where one bar stands: its left edge and width, and the zero line's
/// height (px).
struct BarSlot {
    x0: f64,
    width: f64,
    zero: f64,
}

/// One bar of value `v` in `slot`, labelled with its value when the label
/// fits ("n/a" for a value that cannot be drawn).
fn draw_bar(
    svg: &mut Svg,
    slot: &BarSlot,
    v: f64,
    y: &super::axis::Axis,
    colour: &str,
    emphasis: bool,
) {
    let &BarSlot { x0, width: w, zero } = slot;
    let Some(top) = y.map(v).filter(|_| v.is_finite()) else {
        svg.text(x0 + w / 2.0, zero - 4.0, "n/a", TextStyle::new(TICK_PX - 1.0, Anchor::Middle));
        return;
    };
    let outline = emphasis.then_some(Stroke::solid("#000", 2.0));
    svg.rect(x0 + 1.0, top.min(zero), w - 2.0, (top - zero).abs(), colour, 1.0, outline);
    let label = value_label(v);
    if text_width(&label, TICK_PX - 1.0) <= w + 4.0 {
        let ly = if v >= 0.0 { top - 4.0 } else { top + TICK_PX + 2.0 };
        svg.text(x0 + w / 2.0, ly, &label, TextStyle::new(TICK_PX - 1.0, Anchor::Middle));
    }
}

/// A value printed over its bar with three significant digits.
fn value_label(v: f64) -> String {
    let a = v.abs();
    let s = if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else {
        let decimals =
            if a == 0.0 { 0 } else { (2.0 - a.log10().floor()).clamp(0.0, 5.0) as usize };
        format!("{v:.decimals$}")
    };
    s.replace('-', "\u{2212}")
}

fn category_label(
    svg: &mut Svg,
    cx: f64,
    bottom: f64,
    name: &str,
    slant: bool,
    bold: bool,
    room: f64,
) {
    let y = bottom + 6.0 + TICK_PX;
    if slant {
        let max_chars =
            ((room / SLANT_DEG.to_radians().sin()) / (TICK_PX * 0.58)).max(4.0) as usize;
        let shown: String = if name.chars().count() > max_chars {
            name.chars().take(max_chars - 1).chain(['…']).collect()
        } else {
            name.to_string()
        };
        let style =
            TextStyle { bold, rotate_deg: -SLANT_DEG, ..TextStyle::new(TICK_PX, Anchor::End) };
        svg.text(cx + 4.0, y, &shown, style);
    } else {
        let style = TextStyle { bold, ..TextStyle::new(TICK_PX, Anchor::Middle) };
        svg.text(cx, y, name, style);
    }
}

#[cfg(test)]
mod tests {
    use super::super::wellformed::check_svg;
    use super::*;

    fn chart() -> BarChart {
        BarChart {
            title: "MDL of the candidates".into(),
            x_label: "candidate".into(),
            y_label: "MDL − best (nats)".into(),
            categories: vec![
                "none".into(),
                "perimeter-pounding".into(),
                "perimeter-friction".into(),
            ],
            groups: vec![BarGroup { name: "MDL".into(), values: vec![41.5, 0.0, f64::NAN] }],
            highlight: Some(1),
            size: PlotSize::default(),
        }
    }

    #[test]
    fn draws_bars_values_and_na() {
        let svg = bar_chart(&chart()).unwrap();
        check_svg(&svg).unwrap();
        assert!(svg.contains(">41.5<"), "value label");
        assert!(svg.contains(">n/a<"));
        assert!(svg.contains("perimeter-pounding"));
    }

    #[test]
    fn shapes_are_checked() {
        let mut c = chart();
        c.groups[0].values.pop();
        assert_eq!(
            bar_chart(&c).unwrap_err().to_string(),
            "MDL of the candidates: group \"MDL\" values: lengths differ (3 expected, 2 found)"
        );
        let mut c = chart();
        c.highlight = Some(3);
        assert!(matches!(bar_chart(&c), Err(ReportError::BadValue { .. })));
        let mut c = chart();
        c.categories.clear();
        assert!(matches!(bar_chart(&c), Err(ReportError::Empty { .. })));
    }

    #[test]
    fn value_labels_have_three_digits() {
        assert_eq!(value_label(41.53), "41.5");
        assert_eq!(value_label(0.012345), "0.0123");
        assert_eq!(value_label(-3.0), "\u{2212}3.00");
        assert_eq!(value_label(0.0), "0");
        assert_eq!(value_label(123456.0), "1.23e5");
    }
}
