//! The columns [`super::write`] writes for each [`Data`] variant, in the file's units:
//! angles in degrees, positioning deviations in arc-seconds or µm (targets in mm),
//! other lengths in metres, speeds in rad/s or m/s.

use std::borrow::Cow;

use crate::io::experiment_file::data::{ServoTrace, Signal};
use crate::io::experiment_file::units::{ARCSEC, DEG, MM, UM};
use crate::io::experiment_file::{Axis, Data, Direction, FrictionMap};

/// The cells of one column to write, in the file's unit.
pub(super) enum Cells<'a> {
    Numbers(Cow<'a, [f64]>),
    /// Whole numbers (a friction map's counts), written without a decimal point.
    Counts(Vec<f64>),
    Directions(&'a [Direction]),
    Runs(&'a [u32]),
}

impl Cells<'_> {
    pub(super) fn len(&self) -> usize {
        match self {
            Cells::Numbers(v) => v.len(),
            Cells::Counts(v) => v.len(),
            Cells::Directions(v) => v.len(),
            Cells::Runs(v) => v.len(),
        }
    }
}

/// A named column.
type Column<'a> = (Cow<'a, str>, Cells<'a>);

/// A column written as stored (SI).
fn plain<'a>(name: impl Into<Cow<'a, str>>, v: &'a [f64]) -> Column<'a> {
    (name.into(), Cells::Numbers(v.into()))
}

/// A column written in a unit of `per_unit` SI units.
fn scaled<'a>(name: impl Into<Cow<'a, str>>, v: &[f64], per_unit: f64) -> Column<'a> {
    let converted = v.iter().map(|x| x / per_unit).collect::<Vec<f64>>();
    (name.into(), Cells::Numbers(converted.into()))
}

/// The columns to write for `data`, extra columns last (none for resonance).
pub(super) fn out_columns(data: &Data) -> Vec<Column<'_>> {
    let Some(extra) = data.extra() else {
        return Vec::new();
    };
    if let Data::FrictionMap(map) = data {
        return friction_map(map);
    }
    let mut columns = match data {
        Data::Resonance { .. } => Vec::new(),
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            phase_rad,
            ..
        } => {
            let mut c = vec![
                plain("frequency_hz", frequency_hz),
                plain("gain_db", gain_db),
            ];
            c.extend(phase_rad.as_deref().map(|p| scaled("phase_deg", p, DEG)));
            c
        }
        Data::TorqueCurve {
            time_s,
            motor_torque_nm,
            table_angle_rad,
            ..
        } => {
            let table = table_angle_rad.as_deref();
            let mut c = vec![
                plain("time_s", time_s),
                plain("motor_torque_nm", motor_torque_nm),
            ];
            c.extend(table.map(|a| scaled("table_angle_deg", a, DEG)));
            c
        }
        Data::ForceCurve {
            time_s,
            force_n,
            table_position_m,
            ..
        } => {
            let table = table_position_m.as_deref();
            let mut c = vec![plain("time_s", time_s), plain("force_n", force_n)];
            c.extend(table.map(|x| plain("table_position_m", x)));
            c
        }
        Data::Positioning { .. } | Data::LinearPositioning { .. } => positioning(data),
        Data::Fluctuation {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            ..
        }
        | Data::Unbalance {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            ..
        } => vec![
            plain("time_s", time_s),
            scaled("motor_angle_deg", motor_angle_rad, DEG),
            scaled("table_angle_deg", table_angle_rad, DEG),
        ],
        Data::FrequencyResponseTime { .. } | Data::FrequencyResponseTimeCurrent { .. } => {
            record(data)
        }
        Data::ServoTrace(trace) => servo_trace(trace),
        Data::FrictionMap(_) => Vec::new(),
    };
    for (name, v) in extra {
        columns.push(plain(name.as_str(), v));
    }
    columns
}

/// The four columns of a positioning file: targets in degrees and deviations in
/// arc-seconds, or targets in mm and deviations in µm.
fn positioning(data: &Data) -> Vec<Column<'_>> {
    let (target, direction, run, deviation) = match data {
        Data::Positioning {
            target_rad,
            direction,
            run,
            deviation_rad,
            ..
        } => (
            scaled("target_deg", target_rad, DEG),
            direction,
            run,
            scaled("deviation_arcsec", deviation_rad, ARCSEC),
        ),
        Data::LinearPositioning {
            target_m,
            direction,
            run,
            deviation_m,
            ..
        } => (
            scaled("target_mm", target_m, MM),
            direction,
            run,
            scaled("deviation_um", deviation_m, UM),
        ),
        _ => return Vec::new(),
    };
    vec![
        target,
        ("direction".into(), Cells::Directions(direction)),
        ("run".into(), Cells::Runs(run)),
        deviation,
    ]
}

/// A frequency-response record's columns, its input as `motor_torque_nm` or
/// `motor_current_a`.
fn record(data: &Data) -> Vec<Column<'_>> {
    let Some(r) = data.time_record() else {
        return Vec::new();
    };
    let drive = if r.current {
        "motor_current_a"
    } else {
        "motor_torque_nm"
    };
    let (time_s, input, motor_angle_rad, table_angle_rad) = (
        r.time_s,
        plain(drive, r.drive),
        r.motor_angle_rad,
        r.table_angle_rad,
    );
    vec![
        plain("time_s", time_s),
        input,
        scaled("motor_angle_deg", motor_angle_rad, DEG),
        scaled("table_angle_deg", table_angle_rad, DEG),
    ]
}

/// A command signal's column, named after its unit.
fn signal<'a>(base: &str, s: &'a Signal) -> Column<'a> {
    plain(format!("{base}_{}", s.unit.suffix()), &s.values)
}

/// A servo trace's columns: positions in degrees or metres, the effort as `torque_nm`
/// or `force_n`, signals in their own unit.
fn servo_trace(t: &ServoTrace) -> Vec<Column<'_>> {
    let (suffix, per_unit, effort) = match t.axis {
        Axis::Rotary => ("deg", DEG, "torque_nm"),
        Axis::Linear => ("m", 1.0, "force_n"),
    };
    let position = |base: &str, v: &[f64]| scaled(format!("{base}_{suffix}"), v, per_unit);
    let mut c = vec![
        plain("time_s", &t.time_s),
        position("reference_position", &t.reference_position),
        position("position", &t.position),
    ];
    c.extend(
        t.table_position
            .as_deref()
            .map(|v| position("table_position", v)),
    );
    c.push(plain(effort, &t.effort));
    c.extend(
        t.controller_output
            .as_ref()
            .map(|s| signal("controller_output", s)),
    );
    c.extend(
        t.controller_added
            .as_ref()
            .map(|s| signal("controller_added", s)),
    );
    c
}

/// A friction map's columns in SI (`speed_rad_s` and `torque_nm`, or `speed_m_s` and
/// `force_n`), the optional ones where given (counts as whole numbers), the extra
/// columns last; every column's rows in order of increasing speed.
fn friction_map(m: &FrictionMap) -> Vec<Column<'static>> {
    let m = m.sorted();
    let [speed, speed_std, effort, effort_std] = match m.axis {
        Axis::Rotary => [
            "speed_rad_s",
            "speed_std_rad_s",
            "torque_nm",
            "torque_std_nm",
        ],
        Axis::Linear => ["speed_m_s", "speed_std_m_s", "force_n", "force_std_n"],
    };
    let numbers = |name: &str, v: Vec<f64>| -> Column<'static> {
        (name.to_string().into(), Cells::Numbers(v.into()))
    };
    let mut c = vec![numbers(speed, m.speed), numbers(effort, m.effort)];
    c.extend(m.speed_std.map(|v| numbers(speed_std, v)));
    c.extend(m.effort_std.map(|v| numbers(effort_std, v)));
    let counts = [
        ("samples", m.samples),
        ("dropped", m.dropped),
        ("transient", m.transient),
    ];
    for (name, v) in counts {
        c.extend(v.map(|v| (name.into(), Cells::Counts(v))));
    }
    c.extend(m.extra.into_iter().map(|(name, v)| numbers(&name, v)));
    c
}
