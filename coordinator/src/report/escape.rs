//! HTML/XML escaping of text and attribute values, and number formatting
//! for SVG coordinates.

/// Escape `text` for HTML/XML text content and double-quoted attribute
/// values: `&`, `<`, `>`, `"` and `'` become entities; control characters
/// other than tab and newline are dropped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            '\t' | '\n' => out.push(c),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

/// A pixel coordinate with at most two decimals and no trailing zeros
/// (keeps SVG paths short); non-finite values become 0.
pub fn px(v: f64) -> String {
    if !v.is_finite() {
        return "0".to_string();
    }
    let s = format!("{:.2}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup_and_quotes() {
        assert_eq!(
            escape(r#"<b>"a" & 'b'</b>"#),
            "&lt;b&gt;&quot;a&quot; &amp; &#39;b&#39;&lt;/b&gt;"
        );
    }

    #[test]
    fn keeps_unicode_and_drops_control_characters() {
        assert_eq!(escape("m/s²\u{0}\u{7}\tΔt"), "m/s²\tΔt");
    }

    #[test]
    fn escaping_twice_escapes_the_ampersands() {
        assert_eq!(escape(&escape("&")), "&amp;amp;");
    }

    #[test]
    fn px_is_short() {
        assert_eq!(px(1.0), "1");
        assert_eq!(px(1.5), "1.5");
        assert_eq!(px(-0.001), "0");
        assert_eq!(px(2.345678), "2.35");
        assert_eq!(px(f64::NAN), "0");
    }
}
