//! Property tests of the report's figures and page: any finite input (with
//! missing readings, markup characters in every text, degenerate ranges)
//! either draws a well-formed, self-contained SVG element (checked with
//! `check_svg`, a strict XML checker) or returns a clear error; never a
//! panic. Pages built from arbitrary text hold no script and no link
//! outside the SVG namespace declaration.

use coordinator::report::{
    bar_chart, check_svg, heatmap, histogram, line_plot, plan_svg, BarChart, BarGroup, Block,
    Direction, Figure, Heatmap, Histogram, LinePlot, Marker, NoteKind, Page, PlanSensor, PlotSize,
    PriorBand, ReportError, Section, SensorKind, Series, SeriesStyle, Table,
};
use proptest::prelude::*;

/// Text with markup characters, quotes, entities, non-ASCII and controls.
fn text() -> impl Strategy<Value = String> {
    "[a-zA-Z0-9 <>&\"'/;=#()²Δ−\u{0}\u{7}\t]{0,24}"
}

/// A reading: finite over a wide range, sometimes missing or infinite.
fn reading() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -1e9..1e9f64,
        2 => -1e-6..1e-6f64,
        1 => -1e300..1e300f64,
        1 => prop_oneof![Just(f64::MAX), Just(f64::MIN), Just(f64::MIN_POSITIVE), Just(-f64::MIN_POSITIVE)],
        1 => Just(0.0),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
    ]
}

fn size() -> impl Strategy<Value = PlotSize> {
    (200u32..1400, 150u32..900).prop_map(|(width_px, height_px)| PlotSize { width_px, height_px })
}

fn series() -> impl Strategy<Value = Series> {
    (text(), proptest::collection::vec((reading(), reading()), 0..300), 0..3u8).prop_map(
        |(name, xy, style)| {
            let style =
                [SeriesStyle::Solid, SeriesStyle::Dashed, SeriesStyle::Points][style as usize];
            let (x, y) = xy.into_iter().unzip();
            Series { name, x, y, style }
        },
    )
}

fn ok_or_clear_error(r: Result<String, ReportError>) -> Result<(), TestCaseError> {
    match r {
        Ok(svg) => {
            check_svg(&svg).map_err(|e| TestCaseError::fail(format!("{e}: {svg}")))?;
        }
        Err(e) => prop_assert!(!matches!(e, ReportError::BadSvg { .. }), "{e}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn line_plots_are_well_formed(
        title in text(), x_label in text(), y_label in text(),
        series in proptest::collection::vec(series(), 0..4),
        log_x: bool, log_y: bool, size in size(),
    ) {
        let plot = LinePlot { title, x_label, y_label, series, log_x, log_y, size };
        let r = line_plot(&plot);
        let drawable = plot.series.iter().any(|s| s.x.iter().zip(&s.y).any(|(x, y)| {
            x.is_finite() && y.is_finite() && (!log_x || *x > 0.0) && (!log_y || *y > 0.0)
        }));
        prop_assert_eq!(r.is_ok(), drawable, "{:?}", r.as_ref().err());
        ok_or_clear_error(r)?;
    }

    #[test]
    fn heatmaps_are_well_formed(
        title in text(), z_label in text(),
        nx in 1usize..25, ny in 1usize..25, x0 in -1e6..1e6f64, dx in 1e-3..1e3f64, y0 in 0.0..100.0f64, dy in 1e-3..10.0f64,
        values in proptest::collection::vec(reading(), 625),
        z_limit in proptest::option::of(1e-3..1e3f64), size in size(),
    ) {
        let map = Heatmap {
            title, x_label: "time (s)".into(), y_label: "frequency (Hz)".into(), z_label,
            x: (0..nx).map(|i| x0 + dx * i as f64).collect(),
            y: (0..ny).map(|j| y0 + dy * j as f64).collect(),
            z: (0..nx).map(|i| (0..ny).map(|j| values[i * 25 + j]).collect()).collect(),
            z_limit, size,
        };
        ok_or_clear_error(heatmap(&map))?;
    }

    #[test]
    fn histograms_are_well_formed(
        title in text(), samples in proptest::collection::vec(reading(), 0..400),
        bins in proptest::option::of(0usize..80), band in proptest::option::of((reading(), reading())),
        marker in reading(), size in size(),
    ) {
        let prior = band.filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|(low, high)| PriorBand { label: "prior".into(), low, high });
        let markers = if marker.is_finite() { vec![Marker { label: "mean".into(), x: marker }] } else { vec![] };
        let h = Histogram { title, x_label: "K (N/mm)".into(), samples, bins, prior, markers, size };
        ok_or_clear_error(histogram(&h))?;
    }

    #[test]
    fn bar_charts_are_well_formed(
        title in text(), categories in proptest::collection::vec(text(), 0..7),
        groups in proptest::collection::vec((text(), proptest::collection::vec(reading(), 7)), 0..4),
        highlight in proptest::option::of(0usize..8), size in size(),
    ) {
        let n = categories.len();
        let groups = groups.into_iter().map(|(name, v)| BarGroup { name, values: v[..n].to_vec() }).collect();
        let chart = BarChart { title, x_label: "model".into(), y_label: "MDL (nats)".into(), categories, groups, highlight, size };
        ok_or_clear_error(bar_chart(&chart))?;
    }

    #[test]
    fn plans_are_well_formed(
        nx in 1usize..30, ny in 1usize..30, module_m in 0.3..1.2f64, main_every in 1usize..4,
        sensors in proptest::collection::vec((text(), 0.0..1.0f64, 0.0..1.0f64, any::<bool>(), any::<bool>(), any::<bool>()), 0..12),
    ) {
        let (lx, ly) = (nx as f64 * module_m, ny as f64 * module_m);
        let sensors: Vec<PlanSensor> = sensors.into_iter().map(|(id, fx, fy, dx, acc, highlight)| PlanSensor {
            id, x_m: fx * lx, y_m: fy * ly,
            direction: if dx { Direction::X } else { Direction::Y },
            kind: if acc { SensorKind::Acceleration } else { SensorKind::Displacement },
            highlight,
        }).collect();
        let svg = plan_svg(lx, ly, module_m, module_m * main_every as f64, &sensors);
        prop_assert!(svg.is_ok(), "{:?}", svg.err());
        ok_or_clear_error(svg)?;
    }

    #[test]
    fn pages_hold_no_script_and_no_link(
        title in text(), subtitle in text(), heading in text(), id in text(), para in text(),
        key in text(), value in text(), cell in text(), note in text(),
    ) {
        for t in [&title, &subtitle, &heading, &id, &para, &key, &value, &cell, &note] {
            prop_assume!(!t.to_ascii_lowercase().contains("http"));
        }
        let svg = plan_svg(3.6, 3.6, 0.6, 1.2, &[]).unwrap();
        let page = Page {
            title, subtitle,
            sections: vec![Section { id, heading, blocks: vec![
                Block::Paragraph(para),
                Block::KeyValues(vec![(key, value)]),
                Block::Table(Table { caption: cell.clone(), header: vec![cell.clone()], rows: vec![vec![cell]], highlight_row: Some(0) }),
                Block::Figure(Figure { caption: note.clone(), svg }),
                Block::Note { kind: NoteKind::Warning, text: note },
            ] }],
        };
        let html = page.to_html();
        prop_assert!(!html.to_ascii_lowercase().contains("<script"));
        let xmlns = r#"xmlns="http://www.w3.org/2000/svg""#;
        prop_assert_eq!(html.matches("http").count(), html.matches(xmlns).count());
        prop_assert_eq!(html.matches("<svg").count(), 1);
        prop_assert_eq!(html.matches("<section").count(), html.matches("</section>").count());
    }
}
