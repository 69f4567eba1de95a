//! The replay of a servo trace: the model in closed loop, its controller sampling on
//! the record's time base and following the recorded reference, the recorded added
//! signal added to its output; and the EMPS benchmark's simulation error.

use serde::Serialize;

use super::{ServoTrace, TraceError};
use crate::model::params::{LoopMode, Params};
use crate::model::rest::moving_state;
use crate::recorder::NullRecorder;
use crate::sim::{SimError, Simulation};

/// Relative difference below which the record's sample period is taken to be the
/// controller's `Tc` exactly (the record's mean step carries rounding and jitter).
const SAME_PERIOD: f64 = 1e-6;

/// The model's side of a trace: what the drive would have recorded, at the record's
/// times (positions table-side, as in [`ServoTrace`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Replay {
    /// The record's times, s.
    pub time_s: Vec<f64>,
    /// The loop encoder's reading at each sample (quantised, delayed like the
    /// controller's), rad or m: semi-closed loop the motor encoder × Rg·Rw,
    /// full-closed the table encoder.
    pub position: Vec<f64>,
    /// The table encoder's reading at each sample, rad or m.
    pub table_position: Vec<f64>,
    /// Torque (N·m) or force (N) applied from each sample on.
    pub force: Vec<f64>,
    /// The controller output from each sample on, in its unit (added signal
    /// included).
    pub controller_output: Vec<f64>,
}

/// The most integration steps a replay may take: about 100 s at the kernel's rate of
/// about 10 M steps/s (docs/performance.md). A longer one is refused up front with its
/// cost, before any step is taken, instead of running for hours.
pub const MAX_REPLAY_STEPS: f64 = 1e9;

/// The benchmark's simulation error of a replay against its record (SI units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Misfit {
    /// RMS of replayed minus recorded position, rad or m.
    pub position_rms: f64,
    /// Largest |replayed − recorded position|, rad or m.
    pub position_max: f64,
    /// RMS of replayed minus recorded force, N·m or N.
    pub force_rms: f64,
}

/// Replays `trace` on the model `params`, closed loop, over the whole record.
///
/// The controller samples at the record's samples: its period is the record's mean
/// step (the parameters' `Tc` when they agree to 1e-6), and at sample k it reads the
/// model's encoders and the recorded reference[k] (and adds controller_added[k]). The
/// run starts from the first recorded position, the whole drive moving at the velocity
/// of the first two samples, (position[1] − position[0])/period — exact for a trace
/// at rest over its first period, as rtid's virtual traces are; a record that starts
/// in motion (EMPS) starts with that estimate, whose error fades within a few periods
/// of the velocity loop. The trace's recorded drive functions (feed-forward,
/// filters), if any, replace the model's controller's.
pub fn replay(params: &Params, trace: &ServoTrace) -> Result<Replay, TraceError> {
    let period = trace.check()?;
    let mut p = params.clone();
    if (period / p.controller.tc - 1.0).abs() > SAME_PERIOD {
        p.controller.tc = period;
    }
    if let Some(functions) = &trace.drive_functions {
        functions.apply(&mut p.controller);
        p.validate().map_err(TraceError::DriveFunctions)?;
    }
    affordable(&p, &trace.time_s)?;
    let velocity = (trace.position[1] - trace.position[0]) / period;
    let start = Start {
        position: trace.position[0],
        velocity,
    };
    Ok(run_servo(
        &p,
        &trace.time_s,
        &trace.reference,
        trace.controller_added.as_deref(),
        start,
    )?)
}

/// The replay's cost in integration steps, refused above [`MAX_REPLAY_STEPS`].
fn affordable(p: &Params, time_s: &[f64]) -> Result<(), TraceError> {
    let step_s = crate::sim::default_step(p)?;
    let duration_s = time_s[time_s.len() - 1] - time_s[0];
    let steps = duration_s / step_s;
    if steps > MAX_REPLAY_STEPS {
        return Err(TraceError::TooLong {
            steps,
            duration_s,
            step_s,
            limit: MAX_REPLAY_STEPS,
        });
    }
    Ok(())
}

/// The simulation error of `replay` against `trace`: RMS and largest position
/// error, RMS force error.
pub fn simulation_error(trace: &ServoTrace, replay: &Replay) -> Result<Misfit, TraceError> {
    let n = trace.len();
    for (field, len) in [
        ("replayed position", replay.position.len()),
        ("replayed force", replay.force.len()),
    ] {
        if len != n {
            return Err(TraceError::Length {
                field,
                len,
                expected: n,
            });
        }
    }
    let diff = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a - b).collect::<Vec<_>>();
    let rms = |d: &[f64]| (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    let position = diff(&replay.position, &trace.position);
    Ok(Misfit {
        position_rms: rms(&position),
        position_max: position.iter().fold(0.0, |m: f64, x| m.max(x.abs())),
        force_rms: rms(&diff(&replay.force, &trace.force)),
    })
}

/// Where a run starts: table-side position and velocity, every body moving rigidly.
#[derive(Clone, Copy, Debug)]
pub(super) struct Start {
    pub position: f64,
    pub velocity: f64,
}

/// The model of `p` under its controller, which samples every `Tc` and follows
/// `reference[k]` (plus `added[k]`) from sample k on; records what a drive records.
pub(super) fn run_servo(
    p: &Params,
    time_s: &[f64],
    reference: &[f64],
    added: Option<&[f64]>,
    start: Start,
) -> Result<Replay, SimError> {
    let mut sim = Simulation::with_default_step(p)?;
    sim.set_state(moving_state(p, start.position, start.velocity));
    let mut controller = sim.controller(p)?;
    if start.velocity != 0.0 {
        controller.start_moving(start.velocity / p.ratio());
    }
    let tc = controller.gains().tc;
    let n = reference.len();
    let mut out = Replay {
        time_s: time_s.to_vec(),
        position: Vec::with_capacity(n),
        table_position: Vec::with_capacity(n),
        force: Vec::with_capacity(n),
        controller_output: Vec::with_capacity(n),
    };
    for (k, &r) in reference.iter().enumerate() {
        if let Some(a) = added {
            controller.set_added(a[k]);
        }
        // One control period: the controller samples at its first step.
        sim.run_closed_loop(&mut controller, &move |_t: f64| r, tc, &mut NullRecorder)?;
        out.position.push(match p.controller.loop_mode {
            LoopMode::SemiClosed => controller.motor_reading() * p.ratio(),
            LoopMode::FullClosed => controller.table_reading(),
        });
        out.table_position.push(controller.table_reading());
        out.force.push(controller.torque());
        out.controller_output.push(controller.output());
    }
    Ok(out)
}
