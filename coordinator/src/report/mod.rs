//! The report page and its figures: a small typed page model
//! ([`Page`] → [`Section`] → [`Block`]) written as one self-contained HTML
//! file, and plot functions that return inline SVG elements: time
//! histories and spectra ([`line_plot`]), time-frequency residual maps
//! ([`heatmap`]), model comparisons ([`bar_chart`]), posterior marginals
//! ([`histogram`]) and the specimen's plan view ([`plan_svg`]).
//!
//! The page needs no network, no scripts and no fonts beyond the
//! browser's own; every text is escaped and every figure is checked
//! ([`check_svg`]) before it is embedded. Axis labels carry their units as
//! the caller writes them ("acceleration (m/s²)"); plot functions never
//! convert units.
//!
//! ```
//! use coordinator::report::{line_plot, Block, LinePlot, Page, PlotSize, Section, Series, SeriesStyle};
//!
//! let t: Vec<f64> = (0..2000).map(|i| i as f64 * 0.005).collect();
//! let plot = LinePlot {
//!     title: "run18, sensor A13".into(),
//!     x_label: "time (s)".into(),
//!     y_label: "acceleration (m/s²)".into(),
//!     series: vec![Series {
//!         name: "measured".into(),
//!         y: t.iter().map(|t| (6.0 * t).sin()).collect(),
//!         x: t,
//!         style: SeriesStyle::Solid,
//!     }],
//!     log_x: false,
//!     log_y: false,
//!     size: PlotSize::default(),
//! };
//! let page = Page {
//!     title: "Diagnosis".into(),
//!     subtitle: "bundle type-c-sweeps".into(),
//!     sections: vec![Section {
//!         id: "histories".into(),
//!         heading: "Time histories".into(),
//!         blocks: vec![Block::figure("Measured acceleration at A13.", line_plot(&plot))],
//!     }],
//! };
//! let html = page.to_html();
//! assert!(html.starts_with("<!DOCTYPE html>") && html.contains("<svg"));
//! ```

mod axis;
mod bar_chart;
mod colour;
mod decimate;
mod error;
mod escape;
mod frame;
mod heatmap;
mod histogram;
mod line_plot;
mod page;
mod plan;
mod png;
mod svg;
mod wellformed;

pub use bar_chart::{bar_chart, BarChart, BarGroup};
pub use decimate::decimate_min_max;
pub use error::ReportError;
pub use escape::escape;
pub use frame::PlotSize;
pub use heatmap::{heatmap, Heatmap, MAX_CELLS_X, MAX_CELLS_Y};
pub use histogram::{histogram, Histogram, Marker, PriorBand};
pub use line_plot::{line_plot, LinePlot, Series, SeriesStyle, MAX_POINTS_PER_SERIES};
pub use page::{Block, Figure, NoteKind, Page, Section, Table};
pub use plan::{plan_svg, Direction, PlanSensor, SensorKind};
pub use wellformed::check_svg;
