//! Experiment files (MODEL.md §7): a JSON manifest plus, for every kind but `resonance`,
//! one CSV file beside it, read into typed data in SI units (angles in rad, time in s,
//! torque in N·m, frequency in Hz, gain in dB) and written back atomically.
//!
//! The contract is "extend, never break": unknown manifest keys, unknown condition keys
//! and extra CSV columns are kept, not rejected. Every malformed input is one
//! [`ExperimentFileError`] naming the file and, where they apply, the line and the
//! column. The format, with an example per kind, is in `docs/experiment-files.md`.

mod table;
#[cfg(test)]
mod tests;
mod writer;

pub use writer::write;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::model::params::LoopMode;

/// Radians per degree.
const DEG: f64 = std::f64::consts::PI / 180.0;
/// Radians per arc-second.
const ARCSEC: f64 = std::f64::consts::PI / 648_000.0;
/// The angle suffixes the reader accepts, with radians per unit.
const ANGLE_UNITS: [(&str, f64); 3] = [("deg", DEG), ("rad", 1.0), ("arcsec", ARCSEC)];

/// Extra numeric columns, by their name in the file, values as written (no unit
/// conversion): columns a reader does not use but keeps, such as a virtual
/// experiment's `contact_loss_drive`.
pub type Columns = BTreeMap<String, Vec<f64>>;

/// Which experiment a file holds (MODEL.md §5 and §7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// Open-loop gain (and optionally phase) over frequency.
    FrequencyResponse,
    /// Resonance peaks only, listed in the manifest (no CSV).
    Resonance,
    /// Motor torque over time during a commanded sinusoidal table motion.
    TorqueCurve,
    /// ISO 230-2 positioning runs: deviation per target, direction and run.
    Positioning,
    /// Table and motor angle over time at constant speed (rotational fluctuation).
    Fluctuation,
    /// As [`Kind::Fluctuation`], with an offset mass on a vertical table.
    Unbalance,
    /// Raw time series of a frequency-response test (motor torque, motor and table
    /// angle, uniformly sampled), from which the gain curve is estimated.
    FrequencyResponseTime,
}

impl Kind {
    /// Every kind, in the order of MODEL.md §7.
    pub const ALL: [Kind; 7] = [
        Kind::FrequencyResponse,
        Kind::Resonance,
        Kind::TorqueCurve,
        Kind::Positioning,
        Kind::Fluctuation,
        Kind::Unbalance,
        Kind::FrequencyResponseTime,
    ];

    /// The name used in manifests (`frequency_response`, …).
    pub fn name(self) -> &'static str {
        match self {
            Kind::FrequencyResponse => "frequency_response",
            Kind::Resonance => "resonance",
            Kind::TorqueCurve => "torque_curve",
            Kind::Positioning => "positioning",
            Kind::Fluctuation => "fluctuation",
            Kind::Unbalance => "unbalance",
            Kind::FrequencyResponseTime => "frequency_response_time",
        }
    }

    /// Whether the experiment has a CSV data file (all kinds but `resonance`).
    pub fn has_data_file(self) -> bool {
        self != Kind::Resonance
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The sense in which a positioning target was approached.
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
    type Err = String;
    /// `up`/`ccw` or `down`/`cw`, in any case.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "up" | "ccw" => Ok(Direction::Up),
            "down" | "cw" => Ok(Direction::Down),
            _ => Err(format!(
                "`{s}` is not a direction (expected up, down, ccw or cw)"
            )),
        }
    }
}

/// How a frequency-response record was excited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Excitation {
    /// A sine held for `dwell_s` at each of `frequencies_hz` in turn.
    SteppedSine,
    /// Random noise, a chirp or a multisine: every frequency at once.
    Broadband,
}

impl Excitation {
    /// The name written to manifests.
    pub fn name(self) -> &'static str {
        match self {
            Excitation::SteppedSine => "stepped_sine",
            Excitation::Broadband => "broadband",
        }
    }
}

/// The `conditions` of a manifest: how the experiment was run. Every field is optional,
/// in the unit its name carries; [`Conditions::with_defaults`] fills in MODEL.md §7's
/// defaults. Unknown keys are kept in `extra`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Conditions {
    /// Frequency response: amplitude of the sinusoidal motor torque, N·m (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_amplitude_nm: Option<f64>,
    /// Frequency response: brake torque on the table, balanced by a motor DC torque, that
    /// keeps the flanks loaded (MODEL.md §5.1), N·m (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preload_nm: Option<f64>,
    /// Torque curve: amplitude of the commanded table motion, deg (default 30).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_deg: Option<f64>,
    /// Torque curve: period of the commanded table motion, s (default 3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// Feedback arrangement: `semi_closed` or `full_closed` (default `full_closed` for the
    /// torque curve, `semi_closed` for positioning, fluctuation and unbalance).
    #[serde(rename = "loop", default, skip_serializing_if = "Option::is_none")]
    pub loop_mode: Option<LoopMode>,
    /// Positioning: dwell at each target, s (default 1). Stepped-sine frequency
    /// response record: time spent at each frequency, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dwell_s: Option<f64>,
    /// Fluctuation and unbalance: table speed, deg/min (default 180 and 360).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_deg_per_min: Option<f64>,
    /// Fluctuation, unbalance and frequency-response records: table turns per motor
    /// turn, Rg·Rw (no default here: it comes from the mechanism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio: Option<f64>,
    /// Unbalance: the offset mass, kg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Unbalance: the mass's distance from the table axis, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    /// Frequency-response record: `stepped_sine` or `broadband` (default: stepped_sine
    /// when `frequencies_hz` is given, else broadband).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub excitation: Option<Excitation>,
    /// Stepped-sine frequency-response record: the drive frequencies in the order
    /// played, Hz, each held for `dwell_s` from the first sample on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequencies_hz: Option<Vec<f64>>,
    /// Condition keys this version does not know, kept as written.
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

impl Conditions {
    /// The JSON keys of the typed fields.
    const KEYS: [&'static str; 12] = [
        "torque_amplitude_nm",
        "preload_nm",
        "amplitude_deg",
        "period_s",
        "loop",
        "dwell_s",
        "speed_deg_per_min",
        "ratio",
        "mass_kg",
        "radius_m",
        "excitation",
        "frequencies_hz",
    ];

    /// True when no condition is given.
    pub fn is_empty(&self) -> bool {
        *self == Conditions::default()
    }

    /// A copy with MODEL.md §7's defaults for `kind` filled in where a value is absent
    /// (the ratio excepted: it depends on the mechanism).
    pub fn with_defaults(&self, kind: Kind) -> Conditions {
        let mut c = self.clone();
        match kind {
            Kind::FrequencyResponse => {
                c.torque_amplitude_nm.get_or_insert(5.0);
                c.preload_nm.get_or_insert(0.0);
            }
            Kind::Resonance => {}
            Kind::TorqueCurve => {
                c.amplitude_deg.get_or_insert(30.0);
                c.period_s.get_or_insert(3.0);
                c.loop_mode.get_or_insert(LoopMode::FullClosed);
            }
            Kind::Positioning => {
                c.loop_mode.get_or_insert(LoopMode::SemiClosed);
                c.dwell_s.get_or_insert(1.0);
            }
            Kind::Fluctuation | Kind::Unbalance => {
                let speed = if kind == Kind::Fluctuation {
                    180.0
                } else {
                    360.0
                };
                c.speed_deg_per_min.get_or_insert(speed);
                c.loop_mode.get_or_insert(LoopMode::SemiClosed);
            }
            Kind::FrequencyResponseTime => {
                let stepped = c.frequencies_hz.is_some();
                c.excitation.get_or_insert(if stepped {
                    Excitation::SteppedSine
                } else {
                    Excitation::Broadband
                });
            }
        }
        c
    }

    /// The numeric fields with their keys.
    fn numbers(&self) -> [(&'static str, Option<f64>); 9] {
        [
            ("torque_amplitude_nm", self.torque_amplitude_nm),
            ("preload_nm", self.preload_nm),
            ("amplitude_deg", self.amplitude_deg),
            ("period_s", self.period_s),
            ("dwell_s", self.dwell_s),
            ("speed_deg_per_min", self.speed_deg_per_min),
            ("ratio", self.ratio),
            ("mass_kg", self.mass_kg),
            ("radius_m", self.radius_m),
        ]
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

/// The measured data of an experiment, in SI units (angles in rad). All series of one
/// variant have the same length; `extra` columns too.
#[derive(Clone, Debug, PartialEq)]
pub enum Data {
    /// Gain of table over motor angle (× Rg·Rw) per drive frequency; frequencies increase
    /// strictly.
    FrequencyResponse {
        frequency_hz: Vec<f64>,
        gain_db: Vec<f64>,
        phase_rad: Option<Vec<f64>>,
        extra: Columns,
    },
    /// Resonance peaks, from the manifest.
    Resonance {
        peaks_hz: Vec<f64>,
        peak_gain_db: Option<Vec<f64>>,
    },
    /// Motor torque over time (times increase strictly).
    TorqueCurve {
        time_s: Vec<f64>,
        motor_torque_nm: Vec<f64>,
        table_angle_rad: Option<Vec<f64>>,
        extra: Columns,
    },
    /// One row per approach: target, direction, run number (≥ 1) and deviation
    /// (measured − target).
    Positioning {
        target_rad: Vec<f64>,
        direction: Vec<Direction>,
        run: Vec<u32>,
        deviation_rad: Vec<f64>,
        extra: Columns,
    },
    /// Motor-shaft and table angle over time (times increase strictly).
    Fluctuation {
        time_s: Vec<f64>,
        motor_angle_rad: Vec<f64>,
        table_angle_rad: Vec<f64>,
        extra: Columns,
    },
    /// As [`Data::Fluctuation`], with the unbalance mass mounted.
    Unbalance {
        time_s: Vec<f64>,
        motor_angle_rad: Vec<f64>,
        table_angle_rad: Vec<f64>,
        extra: Columns,
    },
    /// Motor torque, motor-shaft angle and table angle over uniformly sampled time
    /// (see [`uniform_step`]).
    FrequencyResponseTime {
        time_s: Vec<f64>,
        motor_torque_nm: Vec<f64>,
        motor_angle_rad: Vec<f64>,
        table_angle_rad: Vec<f64>,
        extra: Columns,
    },
}

impl Data {
    /// The kind of experiment this data belongs to.
    pub fn kind(&self) -> Kind {
        match self {
            Data::FrequencyResponse { .. } => Kind::FrequencyResponse,
            Data::Resonance { .. } => Kind::Resonance,
            Data::TorqueCurve { .. } => Kind::TorqueCurve,
            Data::Positioning { .. } => Kind::Positioning,
            Data::Fluctuation { .. } => Kind::Fluctuation,
            Data::Unbalance { .. } => Kind::Unbalance,
            Data::FrequencyResponseTime { .. } => Kind::FrequencyResponseTime,
        }
    }

    /// Number of rows (of peaks, for resonance).
    pub fn len(&self) -> usize {
        match self {
            Data::FrequencyResponse {
                frequency_hz: v, ..
            }
            | Data::Resonance { peaks_hz: v, .. }
            | Data::TorqueCurve { time_s: v, .. }
            | Data::Positioning { target_rad: v, .. }
            | Data::Fluctuation { time_s: v, .. }
            | Data::Unbalance { time_s: v, .. }
            | Data::FrequencyResponseTime { time_s: v, .. } => v.len(),
        }
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The extra columns (none for resonance).
    pub fn extra(&self) -> Option<&Columns> {
        match self {
            Data::Resonance { .. } => None,
            Data::FrequencyResponse { extra, .. }
            | Data::TorqueCurve { extra, .. }
            | Data::Positioning { extra, .. }
            | Data::Fluctuation { extra, .. }
            | Data::Unbalance { extra, .. }
            | Data::FrequencyResponseTime { extra, .. } => Some(extra),
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
    /// [`write`] was given data that would not read back.
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
    let data_path = data_path(path, &manifest);
    let data = table::Table::read(&data_path, path)?.data(manifest.kind)?;
    Ok(Experiment {
        manifest,
        data,
        path: path.to_path_buf(),
        data_path: Some(data_path),
    })
}

/// Reads and checks a manifest alone (the CSV is not opened).
pub fn read_manifest(path: &Path) -> Result<Manifest, ExperimentFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| ExperimentFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let manifest: Manifest =
        serde_json::from_str(&text).map_err(|e| ExperimentFileError::Json {
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
    if manifest.kind == Kind::FrequencyResponseTime {
        check_record_conditions(&manifest.conditions).map_err(|m| manifest_error(path, &m))?;
    }
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

fn manifest_error(path: &Path, message: &str) -> ExperimentFileError {
    ExperimentFileError::Manifest {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// The conditions a frequency-response record needs: for a stepped sine the frequencies
/// (positive) and the dwell (positive); a positive ratio where one is given. (JSON
/// numbers are finite, so `<= 0` is the whole check.)
fn check_record_conditions(c: &Conditions) -> Result<(), String> {
    let c = c.with_defaults(Kind::FrequencyResponseTime);
    if let Some(r) = c.ratio.filter(|r| *r <= 0.0) {
        return Err(format!(
            "`conditions.ratio` is {r}: it must be positive (Rg·Rw)"
        ));
    }
    if c.excitation != Some(Excitation::SteppedSine) {
        return Ok(());
    }
    let frequencies = c.frequencies_hz.as_deref().unwrap_or_default();
    if frequencies.is_empty() {
        return Err(
            "a stepped-sine record needs `conditions.frequencies_hz`: the drive \
                    frequencies in the order played, Hz"
                .into(),
        );
    }
    if let Some(f) = frequencies.iter().find(|f| **f <= 0.0) {
        return Err(format!(
            "`conditions.frequencies_hz` holds {f}: drive frequencies must be positive"
        ));
    }
    match c.dwell_s {
        None => Err(
            "a stepped-sine record needs `conditions.dwell_s`: the time spent at \
                     each frequency, s"
                .into(),
        ),
        Some(d) if d <= 0.0 => Err(format!(
            "`conditions.dwell_s` is {d}: the dwell at each frequency must be positive"
        )),
        Some(_) => Ok(()),
    }
}

/// Largest departure of one time step from the record's median step, as a fraction of
/// that step, that a frequency-response record may have (a DAQ writing times rounded
/// to 1 µs at 20 kHz stays within 2 %; one dropped sample is a 100 % departure).
pub const SAMPLING_TOLERANCE: f64 = 0.05;

/// A time step of a record that should be uniformly sampled but is not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonUniform {
    /// Index of the sample that ends the step.
    pub row: usize,
    /// The step there, s.
    pub step: f64,
    /// The record's median step, s.
    pub median: f64,
}

impl fmt::Display for NonUniform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the step from the previous row is {:.6e} s where the record steps {:.6e} s: \
             the samples must be uniformly spaced (within {:.0} % of a step)",
            self.step,
            self.median,
            100.0 * SAMPLING_TOLERANCE
        )
    }
}

/// Checks that strictly increasing `time` is uniformly sampled: every step within
/// [`SAMPLING_TOLERANCE`] of the median step. Fewer than two samples pass.
pub fn check_uniform(time: &[f64]) -> Result<(), NonUniform> {
    let steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return Ok(());
    }
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    match steps
        .iter()
        .position(|s| (s - median).abs() > SAMPLING_TOLERANCE * median)
    {
        Some(i) => Err(NonUniform {
            row: i + 1,
            step: steps[i],
            median,
        }),
        None => Ok(()),
    }
}

/// The sampling period of a uniformly sampled record: the mean step, which rounding
/// of the individual times does not bias. `None` for fewer than two samples.
pub fn sample_period(time: &[f64]) -> Option<f64> {
    (time.len() >= 2).then(|| (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64)
}
