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

/// Parses `text` (the content of `file`); DTDs are refused (roxmltree's default), so no entity
/// expansion can blow up.
pub(super) fn parse<'a>(file: &str, text: &'a str) -> Result<Document<'a>, SspError> {
    Document::parse(text).map_err(|e| SspError::Invalid {
        file: file.to_string(),
        line: Some(e.pos().row as usize),
        message: format!("XML syntax error: {e}"),
    })
}

/// 1-based line of an element.
pub(super) fn line(n: Node) -> usize {
    n.document().text_pos_at(n.range().start).row as usize
}

/// Whether `n` is the element `name` of namespace `ns`.
pub(super) fn is(n: Node, ns: &str, name: &str) -> bool {
    n.is_element() && n.tag_name().name() == name && n.tag_name().namespace() == Some(ns)
}

/// The element children of `n`.
pub(super) fn elements<'a, 'i>(n: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    n.children().filter(|c| c.is_element())
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

/// Errors located in one file.
#[derive(Clone, Copy)]
pub(super) struct Ctx<'f> {
    pub file: &'f str,
}

impl Ctx<'_> {
    pub fn err(&self, n: Node, message: impl Into<String>) -> SspError {
        SspError::Invalid {
            file: self.file.to_string(),
            line: Some(line(n)),
            message: message.into(),
        }
    }

    /// An element or attribute the master does not support.
    pub fn unsupported(&self, n: Node, what: impl Into<String>) -> SspError {
        SspError::Unsupported {
            file: self.file.to_string(),
            line: Some(line(n)),
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
