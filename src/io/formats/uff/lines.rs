//! The file as a sequence of text lines with binary blocks between them (dataset 58b),
//! read through a buffer, with the line number and byte offset of where it is.

use std::io::BufRead;

use super::Fault;

/// The longest text line accepted (1 MiB). UFF lines are 80 columns; a longer "line"
/// is binary data or a file of another kind, refused before it fills the memory.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// A reader of lines (without their `\n` or `\r\n`) and of binary blocks.
///
/// Line numbers count every `\n` of the file, those inside binary blocks too, so that
/// they are the numbers an editor shows.
pub struct LineReader<R> {
    inner: R,
    text: Vec<u8>,
    /// The 1-based number of the current line (0 before the first).
    line: usize,
    /// The byte offset of the current line's first byte.
    line_start: u64,
    /// The byte offset of the next unread byte.
    offset: u64,
    len: u64,
}

impl<R: BufRead> LineReader<R> {
    /// `len` is the file's length in bytes (what is left to read is checked against it
    /// before a declared size is allocated).
    pub fn new(inner: R, len: u64) -> LineReader<R> {
        LineReader {
            inner,
            text: Vec::with_capacity(128),
            line: 0,
            line_start: 0,
            offset: 0,
            len,
        }
    }

    /// Reads the next line; `false` at the end of the file.
    pub fn advance(&mut self) -> Result<bool, Fault> {
        self.text.clear();
        let limit = MAX_LINE_BYTES as u64 + 2;
        let read = <&mut R as std::io::Read>::take(&mut self.inner, limit)
            .read_until(b'\n', &mut self.text)
            .map_err(|e| Fault::byte(self.offset, format!("read error: {e}")))?;
        if read == 0 {
            return Ok(false);
        }
        self.line += 1;
        self.line_start = self.offset;
        self.offset += read as u64;
        if self.text.last() == Some(&b'\n') {
            self.text.pop();
            if self.text.last() == Some(&b'\r') {
                self.text.pop();
            }
        } else if self.text.len() > MAX_LINE_BYTES {
            return Err(Fault::line(
                self.line,
                format!("a line of more than {MAX_LINE_BYTES} bytes: not a UFF text line"),
            ));
        }
        if self.line == 1 && self.text.starts_with("\u{feff}".as_bytes()) {
            self.text.drain(..3);
        }
        Ok(true)
    }

    /// The current line, without its line end.
    pub fn text(&self) -> &[u8] {
        &self.text
    }

    /// The 1-based number of the current line.
    pub fn line(&self) -> usize {
        self.line
    }

    /// The byte offset of the current line's first byte.
    pub fn line_start(&self) -> u64 {
        self.line_start
    }

    /// The byte offset of the next unread byte.
    pub fn offset(&self) -> u64 {
        self.offset
    }

    /// The bytes after the current position.
    pub fn remaining(&self) -> u64 {
        self.len.saturating_sub(self.offset)
    }

    /// Hands the next `n` bytes to `sink` in the pieces the buffer holds them in.
    /// The caller has checked `n` against [`remaining`](Self::remaining); a file that
    /// ends sooner (it shrank while read) is a fault at the offset where it ends.
    pub fn take_block(&mut self, n: u64, mut sink: impl FnMut(&[u8])) -> Result<(), Fault> {
        let mut left = n;
        while left > 0 {
            let chunk = self
                .inner
                .fill_buf()
                .map_err(|e| Fault::byte(self.offset, format!("read error: {e}")))?;
            if chunk.is_empty() {
                return Err(Fault::byte(
                    self.offset,
                    format!("the file ends {left} bytes before the end of the binary block"),
                ));
            }
            let used = chunk.len().min(usize::try_from(left).unwrap_or(usize::MAX));
            let piece = &chunk[..used];
            self.line += piece.iter().filter(|&&b| b == b'\n').count();
            sink(piece);
            self.inner.consume(used);
            self.offset += used as u64;
            left -= used as u64;
        }
        Ok(())
    }
}

/// True for a line holding only the `-1` that opens and closes every dataset (right
/// justified in columns 1-6 by the standard; any blanks around it are accepted).
pub fn is_delimiter(text: &[u8]) -> bool {
    text.trim_ascii() == b"-1"
}

/// True for an empty or blank line.
pub fn is_blank(text: &[u8]) -> bool {
    text.trim_ascii().is_empty()
}

/// A short, printable excerpt of a line for an error message.
pub fn excerpt(text: &[u8]) -> String {
    const MAX: usize = 40;
    let shown = &text[..text.len().min(MAX)];
    let mut s: String = String::from_utf8_lossy(shown)
        .chars()
        .map(|c| if c.is_control() { '·' } else { c })
        .collect();
    if text.len() > MAX {
        s.push('…');
    }
    format!("'{s}'")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reader(bytes: &[u8]) -> LineReader<&[u8]> {
        LineReader::new(bytes, bytes.len() as u64)
    }

    #[test]
    fn lines_lose_their_line_ends_and_count_from_one() {
        let mut r = reader(b"    -1\r\n    58\nlast");
        assert!(r.advance().unwrap());
        assert_eq!((r.text(), r.line(), r.line_start()), (&b"    -1"[..], 1, 0));
        assert!(r.advance().unwrap());
        assert_eq!((r.text(), r.line(), r.line_start()), (&b"    58"[..], 2, 8));
        assert!(r.advance().unwrap());
        assert_eq!((r.text(), r.line()), (&b"last"[..], 3));
        assert!(!r.advance().unwrap());
    }

    #[test]
    fn a_binary_block_counts_its_line_ends() {
        let mut r = reader(b"head\n\x01\n\x02\n\x03    -1\n");
        r.advance().unwrap();
        let mut got = Vec::new();
        r.take_block(5, |p| got.extend_from_slice(p)).unwrap();
        assert_eq!(got, b"\x01\n\x02\n\x03");
        assert_eq!(r.offset(), 10);
        r.advance().unwrap();
        assert_eq!((r.text(), r.line()), (&b"    -1"[..], 4));
    }

    #[test]
    fn a_block_past_the_end_is_a_fault_at_the_end() {
        let mut r = reader(b"ab");
        let fault = r.take_block(5, |_| {}).unwrap_err();
        assert_eq!(fault.location, crate::io::formats::Location::Byte(2));
    }

    #[test]
    fn an_overlong_line_is_refused() {
        let long = vec![b'x'; MAX_LINE_BYTES + 10];
        let mut r = reader(&long);
        let fault = r.advance().unwrap_err();
        assert_eq!(fault.location, crate::io::formats::Location::Line(1));
    }
}
