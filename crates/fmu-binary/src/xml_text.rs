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

#[cfg(test)]
mod tests {
    use super::escape_attribute;

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
