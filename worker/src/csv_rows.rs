//! The one CSV reader behind ceilfarm's tabular inputs: bundle run files
//! and `modal.csv` (coordinator), excitation records (worker) and another
//! simulator's history files (coordinator's `synth`).
//!
//! It wraps the `csv` crate (quoted fields, a UTF-8 byte-order mark, LF,
//! CRLF or CR line ends) and adds what every caller needs: fields trimmed,
//! blank lines skipped, `#` comment lines skipped where the format allows
//! them, the 1-based line of each row, and bounds that keep hostile input
//! from exhausting memory (a line longer than [`CsvLimits::max_line_bytes`]
//! or with more than [`CsvLimits::max_fields`] fields stops the read, as do
//! a NUL byte and text that is not UTF-8). Rows may differ in length; the
//! caller checks counts with its own message.
//!
//! ```
//! use worker::csv_rows::{CsvLimits, CsvRows};
//! let text = "\u{feff}\"t\",a\r\n# a comment\r\n0.0, 1.5\r\n";
//! let mut rows = CsvRows::new(text.as_bytes(), CsvLimits::default(), true);
//! let (line, header) = rows.next_row().unwrap().unwrap();
//! assert_eq!((line, header.iter().collect::<Vec<_>>()), (1, vec!["t", "a"]));
//! let (line, row) = rows.next_row().unwrap().unwrap();
//! assert_eq!((line, &row[1]), (3, "1.5"));
//! assert!(rows.next_row().unwrap().is_none());
//! ```

use csv::StringRecord;
use std::cell::RefCell;
use std::collections::VecDeque;
use std::io::Read;
use std::rc::Rc;

/// Bounds on one CSV file's lines.
#[derive(Debug, Clone, Copy)]
pub struct CsvLimits {
    /// Longest accepted physical line (bytes, line end included).
    pub max_line_bytes: usize,
    /// Most fields in one row.
    pub max_fields: usize,
}

impl Default for CsvLimits {
    fn default() -> Self {
        Self { max_line_bytes: 1 << 20, max_fields: 4096 }
    }
}

/// Why a CSV text cannot be read: the line (1-based) and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The underlying reader failed.
    #[error("{source}")]
    Io {
        /// The cause.
        source: std::io::Error,
    },
    /// A physical line exceeds the limit.
    #[error("line longer than the limit of {limit} bytes")]
    LineTooLong {
        /// The line.
        line: usize,
        /// The limit (bytes).
        limit: usize,
    },
    /// A row has more fields than the limit.
    #[error("{found} columns: more than the limit of {limit}")]
    TooManyFields {
        /// The line.
        line: usize,
        /// Fields found.
        found: usize,
        /// The limit.
        limit: usize,
    },
    /// A NUL byte.
    #[error("NUL byte: expected plain text")]
    Nul {
        /// The line.
        line: usize,
    },
    /// Bytes that are not UTF-8.
    #[error("not UTF-8 text")]
    NotUtf8 {
        /// The line.
        line: usize,
    },
}

impl CsvError {
    /// The 1-based line the error is on, if it is on one.
    pub fn line(&self) -> Option<usize> {
        match self {
            CsvError::Io { .. } => None,
            CsvError::LineTooLong { line, .. }
            | CsvError::TooManyFields { line, .. }
            | CsvError::Nul { line }
            | CsvError::NotUtf8 { line } => Some(*line),
        }
    }
}

/// Rows of one CSV text, read one at a time into a reused record.
pub struct CsvRows<R> {
    reader: csv::Reader<LineBound<R>>,
    record: StringRecord,
    seen: Rc<RefCell<Seen>>,
    limits: CsvLimits,
    comments: bool,
}

impl<R: Read> CsvRows<R> {
    /// Reads `input` within `limits`; `comments`: lines starting with `#`
    /// (after blanks) are skipped.
    pub fn new(input: R, limits: CsvLimits, comments: bool) -> Self {
        let seen = Rc::new(RefCell::new(Seen::default()));
        let bounded = LineBound {
            inner: input,
            since_newline: 0,
            limit: limits.max_line_bytes,
            seen: seen.clone(),
        };
        let reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .comment(comments.then_some(b'#'))
            .from_reader(bounded);
        Self { reader, record: StringRecord::new(), seen, limits, comments }
    }

    /// The next row that is neither blank nor a comment, with its 1-based line.
    pub fn next_row(&mut self) -> Result<Option<(usize, &StringRecord)>, CsvError> {
        loop {
            let more = self.reader.read_record(&mut self.record).map_err(|e| self.error(e))?;
            if !more {
                return Ok(None);
            }
            let line = self.record_line();
            if self.skipped() {
                continue;
            }
            self.check(line)?;
            return Ok(Some((line, &self.record)));
        }
    }

    /// The first line of the record just read. The `csv` crate's own
    /// position is where its search began, before any blank or comment
    /// lines, so the line is counted here from where the record ends.
    fn record_line(&self) -> usize {
        let end = self.reader.position().byte();
        let last = self.seen.borrow_mut().lines_before(end.saturating_sub(1)) + 1;
        let inside = self.record.as_slice().bytes().filter(|&b| b == b'\n').count();
        last.saturating_sub(inside)
    }

    /// Whether the current record is a blank or comment line.
    fn skipped(&self) -> bool {
        let first = self.record.get(0).unwrap_or("");
        let blank = self.record.len() == 1 && first.is_empty();
        blank || (self.comments && first.starts_with('#'))
    }

    /// Refuses a record with too many fields or a NUL byte.
    fn check(&self, line: usize) -> Result<(), CsvError> {
        let found = self.record.len();
        if found > self.limits.max_fields {
            return Err(CsvError::TooManyFields { line, found, limit: self.limits.max_fields });
        }
        if self.record.iter().any(|f| f.contains('\0')) {
            return Err(CsvError::Nul { line });
        }
        Ok(())
    }

    /// Maps a `csv` error to one naming its line.
    fn error(&self, e: csv::Error) -> CsvError {
        if let Some(line) = self.seen.borrow().overlong {
            return CsvError::LineTooLong { line, limit: self.limits.max_line_bytes };
        }
        let end = self.reader.position().byte();
        let line = self.seen.borrow_mut().lines_before(end.saturating_sub(1)) + 1;
        let message = e.to_string();
        match e.into_kind() {
            csv::ErrorKind::Io(source) => CsvError::Io { source },
            csv::ErrorKind::Utf8 { .. } => CsvError::NotUtf8 { line },
            _ => CsvError::Io { source: std::io::Error::other(message) },
        }
    }
}

/// Where the newlines read so far lie, shared between the bounded reader
/// that sees the bytes and the rows that need line numbers.
#[derive(Default)]
struct Seen {
    /// Newlines already counted (before the last record's end).
    counted: usize,
    /// Byte offsets of newlines read ahead and not yet counted.
    pending: VecDeque<u64>,
    /// Bytes read so far.
    read: u64,
    /// The line that exceeded the limit, once one did.
    overlong: Option<usize>,
}

impl Seen {
    /// Newlines at offsets below `offset` (offsets only grow between calls).
    fn lines_before(&mut self, offset: u64) -> usize {
        while self.pending.front().is_some_and(|&o| o < offset) {
            self.pending.pop_front();
            self.counted += 1;
        }
        self.counted
    }
}

/// A reader that fails once a physical line exceeds `limit` bytes, so the
/// `csv` parser never buffers more than one bounded line (plus its
/// read-ahead), and that notes where each newline lies.
struct LineBound<R> {
    inner: R,
    since_newline: usize,
    limit: usize,
    seen: Rc<RefCell<Seen>>,
}

impl<R: Read> Read for LineBound<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut seen = self.seen.borrow_mut();
        for &b in &buf[..n] {
            self.since_newline += 1;
            if b == b'\n' {
                let at = seen.read;
                seen.pending.push_back(at);
                self.since_newline = 0;
            } else if self.since_newline > self.limit {
                let line = seen.counted + seen.pending.len() + 1;
                seen.overlong = Some(line);
                return Err(std::io::Error::other("line too long"));
            }
            seen.read += 1;
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(text: &str, comments: bool) -> Vec<(usize, Vec<String>)> {
        let mut r = CsvRows::new(text.as_bytes(), CsvLimits::default(), comments);
        let mut out = Vec::new();
        while let Some((line, rec)) = r.next_row().unwrap() {
            out.push((line, rec.iter().map(str::to_string).collect()));
        }
        out
    }

    #[test]
    fn bom_crlf_quotes_and_comments_are_read() {
        let got = rows("\u{feff}\"t\",\"a,b\"\r\n\r\n # note\r\n1,2\r\n", true);
        assert_eq!(
            got,
            vec![(1, vec!["t".into(), "a,b".into()]), (4, vec!["1".into(), "2".into()])]
        );
    }

    #[test]
    fn comments_are_data_when_not_allowed() {
        let got = rows("t_s\n#1\n", false);
        assert_eq!(got[1], (2, vec!["#1".to_string()]));
    }

    #[test]
    fn an_overlong_line_is_refused_with_its_line() {
        let text = format!("t\n1\n{}\n", "9".repeat(100));
        let limits = CsvLimits { max_line_bytes: 50, max_fields: 10 };
        let mut r = CsvRows::new(text.as_bytes(), limits, true);
        // The error comes as soon as the read-ahead reaches the line.
        let e = loop {
            match r.next_row() {
                Ok(Some(_)) => continue,
                Ok(None) => panic!("the overlong line was accepted"),
                Err(e) => break e,
            }
        };
        assert_eq!(e.line(), Some(3));
        assert_eq!(e.to_string(), "line longer than the limit of 50 bytes");
    }

    #[test]
    fn nul_too_many_fields_and_bad_utf8_are_refused() {
        let limits = CsvLimits { max_line_bytes: 100, max_fields: 2 };
        let e = CsvRows::new(&b"t\n1\0\n"[..], limits, true).next_row().map(|_| ()).err();
        assert!(e.is_none(), "the first row is fine");
        let mut r = CsvRows::new(&b"t\n1\0\n"[..], limits, true);
        r.next_row().unwrap();
        assert_eq!(r.next_row().unwrap_err().to_string(), "NUL byte: expected plain text");
        let mut r = CsvRows::new(&b"a,b,c\n"[..], limits, true);
        assert_eq!(r.next_row().unwrap_err().to_string(), "3 columns: more than the limit of 2");
        let mut r = CsvRows::new(&b"t\n\xff\n"[..], limits, true);
        r.next_row().unwrap();
        let e = r.next_row().unwrap_err();
        assert_eq!((e.line(), e.to_string()), (Some(2), "not UTF-8 text".to_string()));
    }
}
