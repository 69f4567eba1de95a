//! `compensation.json`: an axis's backlash and error table in the field's units
//! (docs/compensation.md), read and written atomically; [`sinumerik`] and [`csv`]
//! write the same table for a controller and for a spreadsheet.
//!
//! ```json
//! {
//!   "axis": "rotary",
//!   "unit": "deg",
//!   "backlash": { "value": -0.0097 },
//!   "table": { "positions": [0, 30, …, 360], "values": [0.0049, …], "modulo": 360 },
//!   "source": [ { "file": "positioning.json", "runs": "1-3" } ]
//! }
//! ```
//!
//! Positions, values, backlash and modulo are all in `unit`: degrees on a rotary
//! axis, millimetres on a linear one; each value is added to the commanded position
//! (the backlash while the commanded direction is down), as in
//! [`crate::controller::Compensation`]. A friction compensation is not part of this
//! version of the file: a `friction` field is refused rather than ignored.

pub mod sinumerik;
pub mod table_csv;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::controller::{
    Compensation, ErrorTable, FrictionCompensation, ReversalPulse, TableError,
};
use crate::model::friction::{Rise, SteadyFriction};
use crate::model::Axis;

/// Where a compensation came from: a record and its runs (`None`: all).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    pub file: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs: Option<String>,
    /// Where the compensation is the model's: which of its virtual tests gave it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
}

/// A compensation file's content, SI inside (rad or m).
#[derive(Clone, Debug, PartialEq)]
pub struct CompensationFile {
    pub axis: Axis,
    pub compensation: Compensation,
    pub source: Vec<Source>,
}

/// A compensation file that cannot be read or written; names the file and the field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CompensationFileError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {source}")]
    Json {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error("{path}: field `unit`: `{unit}` is not the unit of a {axis} axis (`{want}`)")]
    Unit {
        path: PathBuf,
        axis: &'static str,
        unit: String,
        want: &'static str,
    },
    #[error("{path}: field `table`: {source}")]
    Table { path: PathBuf, source: TableError },
    #[error("{path}: field `{field}`: {problem}")]
    Field {
        path: PathBuf,
        field: &'static str,
        problem: String,
    },
    #[error(
        "{path}: a compensation of a {compensation} axis cannot be applied to a record of a {record} axis"
    )]
    Axis {
        path: PathBuf,
        compensation: &'static str,
        record: &'static str,
    },
}

/// The file as written, in the field's unit.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileForm {
    axis: Axis,
    unit: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    backlash: Option<BacklashForm>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    table: Option<TableForm>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    friction: Option<FrictionForm>,
    #[serde(default)]
    source: Vec<Source>,
}

/// The friction compensation as written: the law at the motor in SI, its units
/// stated (`N·m` and `rad/s` on a rotary axis, `N` and `m/s` on a linear one).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FrictionForm {
    effort_unit: String,
    speed_unit: String,
    coulomb: f64,
    viscous: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stribeck: Option<StribeckForm>,
    #[serde(default)]
    offset: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pulse: Option<PulseForm>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StribeckForm {
    rise: f64,
    speed: f64,
    shape: f64,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PulseForm {
    amplitude: f64,
    decay_s: f64,
}

/// The units of a friction law at the motor of `axis`: effort, speed.
pub fn friction_units(axis: Axis) -> (&'static str, &'static str) {
    match axis {
        Axis::Rotary => ("N·m", "rad/s"),
        Axis::Linear => ("N", "m/s"),
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BacklashForm {
    value: f64,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TableForm {
    positions: Vec<f64>,
    values: Vec<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    modulo: Option<f64>,
}

/// The unit of `axis` in the file (`deg`, `mm`) and field units per SI unit.
pub fn unit_of(axis: Axis) -> (&'static str, f64) {
    match axis {
        Axis::Rotary => ("deg", 180.0 / std::f64::consts::PI),
        Axis::Linear => ("mm", 1e3),
    }
}

/// `rotary` or `linear`.
pub fn axis_name(axis: Axis) -> &'static str {
    match axis {
        Axis::Rotary => "rotary",
        Axis::Linear => "linear",
    }
}

/// What a compensation built from a model rests on, in the file's `source`.
pub const MODEL_SOURCE: &str =
    "the virtual positioning test (ISO 230-2 standard cycle) of the identified model";

/// Reads and checks a compensation file.
pub fn read(path: &Path) -> Result<CompensationFile, CompensationFileError> {
    let text = super::read_input(path).map_err(|source| CompensationFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text, path)
}

/// Checks a compensation file's text (`path` names it in errors).
pub fn parse(text: &str, path: &Path) -> Result<CompensationFile, CompensationFileError> {
    let form: FileForm = serde_json::from_str(super::without_bom(text)).map_err(|source| {
        CompensationFileError::Json {
            path: path.to_path_buf(),
            source,
        }
    })?;
    from_form(form, path)
}

/// The file's text, as [`write`] writes it.
pub fn to_text(file: &CompensationFile) -> Result<String, super::json::JsonError> {
    Ok(format!("{}\n", super::json::pretty(&to_form(file))?))
}

/// Writes `file` at `path` atomically.
pub fn write(path: &Path, file: &CompensationFile) -> Result<(), CompensationFileError> {
    let io = |source| CompensationFileError::Io {
        path: path.to_path_buf(),
        source,
    };
    let text = to_text(file).map_err(|e| io(std::io::Error::other(e)))?;
    super::atomic::write(path, text.as_bytes()).map_err(io)
}

impl CompensationFile {
    /// Refuses to apply this compensation (read from `path`) to a record of `record`.
    pub fn check_axis(&self, path: &Path, record: Axis) -> Result<(), CompensationFileError> {
        if self.axis == record {
            return Ok(());
        }
        Err(CompensationFileError::Axis {
            path: path.to_path_buf(),
            compensation: axis_name(self.axis),
            record: axis_name(record),
        })
    }
}

fn to_form(file: &CompensationFile) -> FileForm {
    let (unit, k) = unit_of(file.axis);
    let c = &file.compensation;
    FileForm {
        axis: file.axis,
        unit: unit.to_string(),
        backlash: c.backlash.map(|b| BacklashForm { value: b * k }),
        table: c.table.as_ref().map(|t| {
            // A rotary modulo table is one turn: 360 exactly, its positions within it
            // (2π·180/π may round above 360).
            let modulo = t.modulo.map(|_| 360.0);
            let within = |p: f64| match modulo {
                Some(m) => p.clamp(0.0, m),
                None => p,
            };
            TableForm {
                positions: t.positions.iter().map(|p| within(p * k)).collect(),
                values: t.values.iter().map(|v| v * k).collect(),
                modulo,
            }
        }),
        friction: c.friction.as_ref().map(|f| friction_form(f, file.axis)),
        source: file.source.clone(),
    }
}

fn friction_form(f: &FrictionCompensation, axis: Axis) -> FrictionForm {
    let (effort_unit, speed_unit) = friction_units(axis);
    FrictionForm {
        effort_unit: effort_unit.into(),
        speed_unit: speed_unit.into(),
        coulomb: f.law.coulomb,
        viscous: f.law.viscous,
        stribeck: f.law.rise.map(|r| StribeckForm {
            rise: r.rise,
            speed: r.speed,
            shape: r.shape,
        }),
        offset: f.offset,
        pulse: f.pulse.map(|p| PulseForm {
            amplitude: p.amplitude,
            decay_s: p.decay_s,
        }),
    }
}

/// The friction compensation of `form` on `axis`, checked: its units the axis's,
/// every number finite, the levels and the pulse non-negative, speeds, shape and
/// decay positive.
fn friction_from(
    form: FrictionForm,
    axis: Axis,
    path: &Path,
) -> Result<FrictionCompensation, CompensationFileError> {
    let (effort, speed) = friction_units(axis);
    for (name, got, want) in [
        ("friction.effort_unit", &form.effort_unit, effort),
        ("friction.speed_unit", &form.speed_unit, speed),
    ] {
        if got != want {
            return Err(field(
                path,
                name,
                format!("`{got}`: a {} axis's law is in `{want}`", axis_name(axis)),
            ));
        }
    }
    let check = |name: &'static str, v: f64, positive: bool| {
        let ok = v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 };
        let what = if positive { "positive" } else { "non-negative" };
        if ok {
            Ok(v)
        } else {
            Err(field(path, name, format!("{v}: must be finite and {what}")))
        }
    };
    let rise = match form.stribeck {
        Some(r) => Some(Rise {
            rise: check("friction.stribeck.rise", r.rise, false)?,
            speed: check("friction.stribeck.speed", r.speed, true)?,
            shape: check("friction.stribeck.shape", r.shape, true)?,
        }),
        None => None,
    };
    let pulse = match form.pulse {
        Some(p) => Some(ReversalPulse {
            amplitude: check("friction.pulse.amplitude", p.amplitude, false)?,
            decay_s: check("friction.pulse.decay_s", p.decay_s, true)?,
        }),
        None => None,
    };
    if !form.offset.is_finite() {
        return Err(field(path, "friction.offset", "not a finite number".into()));
    }
    Ok(FrictionCompensation {
        law: SteadyFriction {
            coulomb: check("friction.coulomb", form.coulomb, false)?,
            viscous: check("friction.viscous", form.viscous, false)?,
            rise,
        },
        offset: form.offset,
        pulse,
    })
}

/// The checked content of `form`, read from `path`, in SI.
fn from_form(form: FileForm, path: &Path) -> Result<CompensationFile, CompensationFileError> {
    let (want, k) = unit_of(form.axis);
    let p = || path.to_path_buf();
    if form.unit != want {
        return Err(CompensationFileError::Unit {
            path: p(),
            axis: axis_name(form.axis),
            unit: form.unit,
            want,
        });
    }
    let friction = form
        .friction
        .map(|f| friction_from(f, form.axis, path))
        .transpose()?;
    let backlash = match form.backlash {
        Some(b) if !b.value.is_finite() => {
            return Err(field(path, "backlash.value", "not a finite number".into()))
        }
        b => b.map(|b| b.value / k),
    };
    let table = form
        .table
        .map(|t| table_from(t, form.axis, path))
        .transpose()?;
    Ok(CompensationFile {
        axis: form.axis,
        compensation: Compensation {
            backlash,
            table,
            friction,
        },
        source: form.source,
    })
}

fn field(path: &Path, field: &'static str, problem: String) -> CompensationFileError {
    CompensationFileError::Field {
        path: path.to_path_buf(),
        field,
        problem,
    }
}

/// The table of `form` in SI, checked: a modulo only on a rotary axis and only one
/// turn (360), its positions within it.
fn table_from(
    form: TableForm,
    axis: Axis,
    path: &Path,
) -> Result<ErrorTable, CompensationFileError> {
    let (_, k) = unit_of(axis);
    if let Some(m) = form.modulo {
        if axis == Axis::Linear {
            return Err(field(
                path,
                "table.modulo",
                "a linear axis has no modulo".into(),
            ));
        }
        if m != 360.0 {
            return Err(field(
                path,
                "table.modulo",
                format!("{m}: a rotary axis's period is 360 (degrees)"),
            ));
        }
        if let Some(p) = form.positions.iter().find(|p| !(0.0..=360.0).contains(*p)) {
            return Err(field(
                path,
                "table.positions",
                format!("{p} is outside the modulo range 0…360"),
            ));
        }
    }
    // Checked in the file's unit, so that a message quotes the file's numbers.
    let in_file = ErrorTable {
        positions: form.positions,
        values: form.values,
        modulo: form.modulo,
    };
    in_file
        .check()
        .map_err(|source| CompensationFileError::Table {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(ErrorTable {
        positions: in_file.positions.iter().map(|p| p / k).collect(),
        values: in_file.values.iter().map(|v| v / k).collect(),
        modulo: in_file.modulo.map(|m| m / k),
    })
}

#[cfg(test)]
mod tests;
