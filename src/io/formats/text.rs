//! A text export read line by line, for the text formats ([`super::twincat_scope`],
//! [`super::epos_studio`]), and numbers with a decimal point or comma
//! ([`parse_number`], [`super::delimited`] too): 1-based line numbers, LF or CR LF line ends,
//! whether the last line was cut off before its line end, and the decoding of header
//! text that is UTF-8 or, failing that, Windows-1252.
//!
//! Lines are handed out as bytes borrowed from one reused buffer, so a large file is
//! streamed, never held whole.

use std::io::{self, BufRead, Read};

/// The longest line read (64 MiB): a longer one is not a text export (a binary file
/// without line ends), and refusing it keeps memory bounded.
pub(in crate::io::formats) const MAX_LINE: usize = 64 << 20;

/// One line of the file, without its line end.
pub(in crate::io::formats) struct Line<'a> {
    /// 1-based.
    pub number: usize,
    pub bytes: &'a [u8],
    /// False for a last line that ends without LF: the file was cut off there (or
    /// written by a tool that omits the last line end).
    pub terminated: bool,
}

/// Why a line could not be read.
#[derive(Debug, thiserror::Error)]
pub(in crate::io::formats) enum LineError {
    #[error("cannot read the file: {0}")]
    Io(#[from] io::Error),
    #[error("a line longer than {0} bytes: not a text export")]
    TooLong(usize),
}

/// The lines of a reader, numbered.
pub(in crate::io::formats) struct Lines<R> {
    reader: R,
    buf: Vec<u8>,
    number: usize,
    limit: usize,
}

impl<R: BufRead> Lines<R> {
    pub fn new(reader: R) -> Self {
        Self::with_limit(reader, MAX_LINE)
    }

    /// Lines of at most `limit` bytes.
    pub fn with_limit(reader: R, limit: usize) -> Self {
        Lines {
            reader,
            buf: Vec::new(),
            number: 0,
            limit,
        }
    }

    /// The number of the last line handed out (0 before the first).
    pub fn number(&self) -> usize {
        self.number
    }

    /// The next line, or `None` at the end of the file. A UTF-8 byte-order mark
    /// opening the file is dropped.
    pub fn next_line(&mut self) -> Result<Option<Line<'_>>, LineError> {
        self.buf.clear();
        let take = self.limit as u64 + 1;
        let n = (&mut self.reader)
            .take(take)
            .read_until(b'\n', &mut self.buf)?;
        if n == 0 {
            return Ok(None);
        }
        let terminated = self.buf.last() == Some(&b'\n');
        if !terminated && self.buf.len() > self.limit {
            return Err(LineError::TooLong(self.limit));
        }
        self.number += 1;
        let mut bytes = &self.buf[..];
        if terminated {
            bytes = &bytes[..bytes.len() - 1];
        }
        if bytes.last() == Some(&b'\r') {
            bytes = &bytes[..bytes.len() - 1];
        }
        if self.number == 1 {
            bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        }
        Ok(Some(Line {
            number: self.number,
            bytes,
            terminated,
        }))
    }
}

/// How a file's header text is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::io::formats) enum Encoding {
    Utf8,
    /// Windows-1252 ("ANSI" on a western-European Windows): what a Windows tool
    /// writes when it does not write UTF-8. Every byte decodes, so this is the
    /// fallback for text that is not valid UTF-8.
    Windows1252,
}

impl Encoding {
    /// UTF-8 when every line is valid UTF-8, else Windows-1252.
    pub fn of<'a>(mut lines: impl Iterator<Item = &'a [u8]>) -> Encoding {
        if lines.all(|l| std::str::from_utf8(l).is_ok()) {
            Encoding::Utf8
        } else {
            Encoding::Windows1252
        }
    }

    pub fn decode(self, bytes: &[u8]) -> String {
        match self {
            Encoding::Utf8 => String::from_utf8_lossy(bytes).into_owned(),
            Encoding::Windows1252 => bytes.iter().map(|&b| windows_1252(b)).collect(),
        }
    }
}

/// One Windows-1252 byte as a character, per the WHATWG Encoding Standard's
/// `index-windows-1252` (the five bytes Windows leaves undefined map to the C1
/// controls of the same value, as there).
fn windows_1252(b: u8) -> char {
    const HIGH: [u16; 32] = [
        0x20AC, 0x0081, 0x201A, 0x0192, 0x201E, 0x2026, 0x2020, 0x2021, // 80–87
        0x02C6, 0x2030, 0x0160, 0x2039, 0x0152, 0x008D, 0x017D, 0x008F, // 88–8F
        0x0090, 0x2018, 0x2019, 0x201C, 0x201D, 0x2022, 0x2013, 0x2014, // 90–97
        0x02DC, 0x2122, 0x0161, 0x203A, 0x0153, 0x009D, 0x017E, 0x0178, // 98–9F
    ];
    match b {
        0x80..=0x9F => char::from_u32(u32::from(HIGH[usize::from(b - 0x80)])).unwrap_or('\u{FFFD}'),
        _ => char::from(b),
    }
}

/// A number as TwinCAT writes it: with a decimal point, or a decimal comma when the
/// comma is not the separator (the export's "DecimalMark"). `NaN` and `inf` are read
/// as such (a REAL can hold them).
pub(in crate::io::formats) fn parse_number(cell: &[u8], comma_is_decimal: bool) -> Option<f64> {
    let cell = cell.trim_ascii();
    let mut buf = [0u8; 64];
    let text = if comma_is_decimal && cell.contains(&b',') {
        let out = buf.get_mut(..cell.len())?;
        for (o, &b) in out.iter_mut().zip(cell) {
            *o = if b == b',' { b'.' } else { b };
        }
        &out[..]
    } else {
        cell
    };
    std::str::from_utf8(text).ok()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_lines(text: &[u8]) -> Vec<(usize, Vec<u8>, bool)> {
        let mut lines = Lines::new(text);
        let mut out = Vec::new();
        while let Some(l) = lines.next_line().unwrap() {
            out.push((l.number, l.bytes.to_vec(), l.terminated));
        }
        out
    }

    #[test]
    fn line_ends_and_a_cut_last_line() {
        let got = all_lines(b"\xEF\xBB\xBFa\r\nb\n\nc");
        let want = vec![
            (1, b"a".to_vec(), true),
            (2, b"b".to_vec(), true),
            (3, b"".to_vec(), true),
            (4, b"c".to_vec(), false),
        ];
        assert_eq!(got, want);
    }

    #[test]
    fn a_line_over_the_limit_is_refused_not_read_whole() {
        let text = [b'x'; 100];
        let mut lines = Lines::with_limit(&text[..], 10);
        assert!(matches!(lines.next_line(), Err(LineError::TooLong(10))));
        let mut lines = Lines::with_limit(&b"0123456789\nab"[..], 10);
        assert_eq!(lines.next_line().unwrap().unwrap().bytes, b"0123456789");
    }

    #[test]
    fn windows_1252_decodes_german_and_the_euro() {
        let bytes = b"\xE4\xF6\xFC\xDF\xB2 \x80";
        assert_eq!(
            Encoding::of([&bytes[..]].into_iter()),
            Encoding::Windows1252
        );
        assert_eq!(Encoding::Windows1252.decode(bytes), "äöüß² €");
        assert_eq!(Encoding::of(["äö".as_bytes()].into_iter()), Encoding::Utf8);
    }
}
