//! Text for the XML files the workspace writes (modelDescription.xml, the FMU documentation,
//! SSP's .ssd and .ssv). It lives in this leaf crate because both writers, the FMU glue and the
//! master, already depend on it and neither may depend on the other.

/// Escapes `s` for an XML attribute value in double quotes (also valid as element text).
/// Tab, line feed and carriage return are written as character references: a parser
/// normalises them to spaces in an attribute value otherwise (XML 1.0, section 3.3.3), so the
/// value would not read back as written.
pub fn escape_attribute(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c => out.push(c),
        }
    }
    out
}

/// The first character of `s` that XML 1.0 cannot hold, not even as a character reference
/// (section 2.2: the C0 controls other than tab, line feed and carriage return, and U+FFFE,
/// U+FFFF). A writer refuses such a text instead of writing a file no parser reads.
pub fn forbidden_in_xml(s: &str) -> Option<char> {
    s.chars().find(|&c| {
        (c < ' ' && !matches!(c, '\t' | '\n' | '\r')) || c == '\u{FFFE}' || c == '\u{FFFF}'
    })
}

#[cfg(test)]
mod tests {
    use super::{escape_attribute, forbidden_in_xml};

    #[test]
    fn characters_xml_cannot_hold_are_found() {
        assert_eq!(forbidden_in_xml("tab\tline\nreturn\r ünï ✓"), None);
        assert_eq!(forbidden_in_xml("a\u{1}b"), Some('\u{1}'));
        assert_eq!(forbidden_in_xml("nul\0"), Some('\0'));
        assert_eq!(forbidden_in_xml("\u{FFFF}"), Some('\u{FFFF}'));
        // DEL and the C1 controls are allowed in XML 1.0
        assert_eq!(forbidden_in_xml("\u{7F}\u{85}"), None);
        for bad in ["a\u{1}b", "\u{1F}", "\u{FFFE}"] {
            let xml = format!(r#"<a v="{}"/>"#, escape_attribute(bad));
            assert!(roxmltree::Document::parse(&xml).is_err(), "{bad:?} parsed");
        }
    }

    #[test]
    fn every_value_reads_back_as_written() {
        for s in [
            "",
            "plain",
            "a & b < c > d",
            r#"say "hi" and 'bye'"#,
            "line\nbreak\r\nand\ttab",
            "&amp; already escaped",
            "ünïcödé ✓",
        ] {
            let xml = format!(
                r#"<a v="{}">{}</a>"#,
                escape_attribute(s),
                escape_attribute(s)
            );
            let doc = roxmltree::Document::parse(&xml).unwrap();
            let root = doc.root_element();
            assert_eq!(root.attribute("v"), Some(s), "attribute of {s:?}");
            assert_eq!(root.text().unwrap_or(""), s, "text of {s:?}");
        }
    }
}
