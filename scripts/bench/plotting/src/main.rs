//! One report figure drawn both ways, the report's own SVG writer and
//! plotters' SVG backend, and what each costs: output bytes, whether the
//! coordinates keep their 0.01 px (content), CPU time per figure, lines of
//! code.
//!
//! The figure is Figure 18 of the demo's report ("run sx-strong, sensor
//! A1x": measured, baseline dashed, extended), its three series decoded
//! from that page by `make-fixture` into `fixture.csv`.
//!
//! Run from the repository root: `scripts/bench/plotting/run`.

#[allow(dead_code, unused_imports)]
#[path = "../../../../coordinator/src/report/mod.rs"]
mod report;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use report::{line_plot, LinePlot, PlotSize, Series, SeriesStyle};
use std::path::Path;

const TITLE: &str = "run sx-strong, sensor A1x";
const X_LABEL: &str = "time (s)";
const Y_LABEL: &str = "acceleration (m/s²)";
/// The report's series colours (coordinator/src/report/colour.rs).
const COLOURS: [RGBColor; 3] =
    [RGBColor(0, 0, 0), RGBColor(0, 0x72, 0xB2), RGBColor(0xD5, 0x5E, 0)];

/// Reads `series,x,y` rows into series, in order of first appearance.
fn read_fixture(path: &Path) -> Vec<Series> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut series: Vec<Series> = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |s: &str| {
            s.parse::<f64>().unwrap_or_else(|e| panic!("{}:{}: {s}: {e}", path.display(), i + 1))
        };
        let (x, y) = (num(f[1]), num(f[2]));
        if series.last().is_none_or(|s| s.name != f[0]) {
            let style = if f[0] == "baseline" { SeriesStyle::Dashed } else { SeriesStyle::Solid };
            series.push(Series { name: f[0].into(), x: vec![], y: vec![], style });
        }
        let s = series.last_mut().expect("pushed above");
        s.x.push(x);
        s.y.push(y);
    }
    series
}

/// The figure as the report draws it.
fn ours(series: &[Series]) -> String {
    line_plot(&LinePlot {
        title: TITLE.into(),
        x_label: X_LABEL.into(),
        y_label: Y_LABEL.into(),
        series: series.to_vec(),
        log_x: false,
        log_y: false,
        size: PlotSize::default(),
    })
    .expect("the fixture draws")
}

// BEGIN plotters figure
/// The same figure through plotters: title, legend, grid, ticks, axis
/// labels, the three series (baseline dashed), 900 x 360 px, axes 0–12 s
/// and ±15 m/s² as the report chose them.
fn plotters_figure(series: &[Series]) -> String {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (900, 360)).into_drawing_area();
        root.fill(&WHITE).expect("svg");
        let mut chart = plotters_chart(&root);
        chart
            .configure_mesh()
            .x_desc(X_LABEL)
            .y_desc(Y_LABEL)
            .x_labels(7)
            .y_labels(7)
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 13))
            .draw()
            .expect("svg");
        for (s, colour) in series.iter().zip(COLOURS) {
            let style = colour.stroke_width(2);
            // A missing reading breaks the line: one plotters series per run.
            let points: Vec<(f64, f64)> = s.x.iter().copied().zip(s.y.iter().copied()).collect();
            let runs = points.split(|p| !(p.0.is_finite() && p.1.is_finite()));
            for (k, run) in runs.filter(|r| !r.is_empty()).enumerate() {
                let run = run.iter().copied();
                let drawn = if s.style == SeriesStyle::Dashed {
                    chart.draw_series(DashedLineSeries::new(run, 6, 4, style)).expect("svg")
                } else {
                    chart.draw_series(LineSeries::new(run, style)).expect("svg")
                };
                if k == 0 {
                    let legend = move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style);
                    drawn.label(s.name.as_str()).legend(legend);
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 13))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .expect("svg");
        root.present().expect("svg");
    }
    out
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The chart's frame on `root`: caption, margins, the axes' ranges.
fn plotters_chart<'a, 'b>(root: &'a DrawingArea<SVGBackend<'b>, Shift>) -> Chart<'a, 'b> {
    ChartBuilder::on(root)
        .caption(TITLE, ("sans-serif", 15).into_font().style(FontStyle::Bold))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(0f64..12f64, -15f64..15f64)
        .expect("svg")
}
// END plotters figure

/// How far plotters moves the series' vertices from their exact pixel
/// positions (its backend takes `(i32, i32)`): largest and mean distance
/// (px), and how many vertices land on the pixel of the one before.
fn plotters_displacement(series: &[Series]) -> (f64, f64, usize, usize) {
    let mut out = String::new();
    let root = SVGBackend::with_string(&mut out, (900, 360)).into_drawing_area();
    let chart = plotters_chart(&root);
    let ((x0, y0), (x1, y1)) =
        (chart.backend_coord(&(0.0, -15.0)), chart.backend_coord(&(12.0, 15.0)));
    let exact = |x: f64, y: f64| {
        (x0 as f64 + (x1 - x0) as f64 * x / 12.0, y0 as f64 + (y1 - y0) as f64 * (y + 15.0) / 30.0)
    };
    let (mut max, mut sum, mut n, mut same) = (0.0f64, 0.0, 0usize, 0usize);
    for s in series {
        let mut last = None;
        for (&x, &y) in s.x.iter().zip(&s.y).filter(|p| p.0.is_finite() && p.1.is_finite()) {
            let (p, e) = (chart.backend_coord(&(x, y)), exact(x, y));
            let d = (p.0 as f64 - e.0).hypot(p.1 as f64 - e.1);
            (max, sum, n) = (max.max(d), sum + d, n + 1);
            same += usize::from(last == Some(p));
            last = Some(p);
        }
    }
    (max, sum / n as f64, same, n)
}

/// CPU time of this process (s).
fn cpu_s() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `t` is a valid timespec; CLOCK_PROCESS_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// Median, min and max CPU time per figure (ms) over `rounds` of `reps` figures.
fn cpu_per_figure(rounds: usize, reps: usize, draw: impl Fn() -> String) -> (f64, f64, f64) {
    let mut per: Vec<f64> = (0..rounds)
        .map(|_| {
            let t0 = cpu_s();
            let bytes: usize = (0..reps).map(|_| std::hint::black_box(draw()).len()).sum();
            std::hint::black_box(bytes);
            (cpu_s() - t0) / reps as f64 * 1e3
        })
        .collect();
    per.sort_by(f64::total_cmp);
    (per[rounds / 2], per[0], per[rounds - 1])
}

/// Numbers in the figure's line geometry: `(all, with a fractional part)`.
fn coordinates(svg: &str) -> (usize, usize) {
    let mut all = 0;
    let mut frac = 0;
    for chunk in
        svg.split(['<', '>']).filter(|c| c.starts_with("path") || c.starts_with("polyline"))
    {
        let geometry = chunk.split(" d=\"").nth(1).or_else(|| chunk.split(" points=\"").nth(1));
        let geometry = geometry.and_then(|g| g.split('"').next()).unwrap_or("");
        for n in
            geometry.split(|c: char| !(c.is_ascii_digit() || c == '.')).filter(|n| !n.is_empty())
        {
            all += 1;
            frac += usize::from(n.contains('.'));
        }
    }
    (all, frac)
}

/// Code lines (not blank, not comments) of `path` before its tests, or
/// between `from` and `to` markers.
fn code_lines(text: &str, from: Option<(&str, &str)>) -> usize {
    let body = match from {
        Some((a, b)) => &text[text.find(a).expect("marker")..text.find(b).expect("marker")],
        None => text.split("#[cfg(test)]").next().unwrap_or(text),
    };
    body.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with("//")).count()
}

fn main() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let series = read_fixture(&here.join("fixture.csv"));
    let points: usize = series.iter().map(|s| s.y.iter().filter(|v| v.is_finite()).count()).sum();
    let (a, b) = (ours(&series), plotters_figure(&series));
    let out = here.join("out");
    std::fs::create_dir_all(&out).expect("out/");
    std::fs::write(out.join("ours.svg"), &a).expect("ours.svg");
    std::fs::write(out.join("plotters.svg"), &b).expect("plotters.svg");
    println!("figure: {TITLE}, {} series, {points} points (fixture.csv)", series.len());
    println!("{:<34}{:>14}{:>14}", "", "hand-written", "plotters");
    println!("{:<34}{:>14}{:>14}", "output bytes", a.len(), b.len());
    let ((na, fa), (nb, fb)) = (coordinates(&a), coordinates(&b));
    println!("{:<34}{:>14}{:>14}", "line coordinates", na, nb);
    println!("{:<34}{:>14}{:>14}", "  with a fractional part", fa, fb);
    let (dmax, dmean, same, n) = plotters_displacement(&series);
    println!(
        "plotters moves the {n} vertices to whole pixels: by up to {dmax:.2} px (mean {dmean:.2}); \
         {same} land on the pixel of the vertex before"
    );
    println!("(hand-written: every vertex within 0.005 px of its exact position)");
    let (ma, la, ha) = cpu_per_figure(15, 40, || ours(&series));
    let (mb, lb, hb) = cpu_per_figure(15, 40, || plotters_figure(&series));
    println!(
        "{:<34}{:>14}{:>14}",
        "CPU ms/figure, median of 15x40",
        format!("{ma:.3}"),
        format!("{mb:.3}")
    );
    println!(
        "{:<34}{:>14}{:>14}",
        "  (min to max)",
        format!("{la:.3}-{ha:.3}"),
        format!("{lb:.3}-{hb:.3}")
    );
    let report = here.join("../../../coordinator/src/report");
    let modules = ["line_plot", "frame", "axis", "svg", "escape", "decimate", "colour"];
    let ours_loc: usize = modules
        .iter()
        .map(|m| {
            let p = report.join(format!("{m}.rs"));
            code_lines(
                &std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())),
                None,
            )
        })
        .sum();
    let main_rs = std::fs::read_to_string(here.join("src/main.rs")).expect("main.rs");
    let theirs_loc = code_lines(
        &main_rs,
        Some((concat!("// BEGIN ", "plotters figure"), concat!("// END ", "plotters figure"))),
    );
    println!("{:<34}{:>14}{:>14}", "code lines for this figure", ours_loc, theirs_loc);
    println!("  (hand-written: {} in coordinator/src/report, tests excluded; plotters: the figure function)", modules.join(", "));
    println!("SVGs written to {}", out.display());
}
