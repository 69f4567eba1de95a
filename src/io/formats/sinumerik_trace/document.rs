//! The XML as the SAT library writes it, element by element: members are child
//! elements whose tag is their type (`float`, `unsigned_int`, `boolean`, `string`, a
//! class name) and whose `name` attribute is the member's name; lists are `LinkedList`
//! elements of such children; numeric arrays are `NumericArray` elements holding
//! `m_length` and a `<raw>` base85 text. Every error names the element (its tag and
//! `name`) and the byte of the file where it starts.

use std::path::Path;
use std::str::FromStr;

use roxmltree::Node;

use super::base85;
use crate::io::formats::{FormatError, Location};

/// The file's text, and how its offsets map back to the file's bytes.
pub(super) struct Text {
    pub text: String,
    /// Decoded from ISO-8859-1 (the encoding the files declare) because it is not
    /// UTF-8: each character was one byte.
    latin1: bool,
}

impl Text {
    /// The bytes as text: UTF-8 (ASCII, as the shared file is) as it is, else
    /// ISO-8859-1, one character per byte.
    pub fn decode(bytes: Vec<u8>) -> Text {
        match String::from_utf8(bytes) {
            Ok(text) => Text {
                text,
                latin1: false,
            },
            Err(e) => Text {
                text: e.into_bytes().iter().map(|&b| char::from(b)).collect(),
                latin1: true,
            },
        }
    }

    /// The file's byte at offset `at` of the text.
    pub fn byte(&self, at: usize) -> u64 {
        let at = at.min(self.text.len());
        if self.latin1 {
            self.text[..at].chars().count() as u64
        } else {
            at as u64
        }
    }

    /// The offset of 1-based `row` and `col` (in characters), as roxmltree reports
    /// a syntax error.
    pub fn offset_of(&self, row: u32, col: u32) -> usize {
        let line_start: usize = self
            .text
            .split_inclusive('\n')
            .take(row.saturating_sub(1) as usize)
            .map(str::len)
            .sum();
        let line = &self.text[line_start.min(self.text.len())..];
        line_start
            + line
                .char_indices()
                .nth(col.saturating_sub(1) as usize)
                .map_or(line.len(), |(i, _)| i)
    }
}

/// The parsed document with the file it came from, for errors.
pub(super) struct Doc<'a> {
    pub path: &'a Path,
    pub text: &'a Text,
}

impl<'a> Doc<'a> {
    /// An error at `node`: `<Tag name="…">: message`, at the byte it starts.
    pub fn fail(&self, node: Node, message: impl std::fmt::Display) -> FormatError {
        self.fail_at(node, node.range().start, message)
    }

    /// An error about `node` at text offset `at`.
    pub fn fail_at(&self, node: Node, at: usize, message: impl std::fmt::Display) -> FormatError {
        FormatError::new(
            self.path,
            Location::Byte(self.text.byte(at)),
            format!("{}: {message}", describe(node)),
        )
    }

    /// The direct child element of `node` of type `tag` named `name`.
    pub fn child<'b>(&self, node: Node<'b, 'b>, tag: &str, name: &str) -> Option<Node<'b, 'b>> {
        node.children()
            .find(|c| c.has_tag_name(tag) && c.attribute("name") == Some(name))
    }

    /// The required direct child `<tag name="name">`.
    pub fn need<'b>(
        &self,
        node: Node<'b, 'b>,
        tag: &str,
        name: &str,
    ) -> Result<Node<'b, 'b>, FormatError> {
        self.child(node, tag, name).ok_or_else(|| {
            self.fail(
                node,
                format!("no member <{tag} name=\"{name}\"> where the SAT library writes one"),
            )
        })
    }

    /// The value of the member `<tag name="name">` of `node`, parsed.
    pub fn value<T: FromStr>(&self, node: Node, tag: &str, name: &str) -> Result<T, FormatError> {
        let member = self.need(node, tag, name)?;
        let text = member.text().unwrap_or("").trim();
        text.parse().map_err(|_| {
            self.fail(
                member,
                format!("`{}` is not a {tag}", text.escape_default()),
            )
        })
    }

    /// The member `<float name="name">`, finite.
    pub fn float(&self, node: Node, name: &str) -> Result<f64, FormatError> {
        let v: f64 = self.value(node, "float", name)?;
        if v.is_finite() {
            Ok(v)
        } else {
            let member = self.need(node, "float", name)?;
            Err(self.fail(member, format!("{v} is not a finite number")))
        }
    }

    /// The member `<boolean name="name">`: `true` or `false`.
    pub fn boolean(&self, node: Node, name: &str) -> Result<bool, FormatError> {
        self.value(node, "boolean", name)
    }

    /// The member `<unsigned_int name="name">`.
    pub fn unsigned(&self, node: Node, name: &str) -> Result<u32, FormatError> {
        self.value(node, "unsigned_int", name)
    }

    /// The elements of the `LinkedList` member `name` of `node`.
    pub fn list<'b>(
        &self,
        node: Node<'b, 'b>,
        name: &str,
    ) -> Result<Vec<Node<'b, 'b>>, FormatError> {
        let list = self.need(node, "LinkedList", name)?;
        Ok(list.children().filter(Node::is_element).collect())
    }

    /// The doubles of the `NumericArray` member `name` of `node`: `m_length` values,
    /// twice as many doubles (real and imaginary interleaved) for an array of
    /// `ComplexNumber`s. The declared length must be what the text holds.
    pub fn array(&self, node: Node, name: &str) -> Result<Vec<f64>, FormatError> {
        let array = self.need(node, "NumericArray", name)?;
        let per_value = match array.attribute("elementtype") {
            Some("double") => 1,
            Some("ComplexNumber") => 2,
            other => {
                return Err(self.fail(
                    array,
                    format!(
                        "elements of type `{}`: rtid reads double and ComplexNumber arrays",
                        other.unwrap_or("(none)")
                    ),
                ))
            }
        };
        if let Some(f) = array.attribute("format").filter(|f| *f != "base85") {
            return Err(self.fail(array, format!("format `{f}`: rtid reads base85 arrays")));
        }
        let declared: u64 = self.value(array, "unsigned_int", "m_length")?;
        let raw = self.need(array, "raw", "m_pNumberArray")?;
        let values = self.raw_doubles(raw)?;
        if values.len() as u64 != declared.saturating_mul(per_value) {
            return Err(self.fail(
                raw,
                format!(
                    "m_length declares {declared} values, the text holds {} doubles{}",
                    values.len(),
                    if per_value == 2 {
                        " (two per complex value)"
                    } else {
                        ""
                    }
                ),
            ));
        }
        Ok(values)
    }

    /// The doubles of a `<raw>` element's text (CDATA or plain).
    fn raw_doubles(&self, raw: Node) -> Result<Vec<f64>, FormatError> {
        let Some(text_node) = raw.first_child().filter(|c| c.is_text()) else {
            return Ok(Vec::new());
        };
        let text = text_node.text().unwrap_or("");
        base85::doubles(text).map_err(|fault| {
            let start = text_node.range().start;
            let source = &self.text.text[start..];
            let skip = if source.starts_with("<![CDATA[") {
                9
            } else {
                0
            };
            self.fail_at(raw, start + skip + fault.at, fault.message)
        })
    }
}

/// `<Tag name="…">` of an element, for messages.
pub(super) fn describe(node: Node) -> String {
    match node.attribute("name") {
        Some(name) => format!("<{} name=\"{name}\">", node.tag_name().name()),
        None => format!("<{}>", node.tag_name().name()),
    }
}
