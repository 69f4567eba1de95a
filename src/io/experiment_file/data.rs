//! The measured data of an experiment, typed per kind and in SI units.
//!
//! A kind whose files may be rotary or linear has one variant per axis
//! ([`Data::TorqueCurve`] and [`Data::ForceCurve`], [`Data::Positioning`] and
//! [`Data::LinearPositioning`]), and the frequency-response record one per input
//! ([`Data::FrequencyResponseTime`] and [`Data::FrequencyResponseTimeCurrent`]), rather
//! than an axis flag beside fields named `_rad` and `_nm`: every field's name states its
//! unit, and code written for the rotary variants cannot take metres for radians
//! without noticing. [`Data::axis`] says which axis a variant belongs to.

use super::{Axis, Columns, CommandUnit, Direction, FrictionMap, Kind};

/// The measured data of an experiment, in SI units (angles in rad, lengths in m). All
/// series of one variant have the same length; `extra` columns too.
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
    /// Motor torque over time (times increase strictly), rotary axis.
    TorqueCurve {
        time_s: Vec<f64>,
        motor_torque_nm: Vec<f64>,
        table_angle_rad: Option<Vec<f64>>,
        extra: Columns,
    },
    /// A `torque_curve` on a linear axis: the drive's force over time (times increase
    /// strictly) and optionally the carriage position.
    ForceCurve {
        time_s: Vec<f64>,
        force_n: Vec<f64>,
        table_position_m: Option<Vec<f64>>,
        extra: Columns,
    },
    /// One row per approach: target, direction, run number (≥ 1) and deviation
    /// (measured − target), rotary axis.
    Positioning {
        target_rad: Vec<f64>,
        direction: Vec<Direction>,
        run: Vec<u32>,
        deviation_rad: Vec<f64>,
        extra: Columns,
    },
    /// `positioning` on a linear axis (ISO 230-2 in lengths): targets and deviations
    /// in m; [`Direction::Up`] is the approach in the positive direction of the axis.
    LinearPositioning {
        target_m: Vec<f64>,
        direction: Vec<Direction>,
        run: Vec<u32>,
        deviation_m: Vec<f64>,
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
    /// (see [`super::check_uniform`]).
    FrequencyResponseTime {
        time_s: Vec<f64>,
        motor_torque_nm: Vec<f64>,
        motor_angle_rad: Vec<f64>,
        table_angle_rad: Vec<f64>,
        extra: Columns,
    },
    /// A `frequency_response_time` record driven by the motor current (no torque
    /// constant known): responses to it are per ampere. `table_angle_rad` is the
    /// table's — or the load's, read from `load_angle_*` — angle.
    FrequencyResponseTimeCurrent {
        time_s: Vec<f64>,
        motor_current_a: Vec<f64>,
        motor_angle_rad: Vec<f64>,
        table_angle_rad: Vec<f64>,
        extra: Columns,
    },
    /// A recorded closed-loop run (`servo_trace`).
    ServoTrace(ServoTrace),
    /// Constant-speed runs' mean speeds and efforts (`friction_map`), rotary or linear.
    FrictionMap(FrictionMap),
}

/// A recorded closed-loop run, uniformly sampled: the position command, the loop's
/// encoder, the drive's effort and what the controller sent. Positions are in rad on a
/// rotary axis and m on a linear one, efforts in N·m or N, as `axis` says (every
/// position and effort column of one file agrees).
#[derive(Clone, Debug, PartialEq)]
pub struct ServoTrace {
    /// Rotary (rad, N·m) or linear (m, N).
    pub axis: Axis,
    /// Time, s, uniformly sampled.
    pub time_s: Vec<f64>,
    /// The position command the loop follows, rad or m.
    pub reference_position: Vec<f64>,
    /// The loop's encoder (motor side in a semi-closed loop), rad or m, in the same
    /// frame as the reference.
    pub position: Vec<f64>,
    /// A second encoder on the table or carriage, rad or m.
    pub table_position: Option<Vec<f64>>,
    /// The drive's output: torque (N·m) or force (N).
    pub effort: Vec<f64>,
    /// The controller output as recorded (it includes `controller_added`).
    pub controller_output: Option<Signal>,
    /// A recorded signal added to the controller output (test pulses, dither), in the
    /// controller output's unit.
    pub controller_added: Option<Signal>,
    /// Columns not interpreted, values as written.
    pub extra: Columns,
}

/// A command signal and its unit.
#[derive(Clone, Debug, PartialEq)]
pub struct Signal {
    pub unit: CommandUnit,
    pub values: Vec<f64>,
}

/// The channels of a `frequency_response_time` record, whichever input drove it.
#[derive(Clone, Copy, Debug)]
pub struct TimeRecord<'a> {
    pub time_s: &'a [f64],
    /// `motor_torque_nm`, or `motor_current_a` when `current`.
    pub drive: &'a [f64],
    pub current: bool,
    pub motor_angle_rad: &'a [f64],
    pub table_angle_rad: &'a [f64],
}

/// The rows of a `positioning` experiment, in SI: one per approach.
#[derive(Clone, Debug, PartialEq)]
pub struct Approaches {
    /// Targets, rad or m.
    pub target: Vec<f64>,
    pub direction: Vec<Direction>,
    pub run: Vec<u32>,
    /// Measured − target, rad or m.
    pub deviation: Vec<f64>,
}

impl Data {
    /// A `torque_curve` on `axis`: effort in N·m and position in rad on a rotary axis,
    /// N and m on a linear one.
    pub fn effort_curve(
        axis: Axis,
        time_s: Vec<f64>,
        effort: Vec<f64>,
        position: Option<Vec<f64>>,
    ) -> Data {
        match axis {
            Axis::Rotary => Data::TorqueCurve {
                time_s,
                motor_torque_nm: effort,
                table_angle_rad: position,
                extra: Columns::new(),
            },
            Axis::Linear => Data::ForceCurve {
                time_s,
                force_n: effort,
                table_position_m: position,
                extra: Columns::new(),
            },
        }
    }

    /// A `positioning` test on `axis` (ISO 230-2 in angles or in lengths).
    pub fn positioning(axis: Axis, a: Approaches) -> Data {
        match axis {
            Axis::Rotary => Data::Positioning {
                target_rad: a.target,
                direction: a.direction,
                run: a.run,
                deviation_rad: a.deviation,
                extra: Columns::new(),
            },
            Axis::Linear => Data::LinearPositioning {
                target_m: a.target,
                direction: a.direction,
                run: a.run,
                deviation_m: a.deviation,
                extra: Columns::new(),
            },
        }
    }

    /// A frequency response's phase dropped, its gain kept (other kinds unchanged):
    /// what a gain-only file of the same data would give.
    pub fn drop_phase(&mut self) {
        if let Data::FrequencyResponse { phase_rad, .. } = self {
            *phase_rad = None;
        }
    }

    /// The channels of a `frequency_response_time` record (torque- or current-driven);
    /// `None` for other kinds.
    pub fn time_record(&self) -> Option<TimeRecord<'_>> {
        let (time_s, drive, current, motor_angle_rad, table_angle_rad) = match self {
            Data::FrequencyResponseTime {
                time_s,
                motor_torque_nm,
                motor_angle_rad,
                table_angle_rad,
                ..
            } => (
                time_s,
                motor_torque_nm,
                false,
                motor_angle_rad,
                table_angle_rad,
            ),
            Data::FrequencyResponseTimeCurrent {
                time_s,
                motor_current_a,
                motor_angle_rad,
                table_angle_rad,
                ..
            } => (
                time_s,
                motor_current_a,
                true,
                motor_angle_rad,
                table_angle_rad,
            ),
            _ => return None,
        };
        Some(TimeRecord {
            time_s,
            drive,
            current,
            motor_angle_rad,
            table_angle_rad,
        })
    }

    /// The kind of experiment this data belongs to.
    pub fn kind(&self) -> Kind {
        match self {
            Data::FrequencyResponse { .. } => Kind::FrequencyResponse,
            Data::Resonance { .. } => Kind::Resonance,
            Data::TorqueCurve { .. } | Data::ForceCurve { .. } => Kind::TorqueCurve,
            Data::Positioning { .. } | Data::LinearPositioning { .. } => Kind::Positioning,
            Data::Fluctuation { .. } => Kind::Fluctuation,
            Data::Unbalance { .. } => Kind::Unbalance,
            Data::FrequencyResponseTime { .. } | Data::FrequencyResponseTimeCurrent { .. } => {
                Kind::FrequencyResponseTime
            }
            Data::ServoTrace(_) => Kind::ServoTrace,
            Data::FrictionMap(_) => Kind::FrictionMap,
        }
    }

    /// The axis the positions and efforts belong to; `None` for a gain curve or
    /// resonances, which are dimensionless.
    pub fn axis(&self) -> Option<Axis> {
        match self {
            Data::FrequencyResponse { .. } | Data::Resonance { .. } => None,
            Data::ForceCurve { .. } | Data::LinearPositioning { .. } => Some(Axis::Linear),
            Data::ServoTrace(t) => Some(t.axis),
            Data::FrictionMap(m) => Some(m.axis),
            Data::TorqueCurve { .. }
            | Data::Positioning { .. }
            | Data::Fluctuation { .. }
            | Data::Unbalance { .. }
            | Data::FrequencyResponseTime { .. }
            | Data::FrequencyResponseTimeCurrent { .. } => Some(Axis::Rotary),
        }
    }

    /// Number of rows (of peaks, for resonance; of runs, for a friction map).
    pub fn len(&self) -> usize {
        match self {
            Data::FrequencyResponse {
                frequency_hz: v, ..
            }
            | Data::Resonance { peaks_hz: v, .. }
            | Data::TorqueCurve { time_s: v, .. }
            | Data::ForceCurve { time_s: v, .. }
            | Data::Positioning { target_rad: v, .. }
            | Data::LinearPositioning { target_m: v, .. }
            | Data::Fluctuation { time_s: v, .. }
            | Data::Unbalance { time_s: v, .. }
            | Data::FrequencyResponseTime { time_s: v, .. }
            | Data::FrequencyResponseTimeCurrent { time_s: v, .. }
            | Data::ServoTrace(ServoTrace { time_s: v, .. })
            | Data::FrictionMap(FrictionMap { speed: v, .. }) => v.len(),
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
            | Data::ForceCurve { extra, .. }
            | Data::Positioning { extra, .. }
            | Data::LinearPositioning { extra, .. }
            | Data::Fluctuation { extra, .. }
            | Data::Unbalance { extra, .. }
            | Data::FrequencyResponseTime { extra, .. }
            | Data::FrequencyResponseTimeCurrent { extra, .. }
            | Data::ServoTrace(ServoTrace { extra, .. })
            | Data::FrictionMap(FrictionMap { extra, .. }) => Some(extra),
        }
    }
}
