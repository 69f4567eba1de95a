//! Servo traces: recorded closed-loop runs of an axis, their replay on the model, the
//! benchmark's simulation error, virtual traces of rtid's own presets, and the
//! friction law fitted to any of them (docs/model.md §1).
//!
//! A [`ServoTrace`] is what a drive's oscilloscope records at its control period:
//! time, the position reference, the loop encoder, optionally a second (table)
//! encoder, the drive's force or torque, optionally the controller output and a signal
//! added to it (test pulses, dither). SI units throughout, and **table-side positions**:
//! rad on a rotary axis, m on a linear one. For a geared table in semi-closed loop the
//! loop encoder is the motor's, and `position` is its reading times Rg·Rw (the table
//! angle the motor encoder implies, lost motion not included); in full-closed loop it is
//! the table encoder's reading. `force` is the torque at the motor (N·m) or the
//! force on the carriage (N). The type is plain data, independent of the experiment
//! files (`io`), which read and write it.
//!
//! - [`replay`]: the model driven by the recorded reference through the sampled
//!   controller, closed loop, over the whole record (the EMPS benchmark's simulation);
//! - [`simulation_error`]: the benchmark's metric, RMS and largest position error and
//!   RMS force error;
//! - [`virtual_trace`]: the model run along [`TrapezoidalMoves`] and recorded as a
//!   trace (quantised encoders), so that rtid makes traces of its own presets;
//! - [`ServoTrace::fit_friction`]: the friction law F = M·a + Fv·v + Fc·sign(v) +
//!   offset by inverse-dynamic least squares (inverse_dynamics.rs);
//! - [`ServoTrace::from_file`]: a trace from a `servo_trace` experiment file.
//!
//! Reference: A. Janot, M. Gautier, M. Brunot, "Data Set and Reference Models of EMPS",
//! Nonlinear System Identification Benchmarks workshop, Eindhoven, 2019.

mod evaluate;
mod replay;
mod virtual_trace;

pub use evaluate::{evaluate, EvaluateError, TraceEvaluation};
pub use replay::{replay, replay_batch, simulation_error, Misfit, Replay};
pub use virtual_trace::{command_unit, to_file, virtual_trace, MoveTo, TrapezoidalMoves};

use crate::estimation::inverse_dynamics::{self, IdimError, IdimFit, IdimSettings};
use crate::io::experiment_file::{self as file, check_uniform, sample_period, NonUniform};
use crate::sim::SimError;

/// A recorded closed-loop run, SI units, table-side positions (module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ServoTrace {
    /// Sample times, s: the controller's samples, uniformly spaced (storage jitter up
    /// to 1e-3 of a period is tolerated).
    pub time_s: Vec<f64>,
    /// The position reference (command), rad or m.
    pub reference: Vec<f64>,
    /// The loop encoder's reading, rad or m (semi-closed loop: the motor encoder
    /// times Rg·Rw; full-closed: the table encoder).
    pub position: Vec<f64>,
    /// A second, table encoder's reading, rad or m, if recorded.
    pub table_position: Option<Vec<f64>>,
    /// The drive's torque at the motor (N·m) or force (N).
    pub force: Vec<f64>,
    /// The controller output in its own unit (V, A, or N·m/N for a torque command),
    /// the added signal included, if recorded.
    pub controller_output: Option<Vec<f64>>,
    /// The signal added to the controller output, same unit, if any.
    pub controller_added: Option<Vec<f64>>,
    /// The drive's controller functions as recorded (feed-forward, filters), which a
    /// replay sets on the model's controller; `None`: the model's own.
    pub drive_functions: Option<file::DriveFunctions>,
}

/// A trace that cannot be replayed or evaluated, or a replay that failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TraceError {
    #[error("the trace has {samples} samples; at least 2 are needed")]
    TooShort { samples: usize },
    #[error("trace field {field} has {len} samples, time_s has {expected}")]
    Length {
        field: &'static str,
        len: usize,
        expected: usize,
    },
    #[error("trace field {field}, row {row}: {value} is not a finite number")]
    NotFinite {
        field: &'static str,
        row: usize,
        value: f64,
    },
    #[error("trace time_s, row {row}: {0}", row = .0.row)]
    NotUniform(NonUniform),
    #[error("the trace's `conditions.controller`: {0}")]
    DriveFunctions(crate::model::ParamError),
    #[error("trapezoidal moves: {name} = {value} {reason}")]
    Moves {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error(
        "replaying the trace takes {steps:.2e} steps of the model ({duration_s} s of \
         record at its integration step of {step_s:.3e} s), more than the {limit:.0e} \
         (about 100 s at 10 M steps/s) a replay may take, and an identification replays \
         it many times: cut the record to the stretch needed (its file's rows), or take \
         a model whose stiffest mode allows a longer step (rtid modes)"
    )]
    TooLong {
        steps: f64,
        duration_s: f64,
        step_s: f64,
        limit: f64,
    },
    #[error(transparent)]
    Simulation(#[from] SimError),
}

/// A trace the friction law cannot be fitted to.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    #[error(transparent)]
    Trace(#[from] TraceError),
    #[error(transparent)]
    Fit(#[from] IdimError),
}

impl ServoTrace {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// Whether the trace has no samples.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// Checks equal lengths, finite values and a uniform time base; returns the
    /// sample period, s.
    pub fn check(&self) -> Result<f64, TraceError> {
        let n = self.len();
        if n < 2 {
            return Err(TraceError::TooShort { samples: n });
        }
        for (field, series) in self.series() {
            if series.len() != n {
                return Err(TraceError::Length {
                    field,
                    len: series.len(),
                    expected: n,
                });
            }
            if let Some(row) = series.iter().position(|v| !v.is_finite()) {
                return Err(TraceError::NotFinite {
                    field,
                    row,
                    value: series[row],
                });
            }
        }
        check_uniform(&self.time_s).map_err(TraceError::NotUniform)?;
        Ok(sample_period(&self.time_s).unwrap_or(f64::NAN))
    }

    /// Every series present, with its field name.
    fn series(&self) -> Vec<(&'static str, &[f64])> {
        let mut out: Vec<(&'static str, &[f64])> = vec![
            ("time_s", &self.time_s),
            ("reference", &self.reference),
            ("position", &self.position),
            ("force", &self.force),
        ];
        let optional = [
            ("table_position", &self.table_position),
            ("controller_output", &self.controller_output),
            ("controller_added", &self.controller_added),
        ];
        for (name, s) in optional {
            if let Some(s) = s {
                out.push((name, s));
            }
        }
        out
    }

    /// The trace of a `servo_trace` experiment file (read and checked by `io`): the
    /// reference, the loop encoder, the effort, the controller signals' values.
    pub fn from_file(trace: &file::ServoTrace) -> ServoTrace {
        ServoTrace {
            time_s: trace.time_s.clone(),
            reference: trace.reference_position.clone(),
            position: trace.position.clone(),
            table_position: trace.table_position.clone(),
            force: trace.effort.clone(),
            controller_output: trace.controller_output.as_ref().map(|s| s.values.clone()),
            controller_added: trace.controller_added.as_ref().map(|s| s.values.clone()),
            drive_functions: None,
        }
    }

    /// The trace of the `servo_trace` experiment `exp`, with the controller functions
    /// its manifest states (`conditions.controller`); `None` for another kind.
    pub fn from_experiment(exp: &file::Experiment) -> Option<ServoTrace> {
        let file::Data::ServoTrace(data) = &exp.data else {
            return None;
        };
        Some(ServoTrace::from_record(data, &exp.manifest.conditions))
    }

    /// The trace of a `servo_trace` file's data with the controller functions its
    /// manifest's `conditions` state.
    pub fn from_record(trace: &file::ServoTrace, conditions: &file::Conditions) -> ServoTrace {
        ServoTrace {
            drive_functions: conditions.controller.clone(),
            ..ServoTrace::from_file(trace)
        }
    }

    /// The trace as a `servo_trace` experiment file's data on `axis`, the controller
    /// signals in `unit`.
    pub fn to_file(&self, axis: file::Axis, unit: file::CommandUnit) -> file::ServoTrace {
        let signal = |v: &Option<Vec<f64>>| {
            v.as_ref().map(|values| file::Signal {
                unit,
                values: values.clone(),
            })
        };
        file::ServoTrace {
            axis,
            time_s: self.time_s.clone(),
            reference_position: self.reference.clone(),
            position: self.position.clone(),
            table_position: self.table_position.clone(),
            effort: self.force.clone(),
            controller_output: signal(&self.controller_output),
            controller_added: signal(&self.controller_added),
            extra: Default::default(),
        }
    }

    /// The friction law F = M·a + Fv·v + Fc·sign(v) + offset fitted to the loop
    /// encoder's position and the force (inverse_dynamics.rs). On a geared axis
    /// these are in neither frame (the motor's torque over the table's acceleration):
    /// [`ServoTrace::fit_friction_at_motor`] gives them at the motor.
    pub fn fit_friction(&self, settings: &IdimSettings) -> Result<IdimFit, FitError> {
        self.fit_on(&self.position, settings)
    }

    /// [`ServoTrace::fit_friction`] with the position taken to the motor side,
    /// divided by `ratio` (table turns per motor turn, Rg·Rw): J, Fv, Fc and the
    /// offset at the motor, the speed threshold in motor rad/s.
    pub fn fit_friction_at_motor(
        &self,
        ratio: f64,
        settings: &IdimSettings,
    ) -> Result<IdimFit, FitError> {
        let motor: Vec<f64> = self.position.iter().map(|x| x / ratio).collect();
        self.fit_on(&motor, settings)
    }

    /// IDIM-LS of `position` (the trace's, in some frame) against the force.
    fn fit_on(&self, position: &[f64], settings: &IdimSettings) -> Result<IdimFit, FitError> {
        let period = self.check()?;
        Ok(inverse_dynamics::identify(
            period,
            position,
            &self.force,
            settings,
        )?)
    }
}
