//! Universal File Format (UFF, "universal files" of SDRC I-DEAS) datasets 58 and 58b,
//! "Function at Nodal DOF": the time responses, spectra and frequency response
//! functions that modal and drive-test systems export.
//!
//! Source: the dataset 58 description (records 1-12, Addendum B's eight data layouts)
//! and UC-SDRL's "Binary 58 universal file format", as reproduced in pyuff
//! (github ladisk/pyuff, `pyuff/datasets/dataset_58.py`, MIT), whose reader showed the
//! quirks of real files; this reader is written from the description, not translated.
//!
//! A file is a sequence of datasets, each between two lines `    -1`, the first line
//! after the opening `-1` giving the dataset's number. Each dataset 58 becomes one
//! [`Channel`]; datasets of other numbers (151 header, 164 units, 2411 nodes…) are
//! skipped with a note naming the number and the line (a binary one, `NNNb`, by the
//! byte count of its ID line). A file without a dataset 58 is an error.
//!
//! What a channel takes from a dataset:
//! - **name**: ID line 1 (record 1) without the blanks around it; when it is blank or
//!   `NONE` (the description's word for an unused ID line), `resp NODE:DIR / ref
//!   NODE:DIR` from record 6, directions written `S` (scalar), `+X`, `-Y`, `+Z` for
//!   translations and `+RX`, `-RZ`… for rotations. A name already given in the file
//!   gets ` #2`, ` #3`… from its second occurrence on, in the order of the file.
//! - **unit**: record 9's units label (the ordinate, or its numerator), over record
//!   10's (the denominator) when that is given: `m/N`; `NONE` counts as not given.
//! - **abscissa**: even spacing (record 7 field 3 = 1) is
//!   [`Abscissa::Uniform`](super::Abscissa::Uniform) from record 7's minimum and
//!   increment, uneven spacing [`Abscissa::Values`](super::Abscissa::Values) from the
//!   values stored with each point; its unit is record 8's units label, or, when
//!   that is blank or `NONE` (pyuff's default), the one record 8's specific data type
//!   implies (17 time: `s`, 18 frequency: `Hz`), with a note.
//! - **samples**: data types 2 and 4 (real) are
//!   [`Samples::Real`](super::Samples::Real), 5 and 6 (complex)
//!   [`Samples::Complex`](super::Samples::Complex); single precision is read from the
//!   file's decimal text or `f32` bits and held as the nearest `f64`.
//! - **note**: one per channel, `NAME: dataset 58 at line L, function type 4
//!   (frequency response function), response 1:+Z, reference 1:+Z, complex
//!   double-precision ordinate`, with the entity name in brackets after a node when
//!   record 6 gives one.
//!
//! Header text (ID lines, entity names, labels) is UTF-8 when it is valid UTF-8 and
//! Latin-1 otherwise (`g²/Hz` with `²` as byte 0xB2, which pyuff shows as U+FFFD),
//! and its columns count characters, as the writers counted them.
//!
//! What real files do, and is read: numbers that run together in their fixed-width
//! fields (`-1.23456E+000-2.34567E+000`, read by the columns of `6E13.5`, `4E20.12`,
//! `2(E13.5,E20.12)`, `E13.5,2E20.12`); Fortran's `D` exponents and three-digit
//! exponents without their letter (`1.23456-100`); data lines not all filled, or
//! padded with blanks. What real files do against the description, and is read and
//! told in a note: data lines that ignore the columns (read between blanks); in 58b,
//! line ends between the binary data and the closing `-1`, and an ID line byte count
//! that record 7 contradicts (record 7 is read).
//!
//! Errors name the file and the line, or in a 58b binary block the byte offset; a
//! declared size is checked against what is left of the file before anything is
//! allocated. The file is read through a buffer, its numbers going straight into the
//! channel's columns.

mod ascii_data;
mod binary_data;
mod binary_id;
mod channel;
mod columns;
mod fields;
mod header;
mod lines;
mod number;
#[cfg(test)]
mod tests;

use std::io::{BufRead, BufReader};
use std::path::Path;

use self::binary_id::BinaryLayout;
use self::channel::Names;
use self::columns::Tolerated;
use self::header::Header58;
use self::lines::{excerpt, is_blank, is_delimiter, LineReader};
use super::{Channel, FormatError, Location, Recording};

/// The format's name in a [`Recording`].
pub const FORMAT: &str = "uff58";

/// A problem at a place of the file; [`read`] adds the file's path.
#[derive(Debug)]
struct Fault {
    location: Location,
    message: String,
}

impl Fault {
    fn line(line: usize, message: impl Into<String>) -> Fault {
        Fault {
            location: Location::Line(line),
            message: message.into(),
        }
    }

    fn byte(offset: u64, message: impl Into<String>) -> Fault {
        Fault {
            location: Location::Byte(offset),
            message: message.into(),
        }
    }

    fn file(message: impl Into<String>) -> Fault {
        Fault {
            location: Location::File,
            message: message.into(),
        }
    }

    fn into_error(self, path: &Path) -> FormatError {
        FormatError::new(path, self.location, self.message)
    }
}

/// The format as `--format` names it and [`super::detect`] recognises it.
pub static DEFINITION: super::format::Definition = super::format::Definition {
    name: "uff",
    sniff: |head| sniff(head.bytes),
    read,
};

/// Reads the datasets 58 and 58b of a universal file as channels.
pub fn read(path: &Path) -> Result<Recording, FormatError> {
    let file = crate::io::open_input(path)
        .map_err(|e| FormatError::new(path, Location::File, format!("cannot open: {e}")))?;
    let len = file
        .metadata()
        .map_err(|e| FormatError::new(path, Location::File, format!("cannot read its size: {e}")))?
        .len();
    let mut lines = LineReader::new(BufReader::with_capacity(1 << 16, file), len);
    read_datasets(&mut lines).map_err(|fault| fault.into_error(path))
}

/// True when `head`, the first bytes of a file, starts as a universal file: a line
/// `-1` (blank lines before it allowed) and a line starting with a dataset number,
/// `58`, `58b`, `151`…
pub fn sniff(head: &[u8]) -> bool {
    let head = head.strip_prefix("\u{feff}".as_bytes()).unwrap_or(head);
    let mut lines = head.split(|&b| b == b'\n').skip_while(|l| is_blank(l));
    let (Some(first), Some(second)) = (lines.next(), lines.next()) else {
        return false;
    };
    is_delimiter(first) && dataset_number(second).is_some()
}

/// The dataset number at the start of a dataset's ID line and whether a `b` (binary)
/// follows it: `    58b     1 …` is (58, true).
fn dataset_number(text: &[u8]) -> Option<(u32, bool)> {
    let text = text.trim_ascii_start();
    let digits = text.iter().take_while(|b| b.is_ascii_digit()).count();
    let number = std::str::from_utf8(&text[..digits]).ok()?.parse().ok()?;
    match text.get(digits) {
        None => Some((number, false)),
        Some(b'b' | b'B') => Some((number, true)),
        Some(b) if b.is_ascii_whitespace() => Some((number, false)),
        Some(_) => None,
    }
}

/// What the datasets of a file have given so far.
#[derive(Default)]
struct Collected {
    channels: Vec<Channel>,
    notes: Vec<String>,
    names: Names,
    /// (number, line) of each dataset skipped.
    skipped: Vec<(u32, usize)>,
    tolerated: Vec<(String, Tolerated)>,
}

/// Reads dataset after dataset to the end of the file.
fn read_datasets<R: BufRead>(lines: &mut LineReader<R>) -> Result<Recording, Fault> {
    let mut collected = Collected::default();
    while let Some(start) = next_dataset(lines)? {
        let (number, binary) = dataset_id(lines, start)?;
        let layout = if binary {
            Some(binary_id::binary_layout(lines.text(), lines.line())?)
        } else {
            None
        };
        if number == 58 {
            read_dataset58(lines, start, layout, &mut collected)?;
        } else {
            skip_dataset(lines, start, number, layout)?;
            collected.skipped.push((number, start));
        }
    }
    finish(collected)
}

/// Advances to the `-1` opening the next dataset (blank lines before it skipped) and
/// gives its line; `None` at the end of the file.
fn next_dataset<R: BufRead>(lines: &mut LineReader<R>) -> Result<Option<usize>, Fault> {
    while lines.advance()? {
        if is_delimiter(lines.text()) {
            return Ok(Some(lines.line()));
        }
        if !is_blank(lines.text()) {
            let hint = if dataset_number(lines.text()).is_some() {
                " (a dataset number: did the dataset before lack its closing -1?)"
            } else {
                ""
            };
            return Err(Fault::line(
                lines.line(),
                format!(
                    "{} where a -1 opening a dataset should be{hint}",
                    excerpt(lines.text())
                ),
            ));
        }
    }
    Ok(None)
}

/// Reads the ID line after the `-1` on line `start`: the dataset number and whether it
/// is binary.
fn dataset_id<R: BufRead>(lines: &mut LineReader<R>, start: usize) -> Result<(u32, bool), Fault> {
    if !lines.advance()? {
        return Err(Fault::line(
            start,
            "the file ends after the -1 opening a dataset, before its number",
        ));
    }
    dataset_number(lines.text()).ok_or_else(|| {
        Fault::line(
            lines.line(),
            format!(
                "{} where the number of the dataset opened at line {start} should be",
                excerpt(lines.text())
            ),
        )
    })
}

/// Reads a dataset 58 (`layout` given for 58b) into `collected`.
fn read_dataset58<R: BufRead>(
    lines: &mut LineReader<R>,
    start: usize,
    layout: Option<BinaryLayout>,
    collected: &mut Collected,
) -> Result<(), Fault> {
    if let Some(layout) = &layout {
        binary_id::check_layout(layout, lines.line())?;
    }
    let header = header::read_header(lines, start)?;
    let (columns, tolerated) = match &layout {
        Some(layout) => binary_data::read_values(lines, &header, layout, start)?,
        None => ascii_data::read_values(lines, &header, start)?,
    };
    let columns = columns.into_columns();
    check_abscissae(&header, &columns, start)?;
    let name = collected.names.unique(&channel::base_name(&header));
    collected
        .notes
        .push(channel::note(&name, &header, layout.is_some(), start));
    if let (_, Some(note)) = channel::abscissa_unit(&header.abscissa) {
        collected.notes.push(format!("{name}: {note}"));
    }
    if tolerated != Tolerated::default() {
        collected.tolerated.push((name.clone(), tolerated));
    }
    collected
        .channels
        .push(channel::channel(name, &header, columns));
    Ok(())
}

/// An uneven abscissa (the first column) must be finite: a NaN or an overflowed
/// frequency or time cannot place its sample. The ordinates may hold NaN (a writer's
/// missing value); what uses a channel decides.
fn check_abscissae(header: &Header58, columns: &[Vec<f64>], start: usize) -> Result<(), Fault> {
    if header.form.even {
        return Ok(());
    }
    let Some((k, v)) = columns
        .first()
        .and_then(|c| c.iter().enumerate().find(|(_, v)| !v.is_finite()))
    else {
        return Ok(());
    };
    Err(Fault::line(
        start,
        format!(
            "the abscissa of point {} of the dataset opened here is {v}, not a finite number",
            k + 1
        ),
    ))
}

/// Skips a dataset of another number through its closing `-1`: line by line, or for a
/// binary one by its ID line's ASCII lines and bytes.
fn skip_dataset<R: BufRead>(
    lines: &mut LineReader<R>,
    start: usize,
    number: u32,
    layout: Option<BinaryLayout>,
) -> Result<(), Fault> {
    let unclosed = |lines: &LineReader<R>| {
        Fault::line(
            lines.line(),
            format!(
                "the file ends without the -1 closing the dataset {number} begun at line {start}"
            ),
        )
    };
    if let Some(layout) = layout {
        for _ in 0..layout.ascii_lines {
            if !lines.advance()? {
                return Err(unclosed(lines));
            }
        }
        if layout.bytes > lines.remaining() {
            return Err(Fault::byte(
                lines.offset(),
                format!(
                    "the dataset {number}b begun at line {start} declares {} binary bytes, and {} follow",
                    layout.bytes,
                    lines.remaining()
                ),
            ));
        }
        lines.take_block(layout.bytes, |_| {})?;
    }
    while lines.advance()? {
        if is_delimiter(lines.text()) {
            return Ok(());
        }
    }
    Err(unclosed(lines))
}

/// The recording, with the notes on skipped datasets and tolerated quirks; a file
/// without a dataset 58 is a fault.
fn finish(collected: Collected) -> Result<Recording, Fault> {
    let Collected {
        channels,
        mut notes,
        skipped,
        tolerated,
        ..
    } = collected;
    if channels.is_empty() {
        return Err(Fault::file(no_dataset58(&skipped)));
    }
    for (number, line) in &skipped {
        notes.push(format!(
            "dataset {number} at line {line} skipped (not a dataset 58, function at nodal DOF)"
        ));
    }
    for (name, t) in &tolerated {
        notes.extend(tolerated_notes(name, t));
    }
    Ok(Recording {
        format: FORMAT,
        channels,
        notes,
        groups: Vec::new(),
    })
}

/// The message for a file without a dataset 58.
fn no_dataset58(skipped: &[(u32, usize)]) -> String {
    if skipped.is_empty() {
        return "no UFF dataset: the file is empty".to_string();
    }
    let listed: Vec<String> = skipped
        .iter()
        .take(10)
        .map(|(n, line)| format!("{n} (line {line})"))
        .collect();
    let more = if skipped.len() > 10 { ", …" } else { "" };
    format!(
        "no dataset 58 (function at nodal DOF) among its {} datasets: {}{more}",
        skipped.len(),
        listed.join(", ")
    )
}

/// The notes on what a dataset's data did that the description does not.
fn tolerated_notes(name: &str, t: &Tolerated) -> Vec<String> {
    let mut notes = Vec::new();
    if let Some((n, first)) = t.free_format_lines {
        notes.push(format!(
            "{name}: {n} data line(s) not in the fixed-width columns of the format, read as blank-separated numbers (first: line {first})"
        ));
    }
    if let Some(offset) = t.line_end_before_closing {
        notes.push(format!(
            "{name}: a line end between the binary data and the closing -1 (byte {offset}), skipped"
        ));
    }
    if let Some((declared, read)) = t.byte_count {
        notes.push(format!(
            "{name}: the 58b ID line declares {declared} bytes, record 7 {read}; read {read}"
        ));
    }
    notes
}
