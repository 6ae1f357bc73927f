//! Reading SSP XML with roxmltree: namespaces, line numbers, required and typed attributes.
//! Every reader walks all children of an element and either uses, deliberately skips
//! (graphics, tool annotations it does not know, meta data) or refuses each one.

use roxmltree::{Document, Node};

use super::SspError;
use crate::show;

pub(super) const NS_SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
pub(super) const NS_SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
pub(super) const NS_SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";
pub(super) const NS_SSM: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping";

/// Attributes one element may have at most: roxmltree checks each new attribute against the
/// element's others, so a tag of 200 000 attributes (1 MB) took minutes to parse.
const MAX_ATTRIBUTES_PER_ELEMENT: usize = 10_000;

/// The byte offset of each line's start in a document's text, for the line of an element
/// (roxmltree's own position lookup scans the text from its start: the line of every element
/// was quadratic in the file's size, and a 40 MB description did not parse in 10 minutes).
/// u32: a member is at most 64 MiB.
pub(super) struct LineStarts(Vec<u32>);

impl LineStarts {
    fn of(text: &str) -> Self {
        LineStarts(
            std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| (i + 1) as u32))
                .collect(),
        )
    }

    /// 1-based line of an element.
    pub fn line(&self, n: Node) -> usize {
        let pos = n.range().start;
        self.0.partition_point(|&s| s as usize <= pos)
    }
}

/// Parses `text` (the content of `file`), with its line starts; DTDs are refused (roxmltree's
/// default), so no entity expansion can blow up.
pub(super) fn parse<'a>(file: &str, text: &'a str) -> Result<(Document<'a>, LineStarts), SspError> {
    let invalid = |line: usize, message: String| SspError::Invalid {
        file: file.to_string(),
        line: Some(line),
        message,
    };
    if u32::try_from(text.len()).is_err() {
        return Err(invalid(1, "larger than 4 GiB".into()));
    }
    if let Some(line) = crowded_tag(text) {
        return Err(invalid(
            line,
            format!("an element has more than {MAX_ATTRIBUTES_PER_ELEMENT} attributes"),
        ));
    }
    let doc = Document::parse(text)
        .map_err(|e| invalid(e.pos().row as usize, format!("XML syntax error: {e}")))?;
    Ok((doc, LineStarts::of(text)))
}

/// The line of the first tag with more than [`MAX_ATTRIBUTES_PER_ELEMENT`] attributes, counted
/// as the `=` of a tag outside its quoted values (a value may hold `>` and `=`); comments,
/// declarations and processing instructions (`<!`, `<?`) are not tags.
fn crowded_tag(text: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let (mut tag_start, mut quote, mut count) = (None::<usize>, None::<u8>, 0usize);
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        match (tag_start, quote) {
            (None, _) => {
                if b == b'<' {
                    match bytes.get(i + 1) {
                        Some(b'!') if bytes[i..].starts_with(b"<!--") => {
                            // a comment ends at "-->" whatever it holds
                            let end = text[i + 4..].find("-->").map_or(bytes.len(), |e| i + 4 + e);
                            i = end;
                        }
                        Some(b'!' | b'?') => {
                            let end = text[i..].find('>').map_or(bytes.len(), |e| i + e);
                            i = end;
                        }
                        _ => (tag_start, count) = (Some(i), 0),
                    }
                }
            }
            (Some(_), Some(q)) => {
                if b == q {
                    quote = None;
                }
            }
            (Some(at), None) => match b {
                b'"' | b'\'' => quote = Some(b),
                b'>' => tag_start = None,
                b'=' => {
                    count += 1;
                    if count > MAX_ATTRIBUTES_PER_ELEMENT {
                        return Some(1 + bytes[..at].iter().filter(|&&c| c == b'\n').count());
                    }
                }
                _ => {}
            },
        }
        i += 1;
    }
    None
}

/// Whether `n` is the element `name` of namespace `ns`.
pub(super) fn is(n: Node, ns: &str, name: &str) -> bool {
    n.is_element() && n.tag_name().name() == name && n.tag_name().namespace() == Some(ns)
}

/// The element children of `n`.
pub(super) fn elements<'a, 'i>(n: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    n.children().filter(|c| c.is_element())
}

/// Meta data and signatures do not change the simulation: skipped wherever the schemas allow
/// them (SSP 1.0 has them in each file's own namespace, 2.0 as `ssc:MetaData` and
/// `ssc:Signature`, several of each).
pub(super) fn is_meta(n: Node) -> bool {
    matches!(n.tag_name().name(), "MetaData" | "Signature")
        && matches!(
            n.tag_name().namespace(),
            Some(NS_SSD | NS_SSC | NS_SSV | NS_SSM)
        )
}

/// The element children of `n` but its meta data ([`is_meta`]): what a reader uses or refuses.
pub(super) fn content<'a, 'i>(n: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    elements(n).filter(|c| !is_meta(*c))
}

/// Refuses a child of `n` given twice where the schemas allow one (every child but meta data,
/// signatures and array dimensions): the readers keep one of each, so a second
/// `<ssd:ParameterBindings>` or `<ssd:System>` dropped the first's content without a word.
pub(super) fn check_single_children(ctx: Ctx, n: Node) -> Result<(), SspError> {
    let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for c in content(n) {
        if c.tag_name().name() == "Dimension" {
            continue;
        }
        let name = qualified(c);
        if let Some(first) = seen.get(&name) {
            return Err(ctx.err(
                c,
                format!(
                    "<{name}> is given twice in <{}> (first at line {first}); the schema allows \
                     one",
                    qualified(n)
                ),
            ));
        }
        seen.insert(name, ctx.line(c));
    }
    Ok(())
}

/// `name` with its namespace's usual SSP prefix, for messages.
pub(super) fn qualified(n: Node) -> String {
    let prefix = match n.tag_name().namespace() {
        Some(NS_SSD) => "ssd:",
        Some(NS_SSC) => "ssc:",
        Some(NS_SSV) => "ssv:",
        Some(NS_SSM) => "ssm:",
        _ => "",
    };
    format!("{prefix}{}", n.tag_name().name())
}

/// Errors located in one file: its name and line starts.
#[derive(Clone, Copy)]
pub(super) struct Ctx<'f> {
    pub file: &'f str,
    pub lines: &'f LineStarts,
}

impl Ctx<'_> {
    /// 1-based line of an element of this file.
    pub fn line(&self, n: Node) -> usize {
        self.lines.line(n)
    }

    pub fn err(&self, n: Node, message: impl Into<String>) -> SspError {
        SspError::Invalid {
            file: self.file.to_string(),
            line: Some(self.line(n)),
            message: message.into(),
        }
    }

    /// An element or attribute the master does not support.
    pub fn unsupported(&self, n: Node, what: impl Into<String>) -> SspError {
        SspError::Unsupported {
            file: self.file.to_string(),
            line: Some(self.line(n)),
            what: what.into(),
        }
    }

    /// A child element that has no place here.
    pub fn unexpected(&self, n: Node) -> SspError {
        self.unsupported(
            n,
            format!(
                "element <{}> in <{}>",
                qualified(n),
                n.parent_element().map(qualified).unwrap_or_default()
            ),
        )
    }

    pub fn req<'a>(&self, n: Node<'a, '_>, attr: &str) -> Result<&'a str, SspError> {
        n.attribute(attr).ok_or_else(|| {
            self.err(
                n,
                format!("<{}> lacks the required attribute '{attr}'", qualified(n)),
            )
        })
    }

    pub fn f64(&self, n: Node, attr: &str) -> Result<Option<f64>, SspError> {
        match n.attribute(attr) {
            None => Ok(None),
            Some(v) => v
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| {
                    self.err(
                        n,
                        format!(
                            "<{} {attr}=\"{}\">: not a finite number",
                            qualified(n),
                            show::text(v)
                        ),
                    )
                }),
        }
    }

    pub fn i64(&self, n: Node, attr: &str) -> Result<Option<i64>, SspError> {
        match n.attribute(attr) {
            None => Ok(None),
            Some(v) => v.trim().parse::<i64>().map(Some).map_err(|_| {
                self.err(
                    n,
                    format!(
                        "<{} {attr}=\"{}\">: not an integer",
                        qualified(n),
                        show::text(v)
                    ),
                )
            }),
        }
    }

    pub fn bool(&self, n: Node, attr: &str) -> Result<Option<bool>, SspError> {
        match n.attribute(attr).map(str::trim) {
            None => Ok(None),
            Some("true") | Some("1") => Ok(Some(true)),
            Some("false") | Some("0") => Ok(Some(false)),
            Some(v) => Err(self.err(
                n,
                format!(
                    "<{} {attr}=\"{}\">: not true or false",
                    qualified(n),
                    show::text(v)
                ),
            )),
        }
    }
}

/// The value of `<TYPE value="...">` of SSP 2.0 may be a list (an array value); the master takes
/// scalars only.
pub(super) fn scalar<'a>(ctx: Ctx, n: Node<'a, '_>) -> Result<&'a str, SspError> {
    let v = ctx.req(n, "value")?;
    if v.split_whitespace().count() > 1 {
        return Err(ctx.unsupported(
            n,
            format!(
                "array value \"{}\" of <{}> (scalars only)",
                show::text(v),
                qualified(n)
            ),
        ));
    }
    Ok(v.trim())
}

pub(super) use fmu_binary::escape_attribute as escape;

#[cfg(test)]
mod crowded_tag_tests {
    use super::crowded_tag;

    #[test]
    fn attributes_are_counted_outside_values_comments_and_declarations() {
        let many =
            |value: &str| -> String { (0..10_001).map(|k| format!(" a{k}=\"{value}\"")).collect() };
        // quoted '>' and '=' neither end the tag nor count
        assert_eq!(
            crowded_tag(&format!("<r>\n<x{}/></r>", many(">="))),
            Some(2)
        );
        assert_eq!(crowded_tag(&format!("<x{}/>", many("'"))), Some(1));
        // fewer: not crowded
        let few: String = (0..100).map(|k| format!(" a{k}=\"1\"")).collect();
        assert_eq!(crowded_tag(&format!("<x{few}/>")), None);
        // '=' in a comment, a declaration or an instruction is no attribute
        let eqs = "=".repeat(20_000);
        let text = format!("<?xml version=\"1.0\"?><!-- {eqs} \" --><!DOCTYPE x><r a=\"1\"/>");
        assert_eq!(crowded_tag(&text), None);
    }
}
