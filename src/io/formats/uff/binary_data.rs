//! Record 12 of a dataset 58b: the values as IEEE 754 binary numbers right after the
//! line end of record 11, in the order of the ASCII dataset ("Binary 58 universal
//! file format", UC-SDRL, as reproduced in pyuff's `dataset_58.py`).

use std::io::BufRead;

use super::binary_id::BinaryLayout;
use super::columns::{Columns, Tolerated};
use super::header::Header58;
use super::lines::{excerpt, is_blank, is_delimiter, LineReader};
use super::Fault;

/// Reads the binary values and the closing `-1` of the dataset whose `-1` is on line
/// `start`.
///
/// Every value (abscissa included, for uneven spacing) has the ordinate's precision,
/// 4 bytes for data types 2 and 5, 8 for 4 and 6, as pyuff and the UC-SDRL readers
/// store them. The block's length is the one record 7 implies, checked against what
/// is left of the file before anything is read; the ID line's byte count is compared
/// with it and a difference told, not trusted (pyuff writes points × 8 for complex and
/// uneven data, half the block). Line ends between the block and the `-1` (which the
/// description forbids and some writers put there) are skipped and told.
pub fn read_values<R: BufRead>(
    lines: &mut LineReader<R>,
    header: &Header58,
    layout: &BinaryLayout,
    start: usize,
) -> Result<(Columns, Tolerated), Fault> {
    let form = &header.form;
    let size: u64 = if form.ordinate.is_double() { 8 } else { 4 };
    let bytes = form.values().saturating_mul(size);
    let at = lines.offset();
    if bytes > lines.remaining() {
        return Err(Fault::byte(
            at,
            format!(
                "record 7 (line {}) declares {} points, {bytes} bytes of binary data, and {} bytes follow",
                header.form_line,
                form.points,
                lines.remaining()
            ),
        ));
    }
    let mut decoder = Decoder {
        columns: Columns::new(form.values_per_point(), form.points),
        pending: Vec::with_capacity(8),
        size: size as usize,
        big_endian: layout.byte_order == 2,
    };
    lines.take_block(bytes, |piece| decoder.feed(piece))?;
    let mut tolerated = Tolerated {
        byte_count: (layout.bytes != bytes).then_some((layout.bytes, bytes)),
        ..Tolerated::default()
    };
    tolerated.line_end_before_closing = closing_line(lines, header, layout, start, bytes)?;
    Ok((decoder.columns, tolerated))
}

/// Reads the `-1` after the block (ending at the current offset); `Some(offset)` when
/// line ends came first.
fn closing_line<R: BufRead>(
    lines: &mut LineReader<R>,
    header: &Header58,
    layout: &BinaryLayout,
    start: usize,
    bytes: u64,
) -> Result<Option<u64>, Fault> {
    let end = lines.offset();
    let mut line_end = None;
    loop {
        if !lines.advance()? {
            return Err(Fault::byte(
                end,
                format!("the file ends after the binary data without the -1 closing the dataset 58b begun at line {start}"),
            ));
        }
        if is_delimiter(lines.text()) {
            return Ok(line_end);
        }
        if !is_blank(lines.text()) {
            let id_line = if layout.bytes == bytes {
                String::new()
            } else {
                format!(" (the 58b ID line says {})", layout.bytes)
            };
            return Err(Fault::byte(
                end,
                format!(
                    "{} where the -1 closing the dataset 58b begun at line {start} should follow the {bytes} bytes of binary data record 7 (line {}) implies{id_line}",
                    excerpt(lines.text()),
                    header.form_line
                ),
            ));
        }
        line_end.get_or_insert(lines.line_start());
    }
}

/// Turns the block's bytes into numbers as the buffer hands them over; a number split
/// between two pieces waits in `pending`.
struct Decoder {
    columns: Columns,
    pending: Vec<u8>,
    size: usize,
    big_endian: bool,
}

impl Decoder {
    fn feed(&mut self, mut piece: &[u8]) {
        if !self.pending.is_empty() {
            let take = (self.size - self.pending.len()).min(piece.len());
            self.pending.extend_from_slice(&piece[..take]);
            piece = &piece[take..];
            if self.pending.len() < self.size {
                return;
            }
            let pending = std::mem::take(&mut self.pending);
            let value = self.decode(&pending);
            self.columns.push(value);
        }
        let mut chunks = piece.chunks_exact(self.size);
        for chunk in &mut chunks {
            let value = self.decode(chunk);
            self.columns.push(value);
        }
        self.pending.extend_from_slice(chunks.remainder());
    }

    fn decode(&self, b: &[u8]) -> f64 {
        match (self.size, self.big_endian) {
            (4, false) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            (4, true) => f64::from(f32::from_be_bytes([b[0], b[1], b[2], b[3]])),
            (_, false) => f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
            (_, true) => f64::from_be_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_split_between_pieces_are_joined() {
        let values = [1.5f64, -2.25, 1e-300];
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        let mut decoder = Decoder {
            columns: Columns::new(1, 3),
            pending: Vec::new(),
            size: 8,
            big_endian: true,
        };
        for piece in bytes.chunks(5) {
            decoder.feed(piece);
        }
        assert_eq!(decoder.columns.into_columns(), vec![values.to_vec()]);
    }
}
