//! The header of a TwinCAT Scope CSV export: the separator, the channel layout (which
//! column is whose time and whose values), names, units, sample times and the scaling
//! each channel declares.
//!
//! The file opens with `Name`, the scope's name, `File`, `Starttime of export` and
//! `Endtime of export`; after blank lines comes the channel block, one row per
//! property. Each property row repeats its key before every group of channels that
//! share a time column (`Name⇥t1⇥Name⇥a⇥b` means: column 0 is the time of channel
//! `t1` in column 1, column 2 the time of `a` and `b` in columns 3 and 4). A blank line
//! (or, without one, the first row of numbers) ends the block.

use std::io::BufRead;
use std::path::Path;

use super::properties::{self, Property};
use crate::io::formats::text::{Encoding, Lines};
use crate::io::formats::{FormatError, Location};

/// How many lines may precede the channel block's `Name` row.
const MAX_PREAMBLE: usize = 1000;

/// What the header says about the columns of the data rows.
#[derive(Debug)]
pub(super) struct Header {
    pub sep: u8,
    /// Columns of a full data row.
    pub width: usize,
    /// In column order.
    pub groups: Vec<Group>,
    /// In column order.
    pub channels: Vec<ChannelHead>,
    pub notes: Vec<String>,
}

/// Channels sharing one time column.
#[derive(Debug)]
pub(super) struct Group {
    pub time_col: usize,
    /// Indices into [`Header::channels`].
    pub channels: std::ops::Range<usize>,
}

/// One channel's header properties.
#[derive(Debug)]
pub(super) struct ChannelHead {
    pub name: String,
    pub unit: String,
    pub value_col: usize,
    pub group: usize,
    /// `SampleTime[ms]`, when the file gives one per channel.
    pub sample_time_ms: Option<f64>,
}

/// A data row the header block ran into without a blank line before it.
pub(super) struct PendingRow {
    pub number: usize,
    pub bytes: Vec<u8>,
    pub terminated: bool,
}

/// The separator: the character after `Name` on the first line, as pytcs finds it
/// (`ScopeFile._read_header`). Any ASCII character that cannot start or continue a
/// name or a number may be one (TwinCAT offers tab, space, colon, semicolon, comma
/// and a custom character).
pub(super) fn separator_of(first_line: &[u8]) -> Option<u8> {
    let rest = first_line.strip_prefix(b"Name")?;
    rest.first().copied().filter(|&c| is_separator(c))
}

fn is_separator(c: u8) -> bool {
    c.is_ascii() && !c.is_ascii_alphanumeric() && !b"\"'.-+_()[]\r\n".contains(&c)
}

/// Reads the header, leaving `lines` at the line after it.
pub(super) fn read<R: BufRead>(
    lines: &mut Lines<R>,
    path: &Path,
) -> Result<(Header, Option<PendingRow>), FormatError> {
    let at = |n: usize, m: String| FormatError::new(path, Location::Line(n), m);
    let line_error = |n: usize, e: crate::io::formats::text::LineError| at(n, e.to_string());
    let first = match lines.next_line().map_err(|e| line_error(1, e))? {
        Some(l) => l,
        None => return Err(FormatError::new(path, Location::File, "the file is empty")),
    };
    let sep = separator_of(first.bytes).ok_or_else(|| {
        at(
            1,
            "not a TwinCAT Scope export: the first line is not `Name` and a separator".into(),
        )
    })?;
    let (rows, pending) = block_rows(lines, sep, path)?;
    let encoding = Encoding::of(rows.iter().map(|(_, b)| &b[..]));
    let texts: Vec<(usize, String)> = rows.iter().map(|(n, b)| (*n, encoding.decode(b))).collect();
    let props: Vec<Property> = texts
        .iter()
        .map(|(n, t)| properties::parse(*n, t, sep))
        .collect();
    let mut header = build(&props, sep).map_err(|(n, m)| at(n, m))?;
    if encoding == Encoding::Windows1252 {
        header.notes.push(
            "the header is not UTF-8: read as Windows-1252 (ANSI on a western-European Windows)"
                .into(),
        );
    }
    Ok((header, pending))
}

type Rows = Vec<(usize, Vec<u8>)>;

/// The raw lines of the channel block, from its `Name` row to the blank line ending it,
/// and the data row that ends it instead when there is no blank line.
fn block_rows<R: BufRead>(
    lines: &mut Lines<R>,
    sep: u8,
    path: &Path,
) -> Result<(Rows, Option<PendingRow>), FormatError> {
    let at = |n: usize, m: String| FormatError::new(path, Location::Line(n), m);
    let mut rows: Rows = Vec::new();
    loop {
        let n = lines.number() + 1;
        let Some(line) = lines.next_line().map_err(|e| at(n, e.to_string()))? else {
            let what = if rows.is_empty() {
                "the file ends before the channel header (a row `Name…` after the first line)"
            } else {
                "the file ends inside the channel header: no samples"
            };
            return Err(at(lines.number(), what.into()));
        };
        if rows.is_empty() {
            if separator_of(line.bytes) == Some(sep) {
                rows.push((line.number, line.bytes.to_vec()));
            } else if line.number > MAX_PREAMBLE {
                return Err(at(
                    line.number,
                    format!("no channel header (a row `Name…`) in the first {MAX_PREAMBLE} lines"),
                ));
            }
            continue;
        }
        if is_blank(line.bytes, sep) {
            return Ok((rows, None));
        }
        if starts_with_number(line.bytes, sep) {
            let pending = PendingRow {
                number: line.number,
                bytes: line.bytes.to_vec(),
                terminated: line.terminated,
            };
            return Ok((rows, Some(pending)));
        }
        rows.push((line.number, line.bytes.to_vec()));
    }
}

/// A line of nothing but white space and separators.
pub(super) fn is_blank(bytes: &[u8], sep: u8) -> bool {
    bytes.iter().all(|&b| b.is_ascii_whitespace() || b == sep)
}

/// Whether a line's first cell is a number (a data row, not a property row).
pub(super) fn starts_with_number(bytes: &[u8], sep: u8) -> bool {
    let cell = bytes.split(|&b| b == sep).next().unwrap_or(&[]);
    crate::io::formats::text::parse_number(cell, sep != b',').is_some()
}

/// The header from its property rows: layout first, then what each channel declares.
fn build(props: &[Property], sep: u8) -> Result<Header, (usize, String)> {
    let names = props
        .iter()
        .find(|p| p.key == "Name")
        .expect("the block starts with its Name row");
    let counts = properties::layout(names, props, sep)?;
    let name_cells = properties::fit(names, &counts, sep).map_err(|m| (names.line, m))?;
    let mut notes = Vec::new();
    let units = properties::units(props, &counts, sep, &mut notes)?;
    let sample_time_keys = ["SampleTime[ms]", "SampleTime"];
    let sample_times = properties::numbers(props, &sample_time_keys, &counts, sep, &mut notes);
    properties::note_scaling(props, &counts, sep, &name_cells, &mut notes);
    properties::note_unused(props, &mut notes);

    let mut groups = Vec::with_capacity(counts.len());
    let mut channels = Vec::with_capacity(name_cells.len());
    let mut col = 0;
    for (g, &count) in counts.iter().enumerate() {
        let first = channels.len();
        let time_col = col;
        col += 1;
        for _ in 0..count {
            let i = channels.len();
            channels.push(ChannelHead {
                name: name_cells[i].to_string(),
                unit: units[i].clone(),
                value_col: col,
                group: g,
                sample_time_ms: sample_times.as_ref().map(|s| s[i]),
            });
            col += 1;
        }
        groups.push(Group {
            time_col,
            channels: first..channels.len(),
        });
    }
    Ok(Header {
        sep,
        width: col,
        groups,
        channels,
        notes,
    })
}
