//! Beckhoff TwinCAT 3 Scope View CSV exports (`format: "twincat-scope"`).
//!
//! # The file
//!
//! As the TC3 Scope View's exporter writes it (Beckhoff Infosys, TE13xx "Export in
//! csv"; the layout as pytcs 0.2.2 `ScopeFile._read_header` reads it, BSD-3): a file
//! block (`Name`, `File`, `Starttime of export`, `Endtime of export`), blank lines, a
//! channel block with one row per property (`Name`, `SymbolComment`, `Data-Type`,
//! `SampleTime[ms]`, … `Offset`, `ScaleFactor`, `BitMask`, `Unit`, `Unit ScaleFactor`,
//! `Unit Offset`), a blank line, then one row per sample index. Every property row
//! repeats its key before each group of channels sharing a time column, which is how
//! the columns are told apart. Optionally a last line `EOF`.
//!
//! Export options read (all those of the shared sample exports, pytcs `tests/data`, and
//! of the colon- and comma-separated and unsorted shared-time exports the tests make
//! from them):
//! - **Separator**: the character after `Name` on the first line: tab, space, colon,
//!   semicolon, comma or another one. A space- (or comma-) separated export whose names
//!   contain that character cannot be split and is refused with the line; units of a
//!   space-separated export are split after each word in parentheses (`V (Voltage)`),
//!   as TwinCAT writes them, with a note.
//! - **Decimal mark**: a point, or a comma when the comma is not the separator, in any
//!   cell. `SampleTime[ms]` is written with a comma in every sample export, whatever
//!   the decimal mark of the data, so the header is read the same way.
//! - **Time columns**: one per channel, or one per run of channels with the same sample
//!   time ("ExcludeDoubleTimestamp"); sorted or not; channels of different sample times
//!   and hence lengths (the shorter end with blank cells ` ` or with the row cut short).
//! - **EOF marker**: ends the data; lines after it are noted, not read.
//! - Line ends LF or CR LF; a UTF-8 byte-order mark is dropped.
//!
//! Not read: "Full Timestamp" exports (absolute Windows file times instead of ms since
//! the start; refused with the line), "Timelines: None" (no time columns; the layout
//! does not match and the file is refused), array channels, trigger and marker tables.
//!
//! # What a channel holds
//!
//! - **Name** and **unit** as the file spells them (UTF-8: TwinCAT 3 writes UTF-8, as
//!   the sample exports' `test_special([{äöü!?ß$²}])` shows; a header that is not
//!   valid UTF-8 is read as Windows-1252, with a note). A unit `(None)` or empty is "";
//!   `V (Voltage)` is kept whole (pytcs keeps only `V`). Channels without a name are
//!   skipped with a note, as pytcs does.
//! - **Abscissa**: [`Abscissa::Values`], the channel's own time column converted from
//!   milliseconds to seconds. The time columns are milliseconds since the export's
//!   first sample (Infosys: "otherwise the timestamps are stored as milliseconds
//!   relative to the first data point"; `SampleTime[ms]`; in the sample exports a 0.2 ms
//!   channel steps 0, 0.2, 0.4). Values rather than `Uniform` because a time column may
//!   start before zero (`func_freesample` at −3 ms) and an exported time column is what
//!   the file states; a note tells when a column's mean step disagrees with the
//!   header's `SampleTime[ms]`.
//! - **Samples**: the numbers as written. TwinCAT applies a channel's scaling,
//!   `y = ScaleFactor·x + Offset` and then `Unit ScaleFactor·y + Unit Offset`, when it
//!   exports with "Scale values before export" (Infosys: "convert the values with the
//!   scale factor and offset configured on the channel"). The file does not record that
//!   option: of the four shared exports of one recording, three hold `func_scaled` =
//!   1 − x (ScaleFactor −1, Offset 1) and `func_units_scaled` = 10 − 10x (Unit
//!   ScaleFactor −10, Unit Offset 10), while `-default.csv`, with the same header, holds
//!   x for both. pytcs applies none of the factors. So neither does rtid: applying them
//!   would scale the three scaled exports twice; a note names every channel declaring a
//!   scaling.
//! - **first_line**: the line of the first data row (every channel starts there; sample
//!   i is on line `first_line + i`).

use std::io::BufReader;
use std::path::Path;

use super::{Abscissa, Channel, FormatError, Location, Recording, Samples};

mod data;
mod header;
mod properties;

#[cfg(test)]
mod tests;

/// Whether a first line is probably a TwinCAT Scope export's: `Name`, a separator and
/// the scope's name (one cell, quoted if it holds the separator).
pub fn sniff(first_line: &str) -> bool {
    let line = first_line.trim_start_matches('\u{feff}');
    let line = line.trim_end_matches(['\r', '\n']);
    let Some(sep) = header::separator_of(line.as_bytes()) else {
        return false;
    };
    let sep = char::from(sep);
    let value = &line[5..];
    let value = value.strip_suffix(sep).unwrap_or(value);
    let quoted = value.len() >= 2 && value.starts_with('"') && value.ends_with('"');
    !value.trim().is_empty() && (quoted || !value.contains(sep))
}

/// The format as `--format` names it and [`super::detect`] recognises it.
pub static DEFINITION: super::format::Definition = super::format::Definition {
    name: "twincat-scope",
    sniff: |head| sniff(head.first_line),
    read,
};

/// Reads a TwinCAT 3 Scope View CSV export.
pub fn read(path: &Path) -> Result<Recording, FormatError> {
    let file = crate::io::open_input(path)
        .map_err(|e| FormatError::new(path, Location::File, format!("cannot open: {e}")))?;
    let mut lines = super::text::Lines::new(BufReader::with_capacity(1 << 16, file));
    let (header, pending) = header::read(&mut lines, path)?;
    let mut columns = data::Columns::new(&header);
    let (first_line, row_notes) = data::read_rows(&mut lines, pending, &mut columns, path)?;
    let series = columns.finish();

    let mut notes = header.notes.clone();
    notes.extend(row_notes);
    let mut channels = Vec::with_capacity(series.len());
    for (head, (times, values)) in header.channels.iter().zip(series) {
        if head.name.trim().is_empty() {
            notes.push(format!(
                "column {} has no name: skipped",
                head.value_col + 1
            ));
            continue;
        }
        if values.is_empty() {
            let msg = format!("channel `{}` has no sample on its first row", head.name);
            return Err(FormatError::new(path, Location::Line(first_line), msg));
        }
        if let Some(note) = sample_time_note(head, &times) {
            notes.push(note);
        }
        channels.push(Channel {
            name: head.name.clone(),
            unit: head.unit.clone(),
            abscissa: Abscissa::Values {
                values: times,
                unit: "s".into(),
            },
            samples: Samples::Real(values),
            first_line: Some(first_line),
        });
    }
    Ok(Recording {
        format: "twincat-scope",
        channels,
        notes,
        groups: Vec::new(),
    })
}

/// A note when a channel's mean time step (s) is not its header's `SampleTime[ms]`.
fn sample_time_note(head: &header::ChannelHead, times: &[f64]) -> Option<String> {
    let declared = head.sample_time_ms?;
    let (first, last) = (times.first()?, times.last()?);
    if times.len() < 2 {
        return None;
    }
    let step_ms = (last - first) / (times.len() - 1) as f64 * 1000.0;
    ((step_ms - declared).abs() > 1e-6 * declared.abs()).then(|| {
        format!(
            "`{}`: the time column steps {step_ms} ms on average, the header's SampleTime is {declared} ms",
            head.name
        )
    })
}
