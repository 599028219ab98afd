//! A minimal SVG writer: the handful of elements the plots use, every text
//! escaped, every coordinate rounded to 0.01 px. Colours are CSS colour
//! strings chosen by this module, never by the caller.
//!
//! Hand-written rather than through plotters' SVG backend, measured on one
//! figure drawn both ways (Figure 18 of the demo's report, run sx-strong,
//! sensor A1x: three series, 3 601 points; plotters 0.3.7;
//! `scripts/bench/plotting/run` reprints the numbers). plotters draws on
//! whole pixels (`BackendCoord = (i32, i32)`, floored) and moves the
//! vertices by up to 1.39 px (mean 0.76; 103 land on the pixel of the one
//! before), where this writer keeps them within 0.005 px; it writes its own
//! text ("-15.0" for "−15", font sizes 12.1, 10.5 and 9.7 px for 15, 13 and
//! 12, no `<title>` for screen readers) and one polyline per dash, so the
//! figure is 87 111 bytes against 54 143. plotters is faster (0.79 ms of
//! CPU per figure against 1.59, median of 15 rounds of 40) and shorter (55
//! lines for this figure against the 765 of line_plot, frame, axis, svg,
//! escape, decimate and colour, which every x-y figure shares), but the
//! page's figures must keep their content, so the workspace does not
//! declare plotters; the measurement builds it in a crate of its own.

use super::escape::{escape, px};

/// Horizontal text alignment (SVG `text-anchor`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Anchor {
    /// Text starts at x.
    Start,
    /// Text is centred on x.
    Middle,
    /// Text ends at x.
    End,
}

impl Anchor {
    fn attr(self) -> &'static str {
        match self {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        }
    }
}

/// Stroke of a line or path: colour, width (px) and optional dash pattern.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stroke<'a> {
    /// CSS colour.
    pub colour: &'a str,
    /// Width in px.
    pub width: f64,
    /// `stroke-dasharray`, e.g. "6 4".
    pub dash: Option<&'a str>,
}

impl<'a> Stroke<'a> {
    /// A solid stroke.
    pub fn solid(colour: &'a str, width: f64) -> Self {
        Stroke { colour, width, dash: None }
    }

    fn attrs(&self) -> String {
        let dash = self.dash.map(|d| format!(r#" stroke-dasharray="{d}""#)).unwrap_or_default();
        format!(r#"stroke="{}" stroke-width="{}"{dash}"#, self.colour, px(self.width))
    }
}

/// Text style: size (px), anchor, bold, rotation (degrees about the anchor).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TextStyle {
    /// Font size in px.
    pub size: f64,
    /// Alignment.
    pub anchor: Anchor,
    /// Bold weight.
    pub bold: bool,
    /// Rotation in degrees (clockwise) about the text's anchor point.
    pub rotate_deg: f64,
}

impl TextStyle {
    /// Regular text of `size` px with `anchor`.
    pub fn new(size: f64, anchor: Anchor) -> Self {
        TextStyle { size, anchor, bold: false, rotate_deg: 0.0 }
    }
}

/// Estimated width (px) of `text` at `size` px in a sans-serif face.
pub(crate) fn text_width(text: &str, size: f64) -> f64 {
    text.chars().count() as f64 * size * 0.58
}

/// An SVG document under construction.
pub(crate) struct Svg {
    out: String,
}

impl Svg {
    /// Start a `width` x `height` px drawing titled `title` (for screen readers).
    pub fn new(width: f64, height: f64, title: &str) -> Self {
        let mut out = String::with_capacity(16 * 1024);
        out.push_str(&format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" role="img" font-family="system-ui, -apple-system, 'Segoe UI', Roboto, 'DejaVu Sans', sans-serif" fill="#222">"##,
            w = px(width),
            h = px(height)
        ));
        out.push_str(&format!("<title>{}</title>", escape(title)));
        out.push_str(&format!(
            r##"<rect x="0" y="0" width="{}" height="{}" fill="#fff"/>"##,
            px(width),
            px(height)
        ));
        Svg { out }
    }

    /// A straight line.
    pub fn line(&mut self, x1: f64, y1: f64, x2: f64, y2: f64, stroke: Stroke) {
        self.out.push_str(&format!(
            r#"<line x1="{}" y1="{}" x2="{}" y2="{}" {}/>"#,
            px(x1),
            px(y1),
            px(x2),
            px(y2),
            stroke.attrs()
        ));
    }

    /// A rectangle filled with `fill` (opacity 0..1), optionally outlined.
    #[allow(clippy::too_many_arguments)] // geometry plus style, mirroring the SVG element
    pub fn rect(
        &mut self,
        x: f64,
        y: f64,
        w: f64,
        h: f64,
        fill: &str,
        opacity: f64,
        stroke: Option<Stroke>,
    ) {
        let stroke = stroke.map(|s| format!(" {}", s.attrs())).unwrap_or_default();
        let op = if opacity < 1.0 {
            format!(r#" fill-opacity="{}""#, px(opacity))
        } else {
            String::new()
        };
        self.out.push_str(&format!(
            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{fill}"{op}{stroke}/>"#,
            px(x),
            px(y),
            px(w.max(0.0)),
            px(h.max(0.0))
        ));
    }

    /// A circle of radius `r` filled with `fill`.
    pub fn circle(&mut self, cx: f64, cy: f64, r: f64, fill: &str, stroke: Option<Stroke>) {
        let stroke = stroke.map(|s| format!(" {}", s.attrs())).unwrap_or_default();
        self.out.push_str(&format!(
            r#"<circle cx="{}" cy="{}" r="{}" fill="{fill}"{stroke}/>"#,
            px(cx),
            px(cy),
            px(r)
        ));
    }

    /// An unfilled path with data `d` (built with [`PathData`]).
    pub fn path(&mut self, d: &str, stroke: Stroke) {
        if d.is_empty() {
            return;
        }
        self.out.push_str(&format!(
            r#"<path d="{d}" fill="none" stroke-linejoin="round" stroke-linecap="round" {}/>"#,
            stroke.attrs()
        ));
    }

    /// A filled closed path with data `d`.
    pub fn filled_path(&mut self, d: &str, fill: &str) {
        if d.is_empty() {
            return;
        }
        self.out.push_str(&format!(r#"<path d="{d}" fill="{fill}"/>"#));
    }

    /// Text at (x, y) (baseline), escaped.
    pub fn text(&mut self, x: f64, y: f64, text: &str, style: TextStyle) {
        let weight = if style.bold { r#" font-weight="bold""# } else { "" };
        let rotate = if style.rotate_deg != 0.0 {
            format!(r#" transform="rotate({} {} {})""#, px(style.rotate_deg), px(x), px(y))
        } else {
            String::new()
        };
        self.out.push_str(&format!(
            r#"<text x="{}" y="{}" font-size="{}" text-anchor="{}"{weight}{rotate}>{}</text>"#,
            px(x),
            px(y),
            px(style.size),
            style.anchor.attr(),
            escape(text)
        ));
    }

    /// An embedded PNG image (base64 data) stretched over the rectangle.
    pub fn png(&mut self, x: f64, y: f64, w: f64, h: f64, base64: &str) {
        self.out.push_str(&format!(
            r#"<image x="{}" y="{}" width="{}" height="{}" preserveAspectRatio="none" style="image-rendering:pixelated" href="data:image/png;base64,{base64}"/>"#,
            px(x),
            px(y),
            px(w),
            px(h)
        ));
    }

    /// Close the document and return it.
    pub fn finish(mut self) -> String {
        self.out.push_str("</svg>");
        self.out
    }
}

/// Path data (`d`) built from polylines; a non-finite point breaks the line.
#[derive(Default)]
pub(crate) struct PathData {
    d: String,
    points_in_run: usize,
}

impl PathData {
    /// Add a point; `None` lifts the pen (a gap).
    pub fn point(&mut self, p: Option<(f64, f64)>) {
        match p {
            Some((x, y)) => {
                let cmd = if self.points_in_run > 0 { 'L' } else { 'M' };
                self.d.push_str(&format!("{cmd}{} {}", px(x), px(y)));
                self.points_in_run += 1;
            }
            None => self.lift(),
        }
    }

    /// Lift the pen; a lone point becomes a zero-length segment, which a
    /// round line cap draws as a dot.
    fn lift(&mut self) {
        if self.points_in_run == 1 {
            self.d.push_str("h0");
        }
        self.points_in_run = 0;
    }

    /// Close the current subpath.
    pub fn close(&mut self) {
        self.d.push('Z');
        self.points_in_run = 0;
    }

    /// The `d` attribute value.
    pub fn into_string(mut self) -> String {
        self.lift();
        self.d
    }
}
