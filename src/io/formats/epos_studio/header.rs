//! The header of an EPOS Studio data-recorder export: `Key:;value…` lines, then the
//! row of column names and the row of units.

use std::io::BufRead;
use std::path::Path;

use super::cells::{split, Split};
use crate::io::formats::text::{Encoding, Lines};
use crate::io::formats::{FormatError, Location};

/// How many `Key:` lines may precede the names.
const MAX_HEADER: usize = 200;

/// What the header declares.
#[derive(Debug)]
pub(super) struct Header {
    /// The channels, without the time column.
    pub names: Vec<String>,
    pub units: Vec<String>,
    /// Units of the time column per second (`ms`: 1000).
    pub per_second: f64,
    /// `Recorded samples:`, with its line.
    pub recorded: Option<(usize, u64)>,
    /// `Sampling period:` in ms, with its line.
    pub period_ms: Option<(usize, f64)>,
    /// The line of the units row.
    pub last_line: usize,
}

/// Lines a spreadsheet left marks on, and what it noted by hand.
#[derive(Debug, Default)]
pub(super) struct Quirks {
    stray_lines: usize,
    first: usize,
    last: usize,
    pub notes: Vec<String>,
}

impl Quirks {
    pub fn record(&mut self, line: usize, s: &Split) {
        if s.stray.is_none() {
            return;
        }
        self.stray_lines += 1;
        self.last = line;
        if self.first == 0 {
            self.first = line;
        }
        if let Some(text) = s.hand_text() {
            self.notes.push(format!(
                "line {line}: text after the last value, not read: `{text}`"
            ));
        }
    }

    /// The notes, with one for all the stray cells.
    pub fn into_notes(mut self) -> Vec<String> {
        if self.stray_lines > 0 {
            self.notes.insert(
                0,
                format!(
                    "{} lines ({}–{}) end with stray spreadsheet cells (`,,`): ignored",
                    self.stray_lines, self.first, self.last
                ),
            );
        }
        self.notes
    }
}

/// Reads the header, leaving `lines` at the first data row.
pub(super) fn read<R: BufRead>(
    lines: &mut Lines<R>,
    path: &Path,
    quirks: &mut Quirks,
    notes: &mut Vec<String>,
) -> Result<Header, FormatError> {
    let at = |n: usize, m: String| FormatError::new(path, Location::Line(n), m);
    let mut recorded = None;
    let mut period_ms = None;
    let mut unused: Vec<String> = Vec::new();
    let mut ansi = false;
    let mut names: Option<Vec<String>> = None;
    loop {
        let n = lines.number() + 1;
        let line = lines.next_line().map_err(|e| at(n, e.to_string()))?;
        let Some(line) = line else {
            let msg = "the file ends inside the header: no samples";
            return Err(at(lines.number().max(1), msg.into()));
        };
        let (number, text) = (line.number, decode(line.bytes, &mut ansi));
        let s = split(&text);
        quirks.record(number, &s);
        let cells: Vec<&str> = s.cells().collect();
        if let Some(names) = names.take() {
            let header =
                units_row(number, &cells, names, recorded, period_ms).map_err(|m| at(number, m))?;
            note_header(notes, &unused, ansi);
            return Ok(header);
        }
        let key = cells[0];
        if number == 1 && !key.ends_with(':') {
            let msg = "not an EPOS Studio export: the first line is not `Key:;value`";
            return Err(at(1, msg.into()));
        }
        if !key.ends_with(':') {
            names = Some(cells[1..].iter().map(|c| c.to_string()).collect());
            continue;
        }
        if number > MAX_HEADER {
            return Err(at(
                number,
                format!("no column names in the first {MAX_HEADER} lines"),
            ));
        }
        let value = cells.get(1).map_or("", |v| v.trim());
        let unreadable = || format!("line {number}: `{key}` `{value}` is not a number: not used");
        match key {
            "Recorded samples:" => match value.parse() {
                Ok(v) => recorded = Some((number, v)),
                Err(_) => notes.push(unreadable()),
            },
            "Sampling period:" => match value.parse() {
                Ok(v) => period_ms = Some((number, v)),
                Err(_) => notes.push(unreadable()),
            },
            _ => {
                let key = key.trim_end_matches(':').to_string();
                if !unused.contains(&key) {
                    unused.push(key);
                }
            }
        }
    }
}

/// The header from the units row that ends it.
fn units_row(
    number: usize,
    cells: &[&str],
    names: Vec<String>,
    recorded: Option<(usize, u64)>,
    period_ms: Option<(usize, f64)>,
) -> Result<Header, String> {
    if names.is_empty() {
        return Err("the row before names no channel".into());
    }
    if cells.len() != names.len() + 1 {
        return Err(format!(
            "{} units for a time column and {} channels",
            cells.len(),
            names.len()
        ));
    }
    let per_second = match cells[0].trim() {
        "ms" => 1e3,
        "s" => 1.0,
        "µs" | "us" => 1e6,
        other => {
            return Err(format!(
                "the time column's unit `{other}` is not s, ms or µs"
            ))
        }
    };
    Ok(Header {
        names,
        units: cells[1..].iter().map(|u| u.trim().to_string()).collect(),
        per_second,
        recorded,
        period_ms,
        last_line: number,
    })
}

/// A header line as text: UTF-8, else Windows-1252 (and `ansi` set).
fn decode(bytes: &[u8], ansi: &mut bool) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => {
            *ansi = true;
            Encoding::Windows1252.decode(bytes)
        }
    }
}

fn note_header(notes: &mut Vec<String>, unused: &[String], ansi: bool) {
    if ansi {
        notes.push("header lines that are not UTF-8 read as Windows-1252".into());
    }
    if !unused.is_empty() {
        let scale = if unused.iter().any(|k| k == "Scale") {
            " (`Scale:` is the plot's display range, not a scaling of the values)"
        } else {
            ""
        };
        notes.push(format!(
            "header lines not used: {}{scale}",
            unused.join(", ")
        ));
    }
}
