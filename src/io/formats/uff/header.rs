//! Records 1-11 of dataset 58 (the ID lines, the DOF identification, the data form and
//! the axis characteristics), read by the columns of the dataset 58 description (SDRC
//! I-DEAS universal file datasets, "Dataset 58: Function at Nodal DOF", as reproduced
//! by UC-SDRL and in pyuff's `dataset_58.py`).

use std::borrow::Cow;
use std::io::BufRead;

use super::fields::{column_span, columns, decode};
use super::lines::{excerpt, is_delimiter, LineReader};
use super::number::{parse_int, parse_real};
use super::Fault;

/// Record 6: what the function is and where it was measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Dof {
    /// Field 1: 1 time response, 4 frequency response function, 9 power spectral
    /// density… (0-27 in the description).
    pub function_type: i64,
    pub response: Point,
    pub reference: Point,
}

/// A response or reference: entity name (`NONE` if unused), node and direction
/// (0 scalar, ±1..±3 translation along X, Y, Z, ±4..±6 rotation about them).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub entity: String,
    pub node: i64,
    pub direction: i64,
}

/// Record 7 field 1: how the ordinate is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ordinate {
    RealSingle,
    RealDouble,
    ComplexSingle,
    ComplexDouble,
}

impl Ordinate {
    fn from_code(code: i64) -> Option<Ordinate> {
        match code {
            2 => Some(Ordinate::RealSingle),
            4 => Some(Ordinate::RealDouble),
            5 => Some(Ordinate::ComplexSingle),
            6 => Some(Ordinate::ComplexDouble),
            _ => None,
        }
    }

    pub fn is_complex(self) -> bool {
        matches!(self, Ordinate::ComplexSingle | Ordinate::ComplexDouble)
    }

    pub fn is_double(self) -> bool {
        matches!(self, Ordinate::RealDouble | Ordinate::ComplexDouble)
    }

    pub fn describe(self) -> &'static str {
        match self {
            Ordinate::RealSingle => "real single-precision ordinate",
            Ordinate::RealDouble => "real double-precision ordinate",
            Ordinate::ComplexSingle => "complex single-precision ordinate",
            Ordinate::ComplexDouble => "complex double-precision ordinate",
        }
    }
}

/// Record 7: the data form.
#[derive(Clone, Debug, PartialEq)]
pub struct DataForm {
    pub ordinate: Ordinate,
    /// Field 2: the number of values (even abscissa) or of pairs (uneven).
    pub points: u64,
    /// Field 3: 1 even (abscissa from `start` and `step`), 0 uneven (abscissa stored
    /// with each point).
    pub even: bool,
    pub start: f64,
    pub step: f64,
}

impl DataForm {
    /// The numbers stored per point: abscissa (uneven only), real part, imaginary part
    /// (complex only).
    pub fn values_per_point(&self) -> u64 {
        1 + u64::from(!self.even) + u64::from(self.ordinate.is_complex())
    }

    /// The numbers the data section holds (saturating: a nonsense count is refused by
    /// the size check that follows).
    pub fn values(&self) -> u64 {
        self.points.saturating_mul(self.values_per_point())
    }
}

/// Records 8-11: an axis' specific data type, label and units label.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub specific_type: i64,
    pub label: String,
    pub unit: String,
}

/// Records 1-11 of one dataset 58.
#[derive(Clone, Debug, PartialEq)]
pub struct Header58 {
    /// ID line 1 (record 1), blanks around it removed.
    pub id1: String,
    pub dof: Dof,
    pub form: DataForm,
    /// The line of record 7, where a size problem is reported.
    pub form_line: usize,
    pub abscissa: Axis,
    pub ordinate: Axis,
    pub denominator: Axis,
}

/// One header record being read: its number, its title and its line.
struct Record<'a> {
    number: usize,
    title: &'static str,
    line: usize,
    text: Cow<'a, str>,
}

impl Record<'_> {
    fn fault(&self, message: impl std::fmt::Display) -> Fault {
        Fault::line(
            self.line,
            format!("record {} ({}): {message}", self.number, self.title),
        )
    }

    fn int(&self, fields: &[&str], widths: &[usize], k: usize, what: &str) -> Result<i64, Fault> {
        parse_int(fields[k]).ok_or_else(|| {
            self.fault(format!(
                "{what} ({}) {} is not an integer",
                column_span(widths, k),
                excerpt(fields[k].as_bytes())
            ))
        })
    }
}

/// Reads the next line as header record `number` of the dataset begun at `start`.
fn next_record<'r, R: BufRead>(
    lines: &'r mut LineReader<R>,
    start: usize,
    number: usize,
    title: &'static str,
) -> Result<Record<'r>, Fault> {
    if !lines.advance()? {
        return Err(Fault::line(
            lines.line(),
            format!("the file ends in the header of the dataset 58 begun at line {start}: record {number} ({title}) is missing"),
        ));
    }
    if is_delimiter(lines.text()) {
        return Err(Fault::line(
            lines.line(),
            format!("the dataset 58 begun at line {start} ends (-1) before its record {number} ({title})"),
        ));
    }
    Ok(Record {
        number,
        title,
        line: lines.line(),
        text: decode(lines.text()),
    })
}

/// Reads records 1-11 of the dataset 58 whose `-1` is on line `start`.
pub fn read_header<R: BufRead>(lines: &mut LineReader<R>, start: usize) -> Result<Header58, Fault> {
    let id1 = next_record(lines, start, 1, "ID line 1")?
        .text
        .trim()
        .to_string();
    for number in 2..=5 {
        next_record(lines, start, number, "ID line")?;
    }
    let dof = dof(&next_record(lines, start, 6, "DOF identification")?)?;
    let record7 = next_record(lines, start, 7, "data form")?;
    let form_line = record7.line;
    let form = data_form(&record7)?;
    let abscissa = axis(&next_record(
        lines,
        start,
        8,
        "abscissa data characteristics",
    )?)?;
    let ordinate = axis(&next_record(
        lines,
        start,
        9,
        "ordinate data characteristics",
    )?)?;
    let denominator = axis(&next_record(
        lines,
        start,
        10,
        "ordinate denominator data characteristics",
    )?)?;
    axis(&next_record(
        lines,
        start,
        11,
        "z-axis data characteristics",
    )?)?;
    Ok(Header58 {
        id1,
        dof,
        form,
        form_line,
        abscissa,
        ordinate,
        denominator,
    })
}

/// Record 6, `Format(2(I5,I10),2(1X,10A1,I10,I4))`.
fn dof(record: &Record) -> Result<Dof, Fault> {
    const WIDTHS: [usize; 10] = [5, 10, 5, 10, 11, 10, 4, 11, 10, 4];
    let f = columns(&record.text, &WIDTHS);
    if f[0].trim().is_empty() {
        return Err(record.fault("the function type (columns 1-5) is blank"));
    }
    let point = |entity: usize, what: &str| -> Result<Point, Fault> {
        Ok(Point {
            entity: f[entity].trim().to_string(),
            node: record.int(&f, &WIDTHS, entity + 1, &format!("{what} node"))?,
            direction: record.int(&f, &WIDTHS, entity + 2, &format!("{what} direction"))?,
        })
    };
    Ok(Dof {
        function_type: record.int(&f, &WIDTHS, 0, "function type")?,
        response: point(4, "response")?,
        reference: point(7, "reference")?,
    })
}

/// Record 7, `Format(3I10,3E13.5)`; a record whose numbers are not in those columns
/// (some writers widen the reals) is read as blank-separated numbers.
fn data_form(record: &Record) -> Result<DataForm, Fault> {
    const WIDTHS: [usize; 6] = [10, 10, 10, 13, 13, 13];
    const WHAT: [&str; 5] = [
        "the ordinate data type",
        "the number of points",
        "the abscissa spacing",
        "the abscissa minimum",
        "the abscissa increment",
    ];
    let fields = columns(&record.text, &WIDTHS);
    let n = numbers_in_columns(&fields[..5])
        .or_else(|| numbers_between_blanks(&record.text))
        .ok_or_else(|| {
            record.fault(format!(
                "{} is not 3 integers and 3 reals (columns 1-30 and 31-69)",
                excerpt(record.text.as_bytes())
            ))
        })?;
    let field = |k: usize| {
        n[k].ok_or_else(|| {
            record.fault(format!(
                "{} ({}) is blank",
                WHAT[k],
                column_span(&WIDTHS, k)
            ))
        })
    };
    let code = field(0)?;
    let ordinate = whole(code).and_then(Ordinate::from_code).ok_or_else(|| {
        record.fault(format!("the ordinate data type {code} is not 2, 4, 5 or 6"))
    })?;
    let count = field(1)?;
    let points = whole(count)
        .and_then(|n| u64::try_from(n).ok())
        .ok_or_else(|| record.fault(format!("the number of points {count} is not a count")))?;
    let even = match whole(field(2)?) {
        Some(1) => true,
        Some(0) => false,
        _ => {
            return Err(record.fault(format!(
                "the abscissa spacing {} is not 0 (uneven) or 1 (even)",
                field(2)?
            )))
        }
    };
    let finite = |k: usize| {
        let v = field(k)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(record.fault(format!("{} {v} is not a finite number", WHAT[k])))
        }
    };
    let (start, step) = if even {
        (finite(3)?, finite(4)?)
    } else {
        (0.0, 0.0)
    };
    Ok(DataForm {
        ordinate,
        points,
        even,
        start,
        step,
    })
}

/// The fields as numbers, `None` for a blank one; `None` overall if a field is
/// neither blank nor a number.
fn numbers_in_columns(fields: &[&str]) -> Option<Vec<Option<f64>>> {
    fields
        .iter()
        .map(|f| {
            if f.trim().is_empty() {
                Some(None)
            } else {
                parse_real(f.as_bytes()).map(Some)
            }
        })
        .collect()
}

/// The first five of 3-6 blank-separated numbers; `None` if there are fewer or more,
/// or one is not a number.
fn numbers_between_blanks(text: &str) -> Option<Vec<Option<f64>>> {
    let words: Vec<&str> = text.split_whitespace().collect();
    if !(3..=6).contains(&words.len()) {
        return None;
    }
    let mut n: Vec<Option<f64>> = words
        .iter()
        .map(|w| parse_real(w.as_bytes()).map(Some))
        .collect::<Option<_>>()?;
    n.resize(5, None);
    n.truncate(5);
    Some(n)
}

/// An integral value as an integer.
fn whole(v: f64) -> Option<i64> {
    (v.fract() == 0.0 && v.abs() < 1e15).then_some(v as i64)
}

/// Records 8-11, `Format(I10,3I5,2(1X,20A1))`: specific data type, three unit
/// exponents, axis label, axis units label.
fn axis(record: &Record) -> Result<Axis, Fault> {
    const WIDTHS: [usize; 6] = [10, 5, 5, 5, 21, 21];
    let f = columns(&record.text, &WIDTHS);
    let specific_type = record.int(&f, &WIDTHS, 0, "specific data type")?;
    for (k, what) in [
        (1, "length units exponent"),
        (2, "force units exponent"),
        (3, "temperature units exponent"),
    ] {
        record.int(&f, &WIDTHS, k, what)?;
    }
    Ok(Axis {
        specific_type,
        label: f[4].trim().to_string(),
        unit: f[5].trim().to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(number: usize, text: &str) -> Record<'_> {
        Record {
            number,
            title: "test",
            line: 9,
            text: Cow::Borrowed(text),
        }
    }

    #[test]
    fn record_6_keeps_blanks_inside_entity_names() {
        let text =
            "    9         0    0         0 Pilot 1            0   0 NONE               2  -3";
        let dof = dof(&record(6, text)).unwrap();
        assert_eq!(dof.function_type, 9);
        assert_eq!(
            (
                dof.response.entity.as_str(),
                dof.response.node,
                dof.response.direction
            ),
            ("Pilot 1", 0, 0)
        );
        assert_eq!(
            (
                dof.reference.entity.as_str(),
                dof.reference.node,
                dof.reference.direction
            ),
            ("NONE", 2, -3)
        );
    }

    #[test]
    fn record_7_by_columns_and_by_blanks() {
        let fixed = "         2        13         1 0.00000E+000 5.00000E-005 0.00000E+000";
        let form = data_form(&record(7, fixed)).unwrap();
        assert_eq!(
            form,
            DataForm {
                ordinate: Ordinate::RealSingle,
                points: 13,
                even: true,
                start: 0.0,
                step: 5e-5
            }
        );
        let wide = "         6       513         1  0.00000000e+00  2.50000000e+00  0.00000000e+00";
        let form = data_form(&record(7, wide)).unwrap();
        assert_eq!(
            (form.ordinate, form.points, form.step),
            (Ordinate::ComplexDouble, 513, 2.5)
        );
        let uneven = "         5      3201         0";
        assert!(!data_form(&record(7, uneven)).unwrap().even);
        let nan = "         2        13         1  0.00000E+00          NaN  0.00000E+00";
        let fault = data_form(&record(7, nan)).unwrap_err();
        assert!(
            fault
                .message
                .contains("increment NaN is not a finite number"),
            "{}",
            fault.message
        );
    }

    #[test]
    fn an_even_record_7_needs_its_minimum_and_increment() {
        let fault = data_form(&record(7, "         2        13         1")).unwrap_err();
        assert!(
            fault
                .message
                .contains("the abscissa minimum (columns 31-43) is blank"),
            "{}",
            fault.message
        );
    }

    #[test]
    fn records_8_to_11_read_labels_by_characters() {
        let text = "        12    0    0    0 Beschl. a²           m/s²                ";
        let axis = axis(&record(9, text)).unwrap();
        assert_eq!(
            (axis.specific_type, axis.label.as_str(), axis.unit.as_str()),
            (12, "Beschl. a²", "m/s²")
        );
    }
}
