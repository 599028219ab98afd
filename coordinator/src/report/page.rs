//! The page model and its HTML: a [`Page`] of [`Section`]s of [`Block`]s,
//! written as one self-contained HTML5 document (inline CSS, figures as
//! inline SVG, a table of contents, no scripts, no external references).
//! Every text is escaped; every figure is checked with [`check_svg`] and
//! replaced by a warning note if it is not well-formed or not
//! self-contained, so the page itself always is.

use super::escape::escape;
use super::wellformed::check_svg;
use super::ReportError;

/// The page's stylesheet, inlined into `<head>`.
const STYLE: &str = include_str!("style.css");

/// A report page: title, subtitle, sections in reading order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Page {
    /// Page title (the `<h1>` and the window title).
    pub title: String,
    /// One line under the title, e.g. the bundle and the date.
    pub subtitle: String,
    /// Sections in order; each gets an entry in the table of contents.
    pub sections: Vec<Section>,
}

/// A section: anchor id, heading, blocks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Section {
    /// Anchor for the table of contents; reduced to `[a-z0-9_-]` and made unique.
    pub id: String,
    /// Heading text.
    pub heading: String,
    /// Content in order.
    pub blocks: Vec<Block>,
}

/// How a note is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoteKind {
    /// Neutral information (blue).
    Info,
    /// Something the reader must not miss (orange).
    Warning,
}

/// A table: caption, header, rows of cells, an optional highlighted row.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// Caption over the table.
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Rows of cells; numeric-looking cells are right-aligned.
    pub rows: Vec<Vec<String>>,
    /// Index into `rows` of the row to highlight (e.g. the chosen model).
    pub highlight_row: Option<usize>,
}

/// A figure: an SVG element from this module's plot functions, and a caption.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Figure {
    /// Caption under the figure (numbered on the page).
    pub caption: String,
    /// One `<svg>` element, e.g. from [`super::line_plot`].
    pub svg: String,
}

/// One piece of a section's content.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A paragraph of text (line breaks kept).
    Paragraph(String),
    /// Label/value pairs, e.g. the specimen's dimensions.
    KeyValues(Vec<(String, String)>),
    /// A table.
    Table(Table),
    /// A figure at full width.
    Figure(Figure),
    /// Figures side by side, wrapping on narrow screens (e.g. posterior marginals).
    FigureGrid(Vec<Figure>),
    /// A highlighted note.
    Note {
        /// Info or warning.
        kind: NoteKind,
        /// The text.
        text: String,
    },
}

impl Block {
    /// A figure from a plot result; a plot that failed becomes a warning
    /// note naming the caption and the error, so one bad plot never loses the page.
    pub fn figure(caption: &str, svg: Result<String, ReportError>) -> Block {
        match svg {
            Ok(svg) => Block::Figure(Figure { caption: caption.to_string(), svg }),
            Err(e) => {
                Block::Note { kind: NoteKind::Warning, text: format!("{caption}: not drawn: {e}") }
            }
        }
    }
}

impl Page {
    /// The page as one self-contained HTML5 document.
    pub fn to_html(&self) -> String {
        let ids = unique_ids(&self.sections);
        let mut out = String::with_capacity(64 * 1024);
        out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
        out.push_str(&format!(
            "<title>{}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n",
            escape(&self.title)
        ));
        out.push_str(&format!("<header>\n<h1>{}</h1>\n", escape(&self.title)));
        if !self.subtitle.is_empty() {
            out.push_str(&format!("<p class=\"subtitle\">{}</p>\n", escape(&self.subtitle)));
        }
        out.push_str("</header>\n");
        out.push_str(&toc(&self.sections, &ids));
        out.push_str("<main>\n");
        let mut figure_no = 0;
        for (s, id) in self.sections.iter().zip(&ids) {
            out.push_str(&format!("<section id=\"{id}\">\n<h2>{}</h2>\n", escape(&s.heading)));
            for b in &s.blocks {
                out.push_str(&block_html(b, &mut figure_no));
            }
            out.push_str("</section>\n");
        }
        out.push_str("</main>\n");
        out.push_str(&format!(
            "<footer>Written by ceilfarm {}.</footer>\n</body>\n</html>\n",
            env!("CARGO_PKG_VERSION")
        ));
        out
    }
}

/// Section ids reduced to `[a-z0-9_-]`, never empty, never repeated.
fn unique_ids(sections: &[Section]) -> Vec<String> {
    let mut seen: Vec<String> = Vec::new();
    for (i, s) in sections.iter().enumerate() {
        let mut id: String =
            s.id.chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                        c.to_ascii_lowercase()
                    } else {
                        '-'
                    }
                })
                .collect();
        if id.is_empty() || !id.starts_with(|c: char| c.is_ascii_alphabetic()) {
            id = format!("s{}-{id}", i + 1).trim_end_matches('-').to_string();
        }
        let base = id.clone();
        let mut n = 2;
        while seen.contains(&id) {
            id = format!("{base}-{n}");
            n += 1;
        }
        seen.push(id);
    }
    seen
}

fn toc(sections: &[Section], ids: &[String]) -> String {
    if sections.is_empty() {
        return String::new();
    }
    let mut out = String::from("<nav class=\"toc\">\n<h2>Contents</h2>\n<ol>\n");
    for (s, id) in sections.iter().zip(ids) {
        out.push_str(&format!("<li><a href=\"#{id}\">{}</a></li>\n", escape(&s.heading)));
    }
    out.push_str("</ol>\n</nav>\n");
    out
}

fn block_html(b: &Block, figure_no: &mut usize) -> String {
    match b {
        Block::Paragraph(t) => format!("<p>{}</p>\n", escape(t)),
        Block::KeyValues(kv) => {
            let items: String = kv
                .iter()
                .map(|(k, v)| format!("<dt>{}</dt><dd>{}</dd>\n", escape(k), escape(v)))
                .collect();
            format!("<dl class=\"kv\">\n{items}</dl>\n")
        }
        Block::Table(t) => table_html(t),
        Block::Figure(f) => figure_html(f, figure_no),
        Block::FigureGrid(fs) => {
            let inner: String = fs.iter().map(|f| figure_html(f, figure_no)).collect();
            format!("<div class=\"figure-grid\">\n{inner}</div>\n")
        }
        Block::Note { kind, text } => note_html(*kind, text),
    }
}

fn note_html(kind: NoteKind, text: &str) -> String {
    let (class, label) = match kind {
        NoteKind::Info => ("info", "Note"),
        NoteKind::Warning => ("warning", "Warning"),
    };
    format!(
        "<div class=\"note {class}\" role=\"note\"><strong>{label}:</strong> {}</div>\n",
        escape(text)
    )
}

fn figure_html(f: &Figure, figure_no: &mut usize) -> String {
    *figure_no += 1;
    let n = *figure_no;
    match check_svg(&f.svg) {
        Ok(()) => format!(
            "<figure id=\"figure-{n}\">\n{}\n<figcaption><strong>Figure {n}.</strong> {}</figcaption>\n</figure>\n",
            f.svg,
            escape(&f.caption)
        ),
        Err(e) => note_html(NoteKind::Warning, &format!("Figure {n} ({}) is not shown: {e}", f.caption)),
    }
}

/// Whether a cell reads as a number (right-aligned): digits with sign,
/// decimal point, exponent, percent or a unit-free suffix like "×".
fn is_numeric(cell: &str) -> bool {
    let t = cell.trim().trim_end_matches('%').trim();
    let t = t.replace('\u{2212}', "-");
    !t.is_empty() && t.parse::<f64>().is_ok()
}

fn table_html(t: &Table) -> String {
    let mut out = String::from("<table>\n");
    if !t.caption.is_empty() {
        out.push_str(&format!("<caption>{}</caption>\n", escape(&t.caption)));
    }
    if !t.header.is_empty() {
        let ths: String =
            t.header.iter().map(|h| format!("<th scope=\"col\">{}</th>", escape(h))).collect();
        out.push_str(&format!("<thead><tr>{ths}</tr></thead>\n"));
    }
    out.push_str("<tbody>\n");
    for (i, row) in t.rows.iter().enumerate() {
        let class = if t.highlight_row == Some(i) { " class=\"highlight\"" } else { "" };
        let tds: String = row
            .iter()
            .map(|c| {
                let num = if is_numeric(c) { " class=\"num\"" } else { "" };
                format!("<td{num}>{}</td>", escape(c))
            })
            .collect();
        out.push_str(&format!("<tr{class}>{tds}</tr>\n"));
    }
    out.push_str("</tbody>\n</table>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn page(blocks: Vec<Block>) -> Page {
        Page {
            title: "Diagnosis <type-c>".into(),
            subtitle: "bundle \"x\" & co".into(),
            sections: vec![Section { id: "Symptoms!".into(), heading: "Symptoms".into(), blocks }],
        }
    }

    #[test]
    fn every_text_is_escaped() {
        let html = page(vec![
            Block::Paragraph("<script>alert(1)</script>".into()),
            Block::KeyValues(vec![("a<b".into(), "c&d".into())]),
            Block::Table(Table {
                caption: "<i>".into(),
                header: vec!["<th>".into()],
                rows: vec![vec!["</td>".into()]],
                highlight_row: Some(0),
            }),
            Block::Note { kind: NoteKind::Warning, text: "\"quoted\"".into() },
        ])
        .to_html();
        assert!(!html.contains("<script"), "{html}");
        for s in [
            "&lt;script&gt;",
            "a&lt;b",
            "c&amp;d",
            "&lt;i&gt;",
            "&lt;th&gt;",
            "&lt;/td&gt;",
            "&quot;quoted&quot;",
        ] {
            assert!(html.contains(s), "missing {s}");
        }
        assert!(html.contains("Diagnosis &lt;type-c&gt;"));
        assert!(html.contains("<tr class=\"highlight\">"));
    }

    #[test]
    fn no_external_reference_anywhere() {
        let html = page(vec![Block::Paragraph("see https://example.org".into())]).to_html();
        assert!(!html.contains("src="));
        // the only "http" is the text the caller wrote
        assert_eq!(html.matches("http").count(), 1);
    }

    #[test]
    fn toc_links_to_cleaned_unique_ids() {
        let mut p = page(vec![]);
        p.sections.push(Section {
            id: "symptoms-".into(),
            heading: "Again".into(),
            blocks: vec![],
        });
        p.sections.push(Section { id: "".into(), heading: "Empty".into(), blocks: vec![] });
        let html = p.to_html();
        assert!(html.contains("<a href=\"#symptoms-\">Symptoms</a>"), "{html}");
        assert!(html.contains("<a href=\"#symptoms--2\">Again</a>"));
        assert!(html.contains("<section id=\"s3\">"));
    }

    #[test]
    fn a_bad_figure_becomes_a_warning() {
        let html = page(vec![
            Block::Figure(Figure {
                caption: "evil".into(),
                svg: "<svg><script>x()</script></svg>".into(),
            }),
            Block::figure(
                "failed",
                Err(ReportError::Empty { plot: "p".into(), what: "no series".into() }),
            ),
        ])
        .to_html();
        assert!(!html.contains("<script"));
        assert!(html.contains("Figure 1 (evil) is not shown"));
        assert!(html.contains("failed: not drawn: p: nothing to draw (no series)"));
    }

    #[test]
    fn numbers_are_right_aligned() {
        assert!(is_numeric("1.5e-3"));
        assert!(is_numeric("\u{2212}12.0"));
        assert!(is_numeric("63 %"));
        assert!(!is_numeric("none"));
        assert!(!is_numeric(""));
    }
}
