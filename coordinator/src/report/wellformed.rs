//! A strict check of an SVG fragment before it goes into a page: it must be
//! well-formed XML (one `<svg>` root, balanced tags, quoted attributes,
//! known entities, no stray `<` or `&`) and self-contained (no `<script>`,
//! no `<foreignObject>`, no `on*` event attributes, links only to `#ids` or
//! inline `data:image/png` images, `url(...)` only to `#ids`).

use super::ReportError;

/// Elements a self-contained, script-free figure must not contain.
const FORBIDDEN_ELEMENTS: [&str; 6] =
    ["script", "foreignobject", "iframe", "object", "embed", "style"];

/// Check `svg` is one well-formed, self-contained `<svg>` element.
pub fn check_svg(svg: &str) -> Result<(), ReportError> {
    let mut p = Parser { s: svg.as_bytes(), at: 0, stack: Vec::new(), roots: 0 };
    p.document()
}

struct Parser<'a> {
    s: &'a [u8],
    at: usize,
    stack: Vec<&'a [u8]>,
    roots: usize,
}

fn bad<T>(what: impl Into<String>, at: usize) -> Result<T, ReportError> {
    Err(ReportError::BadSvg { what: what.into(), at })
}

fn is_name_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_' || c == b':'
}

fn is_name(c: u8) -> bool {
    is_name_start(c) || c.is_ascii_digit() || c == b'-' || c == b'.'
}

impl<'a> Parser<'a> {
    fn document(&mut self) -> Result<(), ReportError> {
        while self.at < self.s.len() {
            match self.s[self.at] {
                b'<' if self.s[self.at..].starts_with(b"<!--") => self.comment()?,
                b'<' if self.s.get(self.at + 1) == Some(&b'/') => self.end_tag()?,
                b'<' => self.start_tag()?,
                b'&' => self.entity()?,
                c if self.stack.is_empty() && !c.is_ascii_whitespace() => {
                    return bad("text outside the <svg> element", self.at)
                }
                _ => self.at += 1,
            }
        }
        if let Some(open) = self.stack.last() {
            return bad(format!("<{}> is never closed", String::from_utf8_lossy(open)), self.at);
        }
        if self.roots != 1 {
            return bad(format!("{} root elements (expected one <svg>)", self.roots), self.at);
        }
        Ok(())
    }

    fn comment(&mut self) -> Result<(), ReportError> {
        match find(self.s, self.at + 4, b"-->") {
            Some(end) => {
                self.at = end + 3;
                Ok(())
            }
            None => bad("unterminated comment", self.at),
        }
    }

    fn entity(&mut self) -> Result<(), ReportError> {
        let start = self.at;
        let end = self.s[start..].iter().take(12).position(|&c| c == b';').map(|p| start + p);
        let Some(end) = end else {
            return bad("bare '&' (expected an entity such as &amp;)", start);
        };
        let name = &self.s[start + 1..end];
        let ok = matches!(name, b"amp" | b"lt" | b"gt" | b"quot" | b"apos")
            || (name.len() > 1 && name[0] == b'#' && name[1..].iter().all(u8::is_ascii_digit))
            || (name.len() > 2
                && name.starts_with(b"#x")
                && name[2..].iter().all(u8::is_ascii_hexdigit));
        if !ok {
            return bad(format!("unknown entity &{};", String::from_utf8_lossy(name)), start);
        }
        self.at = end + 1;
        Ok(())
    }

    fn name(&mut self) -> Result<&'a [u8], ReportError> {
        let start = self.at;
        if !self.s.get(start).copied().is_some_and(is_name_start) {
            return bad("expected a name", start);
        }
        while self.s.get(self.at).copied().is_some_and(is_name) {
            self.at += 1;
        }
        Ok(&self.s[start..self.at])
    }

    fn skip_space(&mut self) {
        while self.s.get(self.at).is_some_and(u8::is_ascii_whitespace) {
            self.at += 1;
        }
    }

    fn start_tag(&mut self) -> Result<(), ReportError> {
        let tag_at = self.at;
        self.at += 1;
        let name = self.name()?;
        let lower = String::from_utf8_lossy(name).to_ascii_lowercase();
        if self.stack.is_empty() {
            self.roots += 1;
            if lower != "svg" {
                return bad(format!("root element <{lower}> (expected <svg>)"), tag_at);
            }
        }
        if FORBIDDEN_ELEMENTS.contains(&lower.as_str()) {
            return bad(format!("<{lower}> is not allowed in a self-contained figure"), tag_at);
        }
        let mut seen: Vec<&[u8]> = Vec::new();
        loop {
            self.skip_space();
            match self.s.get(self.at) {
                Some(b'>') => {
                    self.at += 1;
                    self.stack.push(name);
                    return Ok(());
                }
                Some(b'/') if self.s.get(self.at + 1) == Some(&b'>') => {
                    self.at += 2;
                    return Ok(());
                }
                Some(_) => {
                    let attr = self.attribute()?;
                    if seen.contains(&attr) {
                        return bad(
                            format!("duplicate attribute {}", String::from_utf8_lossy(attr)),
                            self.at,
                        );
                    }
                    seen.push(attr);
                }
                None => return bad("unterminated tag", tag_at),
            }
        }
    }

    fn attribute(&mut self) -> Result<&'a [u8], ReportError> {
        let at = self.at;
        let name = self.name()?;
        self.skip_space();
        if self.s.get(self.at) != Some(&b'=') {
            return bad("attribute without '='", self.at);
        }
        self.at += 1;
        self.skip_space();
        let Some(&quote) = self.s.get(self.at).filter(|&&q| q == b'"' || q == b'\'') else {
            return bad("unquoted attribute value", self.at);
        };
        let start = self.at + 1;
        let Some(end) = self.s[start..].iter().position(|&c| c == quote).map(|p| start + p) else {
            return bad("unterminated attribute value", at);
        };
        let value = &self.s[start..end];
        if let Some(p) = value.iter().position(|&c| c == b'<') {
            return bad("'<' in an attribute value", start + p);
        }
        self.at = start;
        while self.at < end {
            if self.s[self.at] == b'&' {
                self.entity()?;
            } else {
                self.at += 1;
            }
        }
        self.at = end + 1;
        check_attribute(name, value, at)?;
        Ok(name)
    }

    fn end_tag(&mut self) -> Result<(), ReportError> {
        let at = self.at;
        self.at += 2;
        let name = self.name()?;
        self.skip_space();
        if self.s.get(self.at) != Some(&b'>') {
            return bad("malformed end tag", at);
        }
        self.at += 1;
        match self.stack.pop() {
            Some(open) if open == name => Ok(()),
            Some(open) => bad(
                format!(
                    "</{}> closes <{}>",
                    String::from_utf8_lossy(name),
                    String::from_utf8_lossy(open)
                ),
                at,
            ),
            None => {
                bad(format!("</{}> without an open element", String::from_utf8_lossy(name)), at)
            }
        }
    }
}

/// Refuse event handlers, external links and external `url(...)` references.
fn check_attribute(name: &[u8], value: &[u8], at: usize) -> Result<(), ReportError> {
    let name = String::from_utf8_lossy(name).to_ascii_lowercase();
    let value = String::from_utf8_lossy(value).to_ascii_lowercase();
    if name.starts_with("on") {
        return bad(format!("event attribute {name}"), at);
    }
    if (name == "href" || name.ends_with(":href") || name == "src")
        && !(value.starts_with('#') || value.starts_with("data:image/png;base64,"))
    {
        return bad(format!("{name} must point to #id or an inline PNG"), at);
    }
    if name == "xmlns" && value != "http://www.w3.org/2000/svg" {
        return bad("xmlns must be the SVG namespace", at);
    }
    let mut rest = value.as_str();
    while let Some(p) = rest.find("url(") {
        rest = rest[p + 4..].trim_start_matches(['\'', '"', ' ']);
        if !rest.starts_with('#') {
            return bad(format!("{name}: url() must point to #id"), at);
        }
    }
    Ok(())
}

fn find(s: &[u8], from: usize, pat: &[u8]) -> Option<usize> {
    s.get(from..)?.windows(pat.len()).position(|w| w == pat).map(|p| from + p)
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: &str = r#"xmlns="http://www.w3.org/2000/svg""#;

    fn ok(s: &str) {
        check_svg(s).unwrap_or_else(|e| panic!("{s}: {e}"));
    }

    fn err(s: &str, what: &str) {
        let e = check_svg(s).expect_err(s).to_string();
        assert!(e.contains(what), "{s}: {e}");
    }

    #[test]
    fn accepts_nested_elements_entities_comments() {
        ok(&format!(
            r#"<svg {NS}><g><text x="1">a &amp; b &#8722; &#x2212;</text><!-- c --><rect width='2'/></g></svg>"#
        ));
        ok(&format!(
            r##"<svg {NS}><image href="data:image/png;base64,AAAA"/><use href="#a"/></svg>"##
        ));
    }

    #[test]
    fn refuses_malformed_markup() {
        err(&format!("<svg {NS}><g></svg>"), "closes <g>");
        err(&format!("<svg {NS}><g>"), "never closed");
        err(&format!("<svg {NS}>a < b</svg>"), "expected a name");
        err(&format!("<svg {NS}>a & b</svg>"), "bare '&'");
        err(&format!("<svg {NS}>&nbsp;</svg>"), "unknown entity");
        err(&format!("<svg {NS} width=3></svg>"), "unquoted");
        err(&format!(r#"<svg {NS} a="1" a="2"></svg>"#), "duplicate");
        err(&format!("<svg {NS}></svg><svg {NS}></svg>"), "2 root elements");
        err("<g></g>", "root element <g>");
        err(&format!("<svg {NS}></svg>x"), "text outside");
        err("", "0 root elements");
    }

    #[test]
    fn refuses_scripts_and_external_references() {
        err(&format!("<svg {NS}><script>alert(1)</script></svg>"), "<script>");
        err(&format!(r#"<svg {NS}><rect onload="x()"/></svg>"#), "event attribute");
        err(&format!(r#"<svg {NS}><image href="http://example.org/a.png"/></svg>"#), "href");
        err(&format!(r#"<svg {NS}><rect fill="url(http://e.org/p)"/></svg>"#), "url()");
        err(&format!(r#"<svg {NS}><foreignObject/></svg>"#), "foreignobject");
    }
}
