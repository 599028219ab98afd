//! Why a plot could not be drawn: always the plot's title, then what is
//! wrong and what was expected.

/// A plot that could not be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReportError {
    /// Nothing to draw: no series, or no finite value in any of them.
    #[error("{plot}: nothing to draw ({what})")]
    Empty {
        /// The plot's title.
        plot: String,
        /// What was empty, e.g. "no series has a finite point".
        what: String,
    },
    /// Two inputs that must have the same length do not.
    #[error("{plot}: {what}: lengths differ ({expected} expected, {found} found)")]
    LengthMismatch {
        /// The plot's title.
        plot: String,
        /// Which input, e.g. `series "measured" y`.
        what: String,
        /// The length it must have.
        expected: usize,
        /// The length it has.
        found: usize,
    },
    /// A number is outside the range it must lie in.
    #[error("{plot}: {key} = {value} (expected {expected})")]
    BadValue {
        /// The plot's title.
        plot: String,
        /// The input, e.g. `size.width_px` or `sensors[2].x_m`.
        key: String,
        /// Its value.
        value: f64,
        /// What was expected, e.g. "> 0" or "within 0 to 3.6 m".
        expected: String,
    },
    /// The PNG encoder refused an image.
    #[error("{plot}: image: {message}")]
    Image {
        /// The plot's title.
        plot: String,
        /// The encoder's reason.
        message: String,
    },
    /// An SVG fragment is not well-formed or holds something a
    /// self-contained page must not (scripts, external links).
    #[error("svg: {what} at byte {at}")]
    BadSvg {
        /// What is wrong.
        what: String,
        /// Byte offset in the fragment.
        at: usize,
    },
}
