//! Which columns each kind reads, under which names, into which [`Data`] variant. The
//! names are listed once here, for the reader and for [`reserved`] (the names the writer
//! refuses for an extra column).

use super::super::data::{ServoTrace, Signal};
use super::super::friction_map::count;
use super::super::units::{units_for, SPEED_UNITS};
use super::{number, Col, Order, Table};
use crate::io::experiment_file::{
    Axis, CommandUnit, Data, ExperimentFileError as Error, FrictionMap, Kind,
};

use Order::{Any, Time};

/// The table's position in a torque curve: an angle, or a length on a linear axis.
const TABLE: [&str; 2] = ["table_angle", "table_position"];
/// The drive's effort in a torque curve: motor torque, or force on a linear axis.
const CURVE_EFFORT: [(&str, Axis); 2] =
    [("motor_torque_nm", Axis::Rotary), ("force_n", Axis::Linear)];
/// The input of a frequency-response record: a torque, or a current when the torque
/// constant is not known (FdiTools' two-mass bench).
const RECORD_INPUT: [(&str, Input); 2] = [
    ("motor_torque_nm", Input::Torque),
    ("motor_current_a", Input::Current),
];
/// The driven body's angle in a frequency-response record: `load_angle` is the name
/// of a two-mass bench's second motor (FdiTools).
const RECORD_LOAD: [&str; 2] = ["table_angle", "load_angle"];
/// The loop's encoder in a servo trace: `motor_position` is EMPS's name for it (the
/// encoder on the motor, in a semi-closed loop), kept as the file has it.
const SERVO_LOOP: [&str; 2] = ["position", "motor_position"];
/// The drive's effort in a servo trace.
const SERVO_EFFORT: [(&str, Axis); 2] = [("torque_nm", Axis::Rotary), ("force_n", Axis::Linear)];

/// A friction map's mean effort per run: torque, or force on a linear axis.
const MAP_EFFORT: [(&str, Axis); 2] = SERVO_EFFORT;
/// The standard deviation of a friction map's effort per run.
const MAP_EFFORT_STD: [(&str, Axis); 2] = [
    ("torque_std_nm", Axis::Rotary),
    ("force_std_n", Axis::Linear),
];
/// A friction map's speed columns, `{base}_{unit}` with a unit of [`SPEED_UNITS`].
const MAP_SPEEDS: [&str; 2] = ["speed", "speed_std"];
/// A friction map's counts of samples per run.
const MAP_COUNTS: [&str; 3] = ["samples", "dropped", "transient"];

/// What drives a frequency-response record.
#[derive(Clone, Copy, PartialEq)]
enum Input {
    Torque,
    Current,
}

impl Table {
    /// Frequency, gain and optionally phase.
    pub(in crate::io::experiment_file) fn frequency_response(mut self) -> Result<Data, Error> {
        let (f, g) = (self.column("frequency_hz")?, self.column("gain_db")?);
        let p = self.position(&["phase"])?;
        Ok(Data::FrequencyResponse {
            frequency_hz: self.numbers(f, Order::Frequency)?,
            gain_db: self.numbers(g, Any)?,
            phase_rad: p.map(|p| self.numbers(p, Any)).transpose()?,
            extra: self.extras(&frequency_response())?,
        })
    }

    /// A kind without a table (resonance): refused.
    pub(in crate::io::experiment_file) fn no_table(self) -> Result<Data, Error> {
        Err(Error::Manifest {
            path: self.path,
            message: "a resonance experiment has no data file".into(),
        })
    }

    /// Time, the drive's torque or force and optionally the table's angle or position,
    /// all rotary or all linear.
    pub(in crate::io::experiment_file) fn torque_curve(mut self) -> Result<Data, Error> {
        let t = self.column("time_s")?;
        let effort = self.effort(&CURVE_EFFORT)?;
        let table = self.position(&TABLE)?;
        let axis = self.same_axis(&[Some(effort), table])?;
        let time_s = self.numbers(t, Time)?;
        let effort = self.numbers(effort, Any)?;
        let table = table.map(|a| self.numbers(a, Any)).transpose()?;
        let extra = self.extras(&torque_curve())?;
        Ok(match axis {
            Axis::Rotary => Data::TorqueCurve {
                time_s,
                motor_torque_nm: effort,
                table_angle_rad: table,
                extra,
            },
            Axis::Linear => Data::ForceCurve {
                time_s,
                force_n: effort,
                table_position_m: table,
                extra,
            },
        })
    }

    /// Target, direction, run, and deviation from a `deviation_*` column or else as
    /// `measured_*` − target, in angles or in lengths. With both, `deviation_*` is used
    /// and `measured_*` kept as an extra column.
    pub(in crate::io::experiment_file) fn positioning(mut self) -> Result<Data, Error> {
        let target = self.required_position(&["target"])?;
        let (d, r) = (self.column("direction")?, self.column("run")?);
        let (deviation, measured) = match self.position(&["deviation"])? {
            Some(c) => (c, false),
            None => match self.position(&["measured"])? {
                Some(c) => (c, true),
                None => {
                    let mut names = ["measured", "deviation"].into_iter().flat_map(|b| {
                        units_for(b)
                            .iter()
                            .map(move |u| format!("{b}_{}", u.suffix))
                    });
                    let first = names.next().unwrap_or_default();
                    return Err(self.missing(&first, names.collect()));
                }
            },
        };
        let axis = self.same_axis(&[Some(target), Some(deviation)])?;
        let target_si = self.numbers(target, Any)?;
        let deviation_si = if measured {
            self.measured_minus_target(deviation, target)?
        } else {
            self.numbers(deviation, Any)?
        };
        self.deviations_in_range(&deviation_si, deviation, axis)?;
        let (direction, run) = (
            self.parse(d, |s| {
                s.parse()
                    .map_err(|e: crate::names::UnknownName| e.to_string())
            })?,
            self.parse(r, super::run)?,
        );
        let extra = self.extras(&positioning())?;
        Ok(match axis {
            Axis::Rotary => Data::Positioning {
                target_rad: target_si,
                direction,
                run,
                deviation_rad: deviation_si,
                extra,
            },
            Axis::Linear => Data::LinearPositioning {
                target_m: target_si,
                direction,
                run,
                deviation_m: deviation_si,
                extra,
            },
        })
    }

    /// Every deviation within a turn (rotary) or a metre (linear): beyond, it is not a
    /// positioning error but a wrong column or unit (and ISO 230-2's ranges of
    /// deviations of 1e308 overflow).
    fn deviations_in_range(&self, deviation_si: &[f64], col: Col, axis: Axis) -> Result<(), Error> {
        let (limit, what) = match axis {
            Axis::Rotary => (std::f64::consts::TAU, "a turn (2π rad)"),
            Axis::Linear => (1.0, "1 m"),
        };
        match deviation_si.iter().position(|d| d.abs() > limit) {
            Some(i) => Err(self.cell(
                self.rows[i].0,
                col.index,
                format!(
                    "a deviation of {:e} (SI) is beyond {what}: not a positioning error",
                    deviation_si[i]
                ),
            )),
            None => Ok(()),
        }
    }

    /// measured − target in SI units. In a common unit, subtract first and scale once:
    /// exact for close values.
    fn measured_minus_target(&self, measured: Col, target: Col) -> Result<Vec<f64>, Error> {
        let same = measured.scale == target.scale;
        let unit = |c: Col| if same { Col { scale: 1.0, ..c } } else { c };
        let m = self.numbers(unit(measured), Any)?;
        let t = self.numbers(unit(target), Any)?;
        let scale = if same { target.scale } else { 1.0 };
        let mut deviation = Vec::with_capacity(m.len());
        for ((m, t), (line, _)) in m.iter().zip(&t).zip(&self.rows) {
            let x = (m - t) * scale;
            if !x.is_finite() {
                let message = "measured − target is not finite".to_string();
                return Err(self.cell(*line, measured.index, message));
            }
            deviation.push(x);
        }
        Ok(deviation)
    }

    /// Time, motor-shaft angle and table angle (rotary only: docs/experiments.md (rotational fluctuation) evaluates
    /// θt − θm·Rg·Rw over the table angle).
    pub(in crate::io::experiment_file) fn fluctuation(mut self, kind: Kind) -> Result<Data, Error> {
        let t = self.column("time_s")?;
        let m = self.required_position(&["motor_angle"])?;
        let a = self.required_position(&["table_angle"])?;
        let (time_s, motor_angle_rad, table_angle_rad) = (
            self.numbers(t, Time)?,
            self.numbers(m, Any)?,
            self.numbers(a, Any)?,
        );
        let extra = self.extras(&fluctuation())?;
        Ok(if kind == Kind::Fluctuation {
            Data::Fluctuation {
                time_s,
                motor_angle_rad,
                table_angle_rad,
                extra,
            }
        } else {
            Data::Unbalance {
                time_s,
                motor_angle_rad,
                table_angle_rad,
                extra,
            }
        })
    }

    /// A frequency-response record: uniform time, motor torque or current, motor
    /// angle, table (or load) angle.
    pub(in crate::io::experiment_file) fn record(mut self) -> Result<Data, Error> {
        let t = self.column("time_s")?;
        let (input, kind) = self.required_one_of(&RECORD_INPUT, "input")?;
        let m = self.required_position(&["motor_angle"])?;
        let a = self.required_position(&RECORD_LOAD)?;
        let time_s = self.uniform_time(t)?;
        let (input, motor_angle_rad, table_angle_rad) = (
            self.numbers(input, Any)?,
            self.numbers(m, Any)?,
            self.numbers(a, Any)?,
        );
        let extra = self.extras(&record())?;
        Ok(match kind {
            Input::Torque => Data::FrequencyResponseTime {
                time_s,
                motor_torque_nm: input,
                motor_angle_rad,
                table_angle_rad,
                extra,
            },
            Input::Current => Data::FrequencyResponseTimeCurrent {
                time_s,
                motor_current_a: input,
                motor_angle_rad,
                table_angle_rad,
                extra,
            },
        })
    }

    /// A servo trace: uniform time, reference and loop position, optional table
    /// position, effort, optional controller output and added signal.
    pub(in crate::io::experiment_file) fn servo_trace(mut self) -> Result<Data, Error> {
        let t = self.column("time_s")?;
        let reference = self.required_position(&["reference_position"])?;
        let position = self.required_position(&SERVO_LOOP)?;
        let table = self.position(&["table_position"])?;
        let effort = self.effort(&SERVO_EFFORT)?;
        let axis = self.same_axis(&[Some(reference), Some(position), table, Some(effort)])?;
        let output = self.command("controller_output")?;
        let added = self.command("controller_added")?;
        if let (Some((_, out)), Some((col, add))) = (output, added) {
            if out != add {
                let message = format!(
                    "column `{}` is in {add} but the controller output in {out}: an added \
                     signal is in the controller output's unit",
                    self.header[col.index]
                );
                return Err(self.header_error(message));
            }
        }
        let time_s = self.uniform_time(t)?;
        let signal = |(col, unit): (Col, CommandUnit)| -> Result<Signal, Error> {
            let values = self.numbers(col, Any)?;
            Ok(Signal { unit, values })
        };
        Ok(Data::ServoTrace(ServoTrace {
            axis,
            time_s,
            reference_position: self.numbers(reference, Any)?,
            position: self.numbers(position, Any)?,
            table_position: table.map(|c| self.numbers(c, Any)).transpose()?,
            effort: self.numbers(effort, Any)?,
            controller_output: output.map(signal).transpose()?,
            controller_added: added.map(signal).transpose()?,
            extra: self.extras(&servo_trace())?,
        }))
    }

    /// A friction map: each run's speed (non-zero, distinct) and effort, optionally
    /// their standard deviations and the counts of samples averaged, dropped and left
    /// out; all rotary or all linear. The rows come back in order of increasing speed.
    pub(in crate::io::experiment_file) fn friction_map(mut self) -> Result<Data, Error> {
        let speed = self.speed(MAP_SPEEDS[0])?.ok_or_else(|| {
            let mut names = SPEED_UNITS
                .iter()
                .map(|u| format!("{}_{}", MAP_SPEEDS[0], u.suffix));
            let first = names.next().unwrap_or_default();
            self.missing(&first, names.collect())
        })?;
        let effort = self.effort(&MAP_EFFORT)?;
        let speed_std = self.speed(MAP_SPEEDS[1])?;
        let effort_std = self
            .one_of(&MAP_EFFORT_STD, "effort's deviation")?
            .map(|(col, axis)| Col {
                axis: Some(axis),
                ..col
            });
        let axis = self.same_axis(&[Some(speed), Some(effort), speed_std, effort_std])?;
        let counts = MAP_COUNTS.map(|name| {
            let index = self.find(name)?;
            self.used[index] = true;
            Some(Col {
                index,
                scale: 1.0,
                axis: None,
            })
        });
        let optional = |c: Option<Col>| c.map(|c| self.numbers(c, Any)).transpose();
        let whole = |c: Option<Col>| {
            c.map(|c| self.parse(c, |t| number(t).and_then(count)))
                .transpose()
        };
        let map = FrictionMap {
            axis,
            speed: self.map_speeds(speed)?,
            effort: self.numbers(effort, Any)?,
            speed_std: optional(speed_std)?,
            effort_std: optional(effort_std)?,
            samples: whole(counts[0])?,
            dropped: whole(counts[1])?,
            transient: whole(counts[2])?,
            extra: self.extras(&friction_map())?,
        };
        Ok(Data::FrictionMap(map.sorted()))
    }

    /// The speed column `{base}_{unit}` in any unit of [`SPEED_UNITS`], converted to
    /// rad/s or m/s, if there is one; two spellings are an error.
    fn speed(&mut self, base: &str) -> Result<Option<Col>, Error> {
        let names = SPEED_UNITS.map(|u| (format!("{base}_{}", u.suffix), u));
        let choices = names.each_ref().map(|(n, u)| (n.as_str(), *u));
        Ok(self.one_of(&choices, "speed")?.map(|(col, u)| Col {
            scale: u.si,
            axis: Some(u.axis),
            ..col
        }))
    }

    /// A friction map's speeds: none 0 (a run at rest is not on the map), no two alike
    /// (one row per run); the error names the line.
    fn map_speeds(&self, col: Col) -> Result<Vec<f64>, Error> {
        let speed = self.numbers(col, Any)?;
        if let Some(row) = speed.iter().position(|&v| v == 0.0) {
            let message = "a speed of 0: a run at rest is not on a friction map".to_string();
            return Err(self.cell(self.rows[row].0, col.index, message));
        }
        let mut order: Vec<usize> = (0..speed.len()).collect();
        order.sort_by(|&a, &b| speed[a].total_cmp(&speed[b]).then(a.cmp(&b)));
        if let Some(w) = order.windows(2).find(|w| speed[w[0]] == speed[w[1]]) {
            let (first, second) = (self.rows[w[0]].0, self.rows[w[1]].0);
            let message = format!("the same speed as line {first}: one row per run");
            return Err(self.cell(second, col.index, message));
        }
        Ok(speed)
    }

    /// Strictly increasing, uniformly sampled time.
    fn uniform_time(&self, t: Col) -> Result<Vec<f64>, Error> {
        let time_s = self.numbers(t, Time)?;
        match crate::io::experiment_file::check_uniform(&time_s) {
            Ok(()) => Ok(time_s),
            Err(e) => Err(self.cell(self.rows[e.row].0, t.index, e.to_string())),
        }
    }
}

/// A kind's reserved columns: `plain` names, and `positions` with each unit suffix.
fn reserved(plain: &[&str], positions: &[&str]) -> Vec<String> {
    let position_names = positions.iter().flat_map(|b| {
        units_for(b)
            .iter()
            .map(move |u| format!("{b}_{}", u.suffix))
    });
    plain
        .iter()
        .map(|s| s.to_string())
        .chain(position_names)
        .collect()
}

/// Columns a kind's reader or evaluators read when present, beside its [`reserved`]
/// ones (docs/experiment-files.md's optional columns): a frequency response's noise
/// per line, a positioning record's measured positions.
pub(in crate::io::experiment_file) fn optional(kind: Kind) -> Vec<String> {
    match kind {
        Kind::FrequencyResponse => [
            "gain_sigma_db",
            "phase_sigma_deg",
            "coherence",
            "below_resolution",
            "linear_gain_db",
        ]
        .map(String::from)
        .to_vec(),
        Kind::Positioning => reserved(&[], &["measured"]),
        _ => Vec::new(),
    }
}

/// The column names each kind's reader interprets: an extra column must not take one.
pub(in crate::io::experiment_file) fn frequency_response() -> Vec<String> {
    reserved(&["frequency_hz", "gain_db"], &["phase"])
}

pub(in crate::io::experiment_file) fn torque_curve() -> Vec<String> {
    reserved(&["time_s", CURVE_EFFORT[0].0, CURVE_EFFORT[1].0], &TABLE)
}

pub(in crate::io::experiment_file) fn positioning() -> Vec<String> {
    reserved(&["direction", "run"], &["target", "deviation"])
}

pub(in crate::io::experiment_file) fn fluctuation() -> Vec<String> {
    reserved(&["time_s"], &["motor_angle", "table_angle"])
}

pub(in crate::io::experiment_file) fn record() -> Vec<String> {
    let mut p = vec!["motor_angle"];
    p.extend(RECORD_LOAD);
    reserved(&["time_s", RECORD_INPUT[0].0, RECORD_INPUT[1].0], &p)
}

pub(in crate::io::experiment_file) fn servo_trace() -> Vec<String> {
    let mut p = vec!["reference_position", "table_position"];
    p.extend(SERVO_LOOP);
    let commands = ["controller_output", "controller_added"]
        .into_iter()
        .flat_map(|b| CommandUnit::ALL.map(|u| format!("{b}_{}", u.suffix())));
    let mut out = reserved(&["time_s", SERVO_EFFORT[0].0, SERVO_EFFORT[1].0], &p);
    out.extend(commands);
    out
}

pub(in crate::io::experiment_file) fn friction_map() -> Vec<String> {
    let mut plain: Vec<&str> = MAP_EFFORT.iter().map(|(n, _)| *n).collect();
    plain.extend(MAP_EFFORT_STD.iter().map(|(n, _)| *n));
    plain.extend(MAP_COUNTS);
    let speeds = MAP_SPEEDS
        .into_iter()
        .flat_map(|b| SPEED_UNITS.map(|u| format!("{b}_{}", u.suffix)));
    let mut out = reserved(&plain, &[]);
    out.extend(speeds);
    out
}
