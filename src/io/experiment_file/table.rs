//! The CSV half of an experiment file: a header row whose names carry units, `#`
//! comment lines, every cell checked and any fault reported with its line and column.

use std::path::{Path, PathBuf};

pub(super) mod kinds;

use super::units::units_for;
use super::{Axis, Columns, CommandUnit, ExperimentFileError as Error};

/// A CSV file read into memory, with the columns taken so far marked.
pub(super) struct Table {
    path: PathBuf,
    header: Vec<String>,
    header_line: u64,
    /// (line, record) of each data row.
    rows: Vec<(u64, csv::StringRecord)>,
    used: Vec<bool>,
}

/// A column to read: its index, SI units per unit written (1 for a column read as
/// written) and, for a position or an effort, the axis its unit implies.
#[derive(Clone, Copy)]
struct Col {
    index: usize,
    scale: f64,
    axis: Option<Axis>,
}

impl Table {
    /// Reads the CSV at `path`, the data file of the manifest at `manifest`.
    pub(super) fn read(path: &Path, manifest: &Path) -> Result<Table, Error> {
        let file = crate::io::open_input(path).map_err(|source| Error::MissingData {
            manifest: manifest.to_path_buf(),
            data: path.to_path_buf(),
            source,
        })?;
        let mut reader = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .from_reader(file);
        let record = reader.headers().map_err(|e| csv_error(path, e))?.clone();
        let header_line = record.position().map_or(1, |p| p.line());
        let header: Vec<String> = record.iter().map(str::to_string).collect();
        let at = |line: u64, message: &str| Error::Csv {
            path: path.to_path_buf(),
            line,
            message: message.to_string(),
        };
        if header.iter().all(String::is_empty) {
            return Err(at(
                header_line,
                "no header row (the file is empty or holds only comments)",
            ));
        }
        for (i, name) in header.iter().enumerate() {
            if !name.is_empty() && header[..i].contains(name) {
                return Err(at(header_line, &format!("column `{name}` appears twice")));
            }
        }
        let mut rows = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| csv_error(path, e))?;
            rows.push((record.position().map_or(0, |p| p.line()), record));
        }
        if rows.is_empty() {
            return Err(at(header_line, "no data rows"));
        }
        Ok(Table {
            path: path.to_path_buf(),
            used: vec![false; header.len()],
            header,
            header_line,
            rows,
        })
    }

    fn find(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// A required column without unit conversion.
    fn column(&mut self, name: &str) -> Result<Col, Error> {
        let index = self
            .find(name)
            .ok_or_else(|| self.missing(name, Vec::new()))?;
        self.used[index] = true;
        Ok(Col {
            index,
            scale: 1.0,
            axis: None,
        })
    }

    /// The position column `{base}_{unit}` for any of `bases` and the units each base
    /// admits ([`units_for`]), converted to rad or m, if there is one. Two columns for
    /// the same position are an error.
    fn position(&mut self, bases: &[&str]) -> Result<Option<Col>, Error> {
        let mut found: Vec<(String, Col)> = Vec::new();
        for base in bases {
            for unit in units_for(base) {
                let name = format!("{base}_{}", unit.suffix);
                if let Some(index) = self.find(&name) {
                    let col = Col {
                        index,
                        scale: unit.si,
                        axis: Some(unit.axis),
                    };
                    found.push((name, col));
                }
            }
        }
        match found.as_slice() {
            [] => Ok(None),
            [(_, c)] => {
                self.used[c.index] = true;
                Ok(Some(*c))
            }
            [(a, ca), (b, cb), ..] => {
                let rotary = [ca, cb].iter().all(|c| c.axis == Some(Axis::Rotary));
                let what = if rotary { "angle" } else { "position" };
                Err(self.header_error(format!(
                    "columns `{a}` and `{b}` give the same {what}: keep one"
                )))
            }
        }
    }

    /// As [`Table::position`], required: missing, the error names the first base in
    /// degrees (or metres for a base without angles) and every other spelling.
    fn required_position(&mut self, bases: &[&str]) -> Result<Col, Error> {
        self.position(bases)?.ok_or_else(|| {
            let mut names = bases.iter().flat_map(|b| {
                units_for(b)
                    .iter()
                    .map(move |u| format!("{b}_{}", u.suffix))
            });
            let first = names.next().unwrap_or_default();
            self.missing(&first, names.collect())
        })
    }

    /// The one column of `choices` (name, what it means) present, if any; two of them
    /// are an error saying they give the same `what`.
    fn one_of<T: Copy>(
        &mut self,
        choices: &[(&str, T)],
        what: &str,
    ) -> Result<Option<(Col, T)>, Error> {
        let found: Vec<(&str, usize, T)> = choices
            .iter()
            .filter_map(|&(name, t)| self.find(name).map(|i| (name, i, t)))
            .collect();
        match found.as_slice() {
            [] => Ok(None),
            [(_, index, t)] => {
                self.used[*index] = true;
                let col = Col {
                    index: *index,
                    scale: 1.0,
                    axis: None,
                };
                Ok(Some((col, *t)))
            }
            [(a, ..), (b, ..), ..] => Err(self.header_error(format!(
                "columns `{a}` and `{b}` give the same {what}: keep one"
            ))),
        }
    }

    /// As [`Table::one_of`], required.
    fn required_one_of<T: Copy>(
        &mut self,
        choices: &[(&str, T)],
        what: &str,
    ) -> Result<(Col, T), Error> {
        self.one_of(choices, what)?.ok_or_else(|| {
            let rest = choices[1..].iter().map(|(n, _)| n.to_string()).collect();
            self.missing(choices[0].0, rest)
        })
    }

    /// The drive's effort among `choices` (a torque name and a force name), required,
    /// marked with the axis it implies.
    fn effort(&mut self, choices: &[(&str, Axis); 2]) -> Result<Col, Error> {
        let (col, axis) = self.required_one_of(choices, "drive effort")?;
        Ok(Col {
            axis: Some(axis),
            ..col
        })
    }

    /// A command signal `{base}_v`, `_a`, `_nm` or `_n`, if there is one.
    fn command(&mut self, base: &str) -> Result<Option<(Col, CommandUnit)>, Error> {
        let names = CommandUnit::ALL.map(|u| (format!("{base}_{}", u.suffix()), u));
        let choices = names.each_ref().map(|(n, u)| (n.as_str(), *u));
        self.one_of(&choices, "signal")
    }

    /// The axis all of `cols` agree on (rotary when none carries one). A column whose
    /// unit belongs to the other axis than the first one's is an error naming both.
    fn same_axis(&self, cols: &[Option<Col>]) -> Result<Axis, Error> {
        let mut with_axis = cols
            .iter()
            .flatten()
            .filter_map(|c| c.axis.map(|a| (c.index, a)));
        let Some((first, axis)) = with_axis.next() else {
            return Ok(Axis::Rotary);
        };
        match with_axis.find(|(_, a)| *a != axis) {
            None => Ok(axis),
            Some((other, other_axis)) => Err(self.header_error(format!(
                "column `{}` is {} but `{}` is {}: a file's positions and efforts must \
                 all be rotary (deg, rad, arcsec; nm) or all linear (m, mm, um; n)",
                self.header[other],
                unit_kind(other_axis),
                self.header[first],
                unit_kind(axis),
            ))),
        }
    }

    /// An error about the header row.
    fn header_error(&self, message: String) -> Error {
        Error::Csv {
            path: self.path.clone(),
            line: self.header_line,
            message,
        }
    }

    fn missing(&self, column: &str, alternatives: Vec<String>) -> Error {
        Error::MissingColumn {
            path: self.path.clone(),
            line: self.header_line,
            column: column.to_string(),
            alternatives,
            header: self.header.clone(),
        }
    }

    fn cell(&self, line: u64, index: usize, message: String) -> Error {
        Error::Cell {
            path: self.path.clone(),
            line,
            column: self.header.get(index).cloned().unwrap_or_default(),
            message,
        }
    }

    /// The column's numbers in rad (for angles) or as written; all finite, and with
    /// [`Order::Time`] strictly increasing by at least [`MIN_TIME_STEP_S`].
    fn numbers(&self, col: Col, order: Order) -> Result<Vec<f64>, Error> {
        let mut out = Vec::with_capacity(self.rows.len());
        let mut previous: Option<f64> = None;
        for (line, record) in &self.rows {
            let text = record.get(col.index).unwrap_or("");
            let x = number(text).map_err(|m| self.cell(*line, col.index, m))?;
            if (x * col.scale).abs() > MAX_MAGNITUDE {
                let message =
                    format!("{x:e} is beyond ±1e15 in SI units: not a measurement (a unit slip?)");
                return Err(self.cell(*line, col.index, message));
            }
            if order == Order::Frequency && x * col.scale < MIN_FREQUENCY_HZ {
                let message = format!(
                    "{} Hz is below {MIN_FREQUENCY_HZ:e} Hz: a measured line is a positive \
                     frequency a test can reach (a period under 11 days)",
                    crate::names::Num(x * col.scale)
                );
                return Err(self.cell(*line, col.index, message));
            }
            if let (Order::Time | Order::Frequency, Some(p)) = (order, previous) {
                if x <= p {
                    let message = format!("{x} does not increase (previous row {p})");
                    return Err(self.cell(*line, col.index, message));
                }
                if order == Order::Time && x - p < MIN_TIME_STEP_S {
                    let message = format!(
                        "{x} is {} s after the previous row: a time step under \
                         {MIN_TIME_STEP_S:e} s is no recorder's (times in seconds?)",
                        crate::names::Num(x - p)
                    );
                    return Err(self.cell(*line, col.index, message));
                }
            }
            previous = Some(x);
            out.push(x * col.scale);
        }
        Ok(out)
    }

    /// The column's cells through `parse`.
    fn parse<T>(
        &self,
        col: Col,
        parse: impl Fn(&str) -> Result<T, String>,
    ) -> Result<Vec<T>, Error> {
        let parse_cell = |(line, record): &(u64, csv::StringRecord)| {
            parse(record.get(col.index).unwrap_or("")).map_err(|m| self.cell(*line, col.index, m))
        };
        self.rows.iter().map(parse_cell).collect()
    }

    /// The columns not taken, with a name, whose every cell is a finite number. Other
    /// columns (text such as a timestamp) are left out rather than refused; a column
    /// whose name misspells one of the kind's `reserved` names is refused naming it.
    fn extras(&self, reserved: &[String]) -> Result<Columns, Error> {
        let reserved: Vec<&str> = reserved.iter().map(String::as_str).collect();
        let mut extra = Columns::new();
        for (i, name) in self.header.iter().enumerate() {
            if self.used[i] || name.is_empty() {
                continue;
            }
            if let Some(known) = crate::names::misspelling_of(name, &reserved) {
                return Err(self.header_error(format!(
                    "column `{name}` is not one rtid reads: did you mean `{known}`? (a column \
                     of your own goes under a name unlike rtid's)"
                )));
            }
            let values: Option<Vec<f64>> = self
                .rows
                .iter()
                .map(|(_, r)| number(r.get(i).unwrap_or("")).ok())
                .collect();
            if let Some(values) = values {
                extra.insert(name.clone(), values);
            }
        }
        Ok(extra)
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Order {
    Any,
    /// Time in seconds: strictly increasing, by at least [`MIN_TIME_STEP_S`].
    Time,
    /// Strictly increasing frequencies, each at least [`MIN_FREQUENCY_HZ`].
    Frequency,
}

/// The shortest time step a record may have, s: a nanosecond, beyond any drive's
/// recorder (a torque curve lasting 6e-298 s was evaluated to a null friction).
pub const MIN_TIME_STEP_S: f64 = 1e-9;

/// The lowest frequency a response's line may have, Hz: below, no drive test (and
/// subnormal frequencies, 1e-319 Hz, sent the modal fit's arithmetic crawling).
pub const MIN_FREQUENCY_HZ: f64 = 1e-6;

/// The largest magnitude a record's value may have in SI units (s, rad, m, N·m, N, Hz,
/// dB…), as for parameters: beyond, a typo or a unit slip. (Angles of ±1e308 made
/// every derived range overflow, and a plot's axis never finish.)
pub const MAX_MAGNITUDE: f64 = 1e15;

/// A finite number.
fn number(text: &str) -> Result<f64, String> {
    if text.is_empty() {
        return Err("empty cell (a number is needed)".into());
    }
    let x: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("`{text}` is not a finite number"))
    }
}

/// A run number: a whole number ≥ 1 (`3` or `3.0`).
fn run(text: &str) -> Result<u32, String> {
    if let Ok(r) = text.parse::<u32>() {
        return if r >= 1 {
            Ok(r)
        } else {
            Err("run 0: runs are numbered from 1".into())
        };
    }
    let x: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a run number (a whole number ≥ 1)"))?;
    if x.fract() == 0.0 && (1.0..=f64::from(u32::MAX)).contains(&x) {
        Ok(x as u32)
    } else {
        Err(format!("`{text}` is not a run number (a whole number ≥ 1)"))
    }
}

/// What a column of `axis` holds, for an error message.
fn unit_kind(axis: Axis) -> &'static str {
    match axis {
        Axis::Rotary => "an angle or a torque (rotary)",
        Axis::Linear => "a length or a force (linear)",
    }
}

/// A csv crate error as an experiment-file error, with its line where it has one.
fn csv_error(path: &Path, e: csv::Error) -> Error {
    let line = e.position().map_or(0, |p| p.line());
    let message = match e.into_kind() {
        csv::ErrorKind::Io(source) => {
            return Error::Io {
                path: path.to_path_buf(),
                source,
            }
        }
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} fields where the rows before have {expected_len}"),
        csv::ErrorKind::Utf8 { err, .. } => format!("field {} is not UTF-8 text", err.field() + 1),
        other => format!("{other:?}"),
    };
    Error::Csv {
        path: path.to_path_buf(),
        line,
        message,
    }
}
