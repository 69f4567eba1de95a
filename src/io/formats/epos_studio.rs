//! Maxon EPOS Studio data-recorder CSV exports (`format: "epos-studio"`).
//!
//! # The file
//!
//! As EPOS Studio 3.6 writes it (the RViMLab TRO2021-Dynamic-Modelling experiments,
//! commit c3b758b, MIT; Mablekos-Alexiou, da Cruz, Bergeles, IEEE T-RO 37(4), 2021):
//!
//! ```text
//! Date:;2020-07-08 21:24:28
//! Firmware Version:;0x0120;0x6150;0x0000;0x0000
//! …
//! Recorded samples:;500
//! Sampling period:;51.200
//! Scale:;0;True;1.000;10.000;-14.000;-6.000
//! Trigger:;1;0.000000;"Parameter values";"Channel 1";"Rising above value"
//! TriggerAttributes:;1;4;0x30D3;0x01;0.000000
//! ;Velocity actual value averaged;Torque actual value averaged
//! ms;rpm;%
//! 0.000;-10;-32.0
//! 51.200;-10;-32.6
//! ```
//!
//! `Key:;value…` lines (any number, any keys; the first line must be one), the row of
//! column names (its first cell, the time's, empty), the row of units, then one row per
//! sample. CR LF line ends, decimal point, ASCII (a header line that is not UTF-8 is read
//! as Windows-1252, with a note).
//!
//! # What is read, and what was checked
//!
//! - **Channels**: every column after the time, named and with the unit as the file
//!   spells them (`Velocity actual value averaged`, `rpm`; `Torque actual value
//!   averaged`, `%` — of the motor's nominal torque, which the file does not give). The
//!   values as written: the authors' `getEposData.m` negates both channels (the
//!   recorder's sign convention) and converts units; rtid leaves that to the user.
//! - **Abscissa**: [`Abscissa::Values`], the time column converted to seconds (its unit
//!   `ms`, `s` or `µs` is the units row's first cell).
//! - **`Sampling period:` is in milliseconds**, the unit of the time column: in all 66
//!   exports of the set's drives 1 and 2 the time column steps by the header's value, to
//!   0.001 ms (`51.200` → 0, 51.2, 102.4 ms; 500 samples of 51.2 ms make the 25.6 s of a
//!   10 rpm run). The authors' reader reads it as microseconds only after dropping the decimal
//!   point (`regexp(…, '\d*')` turns `51.200` into 51200, then `/10^6` s): the same
//!   51.2 ms. A time that strays from `first + i·period` by more than the 3-decimal
//!   rounding plus one single-precision step (the recorder's own time stamps drift so:
//!   `driveNo2/start_stop/50.csv` runs 0.001 ms early from line 484) gets a note naming
//!   its line; the times are returned as written.
//! - **`Recorded samples:`** against the rows found: fewer rows is an error naming the
//!   header line (the file was cut, and a recording without its end is not what the
//!   recorder made); more rows is a note.
//! - **Spreadsheet marks** (the `cells` submodule): stray `,,` after the last value and
//!   hand-written text in a later cell are not read; a note counts the lines with stray
//!   cells and one note per hand note names its line and text.
//! - **Glitches are kept**: a sample the recorder got wrong (a −1200 % torque among
//!   −28 %, perhaps with a hand note beside it, `-1200,,was -32.0`) is returned as
//!   written; glitch reports are another part of rtid's job (the test
//!   `a_glitch_sample_beside_a_hand_note_is_kept_as_written` builds such a file).
//! - `Scale:` lines are the plot's display range (per division, offset, minimum,
//!   maximum), not a scaling of the values; they and the other keys are listed in a
//!   note as not used.
//!
//! A row with fewer cells than columns, a cell that is not a number, a data row after
//! an empty line, or a last row without a line end (a file cut mid-row) is an error
//! naming the line.

use std::io::BufReader;
use std::path::Path;

use super::text::Lines;
use super::{Abscissa, Channel, FormatError, Location, Recording, Samples};

mod cells;
mod header;
mod rows;

#[cfg(test)]
mod tests;

/// Whether a first line is probably an EPOS Studio export's (`Date:;…`).
pub fn sniff(first_line: &str) -> bool {
    let line = first_line.trim_start_matches('\u{feff}');
    line.trim_start_matches('"').starts_with("Date:;")
}

/// The format as `--format` names it and [`super::detect`] recognises it.
pub static DEFINITION: super::format::Definition = super::format::Definition {
    name: "epos-studio",
    sniff: |head| sniff(head.first_line),
    read,
};

/// Reads an EPOS Studio data-recorder CSV export.
pub fn read(path: &Path) -> Result<Recording, FormatError> {
    let file = crate::io::open_input(path)
        .map_err(|e| FormatError::new(path, Location::File, format!("cannot open: {e}")))?;
    let mut lines = Lines::new(BufReader::new(file));
    let mut quirks = header::Quirks::default();
    let mut notes = Vec::new();
    let header = header::read(&mut lines, path, &mut quirks, &mut notes)?;
    let table = rows::read(&mut lines, &header, path, &mut quirks)?;
    check_count(&header, &table, path, &mut notes)?;
    let first_line = table
        .first_line
        .expect("check_count refuses a file without rows");
    notes.extend(period_note(&header, &table.times, first_line));
    notes.extend(quirks.into_notes());

    let times: Vec<f64> = table.times.iter().map(|t| t / header.per_second).collect();
    let channels = header
        .names
        .iter()
        .zip(&header.units)
        .zip(table.values)
        .map(|((name, unit), values)| Channel {
            name: name.clone(),
            unit: unit.clone(),
            abscissa: Abscissa::Values {
                values: times.clone(),
                unit: "s".into(),
            },
            samples: Samples::Real(values),
            first_line: Some(first_line),
        })
        .collect();
    Ok(Recording {
        format: "epos-studio",
        channels,
        notes,
        groups: Vec::new(),
    })
}

/// `Recorded samples:` against the rows: fewer rows is an error, more a note.
fn check_count(
    header: &header::Header,
    table: &rows::Table,
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<(), FormatError> {
    let found = table.times.len() as u64;
    match header.recorded {
        Some((line, declared)) if found < declared => {
            let msg = format!(
                "the header declares {declared} recorded samples, the file holds {found} \
                 (its last line is {}): cut off?",
                table.last_line
            );
            Err(FormatError::new(path, Location::Line(line), msg))
        }
        _ if found == 0 => {
            let msg = "no samples: the file ends after the header";
            Err(FormatError::new(path, Location::Line(table.last_line), msg))
        }
        Some((line, declared)) if found > declared => {
            notes.push(format!(
                "{found} samples where line {line} declares {declared} recorded samples"
            ));
            Ok(())
        }
        _ => Ok(()),
    }
}

/// A note naming the first line whose time is not `first + i·period`.
fn period_note(header: &header::Header, times: &[f64], first_line: usize) -> Option<String> {
    let (line, period_ms) = header.period_ms?;
    let to_ms = 1e3 / header.per_second;
    let t0 = times.first()? * to_ms;
    let (i, t) = times
        .iter()
        .map(|t| t * to_ms)
        .enumerate()
        .find(|&(i, t)| {
            let tolerance = 0.0005 + t.abs() * f64::from(f32::EPSILON);
            (t - (t0 + i as f64 * period_ms)).abs() > tolerance
        })?;
    Some(format!(
        "line {}: the time {t} ms is not {t0} + {i} × {period_ms} ms, the sampling period of line {line}",
        first_line + i
    ))
}
