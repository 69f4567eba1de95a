//! Delimited text with a header: the fallback for any table a lab writes — a row of
//! channel names, optionally a row of units, then one row of numbers per sample.
//!
//! - Separator: the one of `,` `;` tab `|` that splits the header and the first data
//!   row into the same number (> 1) of cells; else runs of spaces.
//! - Decimal comma: with `;`, tab, `|` or spaces as separator, a comma inside a number is
//!   its decimal mark (`0,25`).
//! - Comment lines (`#`, `%`, `//`) and blank lines are skipped anywhere.
//! - Units: a second row whose cells are not numbers, or in the name as `speed [rpm]`
//!   or `speed (rpm)`.
//! - Abscissa: the first column whose unit is a time is every column's abscissa
//!   (its own too); without one the samples are numbered.
//! - Every data row has a number in every named column: an empty or non-numeric cell
//!   is an error naming the line and the column. Cells beyond the named columns that are
//!   empty (a trailing separator) are ignored.

use std::io::{BufRead, BufReader};
use std::path::Path;

use super::text::parse_number;
use super::units::{self, Quantity};
use super::{Abscissa, Channel, FormatError, Location, Recording, Samples};

/// The format as `--format` names it and [`super::detect`] recognises it.
pub static DEFINITION: super::format::Definition = super::format::Definition {
    name: "delimited",
    sniff: |_| true,
    read,
};

/// Reads a delimited text file.
pub fn read(path: &Path) -> Result<Recording, FormatError> {
    let file = crate::io::open_input(path)
        .map_err(|e| FormatError::new(path, Location::File, format!("cannot read: {e}")))?;
    let mut lines = BufReader::new(file)
        .lines()
        .enumerate()
        .filter_map(|(i, l)| match l {
            Ok(text) if is_skipped(&text) => None,
            Ok(text) => Some(Ok((i + 1, text))),
            Err(e) => Some(Err(FormatError::new(
                path,
                Location::Line(i + 1),
                format!("not text: {e}"),
            ))),
        });
    let (header_line, header) = lines
        .next()
        .transpose()?
        .ok_or_else(|| FormatError::new(path, Location::File, "empty: no header row"))?;
    let (first_line, first) = lines.next().transpose()?.ok_or_else(|| {
        FormatError::new(
            path,
            Location::Line(header_line),
            "a header without data rows",
        )
    })?;
    let separator = Separator::detect(&header, &first);
    let names = separator.split(&header);
    let mut table = Table::new(path, &names, separator);
    if table.is_units_row(&first) {
        table.units = separator
            .split(&first)
            .into_iter()
            .map(|u| u.trim().to_string())
            .collect();
    } else {
        table.push(first_line, &first)?;
    }
    for line in lines {
        let (number, text) = line?;
        table.push(number, &text)?;
    }
    table.finish()
}

fn is_skipped(text: &str) -> bool {
    let t = text.trim_start_matches('\u{feff}').trim();
    t.is_empty() || t.starts_with('#') || t.starts_with('%') || t.starts_with("//")
}

/// How cells are separated.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Separator {
    Char(char),
    Spaces,
}

impl Separator {
    fn detect(header: &str, row: &str) -> Separator {
        for c in ['\t', ';', '|', ','] {
            let h = header.split(c).count();
            if h > 1 && h == row.split(c).count() {
                return Separator::Char(c);
            }
        }
        for c in ['\t', ';', '|', ','] {
            if header.split(c).count() > 1 {
                return Separator::Char(c);
            }
        }
        Separator::Spaces
    }

    fn split(self, line: &str) -> Vec<String> {
        let line = line.trim_start_matches('\u{feff}');
        match self {
            Separator::Char(c) => line
                .split(c)
                .map(|s| s.trim().trim_matches('"').to_string())
                .collect(),
            Separator::Spaces => line.split_whitespace().map(str::to_string).collect(),
        }
    }

    /// Whether a comma inside a cell is a decimal mark.
    fn decimal_comma(self) -> bool {
        self != Separator::Char(',')
    }
}

/// The columns as they are read.
struct Table<'a> {
    path: &'a Path,
    names: Vec<String>,
    units: Vec<String>,
    separator: Separator,
    columns: Vec<Vec<f64>>,
    first_line: Option<usize>,
}

impl<'a> Table<'a> {
    fn new(path: &'a Path, names: &[String], separator: Separator) -> Table<'a> {
        Table {
            path,
            names: names.to_vec(),
            units: Vec::new(),
            separator,
            columns: vec![Vec::new(); names.len()],
            first_line: None,
        }
    }

    /// A row whose cells are not numbers: the units.
    fn is_units_row(&self, row: &str) -> bool {
        let cells = self.separator.split(row);
        cells.len() == self.names.len()
            && cells
                .iter()
                .any(|c| !c.is_empty() && self.number(c).is_none())
            && cells.iter().all(|c| self.number(c).is_none())
    }

    fn number(&self, cell: &str) -> Option<f64> {
        parse_number(cell.as_bytes(), self.separator.decimal_comma()).filter(|v| v.is_finite())
    }

    fn push(&mut self, line: usize, text: &str) -> Result<(), FormatError> {
        let cells = self.separator.split(text);
        let error = |m: String| FormatError::new(self.path, Location::Line(line), m);
        if cells.len() < self.names.len() {
            return Err(error(format!(
                "{} cells, but the header names {} columns",
                cells.len(),
                self.names.len()
            )));
        }
        if let Some(extra) = cells[self.names.len()..].iter().find(|c| !c.is_empty()) {
            return Err(error(format!(
                "a cell `{extra}` beyond the {} named columns",
                self.names.len()
            )));
        }
        for (k, cell) in cells.iter().take(self.names.len()).enumerate() {
            let value = self.number(cell).ok_or_else(|| {
                error(format!(
                    "column `{}`: `{cell}` is not a finite number",
                    self.names[k]
                ))
            })?;
            self.columns[k].push(value);
        }
        self.first_line.get_or_insert(line);
        Ok(())
    }

    fn finish(self) -> Result<Recording, FormatError> {
        if self.columns.first().map_or(true, |c| c.is_empty()) {
            return Err(FormatError::new(
                self.path,
                Location::File,
                "a header without data rows",
            ));
        }
        let labelled: Vec<(String, String)> = self
            .names
            .iter()
            .enumerate()
            .map(|(k, n)| name_and_unit(n, self.units.get(k).map(String::as_str)))
            .collect();
        let time = labelled.iter().position(|(_, u)| is_time(u));
        let abscissa = time.map(|k| Abscissa::Values {
            values: self.columns[k].clone(),
            unit: labelled[k].1.clone(),
        });
        let channels = labelled
            .into_iter()
            .zip(self.columns)
            .map(|((name, unit), values)| Channel {
                name,
                unit,
                abscissa: abscissa.clone().unwrap_or(Abscissa::Index),
                samples: Samples::Real(values),
                first_line: self.first_line,
            })
            .collect();
        Ok(Recording {
            format: "delimited",
            channels,
            notes: Vec::new(),
            groups: Vec::new(),
        })
    }
}

/// `speed [rpm]` → (`speed`, `rpm`); a units row's cell wins over none in the name.
fn name_and_unit(name: &str, unit_row: Option<&str>) -> (String, String) {
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(body) = name.strip_suffix(close) {
            if let Some((n, u)) = body.rsplit_once(open) {
                return (n.trim().to_string(), u.trim().to_string());
            }
        }
    }
    (
        name.trim().to_string(),
        unit_row.unwrap_or("").trim().to_string(),
    )
}

fn is_time(unit: &str) -> bool {
    units::lookup(unit).is_some_and(|u| u.quantity == Quantity::Time)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<Recording, FormatError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        std::fs::write(&path, text).unwrap();
        read(&path)
    }

    #[test]
    fn semicolons_decimal_comma_and_a_units_row() {
        let r = read_text("# bench run 3\ntime;speed;torque\nms;rpm;%\n0;1,5;-9,25\n128;2;-9\n")
            .unwrap();
        assert_eq!(r.channels.len(), 3);
        assert_eq!(r.channels[1].name, "speed");
        assert_eq!(r.channels[1].unit, "rpm");
        assert_eq!(r.channels[1].samples, Samples::Real(vec![1.5, 2.0]));
        assert_eq!(r.channels[2].first_line, Some(4));
        assert_eq!(
            r.channels[2].abscissa,
            Abscissa::Values {
                values: vec![0.0, 128.0],
                unit: "ms".into()
            }
        );
    }

    #[test]
    fn units_in_the_names_and_commas() {
        let r = read_text("t [s],x (mm),v\n0,1.5,2\n0.1,1.6,2.1,\n").unwrap();
        assert_eq!(
            (r.channels[1].name.as_str(), r.channels[1].unit.as_str()),
            ("x", "mm")
        );
        assert_eq!(r.channels[2].unit, "");
        assert_eq!(
            r.channels[0].abscissa,
            Abscissa::Values {
                values: vec![0.0, 0.1],
                unit: "s".into()
            }
        );
        let r = read_text("a b\n1 2\n3 4\n").unwrap();
        assert!(matches!(r.channels[0].abscissa, Abscissa::Index));
        assert_eq!(r.channels[1].samples, Samples::Real(vec![2.0, 4.0]));
    }

    #[test]
    fn bad_rows_name_the_line_and_column() {
        let e = read_text("a,b\n1,2\n3,x\n").unwrap_err().to_string();
        assert!(
            e.contains("line 3") && e.contains("`b`") && e.contains("`x`"),
            "{e}"
        );
        let e = read_text("a,b\n1,2\n3\n").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("1 cells"), "{e}");
        let e = read_text("a,b\n1,2\n3,4,5\n").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("`5`"), "{e}");
        let e = read_text("a,b\n1,NaN\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = read_text("a,b\n").unwrap_err().to_string();
        assert!(e.contains("without data"), "{e}");
        let e = read_text("").unwrap_err().to_string();
        assert!(e.contains("empty"), "{e}");
        let e = read_text("a,b\n\u{0}\u{1}\u{2}\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }
}
