//! Record 12 of an ASCII dataset 58: the values in fixed-width fields, in the eight
//! layouts of the dataset 58 description (Addendum B).

use std::io::BufRead;

use super::columns::{Columns, Tolerated};
use super::header::{DataForm, Header58};
use super::lines::{excerpt, is_blank, is_delimiter, LineReader};
use super::number::parse_real;
use super::Fault;

/// The fewest bytes an ASCII value takes: one character and a blank or line end.
/// Record 7's count is refused before allocating when the rest of the file cannot
/// hold that many.
const MIN_BYTES_PER_VALUE: u64 = 2;

/// The field widths of one line, repeated along it: `6E13.5` for single precision,
/// `4E20.12` for double precision with even spacing, `2(E13.5,E20.12)` and
/// `E13.5,2E20.12` for double precision with uneven spacing (the abscissa is single
/// precision).
fn widths(form: &DataForm) -> &'static [usize] {
    match (
        form.ordinate.is_double(),
        form.even,
        form.ordinate.is_complex(),
    ) {
        (false, _, _) => &[13],
        (true, true, _) => &[20],
        (true, false, false) => &[13, 20],
        (true, false, true) => &[13, 20, 20],
    }
}

/// Reads the values and the closing `-1` of the dataset whose `-1` is on line `start`.
///
/// Each line is read by the columns of the format, so that fields which run together
/// (`-1.23456E+000-2.34567E+000`) are apart; blank fields are skipped, so a line need
/// not be full (the last usually is not; some writers pad it with blanks). A line
/// whose fields are not all numbers in those columns is read as blank-separated
/// numbers instead (and told). The count must come out as record 7 declares.
pub fn read_values<R: BufRead>(
    lines: &mut LineReader<R>,
    header: &Header58,
    start: usize,
) -> Result<(Columns, Tolerated), Fault> {
    let form = &header.form;
    let needed = form.values();
    check_size(lines, header, needed)?;
    let widths = widths(form);
    let mut columns = Columns::new(form.values_per_point(), form.points);
    let mut tolerated = Tolerated::default();
    let mut row = Vec::with_capacity(8);
    while columns.count() < needed {
        next_data_line(lines, header, start, columns.count())?;
        row.clear();
        let in_columns = split_line(lines.text(), widths, &mut row).map_err(|bad| {
            Fault::line(
                lines.line(),
                format!("{} in a data line is not a number", excerpt(bad)),
            )
        })?;
        if !in_columns {
            let (n, first) = tolerated.free_format_lines.unwrap_or((0, lines.line()));
            tolerated.free_format_lines = Some((n + 1, first));
        }
        let left = needed - columns.count();
        if row.len() as u64 > left {
            return Err(Fault::line(
                lines.line(),
                format!(
                    "{} values on a line where {left} complete the {needed} record 7 (line {}) declares",
                    row.len(),
                    header.form_line
                ),
            ));
        }
        row.iter().for_each(|&v| columns.push(v));
    }
    closing_line(lines, header, start)?;
    Ok((columns, tolerated))
}

/// Refuses a count the rest of the file cannot hold.
fn check_size<R: BufRead>(
    lines: &LineReader<R>,
    header: &Header58,
    needed: u64,
) -> Result<(), Fault> {
    let left = lines.remaining();
    if needed > left / MIN_BYTES_PER_VALUE {
        return Err(Fault::line(
            header.form_line,
            format!(
                "record 7 (data form) declares {} points ({needed} values), more than the {left} bytes left in the file hold",
                header.form.points
            ),
        ));
    }
    Ok(())
}

/// Advances to the next data line; the end of the file or a `-1` before the count is
/// complete is a fault.
fn next_data_line<R: BufRead>(
    lines: &mut LineReader<R>,
    header: &Header58,
    start: usize,
    read: u64,
) -> Result<(), Fault> {
    let needed = header.form.values();
    let short = format!(
        "{read} of the {needed} values record 7 (line {}) declares",
        header.form_line
    );
    if !lines.advance()? {
        return Err(Fault::line(
            lines.line(),
            format!(
                "the file ends in the data of the dataset 58 begun at line {start}, after {short}"
            ),
        ));
    }
    if is_delimiter(lines.text()) {
        return Err(Fault::line(
            lines.line(),
            format!("the dataset 58 begun at line {start} ends (-1) after {short}"),
        ));
    }
    Ok(())
}

/// Reads the `-1` closing the dataset (blank lines before it are skipped).
fn closing_line<R: BufRead>(
    lines: &mut LineReader<R>,
    header: &Header58,
    start: usize,
) -> Result<(), Fault> {
    loop {
        if !lines.advance()? {
            return Err(Fault::line(
                lines.line(),
                format!(
                    "the file ends without the -1 closing the dataset 58 begun at line {start}"
                ),
            ));
        }
        if is_delimiter(lines.text()) {
            return Ok(());
        }
        if !is_blank(lines.text()) {
            return Err(Fault::line(
                lines.line(),
                format!(
                    "{} where the -1 closing the dataset 58 begun at line {start} should follow its {} values (record 7, line {})",
                    excerpt(lines.text()),
                    header.form.values(),
                    header.form_line
                ),
            ));
        }
    }
}

/// Appends the numbers of a data line to `row`: by the fixed-width `widths` (repeated
/// along the line), blank fields skipped, and `true`; or, when a field there is not a
/// number, as blank-separated numbers and `false`. `Err` names a word that is not a
/// number either way.
fn split_line<'t>(text: &'t [u8], widths: &[usize], row: &mut Vec<f64>) -> Result<bool, &'t [u8]> {
    if split_fixed(text, widths, row) {
        return Ok(true);
    }
    row.clear();
    for word in text
        .split(u8::is_ascii_whitespace)
        .filter(|w| !w.is_empty())
    {
        row.push(parse_real(word).ok_or(word)?);
    }
    Ok(false)
}

/// The fixed-width reading of [`split_line`]; `false` at the first field that is
/// neither blank nor a number, or that a number runs out of: where no blank separates
/// a field from the next, the field must end in a complete exponent (two digits or
/// more, as every writer spells one), so that numbers wider than the columns
/// (` 1.0000000E+00` in `E13.5` columns) are not cut into two.
fn split_fixed(text: &[u8], widths: &[usize], row: &mut Vec<f64>) -> bool {
    let mut at = 0;
    for &w in widths.iter().cycle() {
        if at >= text.len() {
            return true;
        }
        let field = &text[at..text.len().min(at + w)];
        at += w;
        if is_blank(field) {
            continue;
        }
        let runs_on = text.get(at).is_some_and(|b| !b.is_ascii_whitespace())
            && field.last().is_some_and(|b| !b.is_ascii_whitespace());
        match parse_real(field) {
            Some(v) if !runs_on || ends_in_exponent(field) => row.push(v),
            _ => return false,
        }
    }
    unreachable!("cycle() over a non-empty slice does not end")
}

/// True when `field` ends in an exponent of two digits or more: `E+00`, `D-05`,
/// `e123`, or Fortran's letterless three-digit `-100`.
fn ends_in_exponent(field: &[u8]) -> bool {
    let digits = field
        .iter()
        .rev()
        .take_while(|b| b.is_ascii_digit())
        .count();
    let before = &field[..field.len() - digits];
    let before = before
        .strip_suffix(b"+")
        .or_else(|| before.strip_suffix(b"-"));
    match before {
        Some(rest) => {
            digits >= 2 && (digits >= 3 || rest.last().is_some_and(|b| b"EeDd".contains(b)))
        }
        None => {
            digits >= 2
                && field[..field.len() - digits]
                    .last()
                    .is_some_and(|b| b"EeDd".contains(b))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(text: &str, widths: &[usize]) -> (Vec<f64>, bool) {
        let mut row = Vec::new();
        let in_columns = split_line(text.as_bytes(), widths, &mut row).unwrap();
        (row, in_columns)
    }

    #[test]
    fn fields_that_run_together_are_read_by_their_columns() {
        let (row, fixed) = split("-1.23456E+000-2.34567E+000 3.00000E-001", &[13]);
        assert_eq!(row, [-1.23456, -2.34567, 0.3]);
        assert!(fixed);
        let (row, _) = split(
            "  1.00000e+01  -1.00998154689e-06  -2.56377745272e-09",
            &[13, 20, 20],
        );
        assert_eq!(row, [10.0, -1.00998154689e-06, -2.56377745272e-09]);
    }

    #[test]
    fn blank_fields_and_padding_are_skipped() {
        let padded = format!("{:<80}", " -5.84096E+00");
        assert_eq!(split(&padded, &[13]), (vec![-5.84096], true));
        assert_eq!(split("", &[13]), (vec![], true));
    }

    #[test]
    fn numbers_out_of_their_columns_are_read_between_blanks() {
        assert_eq!(
            split("  1.5  2.25 -3", &[13]),
            (vec![1.5, 2.25, -3.0], false)
        );
        let (row, fixed) = split(" 1.0000000E+00 2.0000000E+00", &[13]);
        assert_eq!((row, fixed), (vec![1.0, 2.0], false));
    }

    #[test]
    fn a_number_wider_than_its_columns_is_not_cut_in_two() {
        // " 1.0000000E+0" and "0" would both read as numbers
        assert_eq!(split(" 1.0000000E+00", &[13]), (vec![1.0], false));
        assert!(ends_in_exponent(b"-1.23456E+000"));
        assert!(ends_in_exponent(b" 1.23456D-05"));
        assert!(ends_in_exponent(b"-1.23456-100"));
        assert!(!ends_in_exponent(b" 1.0000000E+0"));
        assert!(!ends_in_exponent(b" 1.2345678"));
    }

    #[test]
    fn a_word_that_is_no_number_is_named() {
        let mut row = Vec::new();
        assert_eq!(
            split_line(b" 1.0E+00 abc", &[13], &mut row),
            Err(&b"abc"[..])
        );
    }
}
