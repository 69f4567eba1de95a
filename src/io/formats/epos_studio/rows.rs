//! The data rows of an EPOS Studio export: the time, then one value per channel,
//! `;`-separated, one row per sample.

use std::io::BufRead;
use std::path::Path;

use super::cells::split;
use super::header::{Header, Quirks};
use crate::io::formats::text::Lines;
use crate::io::formats::{FormatError, Location};

/// Rows reserved before reading, whatever the header declares.
const MAX_RESERVE: usize = 1 << 16;

/// The samples as written: times in the file's unit.
#[derive(Debug)]
pub(super) struct Table {
    pub first_line: Option<usize>,
    pub last_line: usize,
    pub times: Vec<f64>,
    /// One vector per channel.
    pub values: Vec<Vec<f64>>,
}

/// Reads every data row.
pub(super) fn read<R: BufRead>(
    lines: &mut Lines<R>,
    header: &Header,
    path: &Path,
    quirks: &mut Quirks,
) -> Result<Table, FormatError> {
    let at = |n: usize, m: String| FormatError::new(path, Location::Line(n), m);
    let reserve = header
        .recorded
        .map_or(0, |(_, r)| r)
        .min(MAX_RESERVE as u64) as usize;
    let mut table = Table {
        first_line: None,
        last_line: header.last_line,
        times: Vec::with_capacity(reserve),
        values: vec![Vec::with_capacity(reserve); header.names.len()],
    };
    let mut blank = None;
    loop {
        let n = lines.number() + 1;
        let Some(line) = lines.next_line().map_err(|e| at(n, e.to_string()))? else {
            return Ok(table);
        };
        let number = line.number;
        if line.bytes.trim_ascii().is_empty() {
            blank.get_or_insert(number);
            continue;
        }
        if let Some(b) = blank {
            return Err(at(number, format!("a data row after the empty line {b}")));
        }
        if !line.terminated {
            return Err(at(
                number,
                "the file ends inside this row (no line end): cut off?".into(),
            ));
        }
        let text = String::from_utf8_lossy(line.bytes);
        let s = split(&text);
        quirks.record(number, &s);
        let cells: Vec<&str> = s.cells().collect();
        push_row(&mut table, &cells, header).map_err(|m| at(number, m))?;
        table.first_line.get_or_insert(number);
        table.last_line = number;
    }
}

/// One row's numbers into the table.
fn push_row(table: &mut Table, cells: &[&str], header: &Header) -> Result<(), String> {
    let columns = header.names.len() + 1;
    if cells.len() < columns {
        return Err(format!(
            "{} cells where the header names {columns} columns (the time and {} channels)",
            cells.len(),
            header.names.len()
        ));
    }
    if let Some(extra) = cells[columns..].iter().find(|c| !c.trim().is_empty()) {
        return Err(format!(
            "more cells than the header's {columns} columns (`{extra}`)"
        ));
    }
    let number = |i: usize| {
        let name = if i == 0 { "time" } else { &header.names[i - 1] };
        cells[i]
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                format!(
                    "column {} ({name}): `{}` is not a finite number",
                    i + 1,
                    cells[i]
                )
            })
    };
    let time = number(0)?;
    let row: Vec<f64> = (1..columns).map(number).collect::<Result<_, _>>()?;
    table.times.push(time);
    for (column, x) in table.values.iter_mut().zip(row) {
        column.push(x);
    }
    Ok(())
}
