//! Fixed-column text: the fields of a record by the widths of its Fortran format.

use std::borrow::Cow;

/// Text as the file spells it: UTF-8 when it is valid UTF-8, otherwise Latin-1 (one
/// character per byte), the code page of the instruments that write `²` as byte 0xB2.
pub fn decode(bytes: &[u8]) -> Cow<'_, str> {
    match std::str::from_utf8(bytes) {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
    }
}

/// The fields of a fixed-column record, `widths` counted in characters (a UTF-8 `²`
/// is one column, as the writer counted it); fields past the end of a short line are
/// empty.
pub fn columns<'a>(text: &'a str, widths: &[usize]) -> Vec<&'a str> {
    let mut bounds = text.char_indices().map(|(i, _)| i).chain([text.len()]);
    let mut start = bounds.next().unwrap_or(0);
    let mut fields = Vec::with_capacity(widths.len());
    for &w in widths {
        let end = bounds.nth(w.saturating_sub(1)).unwrap_or(text.len());
        fields.push(&text[start.min(end)..end]);
        start = end;
    }
    fields
}

/// "columns 11-20" of field `k` of a record with these widths.
pub fn column_span(widths: &[usize], k: usize) -> String {
    let first = widths[..k].iter().sum::<usize>() + 1;
    format!("columns {first}-{}", first + widths[k] - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters_and_pad_short_lines() {
        let f = columns("ab²cdef", &[2, 2, 5, 3]);
        assert_eq!(f, ["ab", "²c", "def", ""]);
    }

    #[test]
    fn latin1_text_is_read_byte_by_byte() {
        assert_eq!(decode(b"g\xb2/Hz"), "g²/Hz");
        assert_eq!(decode("m/s²".as_bytes()), "m/s²");
    }

    #[test]
    fn column_spans_are_one_based() {
        assert_eq!(column_span(&[10, 10, 10], 1), "columns 11-20");
    }
}
