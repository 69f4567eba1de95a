//! The ID line of a binary dataset, e.g.
//! `    58b     1     2          11      317168     0     0           0           0`:
//! `Format(I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12)`, the dataset number, `b`, byte order,
//! floating-point format, the number of ASCII lines and of binary bytes that follow,
//! and four unused fields ("Binary 58 universal file format", UC-SDRL, as reproduced
//! in pyuff's `dataset_58.py`).

use super::fields::{columns, decode};
use super::lines::excerpt;
use super::number::parse_int;
use super::Fault;

/// Fields 3-6 of a binary dataset's ID line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BinaryLayout {
    /// Field 3: 1 little endian, 2 big endian.
    pub byte_order: i64,
    /// Field 4: 1 DEC VMS, 2 IEEE 754, 3 IBM 5/370.
    pub float_format: i64,
    /// Field 5: the ASCII lines after the ID line (11 for dataset 58).
    pub ascii_lines: u64,
    /// Field 6: the binary bytes after them.
    pub bytes: u64,
}

/// Reads fields 3-6 of the ID line `text` (on `line`) by their columns, or as
/// blank-separated numbers when they are not in them. All four are required (a blank
/// is not read as 0 here).
pub fn binary_layout(text: &[u8], line: usize) -> Result<BinaryLayout, Fault> {
    const WIDTHS: [usize; 6] = [6, 1, 6, 6, 12, 12];
    let text = decode(text);
    let fields = columns(&text, &WIDTHS);
    let fixed: Option<Vec<i64>> = fields[2..]
        .iter()
        .map(|f| {
            if f.trim().is_empty() {
                None
            } else {
                parse_int(f)
            }
        })
        .collect();
    let free: Option<Vec<i64>> = text
        .split_whitespace()
        .skip(1)
        .take(4)
        .map(parse_int)
        .collect();
    let n = fixed.or(free).filter(|n| n.len() == 4).ok_or_else(|| {
        Fault::line(
            line,
            format!(
                "the binary dataset's ID line {} is not `Format(I6,1A1,I6,I6,I12,I12,…)`: byte order, floating-point format, ASCII lines, bytes",
                excerpt(text.as_bytes())
            ),
        )
    })?;
    let count = |v: i64, what: &str| {
        u64::try_from(v).map_err(|_| {
            Fault::line(
                line,
                format!("the binary dataset's ID line declares {v} {what}"),
            )
        })
    };
    Ok(BinaryLayout {
        byte_order: n[0],
        float_format: n[1],
        ascii_lines: count(n[2], "ASCII lines")?,
        bytes: count(n[3], "bytes")?,
    })
}

/// Checks a 58b ID line (on `line`) before the header is read: 11 ASCII lines, a byte
/// order of 1 (little endian) or 2 (big endian), floating-point format 2 (IEEE 754;
/// 1, DEC VMS, and 3, IBM 5/370, are refused by name).
pub fn check_layout(layout: &BinaryLayout, line: usize) -> Result<(), Fault> {
    if layout.ascii_lines != 11 {
        return Err(Fault::line(
            line,
            format!(
                "the 58b ID line declares {} ASCII lines; dataset 58 has 11 (records 1-11)",
                layout.ascii_lines
            ),
        ));
    }
    if !matches!(layout.byte_order, 1 | 2) {
        return Err(Fault::line(
            line,
            format!(
                "the 58b byte order {} is not 1 (little endian) or 2 (big endian)",
                layout.byte_order
            ),
        ));
    }
    match layout.float_format {
        2 => Ok(()),
        1 => Err(Fault::line(
            line,
            "the 58b floating-point format 1 (DEC VMS) is not supported, only 2 (IEEE 754)",
        )),
        3 => Err(Fault::line(
            line,
            "the 58b floating-point format 3 (IBM 5/370) is not supported, only 2 (IEEE 754)",
        )),
        f => Err(Fault::line(
            line,
            format!("the 58b floating-point format {f} is not 1, 2 or 3"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::formats::Location;

    #[test]
    fn by_columns_and_by_blanks() {
        let fixed =
            b"    58b     1     2          11      317168     0     0           0           0";
        assert_eq!(
            binary_layout(fixed, 2).unwrap(),
            BinaryLayout {
                byte_order: 1,
                float_format: 2,
                ascii_lines: 11,
                bytes: 317168
            }
        );
        assert_eq!(
            binary_layout(b"58b 2 2 11 4096 0 0 0 0", 2).unwrap().bytes,
            4096
        );
    }

    #[test]
    fn a_missing_byte_count_is_refused() {
        let fault = binary_layout(b"    58b     1     2          11", 7).unwrap_err();
        assert_eq!(fault.location, Location::Line(7));
    }

    #[test]
    fn only_ieee_754_is_read() {
        let layout = |float_format, byte_order, ascii_lines| BinaryLayout {
            byte_order,
            float_format,
            ascii_lines,
            bytes: 0,
        };
        assert!(check_layout(&layout(2, 1, 11), 2).is_ok());
        assert!(check_layout(&layout(2, 2, 11), 2).is_ok());
        for bad in [
            layout(1, 1, 11),
            layout(3, 2, 11),
            layout(2, 3, 11),
            layout(2, 1, 12),
        ] {
            let fault = check_layout(&bad, 2).unwrap_err();
            assert_eq!(fault.location, Location::Line(2), "{}", fault.message);
        }
    }
}
