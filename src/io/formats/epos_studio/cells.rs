//! One line of an EPOS Studio export split into its `;` cells, and what a spreadsheet
//! left on it.
//!
//! Some published exports went through a spreadsheet that saved each line as the first
//! cell of a comma-separated row: a line then ends with the spreadsheet's empty cells
//! (`0.000;0;-1200,,`) or with a hand-written note in a later cell
//! (`0.000;0;-1200,,was -8.9`), and a line holding quotes is quoted whole with its
//! quotes doubled (`"Trigger:;1;0.000000;""Parameter values"";…"`). EPOS Studio itself
//! writes no comma (decimal point, `;` separator), so the first comma outside quotes
//! starts the spreadsheet's part.

use std::borrow::Cow;

/// A line's EPOS text and what followed it.
#[derive(Debug, PartialEq)]
pub(super) struct Split<'a> {
    /// The line as EPOS Studio wrote it.
    pub text: Cow<'a, str>,
    /// From the first comma outside quotes to the end (`,,` or `,,was -8.9`).
    pub stray: Option<&'a str>,
}

impl Split<'_> {
    /// Text in the stray cells (a hand note), if any.
    pub fn hand_text(&self) -> Option<&str> {
        let text = self
            .stray?
            .trim_matches(|c: char| c == ',' || c.is_whitespace());
        (!text.is_empty()).then_some(text)
    }

    /// The `;` cells of the EPOS text.
    pub fn cells(&self) -> std::str::Split<'_, char> {
        self.text.split(';')
    }
}

pub(super) fn split(line: &str) -> Split<'_> {
    if let Some((inner, after)) = line.strip_prefix('"').and_then(unquote) {
        return Split {
            text: Cow::Owned(inner),
            stray: (!after.is_empty()).then_some(after),
        };
    }
    match line.find(',') {
        Some(i) => Split {
            text: Cow::Borrowed(&line[..i]),
            stray: Some(&line[i..]),
        },
        None => Split {
            text: Cow::Borrowed(line),
            stray: None,
        },
    }
}

/// The content of a quoted cell (after its opening quote) and what follows its
/// closing quote; `None` when it does not close.
fn unquote(rest: &str) -> Option<(String, &str)> {
    let mut out = String::new();
    let mut chars = rest.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        if c != '"' {
            out.push(c);
        } else if chars.peek().is_some_and(|&(_, next)| next == '"') {
            out.push('"');
            chars.next();
        } else {
            return Some((out, &rest[i + 1..]));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plain_line() {
        let s = split("0.000;-10;-32.0");
        assert_eq!(s.cells().collect::<Vec<_>>(), ["0.000", "-10", "-32.0"]);
        assert_eq!((s.stray, s.hand_text()), (None, None));
    }

    #[test]
    fn stray_commas_and_a_hand_note() {
        let s = split("0.000;0;-1200,,was -8.9");
        assert_eq!(s.text, "0.000;0;-1200");
        assert_eq!(s.stray, Some(",,was -8.9"));
        assert_eq!(s.hand_text(), Some("was -8.9"));
        assert_eq!(split("256.000;0;-9.4,,").hand_text(), None);
    }

    #[test]
    fn a_line_quoted_by_a_spreadsheet() {
        let s = split(r#""Trigger:;1;""Channel 1"";""Rising""",,"#);
        assert_eq!(s.text, r#"Trigger:;1;"Channel 1";"Rising""#);
        assert_eq!(s.stray, Some(",,"));
    }
}
