//! The frame every x-y chart shares: title, legend row(s) under it, plot
//! area with grid lines, ticks and tick labels, and axis labels. The layout
//! reserves room for each part so that nothing overlaps: the left margin
//! follows the widest y tick label, the legend wraps into rows, and x tick
//! labels are thinned until they fit.

use super::axis::{Axis, Scale};
use super::svg::{text_width, Anchor, Stroke, Svg, TextStyle};

/// Font sizes (px).
pub(crate) const TITLE_PX: f64 = 15.0;
/// Axis labels and legend entries.
pub(crate) const LABEL_PX: f64 = 13.0;
/// Tick labels.
pub(crate) const TICK_PX: f64 = 12.0;

/// Width and height of a drawing in px.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotSize {
    /// Width (px), at least 200.
    pub width_px: u32,
    /// Height (px), at least 150.
    pub height_px: u32,
}

impl Default for PlotSize {
    fn default() -> Self {
        PlotSize { width_px: 900, height_px: 360 }
    }
}

impl PlotSize {
    /// Check the size is drawable: at least 200 x 150 px and at most 4000 x 4000.
    pub(crate) fn check(&self, plot: &str) -> Result<(), super::ReportError> {
        for (key, v, lo) in
            [("size.width_px", self.width_px, 200), ("size.height_px", self.height_px, 150)]
        {
            if !(lo..=4000).contains(&v) {
                return Err(super::ReportError::BadValue {
                    plot: plot.to_string(),
                    key: key.to_string(),
                    value: v as f64,
                    expected: format!("{lo} to 4000 px"),
                });
            }
        }
        Ok(())
    }
}

/// How a legend entry is drawn.
#[derive(Debug, Clone)]
pub(crate) enum Swatch {
    /// A short line, optionally dashed.
    Line { colour: &'static str, dash: Option<&'static str> },
    /// A dot.
    Dot { colour: &'static str },
    /// A filled box with opacity.
    Box { colour: &'static str, opacity: f64 },
    /// A small filled square (a marker).
    Square { colour: &'static str },
}

/// One legend entry.
#[derive(Debug, Clone)]
pub(crate) struct LegendItem {
    /// Text.
    pub label: String,
    /// Symbol.
    pub swatch: Swatch,
}

const SWATCH_W: f64 = 22.0;
const ROW_H: f64 = 18.0;

/// Height (px) of the legend laid out in rows of at most `width` px.
pub(crate) fn legend_height(items: &[LegendItem], width: f64) -> f64 {
    legend_layout(items, 0.0, width).last().map_or(0.0, |&(row, _)| (row + 1) as f64 * ROW_H)
}

/// Legend entries laid out in rows of at most `width` px: (row, x) of each.
fn legend_layout(items: &[LegendItem], x0: f64, width: f64) -> Vec<(usize, f64)> {
    let (mut row, mut x) = (0usize, x0);
    items
        .iter()
        .map(|it| {
            let w = SWATCH_W + 6.0 + text_width(&it.label, LABEL_PX) + 18.0;
            if x > x0 && x + w > x0 + width {
                row += 1;
                x = x0;
            }
            let at = (row, x);
            x += w;
            at
        })
        .collect()
}

/// Draw the legend from `top`; returns its height.
pub(crate) fn draw_legend(
    svg: &mut Svg,
    items: &[LegendItem],
    x0: f64,
    width: f64,
    top: f64,
) -> f64 {
    let layout = legend_layout(items, x0, width);
    for (it, &(row, x)) in items.iter().zip(&layout) {
        let y = top + row as f64 * ROW_H + ROW_H / 2.0;
        match it.swatch {
            Swatch::Line { colour, dash } => {
                svg.line(x, y, x + SWATCH_W, y, Stroke { colour, width: 2.0, dash })
            }
            Swatch::Dot { colour } => svg.circle(x + SWATCH_W / 2.0, y, 3.5, colour, None),
            Swatch::Box { colour, opacity } => {
                svg.rect(x, y - 6.0, SWATCH_W, 12.0, colour, opacity, None)
            }
            Swatch::Square { colour } => {
                svg.rect(x + SWATCH_W / 2.0 - 4.5, y - 4.5, 9.0, 9.0, colour, 1.0, None)
            }
        }
        svg.text(x + SWATCH_W + 6.0, y + 4.5, &it.label, TextStyle::new(LABEL_PX, Anchor::Start));
    }
    layout.last().map_or(0.0, |&(row, _)| (row + 1) as f64 * ROW_H)
}

/// What a chart frame shows.
pub(crate) struct FrameSpec<'a> {
    /// Title over the chart.
    pub title: &'a str,
    /// Label under the x axis.
    pub x_label: &'a str,
    /// Label left of the y axis (rotated).
    pub y_label: &'a str,
    /// Legend entries (may be empty).
    pub legend: &'a [LegendItem],
    /// Size of the drawing.
    pub size: PlotSize,
    /// Extra room under the x axis (px) for rotated category labels.
    pub extra_bottom: f64,
    /// Extra room on the right (px), e.g. for a colour bar.
    pub extra_right: f64,
}

/// Draw title, legend, grid, ticks and labels; return the axes placed on
/// the plot area. `x` and `y` come from [`Axis::new`].
pub(crate) fn draw_frame(
    svg: &mut Svg,
    spec: &FrameSpec,
    x: Axis,
    y: Axis,
    x_ticks: bool,
) -> (Axis, Axis) {
    let (w, h) = (spec.size.width_px as f64, spec.size.height_px as f64);
    svg.text(
        w / 2.0,
        20.0,
        spec.title,
        TextStyle { bold: true, ..TextStyle::new(TITLE_PX, Anchor::Middle) },
    );
    let y_tick_w = y.ticks.iter().map(|t| text_width(&t.label, TICK_PX)).fold(0.0, f64::max);
    let left = 10.0 + LABEL_PX + 10.0 + y_tick_w + 8.0;
    let last_x_label = x.ticks.iter().rev().find(|t| !t.label.is_empty());
    let right = 14.0_f64
        .max(last_x_label.map_or(0.0, |t| text_width(&t.label, TICK_PX) / 2.0 + 4.0))
        + spec.extra_right;
    let legend_h = if spec.legend.is_empty() {
        0.0
    } else {
        draw_legend(svg, spec.legend, left, w - left - right, 30.0)
    };
    let top = 30.0 + legend_h + 10.0;
    let bottom = h - (TICK_PX + LABEL_PX + 22.0 + spec.extra_bottom);
    let x = x.placed(left, w - right);
    let y = y.placed(bottom, top);
    draw_y_ticks(svg, &y, left, w - right);
    if x_ticks {
        draw_x_ticks(svg, &x, top, bottom);
    }
    svg.rect(
        left,
        top,
        w - right - left,
        bottom - top,
        "none",
        1.0,
        Some(Stroke::solid("#444", 1.0)),
    );
    svg.text(
        (left + w - right) / 2.0,
        h - 8.0,
        spec.x_label,
        TextStyle::new(LABEL_PX, Anchor::Middle),
    );
    let y_mid = (top + bottom) / 2.0;
    svg.text(
        10.0 + LABEL_PX,
        y_mid,
        spec.y_label,
        TextStyle { rotate_deg: -90.0, ..TextStyle::new(LABEL_PX, Anchor::Middle) },
    );
    (x, y)
}

fn grid_stroke(major: bool) -> Stroke<'static> {
    Stroke::solid(if major { "#d8d8d8" } else { "#eeeeee" }, 1.0)
}

fn draw_y_ticks(svg: &mut Svg, y: &Axis, left: f64, right: f64) {
    for t in &y.ticks {
        let Some(p) = y.map(t.value) else { continue };
        svg.line(left, p, right, p, grid_stroke(!t.label.is_empty()));
        if !t.label.is_empty() {
            svg.line(left - 4.0, p, left, p, Stroke::solid("#444", 1.0));
            svg.text(left - 7.0, p + 4.0, &t.label, TextStyle::new(TICK_PX, Anchor::End));
        }
    }
}

/// Every `k`-th labelled x tick so that labels keep 12 px apart.
fn x_label_stride(x: &Axis) -> usize {
    let labelled: Vec<(f64, f64)> = x
        .ticks
        .iter()
        .filter(|t| !t.label.is_empty())
        .filter_map(|t| Some((x.map(t.value)?, text_width(&t.label, TICK_PX))))
        .collect();
    (1..=labelled.len().max(1))
        .find(|&k| {
            let kept: Vec<&(f64, f64)> = labelled.iter().step_by(k).collect();
            kept.windows(2).all(|w| (w[1].0 - w[0].0).abs() >= (w[0].1 + w[1].1) / 2.0 + 12.0)
        })
        .unwrap_or(1)
}

fn draw_x_ticks(svg: &mut Svg, x: &Axis, top: f64, bottom: f64) {
    let stride = x_label_stride(x);
    let mut nth = 0usize;
    for t in &x.ticks {
        let Some(p) = x.map(t.value) else { continue };
        svg.line(p, top, p, bottom, grid_stroke(!t.label.is_empty()));
        if t.label.is_empty() {
            continue;
        }
        svg.line(p, bottom, p, bottom + 4.0, Stroke::solid("#444", 1.0));
        if nth.is_multiple_of(stride) {
            svg.text(p, bottom + 6.0 + TICK_PX, &t.label, TextStyle::new(TICK_PX, Anchor::Middle));
        }
        nth += 1;
    }
}

/// An axis for data range `range` (or a unit range when `None`).
pub(crate) fn axis_for(range: Option<(f64, f64)>, scale: Scale, target_ticks: usize) -> Axis {
    let (lo, hi) = range.unwrap_or(match scale {
        Scale::Linear => (0.0, 1.0),
        Scale::Log10 => (1.0, 10.0),
    });
    Axis::new(lo, hi, scale, target_ticks)
}
