//! The data rows of a TwinCAT Scope CSV export, streamed into one vector per column.
//!
//! Every channel starts on the first data row. A channel that ends before others (a
//! longer sample time, or a shorter record) leaves its cells blank (` `) or, when its
//! columns are the last of the row, leaves them out. A cell with a value after its
//! column has ended, a value without a time in its row, a cell that is not a number,
//! or a last row without a line end (a file cut off) is an error naming the line.

use std::io::BufRead;
use std::path::Path;

use super::header::{is_blank, starts_with_number, Header, PendingRow};
use crate::io::formats::text::{parse_number, Lines};
use crate::io::formats::{FormatError, Location};

/// A time above this many milliseconds (317 years) is a Windows file time (export
/// option "Full Timestamp": 100 ns ticks since 1601), not a time since the export's
/// first sample.
const MAX_RELATIVE_MS: f64 = 1e13;

/// What each column of a data row holds.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Time { group: usize },
    Value { group: usize },
}

/// The samples read so far, per column (times in seconds).
pub(super) struct Columns<'h> {
    header: &'h Header,
    kinds: Vec<Kind>,
    samples: Vec<Vec<f64>>,
    /// The line of each column's first blank cell.
    ended_at: Vec<Option<usize>>,
    /// Scratch: which groups have a time on the current row.
    time_here: Vec<bool>,
}

impl<'h> Columns<'h> {
    pub fn new(header: &'h Header) -> Self {
        let mut kinds = vec![Kind::Time { group: 0 }; header.width];
        for (g, group) in header.groups.iter().enumerate() {
            kinds[group.time_col] = Kind::Time { group: g };
        }
        for c in &header.channels {
            kinds[c.value_col] = Kind::Value { group: c.group };
        }
        Columns {
            header,
            kinds,
            samples: vec![Vec::new(); header.width],
            ended_at: vec![None; header.width],
            time_here: vec![false; header.groups.len()],
        }
    }

    /// Adds one data row. An error names its line: this row's, or for a value after
    /// its column ended, the line of the row that ended it.
    pub fn push_row(&mut self, bytes: &[u8], line: usize) -> Result<(), (usize, String)> {
        let sep = self.header.sep;
        let mut cells = bytes.split(|&b| b == sep);
        for col in 0..self.header.width {
            let cell = cells.next();
            if sep == b' ' && cell.is_some_and(<[u8]>::is_empty) {
                let msg =
                    "an empty cell in a space-separated export: the columns cannot be counted";
                return Err((line, msg.into()));
            }
            let value = match cell {
                None => None,
                Some(c) if c.trim_ascii().is_empty() => None,
                Some(c) => Some(parse_number(c, sep != b',').ok_or_else(|| {
                    let msg = format!(
                        "column {} ({}): `{}` is not a number",
                        col + 1,
                        self.describe(col),
                        String::from_utf8_lossy(c)
                    );
                    (line, msg)
                })?),
            };
            self.take(col, value, line)?;
        }
        if let Some(extra) = cells.find(|c| !c.trim_ascii().is_empty()) {
            let msg = format!(
                "more cells than the header's {} columns (`{}`)",
                self.header.width,
                String::from_utf8_lossy(extra)
            );
            return Err((line, msg));
        }
        Ok(())
    }

    /// One cell: a sample, or the end of its column.
    fn take(&mut self, col: usize, value: Option<f64>, line: usize) -> Result<(), (usize, String)> {
        let Some(x) = value else {
            self.ended_at[col].get_or_insert(line);
            if let Kind::Time { group } = self.kinds[col] {
                self.time_here[group] = false;
            }
            return Ok(());
        };
        if let Some(end) = self.ended_at[col] {
            let msg = format!(
                "column {} ({}) ends on this row (blank or missing) but has a value on line {line} \
                 again: a row with too few cells?",
                col + 1,
                self.describe(col)
            );
            return Err((end, msg));
        }
        let x = match self.kinds[col] {
            Kind::Time { group } => {
                if !x.is_finite() {
                    let msg = format!("column {}: the time {x} ms is not a finite number", col + 1);
                    return Err((line, msg));
                }
                if x.abs() >= MAX_RELATIVE_MS {
                    let msg = format!(
                        "column {}: the time {x} ms is an absolute file time (export option \
                         \"Full Timestamp\"), which is not read: export times relative to the start",
                        col + 1
                    );
                    return Err((line, msg));
                }
                self.time_here[group] = true;
                x / 1000.0
            }
            Kind::Value { group } if !self.time_here[group] => {
                let msg = format!(
                    "column {} ({}) has a value but its time column {} is blank",
                    col + 1,
                    self.describe(col),
                    self.header.groups[group].time_col + 1
                );
                return Err((line, msg));
            }
            Kind::Value { .. } => x,
        };
        self.samples[col].push(x);
        Ok(())
    }

    /// A column named for messages.
    fn describe(&self, col: usize) -> String {
        match self.kinds[col] {
            Kind::Time { group } => {
                let first = self.header.groups[group].channels.start;
                format!("time of `{}`", self.header.channels[first].name)
            }
            Kind::Value { .. } => {
                let c = self.header.channels.iter().find(|c| c.value_col == col);
                format!("`{}`", c.map_or("", |c| c.name.as_str()))
            }
        }
    }

    /// Each channel's times (s) and values, in header order.
    pub fn finish(mut self) -> Vec<(Vec<f64>, Vec<f64>)> {
        let mut out = Vec::with_capacity(self.header.channels.len());
        for group in &self.header.groups {
            let mut times = std::mem::take(&mut self.samples[group.time_col]);
            for i in group.channels.clone() {
                let values = std::mem::take(&mut self.samples[self.header.channels[i].value_col]);
                let t = if i + 1 == group.channels.end {
                    std::mem::take(&mut times)
                } else {
                    times[..values.len()].to_vec()
                };
                out.push((t, values));
            }
        }
        for (t, v) in &mut out {
            t.truncate(v.len());
        }
        out
    }
}

/// Reads the data rows into `columns`; returns the line of the first one and notes.
pub(super) fn read_rows<R: BufRead>(
    lines: &mut Lines<R>,
    pending: Option<PendingRow>,
    columns: &mut Columns,
    path: &Path,
) -> Result<(usize, Vec<String>), FormatError> {
    let sep = columns.header.sep;
    let mut state = RowState::default();
    if let Some(p) = pending {
        state.row(p.number, &p.bytes, p.terminated, sep, columns, path)?;
    }
    loop {
        let n = lines.number() + 1;
        let next = lines
            .next_line()
            .map_err(|e| FormatError::new(path, Location::Line(n), e.to_string()))?;
        let Some(line) = next else { break };
        state.row(line.number, line.bytes, line.terminated, sep, columns, path)?;
    }
    let Some(first) = state.first else {
        return Err(FormatError::new(
            path,
            Location::Line(lines.number()),
            "no samples: the file ends after the channel header",
        ));
    };
    let mut notes = Vec::new();
    if let (Some(eof), Some(after)) = (state.eof, state.after_eof) {
        notes.push(format!(
            "lines {after}… after the EOF marker (line {eof}) not read"
        ));
    }
    Ok((first, notes))
}

/// Where the reader is in the data block.
#[derive(Default)]
struct RowState {
    first: Option<usize>,
    blank: Option<usize>,
    eof: Option<usize>,
    after_eof: Option<usize>,
}

impl RowState {
    fn row(
        &mut self,
        number: usize,
        bytes: &[u8],
        terminated: bool,
        sep: u8,
        columns: &mut Columns,
        path: &Path,
    ) -> Result<(), FormatError> {
        let at = |m: String| FormatError::new(path, Location::Line(number), m);
        if self.eof.is_some() {
            if !is_blank(bytes, sep) {
                self.after_eof.get_or_insert(number);
            }
            return Ok(());
        }
        if bytes.is_empty() || (is_blank(bytes, sep) && self.first.is_none()) {
            if self.first.is_some() {
                self.blank.get_or_insert(number);
            }
            return Ok(());
        }
        if bytes.trim_ascii() == b"EOF" {
            self.eof = Some(number);
            return Ok(());
        }
        if let Some(blank) = self.blank {
            return Err(at(format!("a data row after the empty line {blank}")));
        }
        if self.first.is_none() && !starts_with_number(bytes, sep) {
            let text = String::from_utf8_lossy(&bytes[..bytes.len().min(60)]).into_owned();
            return Err(at(format!(
                "expected the first row of samples, found `{text}`"
            )));
        }
        if !terminated {
            return Err(at(
                "the file ends inside this row (no line end): cut off?".into()
            ));
        }
        columns
            .push_row(bytes, number)
            .map_err(|(n, m)| FormatError::new(path, Location::Line(n), m))?;
        self.first.get_or_insert(number);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::io::formats::text::parse_number;

    #[test]
    fn numbers_with_either_decimal_mark() {
        assert_eq!(parse_number(b"0,2", true), Some(0.2));
        assert_eq!(parse_number(b" -3.5 ", true), Some(-3.5));
        assert_eq!(parse_number(b"0,2", false), None);
        assert_eq!(parse_number(b"1e3", true), Some(1000.0));
        assert!(parse_number(b"NaN", true).is_some_and(f64::is_nan));
        assert_eq!(parse_number(b"12a", true), None);
        assert_eq!(parse_number(b"", true), None);
    }
}
