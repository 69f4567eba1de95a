//! The CSV half of an experiment file: a header row whose names carry units, `#`
//! comment lines, every cell checked and any fault reported with its line and column.

use std::path::{Path, PathBuf};

use super::{Columns, Data, ExperimentFileError as Error, Kind, ANGLE_UNITS};

/// A CSV file read into memory, with the columns taken so far marked.
pub(super) struct Table {
    path: PathBuf,
    header: Vec<String>,
    header_line: u64,
    /// (line, record) of each data row.
    rows: Vec<(u64, csv::StringRecord)>,
    used: Vec<bool>,
}

/// A column to read: its index and radians per unit (1 for non-angles).
#[derive(Clone, Copy)]
struct Col {
    index: usize,
    scale: f64,
}

impl Table {
    /// Reads the CSV at `path`, the data file of the manifest at `manifest`.
    pub(super) fn read(path: &Path, manifest: &Path) -> Result<Table, Error> {
        let file = std::fs::File::open(path).map_err(|source| Error::MissingData {
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

    /// The typed data of `kind` (not resonance, which has no table).
    pub(super) fn data(mut self, kind: Kind) -> Result<Data, Error> {
        use Order::{Any, Increasing};
        Ok(match kind {
            Kind::FrequencyResponse => {
                let (f, g) = (self.column("frequency_hz")?, self.column("gain_db")?);
                let p = self.angle("phase")?;
                Data::FrequencyResponse {
                    frequency_hz: self.numbers(f, Increasing)?,
                    gain_db: self.numbers(g, Any)?,
                    phase_rad: p.map(|p| self.numbers(p, Any)).transpose()?,
                    extra: self.extras(),
                }
            }
            Kind::Resonance => {
                return Err(Error::Manifest {
                    path: self.path,
                    message: "a resonance experiment has no data file".into(),
                })
            }
            Kind::TorqueCurve => {
                let (t, q) = (self.column("time_s")?, self.column("motor_torque_nm")?);
                let a = self.angle("table_angle")?;
                Data::TorqueCurve {
                    time_s: self.numbers(t, Increasing)?,
                    motor_torque_nm: self.numbers(q, Any)?,
                    table_angle_rad: a.map(|a| self.numbers(a, Any)).transpose()?,
                    extra: self.extras(),
                }
            }
            Kind::Positioning => self.positioning()?,
            Kind::FrequencyResponseTime => {
                let (t, q) = (self.column("time_s")?, self.column("motor_torque_nm")?);
                let m = self.required_angle("motor_angle")?;
                let a = self.required_angle("table_angle")?;
                let time_s = self.numbers(t, Increasing)?;
                if let Err(e) = super::check_uniform(&time_s) {
                    return Err(self.cell(self.rows[e.row].0, t.index, e.to_string()));
                }
                Data::FrequencyResponseTime {
                    time_s,
                    motor_torque_nm: self.numbers(q, Any)?,
                    motor_angle_rad: self.numbers(m, Any)?,
                    table_angle_rad: self.numbers(a, Any)?,
                    extra: self.extras(),
                }
            }
            Kind::Fluctuation | Kind::Unbalance => {
                let t = self.column("time_s")?;
                let m = self.required_angle("motor_angle")?;
                let a = self.required_angle("table_angle")?;
                let (time_s, motor_angle_rad, table_angle_rad) = (
                    self.numbers(t, Increasing)?,
                    self.numbers(m, Any)?,
                    self.numbers(a, Any)?,
                );
                let extra = self.extras();
                if kind == Kind::Fluctuation {
                    Data::Fluctuation {
                        time_s,
                        motor_angle_rad,
                        table_angle_rad,
                        extra,
                    }
                } else {
                    Data::Unbalance {
                        time_s,
                        motor_angle_rad,
                        table_angle_rad,
                        extra,
                    }
                }
            }
        })
    }

    /// Target, direction, run, and deviation from a `deviation_*` column or else as
    /// `measured_*` − target. With both, `deviation_*` is used and `measured_*` kept as
    /// an extra column.
    fn positioning(mut self) -> Result<Data, Error> {
        let target = self.required_angle("target")?;
        let (d, r) = (self.column("direction")?, self.column("run")?);
        let (deviation, measured) = match self.angle("deviation")? {
            Some(c) => (c, false),
            None => match self.angle("measured")? {
                Some(c) => (c, true),
                None => {
                    let mut alternatives = vec!["measured_rad".into(), "measured_arcsec".into()];
                    alternatives.extend(ANGLE_UNITS.map(|(u, _)| format!("deviation_{u}")));
                    return Err(self.missing("measured_deg", alternatives));
                }
            },
        };
        let target_rad = self.numbers(target, Order::Any)?;
        let deviation_rad = if !measured {
            self.numbers(deviation, Order::Any)?
        } else {
            // In a common unit, subtract first and scale once: exact for close values.
            let same = deviation.scale == target.scale;
            let unit = |c: Col| if same { Col { scale: 1.0, ..c } } else { c };
            let m = self.numbers(unit(deviation), Order::Any)?;
            let t = self.numbers(unit(target), Order::Any)?;
            let scale = if same { target.scale } else { 1.0 };
            let mut dev = Vec::with_capacity(m.len());
            for ((m, t), (line, _)) in m.iter().zip(&t).zip(&self.rows) {
                let x = (m - t) * scale;
                if !x.is_finite() {
                    let message = "measured − target is not finite".to_string();
                    return Err(self.cell(*line, deviation.index, message));
                }
                dev.push(x);
            }
            dev
        };
        Ok(Data::Positioning {
            target_rad,
            direction: self.parse(d, |s| s.parse())?,
            run: self.parse(r, run)?,
            deviation_rad,
            extra: self.extras(),
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
        Ok(Col { index, scale: 1.0 })
    }

    /// The angle column `{base}_deg`, `{base}_rad` or `{base}_arcsec`, if there is one.
    fn angle(&mut self, base: &str) -> Result<Option<Col>, Error> {
        let found: Vec<(String, Col)> = ANGLE_UNITS
            .iter()
            .filter_map(|&(unit, scale)| {
                let name = format!("{base}_{unit}");
                self.find(&name).map(|index| (name, Col { index, scale }))
            })
            .collect();
        match found.as_slice() {
            [] => Ok(None),
            [(_, c)] => {
                self.used[c.index] = true;
                Ok(Some(*c))
            }
            [(a, _), (b, _), ..] => Err(Error::Csv {
                path: self.path.clone(),
                line: self.header_line,
                message: format!("columns `{a}` and `{b}` give the same angle: keep one"),
            }),
        }
    }

    fn required_angle(&mut self, base: &str) -> Result<Col, Error> {
        self.angle(base)?.ok_or_else(|| {
            let alternatives = ["rad", "arcsec"].map(|u| format!("{base}_{u}")).to_vec();
            self.missing(&format!("{base}_deg"), alternatives)
        })
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
    /// [`Order::Increasing`] strictly increasing.
    fn numbers(&self, col: Col, order: Order) -> Result<Vec<f64>, Error> {
        let mut out = Vec::with_capacity(self.rows.len());
        let mut previous: Option<f64> = None;
        for (line, record) in &self.rows {
            let text = record.get(col.index).unwrap_or("");
            let x = number(text).map_err(|m| self.cell(*line, col.index, m))?;
            if let (Order::Increasing, Some(p)) = (order, previous) {
                if x <= p {
                    let message = format!("{x} does not increase (previous row {p})");
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
    /// columns (text such as a timestamp) are left out rather than refused.
    fn extras(&self) -> Columns {
        let mut extra = Columns::new();
        for (i, name) in self.header.iter().enumerate() {
            if self.used[i] || name.is_empty() {
                continue;
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
        extra
    }
}

#[derive(Clone, Copy)]
enum Order {
    Any,
    Increasing,
}

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
