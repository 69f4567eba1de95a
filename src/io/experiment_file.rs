//! Experiment files (docs/experiment-files.md): a JSON manifest plus, for every kind but `resonance`,
//! one CSV file beside it, read into typed data in SI units (angles in rad, lengths in
//! m, time in s, torque in N·m, force in N, frequency in Hz, gain in dB) and written
//! back atomically.
//!
//! The contract is "extend, never break": unknown manifest keys, unknown condition keys
//! and extra CSV columns are kept, not rejected. Every malformed input is one
//! [`ExperimentFileError`] naming the file and, where they apply, the line and the
//! column. The format, with an example per kind, is in `docs/experiment-files.md`.

mod conditions;
mod data;
mod friction_map;
mod kind;
mod response;
mod sampling;
mod table;
#[cfg(test)]
mod tests;
mod units;
mod writer;

pub use conditions::{Conditions, DriveFunctions, Excitation};
pub use data::{Approaches, Data, ServoTrace, Signal, TimeRecord};
pub use friction_map::FrictionMap;
pub use kind::{Definition as KindDefinition, Kind, KINDS};
pub use response::{Delay, Reference, Response, ResponseForm};
pub use sampling::{check_uniform, sample_period, NonUniform, SAMPLING_TOLERANCE};
pub use table::MAX_MAGNITUDE;
pub use units::{Axis, CommandUnit};
pub use writer::write;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

/// Extra numeric columns, by their name in the file, values as written (no unit
/// conversion): columns a reader does not use but keeps, such as a virtual
/// experiment's `contact_loss_drive`.
pub type Columns = BTreeMap<String, Vec<f64>>;

/// The sense in which a positioning target was approached (on a linear axis: the
/// positive or negative direction of the axis).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Approach in the positive (counter-clockwise) sense: `up` or `ccw` in a file.
    Up,
    /// Approach in the negative (clockwise) sense: `down` or `cw` in a file.
    Down,
}

impl Direction {
    /// The name written to files.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }

    /// +1 for [`Direction::Up`], −1 for [`Direction::Down`].
    pub fn sign(self) -> f64 {
        match self {
            Direction::Up => 1.0,
            Direction::Down => -1.0,
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Direction {
    type Err = crate::names::UnknownName;
    /// `up`/`ccw` or `down`/`cw`, in any case.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "up" | "ccw" => Ok(Direction::Up),
            "down" | "cw" => Ok(Direction::Down),
            _ => Err(crate::names::UnknownName {
                what: "direction",
                given: s.to_string(),
                expected: "up, down, ccw or cw".into(),
            }),
        }
    }
}

/// The JSON manifest of an experiment. Unknown top-level keys are kept in `extra`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Which experiment this is; required.
    pub kind: Kind,
    /// The CSV file, relative to the manifest's folder. When absent the reader looks for
    /// the manifest's name with the extension `csv`; the writer always fills it in.
    /// Unused for `resonance`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// The table measured: free text or a preset name (`worm-gear`, `roller-gear-cam`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mechanism: Option<String>,
    /// How the experiment was run.
    #[serde(default, skip_serializing_if = "Conditions::is_empty")]
    pub conditions: Conditions,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub notes: Option<String>,
    /// Resonance frequencies, Hz: required for `resonance`, informative for other kinds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peaks_hz: Option<Vec<f64>>,
    /// Gains at the peaks, dB, one per entry of `peaks_hz`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_gain_db: Option<Vec<f64>>,
    /// Top-level keys this version does not know, kept as written.
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

impl Manifest {
    /// The JSON keys of the typed fields.
    const KEYS: [&'static str; 7] = [
        "kind",
        "data",
        "mechanism",
        "conditions",
        "notes",
        "peaks_hz",
        "peak_gain_db",
    ];

    /// A manifest of `kind` with nothing else set.
    pub fn new(kind: Kind) -> Manifest {
        Manifest {
            kind,
            data: None,
            mechanism: None,
            conditions: Conditions::default(),
            notes: None,
            peaks_hz: None,
            peak_gain_db: None,
            extra: Map::new(),
        }
    }
}

/// An experiment as read: its manifest, its data and where they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    pub manifest: Manifest,
    pub data: Data,
    /// The manifest file.
    pub path: PathBuf,
    /// The CSV file (none for resonance).
    pub data_path: Option<PathBuf>,
}

/// An experiment file that cannot be read or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentFileError {
    /// A file cannot be read.
    #[error("cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The manifest is not valid JSON or not a manifest (missing or unknown `kind`, a
    /// value of the wrong type); position and message from serde_json.
    #[error("{path}, line {line}, column {column}: {message}")]
    Json {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// The manifest parses but its content does not fit together.
    #[error("{path}: {message}")]
    Manifest { path: PathBuf, message: String },
    /// The manifest's data file cannot be opened.
    #[error("{manifest}: its data file {data} cannot be opened: {source}")]
    MissingData {
        manifest: PathBuf,
        data: PathBuf,
        source: std::io::Error,
    },
    /// A required CSV column is absent; `header` lists the columns the file has.
    #[error(
        "{path}, line {line}: missing column {} (header: {})",
        either(.column, .alternatives),
        .header.join(",")
    )]
    MissingColumn {
        path: PathBuf,
        line: u64,
        column: String,
        alternatives: Vec<String>,
        header: Vec<String>,
    },
    /// A CSV cell is not what its column needs.
    #[error("{path}, line {line}, column `{column}`: {message}")]
    Cell {
        path: PathBuf,
        line: u64,
        column: String,
        message: String,
    },
    /// The CSV as a whole is malformed: empty, no data rows, rows of unequal length,
    /// duplicate or ambiguous columns, text that is not UTF-8.
    #[error("{path}, line {line}: {message}")]
    Csv {
        path: PathBuf,
        line: u64,
        message: String,
    },
    /// [`write()`] was given data that would not read back.
    #[error("cannot write experiment {path}: {message}")]
    Invalid { path: PathBuf, message: String },
    /// A file cannot be written.
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// "`a` (or `b`, `c`)".
fn either(column: &str, alternatives: &[String]) -> String {
    let mut s = format!("`{column}`");
    if !alternatives.is_empty() {
        let rest: Vec<String> = alternatives.iter().map(|a| format!("`{a}`")).collect();
        s += &format!(" (or {})", rest.join(", "));
    }
    s
}

/// The highest resonance frequency a resonance file may give, Hz: a drive's
/// mechanical modes lie far below (the model's response at 1e308 Hz is not a number).
const MAX_PEAK_HZ: f64 = 1e6;

/// Reads an experiment: the manifest at `path` and, unless it is a resonance, its CSV.
pub fn read(path: &Path) -> Result<Experiment, ExperimentFileError> {
    let manifest = read_manifest(path)?;
    if !manifest.kind.has_data_file() {
        let peaks_hz = manifest.peaks_hz.clone().ok_or_else(|| {
            manifest_error(
                path,
                "a resonance experiment needs `peaks_hz` (an array of frequencies in Hz)",
            )
        })?;
        if peaks_hz.is_empty() {
            return Err(manifest_error(path, "`peaks_hz` is empty"));
        }
        if let Some((i, f)) = peaks_hz
            .iter()
            .enumerate()
            .find(|(_, f)| f.is_nan() || **f <= 0.0)
        {
            return Err(manifest_error(
                path,
                &format!("`peaks_hz`[{i}] = {f}: a resonance frequency is positive (Hz)"),
            ));
        }
        if let Some((i, f)) = peaks_hz.iter().enumerate().find(|(_, f)| **f > MAX_PEAK_HZ) {
            return Err(manifest_error(
                path,
                &format!(
                    "`peaks_hz`[{i}] = {f:e} Hz: above 1 MHz, not a drive's mechanical resonance \
                     (the unit is Hz)"
                ),
            ));
        }
        let data = Data::Resonance {
            peaks_hz,
            peak_gain_db: manifest.peak_gain_db.clone(),
        };
        return Ok(Experiment {
            manifest,
            data,
            path: path.to_path_buf(),
            data_path: None,
        });
    }
    if let Some(data) = &manifest.data {
        if !inside_folder(Path::new(data)) {
            return Err(manifest_error(
                path,
                &format!("`data` = \"{data}\" must name a file in the manifest's folder or below it (a relative path without `..`)"),
            ));
        }
    }
    let data_path = data_path(path, &manifest);
    let data = (manifest.kind.definition().read)(table::Table::read(&data_path, path)?)?;
    check_against_data(&manifest, &data).map_err(|m| manifest_error(path, &m))?;
    Ok(Experiment {
        manifest,
        data,
        path: path.to_path_buf(),
        data_path: Some(data_path),
    })
}

/// Reads and checks a manifest alone (the CSV is not opened).
pub fn read_manifest(path: &Path) -> Result<Manifest, ExperimentFileError> {
    let text = super::read_input(path).map_err(|source| ExperimentFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let manifest: Manifest =
        serde_json::from_str(super::without_bom(&text)).map_err(|e| ExperimentFileError::Json {
            path: path.to_path_buf(),
            line: e.line(),
            column: e.column(),
            message: {
                let full = e.to_string();
                match full.rsplit_once(" at line ") {
                    Some((message, _)) => message.to_string(),
                    None => full,
                }
            },
        })?;
    conditions::check(manifest.kind, &manifest.conditions).map_err(|m| manifest_error(path, &m))?;
    if let (Some(peaks), Some(gains)) = (&manifest.peaks_hz, &manifest.peak_gain_db) {
        if peaks.len() != gains.len() {
            return Err(manifest_error(
                path,
                &format!(
                    "`peaks_hz` has {} values but `peak_gain_db` has {}",
                    peaks.len(),
                    gains.len()
                ),
            ));
        }
    }
    Ok(manifest)
}

/// Where the CSV of the manifest at `path` is: `data` relative to the manifest's folder,
/// or the manifest's path with the extension `csv`.
pub fn data_path(path: &Path, manifest: &Manifest) -> PathBuf {
    match &manifest.data {
        Some(data) => path.parent().unwrap_or(Path::new("")).join(data),
        None => path.with_extension("csv"),
    }
}

/// Whether a relative `data` path stays in the manifest's folder: no root, no drive,
/// no `..`.
fn inside_folder(data: &Path) -> bool {
    use std::path::Component;
    data.components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
        && data.components().next().is_some()
}

fn manifest_error(path: &Path, message: &str) -> ExperimentFileError {
    ExperimentFileError::Manifest {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// The conditions that need the data to be checked: a multisine's period and lines
/// against the record's sampling.
fn check_against_data(manifest: &Manifest, data: &Data) -> Result<(), String> {
    let c = manifest.conditions.with_defaults(manifest.kind);
    match data {
        Data::FrequencyResponseTime { time_s, .. }
        | Data::FrequencyResponseTimeCurrent { time_s, .. }
            if c.excitation == Some(Excitation::Multisine) =>
        {
            conditions::check_multisine_record(&c, time_s)
        }
        _ => Ok(()),
    }
}
