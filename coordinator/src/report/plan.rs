//! The specimen's plan view: the perimeter (wall angle), main tees along y
//! at every `main_tee_spacing_m` in x, cross tees along x at every
//! `module_m` in y, sub cross tees along y midway between main tees, and
//! the sensors with their ids and an arrow along the measured direction.
//! Frame and member layout as in the bundle spec (measured-bundle.md,
//! "Coordinates and directions"): origin at a corner, x along the cross
//! tees, y along the main tees. Drawn to scale, in metres.

use super::axis::Axis;
use super::colour::series_colour;
use super::frame::{draw_legend, legend_height, LegendItem, Swatch, LABEL_PX, TICK_PX, TITLE_PX};
use super::svg::{Anchor, PathData, Stroke, Svg, TextStyle};
use super::ReportError;

/// The horizontal direction a sensor measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Along x (the cross tees).
    X,
    /// Along y (the main tees).
    Y,
}

/// What a sensor measures (drawn as a dot or a square).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorKind {
    /// Absolute acceleration.
    Acceleration,
    /// Displacement relative to the platform.
    Displacement,
}

/// A sensor on the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSensor {
    /// Sensor id, e.g. "A13".
    pub id: String,
    /// Position along x (m), within the ceiling.
    pub x_m: f64,
    /// Position along y (m), within the ceiling.
    pub y_m: f64,
    /// Measured direction.
    pub direction: Direction,
    /// Acceleration or displacement.
    pub kind: SensorKind,
    /// Draw in the emphasis colour (e.g. a sensor whose records tell the diagnosis).
    pub highlight: bool,
}

/// Most grid lines per direction drawn (a larger plan is refused).
const MAX_LINES: f64 = 400.0;
/// Title used in errors and the drawing.
const TITLE: &str = "Specimen plan";

/// Draw the plan of a `length_x_m` x `length_y_m` ceiling as an SVG element.
pub fn plan_svg(
    length_x_m: f64,
    length_y_m: f64,
    module_m: f64,
    main_tee_spacing_m: f64,
    sensors: &[PlanSensor],
) -> Result<String, ReportError> {
    check_dims(length_x_m, length_y_m, module_m, main_tee_spacing_m)?;
    check_sensors(length_x_m, length_y_m, sensors)?;
    let (w, margin, bottom) = (760.0, 64.0, 48.0);
    let legend = legend(sensors);
    // room over the plan for the arrow of a y sensor on the far edge
    let top = 30.0 + legend_height(&legend, w - 2.0 * margin) + 16.0 + 30.0;
    let scale = ((w - 2.0 * margin) / length_x_m).min((640.0 - top - bottom) / length_y_m);
    let h = top + bottom + length_y_m * scale;
    let left = (w - length_x_m * scale) / 2.0;
    let to_px = |x: f64, y: f64| (left + x * scale, top + (length_y_m - y) * scale);
    let mut svg = Svg::new(w, h, TITLE);
    svg.text(
        w / 2.0,
        20.0,
        TITLE,
        TextStyle { bold: true, ..TextStyle::new(TITLE_PX, Anchor::Middle) },
    );
    draw_legend(&mut svg, &legend, margin, w - 2.0 * margin, 30.0);
    draw_grid(&mut svg, length_x_m, length_y_m, module_m, main_tee_spacing_m, &to_px);
    draw_axes(&mut svg, length_x_m, length_y_m, &to_px);
    for s in sensors {
        draw_sensor(&mut svg, s, to_px(s.x_m, s.y_m));
    }
    Ok(svg.finish())
}

fn bad(key: &str, value: f64, expected: String) -> ReportError {
    ReportError::BadValue { plot: TITLE.into(), key: key.into(), value, expected }
}

fn check_dims(lx: f64, ly: f64, module: f64, main: f64) -> Result<(), ReportError> {
    for (key, v) in
        [("length_x_m", lx), ("length_y_m", ly), ("module_m", module), ("main_tee_spacing_m", main)]
    {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(key, v, "finite and > 0".into()));
        }
    }
    if main < module {
        return Err(bad("main_tee_spacing_m", main, format!(">= module_m = {module}")));
    }
    for (key, v) in [("length_x_m", lx), ("length_y_m", ly)] {
        if v / module > MAX_LINES {
            return Err(bad(key, v, format!("at most {MAX_LINES} modules of {module} m")));
        }
    }
    Ok(())
}

fn check_sensors(lx: f64, ly: f64, sensors: &[PlanSensor]) -> Result<(), ReportError> {
    for (i, s) in sensors.iter().enumerate() {
        for (axis, v, l) in [("x_m", s.x_m, lx), ("y_m", s.y_m, ly)] {
            if !(v.is_finite() && v >= -1e-9 * l && v <= l * (1.0 + 1e-9)) {
                return Err(bad(
                    &format!("sensors[{i}] ({}).{axis}", s.id),
                    v,
                    format!("within 0 to {l} m"),
                ));
            }
        }
    }
    Ok(())
}

/// Colour of a sensor: emphasis or normal.
fn sensor_colour(highlight: bool) -> &'static str {
    if highlight {
        series_colour(2)
    } else {
        series_colour(1)
    }
}

fn legend(sensors: &[PlanSensor]) -> Vec<LegendItem> {
    let mut items = vec![
        LegendItem {
            label: "main tee".into(),
            swatch: Swatch::Line { colour: "#333333", dash: None },
        },
        LegendItem {
            label: "cross / sub cross tee".into(),
            swatch: Swatch::Line { colour: "#a8b0bb", dash: None },
        },
    ];
    if sensors.iter().any(|s| s.kind == SensorKind::Acceleration) {
        items.push(LegendItem {
            label: "accelerometer".into(),
            swatch: Swatch::Dot { colour: series_colour(1) },
        });
    }
    if sensors.iter().any(|s| s.kind == SensorKind::Displacement) {
        items.push(LegendItem {
            label: "displacement sensor".into(),
            swatch: Swatch::Square { colour: series_colour(1) },
        });
    }
    if sensors.iter().any(|s| s.highlight) {
        items.push(LegendItem {
            label: "telling sensor".into(),
            swatch: Swatch::Dot { colour: series_colour(2) },
        });
    }
    items
}

/// Grid positions k·step in [0, len] (the ends included when they fall on the grid).
fn positions(len: f64, step: f64, offset: f64) -> Vec<f64> {
    let n = ((len - offset) / step + 1e-9).floor().max(-1.0) as i64;
    (0..=n).map(|k| offset + k as f64 * step).filter(|&v| v <= len + 1e-9).collect()
}

fn draw_grid(
    svg: &mut Svg,
    lx: f64,
    ly: f64,
    module: f64,
    main: f64,
    to_px: &dyn Fn(f64, f64) -> (f64, f64),
) {
    let thin = Stroke::solid("#a8b0bb", 1.0);
    let mut line =
        |(x1, y1): (f64, f64), (x2, y2): (f64, f64), s: Stroke| svg.line(x1, y1, x2, y2, s);
    for y in positions(ly, module, 0.0) {
        line(to_px(0.0, y), to_px(lx, y), thin);
    }
    for x in positions(lx, main, main / 2.0) {
        line(to_px(x, 0.0), to_px(x, ly), thin);
    }
    for x in positions(lx, main, 0.0) {
        line(to_px(x, 0.0), to_px(x, ly), Stroke::solid("#333333", 2.0));
    }
    let (x0, y0) = to_px(0.0, ly);
    let (x1, y1) = to_px(lx, 0.0);
    svg.rect(x0, y0, x1 - x0, y1 - y0, "none", 1.0, Some(Stroke::solid("#111111", 3.0)));
}

fn draw_axes(svg: &mut Svg, lx: f64, ly: f64, to_px: &dyn Fn(f64, f64) -> (f64, f64)) {
    let (_, y_base) = to_px(0.0, 0.0);
    let (x_base, _) = to_px(0.0, 0.0);
    for t in Axis::exact(0.0, lx, 8).ticks.iter().filter(|t| !t.label.is_empty()) {
        let (p, _) = to_px(t.value, 0.0);
        svg.line(p, y_base + 2.0, p, y_base + 6.0, Stroke::solid("#444", 1.0));
        svg.text(p, y_base + 8.0 + TICK_PX, &t.label, TextStyle::new(TICK_PX, Anchor::Middle));
    }
    for t in Axis::exact(0.0, ly, 8).ticks.iter().filter(|t| !t.label.is_empty()) {
        let (_, p) = to_px(0.0, t.value);
        svg.line(x_base - 6.0, p, x_base - 2.0, p, Stroke::solid("#444", 1.0));
        svg.text(x_base - 9.0, p + 4.0, &t.label, TextStyle::new(TICK_PX, Anchor::End));
    }
    let (xm, _) = to_px(lx / 2.0, 0.0);
    svg.text(xm, y_base + 38.0, "x (m)", TextStyle::new(LABEL_PX, Anchor::Middle));
    let (_, ym) = to_px(0.0, ly / 2.0);
    svg.text(
        x_base - 40.0,
        ym,
        "y (m)",
        TextStyle { rotate_deg: -90.0, ..TextStyle::new(LABEL_PX, Anchor::Middle) },
    );
}

/// Marker, arrow along the measured direction, id label placed so that an
/// x and a y sensor at the same node do not collide (x: label below, y: left).
fn draw_sensor(svg: &mut Svg, s: &PlanSensor, (cx, cy): (f64, f64)) {
    let colour = sensor_colour(s.highlight);
    let (dx, dy) = match s.direction {
        Direction::X => (1.0, 0.0),
        Direction::Y => (0.0, -1.0),
    };
    let (tip_x, tip_y) = (cx + 24.0 * dx, cy + 24.0 * dy);
    svg.line(cx, cy, tip_x, tip_y, Stroke::solid(colour, 2.0));
    let mut head = PathData::default();
    head.point(Some((tip_x + 4.0 * dx, tip_y + 4.0 * dy)));
    head.point(Some((tip_x - 6.0 * dx - 5.0 * dy, tip_y - 6.0 * dy + 5.0 * dx)));
    head.point(Some((tip_x - 6.0 * dx + 5.0 * dy, tip_y - 6.0 * dy - 5.0 * dx)));
    head.close();
    svg.filled_path(&head.into_string(), colour);
    match s.kind {
        SensorKind::Acceleration => {
            svg.circle(cx, cy, 5.0, colour, Some(Stroke::solid("#fff", 1.5)))
        }
        SensorKind::Displacement => {
            svg.rect(cx - 5.0, cy - 5.0, 10.0, 10.0, colour, 1.0, Some(Stroke::solid("#fff", 1.5)))
        }
    }
    let style = |anchor| TextStyle { bold: s.highlight, ..TextStyle::new(TICK_PX, anchor) };
    match s.direction {
        Direction::X => svg.text(cx, cy + 19.0, &s.id, style(Anchor::Middle)),
        Direction::Y => svg.text(cx - 9.0, cy + 4.0, &s.id, style(Anchor::End)),
    }
}

#[cfg(test)]
mod tests {
    use super::super::wellformed::check_svg;
    use super::*;

    fn sensor(id: &str, x_m: f64, y_m: f64, direction: Direction) -> PlanSensor {
        PlanSensor {
            id: id.into(),
            x_m,
            y_m,
            direction,
            kind: SensorKind::Acceleration,
            highlight: false,
        }
    }

    #[test]
    fn grid_positions_include_both_ends() {
        assert_eq!(positions(3.6, 1.2, 0.0).len(), 4);
        assert_eq!(positions(3.6, 1.2, 0.6), [0.6, 1.7999999999999998, 3.0]);
        assert_eq!(positions(0.5, 1.2, 0.6), Vec::<f64>::new());
    }

    #[test]
    fn draws_grid_and_labelled_sensors() {
        let s = [sensor("A1", 1.8, 1.8, Direction::X), sensor("A<2>", 1.8, 1.8, Direction::Y)];
        let svg = plan_svg(3.6, 4.8, 0.6, 1.2, &s).unwrap();
        check_svg(&svg).unwrap();
        assert!(svg.contains(">A1<") && svg.contains(">A&lt;2&gt;<"));
        // main tees at x = 0, 1.2, 2.4, 3.6 and the legend's swatch
        assert_eq!(svg.matches(r##"stroke="#333333" stroke-width="2""##).count(), 4 + 1);
    }

    #[test]
    fn sensor_outside_is_an_error_with_its_key() {
        let err =
            plan_svg(3.6, 3.6, 0.6, 1.2, &[sensor("A9", 4.0, 1.0, Direction::X)]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "Specimen plan: sensors[0] (A9).x_m = 4 (expected within 0 to 3.6 m)"
        );
        let err = plan_svg(3.6, 0.0, 0.6, 1.2, &[]).unwrap_err();
        assert_eq!(err.to_string(), "Specimen plan: length_y_m = 0 (expected finite and > 0)");
        assert!(plan_svg(3.6, 3.6, 0.6, 0.3, &[]).is_err());
        assert!(plan_svg(1e6, 3.6, 0.6, 1.2, &[]).is_err());
    }
}
