//! The writing half of an experiment file: the CSV, then the manifest, each atomically,
//! after checking that everything written will read back.

use std::borrow::Cow;
use std::fmt::Write as _;
use std::path::Path;

mod columns;

use columns::{out_columns, Cells};

use super::{Conditions, Data, ExperimentFileError, Kind, Manifest};

/// Writes an experiment: the CSV (unless resonance) beside the manifest, named by
/// `manifest.data` or after the manifest, then the manifest as pretty JSON, each
/// atomically. The written manifest has `data` set to the CSV's name and, for a
/// resonance, `peaks_hz` and `peak_gain_db` from `data`. Angles are written in degrees
/// (positioning deviations in arc-seconds), lengths in metres (positioning targets in
/// mm, deviations in µm), speeds in rad/s or m/s (a friction map's rows in order of
/// increasing speed), numbers in Rust's shortest round-trip form.
/// Data that would not read back (unequal lengths, non-finite values, times not
/// increasing, run 0, a friction map's speed of 0 or repeated, extra columns named like
/// a column the reader uses) is refused before anything is written.
pub fn write(
    manifest_path: &Path,
    manifest: &Manifest,
    data: &Data,
) -> Result<(), ExperimentFileError> {
    let invalid = |path: &Path, message: String| ExperimentFileError::Invalid {
        path: path.to_path_buf(),
        message,
    };
    if data.kind() != manifest.kind {
        return Err(invalid(
            manifest_path,
            format!(
                "the manifest says `{}` but the data is `{}`",
                manifest.kind,
                data.kind()
            ),
        ));
    }
    check_manifest(manifest).map_err(|m| invalid(manifest_path, m))?;
    if let Data::ServoTrace(trace) = data {
        check_signals(trace).map_err(|m| invalid(manifest_path, m))?;
    }
    if let Data::FrictionMap(map) = data {
        map.check().map_err(|m| invalid(manifest_path, m))?;
    }
    let mut out = manifest.clone();
    if let Data::Resonance {
        peaks_hz,
        peak_gain_db,
    } = data
    {
        check_peaks(peaks_hz, peak_gain_db.as_deref()).map_err(|m| invalid(manifest_path, m))?;
        out.peaks_hz = Some(peaks_hz.clone());
        out.peak_gain_db = peak_gain_db.clone();
    } else {
        let name = match &manifest.data {
            Some(name) => name.clone(),
            None => match manifest_path.with_extension("csv").file_name() {
                Some(name) => name.to_string_lossy().into_owned(),
                None => return Err(invalid(manifest_path, "no file name".into())),
            },
        };
        let csv_path = manifest_path.parent().unwrap_or(Path::new("")).join(&name);
        if csv_path == manifest_path {
            return Err(invalid(
                manifest_path,
                "the data file would overwrite the manifest".into(),
            ));
        }
        let columns = out_columns(data);
        check_columns(data, &columns).map_err(|m| invalid(&csv_path, m))?;
        crate::io::atomic::write_with(&csv_path, |w| write_csv(w, data.kind(), &columns)).map_err(
            |source| ExperimentFileError::Write {
                path: csv_path.clone(),
                source,
            },
        )?;
        out.data = Some(name);
    }
    let mut text =
        crate::io::json::pretty(&out).map_err(|e| invalid(manifest_path, e.to_string()))?;
    text.push('\n');
    crate::io::atomic::write(manifest_path, text.as_bytes()).map_err(|source| {
        ExperimentFileError::Write {
            path: manifest_path.to_path_buf(),
            source,
        }
    })
}

/// Refuses what would not survive JSON: extra keys that repeat a typed key (the file
/// would have a duplicate key) and non-finite numbers (JSON has none; they would read
/// back as absent).
fn check_manifest(m: &Manifest) -> Result<(), String> {
    if let Some(key) = m
        .extra
        .keys()
        .find(|k| Manifest::KEYS.contains(&k.as_str()))
    {
        return Err(format!("extra key `{key}` repeats a manifest key"));
    }
    let c = &m.conditions;
    if let Some(key) = c
        .extra
        .keys()
        .find(|k| Conditions::KEYS.contains(&k.as_str()))
    {
        return Err(format!("extra condition `{key}` repeats a condition key"));
    }
    if let Some((key, Some(v))) = c
        .numbers()
        .into_iter()
        .find(|(_, v)| v.is_some_and(|v| !v.is_finite()))
    {
        return Err(format!("condition `{key}` is {v}"));
    }
    if let Some(f) = c.frequencies_hz.iter().flatten().find(|v| !v.is_finite()) {
        return Err(format!("condition `frequencies_hz` holds {f}"));
    }
    super::conditions::check(m.kind, c)?;
    for (key, values) in [("peaks_hz", &m.peaks_hz), ("peak_gain_db", &m.peak_gain_db)] {
        if let Some(v) = values.iter().flatten().find(|v| !v.is_finite()) {
            return Err(format!("`{key}` holds {v}"));
        }
    }
    Ok(())
}

/// An added signal is in the controller output's unit (the reader requires it).
fn check_signals(t: &super::ServoTrace) -> Result<(), String> {
    match (&t.controller_output, &t.controller_added) {
        (Some(out), Some(added)) if out.unit != added.unit => Err(format!(
            "the added signal is in {} but the controller output in {}",
            added.unit, out.unit
        )),
        _ => Ok(()),
    }
}

fn check_peaks(peaks_hz: &[f64], peak_gain_db: Option<&[f64]>) -> Result<(), String> {
    if peaks_hz.is_empty() {
        return Err("`peaks_hz` is empty".into());
    }
    if let Some(g) = peak_gain_db {
        if g.len() != peaks_hz.len() {
            return Err(format!(
                "`peaks_hz` has {} values but `peak_gain_db` has {}",
                peaks_hz.len(),
                g.len()
            ));
        }
    }
    match peaks_hz
        .iter()
        .chain(peak_gain_db.unwrap_or(&[]))
        .find(|v| !v.is_finite())
    {
        Some(v) => Err(format!("a peak value is {v}")),
        None => Ok(()),
    }
}

/// Everything the reader would refuse, checked before a byte is written.
fn check_columns(data: &Data, columns: &[(Cow<'_, str>, Cells<'_>)]) -> Result<(), String> {
    let Some((first, cells)) = columns.first() else {
        return Err("no columns".into());
    };
    let rows = cells.len();
    if rows == 0 {
        return Err("no rows".into());
    }
    let fixed = columns.len() - data.extra().map_or(0, |e| e.len());
    let reserved = (data.kind().definition().reserved)();
    for (i, (name, cells)) in columns.iter().enumerate() {
        if i >= fixed {
            if name.is_empty() || name.trim() != name || name.starts_with('#') {
                return Err(format!("`{name}` cannot be a column name"));
            }
            if reserved.iter().any(|r| r == name) {
                return Err(format!("extra column `{name}` clashes with a data column"));
            }
        }
        if cells.len() != rows {
            return Err(format!(
                "column `{name}` has {} values, `{first}` has {rows}",
                cells.len()
            ));
        }
        match cells {
            Cells::Numbers(v) => {
                if let Some((row, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                    return Err(format!(
                        "column `{name}`, row {}: {x} is not finite",
                        row + 1
                    ));
                }
                if i == 0 && (name == "time_s" || name == "frequency_hz") {
                    if let Some(row) = v.windows(2).position(|w| w[1] <= w[0]) {
                        return Err(format!(
                            "column `{name}`, row {}: {} does not increase",
                            row + 2,
                            v[row + 1]
                        ));
                    }
                    if matches!(data.kind(), Kind::FrequencyResponseTime | Kind::ServoTrace) {
                        if let Err(e) = super::check_uniform(v) {
                            return Err(format!("column `{name}`, row {}: {e}", e.row + 1));
                        }
                    }
                }
            }
            Cells::Counts(v) => {
                let whole = |x: &f64| super::friction_map::count(*x).is_ok();
                if let Some((row, x)) = v.iter().enumerate().find(|(_, x)| !whole(x)) {
                    return Err(format!(
                        "column `{name}`, row {}: {x} is not a whole number ≥ 0",
                        row + 1
                    ));
                }
            }
            Cells::Runs(v) => {
                if let Some(row) = v.iter().position(|&r| r == 0) {
                    return Err(format!(
                        "column `{name}`, row {}: run 0 (runs start at 1)",
                        row + 1
                    ));
                }
            }
            Cells::Directions(_) => {}
        }
    }
    Ok(())
}

fn write_csv(
    w: &mut impl std::io::Write,
    kind: Kind,
    columns: &[(Cow<'_, str>, Cells<'_>)],
) -> std::io::Result<()> {
    writeln!(
        w,
        "# {kind} experiment, written by rtid {} (docs/experiment-files.md)",
        env!("CARGO_PKG_VERSION")
    )?;
    let mut csv = csv::Writer::from_writer(w);
    csv.write_record(columns.iter().map(|(name, _)| name.as_bytes()))?;
    let rows = columns.first().map_or(0, |(_, c)| c.len());
    let mut cell = String::new();
    for row in 0..rows {
        for (_, cells) in columns {
            cell.clear();
            match cells {
                Cells::Numbers(v) => write!(cell, "{:?}", v[row]),
                Cells::Counts(v) => write!(cell, "{}", v[row]),
                Cells::Directions(v) => write!(cell, "{}", v[row]),
                Cells::Runs(v) => write!(cell, "{}", v[row]),
            }
            .map_err(std::io::Error::other)?;
            csv.write_field(&cell)?;
        }
        csv.write_record(None::<&[u8]>)?;
    }
    csv.flush()
}
