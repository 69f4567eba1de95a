//! The replay of a servo trace: the model in closed loop, its controller sampling on
//! the record's time base and following the recorded reference, the recorded added
//! signal added to its output; and the EMPS benchmark's simulation error.

use serde::Serialize;

use super::{ServoTrace, TraceError};
use crate::controller::Controller;
use crate::model::params::{LoopMode, Params};
use crate::model::rest::moving_state;
use crate::recorder::NullRecorder;
use crate::sim::batch::{in_lanes, on_valid, LaneRun};
use crate::sim::{common_step, LaneSimulation, SimError};

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
    let run = TraceRun::of(trace)?;
    let p = prepared(params, trace, run.period)?;
    Ok(run.lone(&p)?)
}

/// [`replay`] of `trace` on each of `params`, in order, in the kernel's lanes where
/// the sets can share them (`sim::batch`): each result is what `replay` gives for
/// its set alone.
pub fn replay_batch(params: &[Params], trace: &ServoTrace) -> Vec<Result<Replay, TraceError>> {
    let run = match TraceRun::of(trace) {
        Ok(run) => run,
        Err(e) => return params.iter().map(|_| Err(e.clone())).collect(),
    };
    let sets = params
        .iter()
        .map(|p| prepared(p, trace, run.period))
        .collect();
    on_valid(sets, |sets| {
        in_lanes(sets, &run)
            .into_iter()
            .map(|r| r.map_err(TraceError::from))
            .collect()
    })
}

/// `params` as the replay of `trace` (its sample period `period`, checked) runs
/// them: the controller's period the record's (when they differ by more than
/// [`SAME_PERIOD`]), the trace's recorded drive functions set; refused if the replay
/// would take more than [`MAX_REPLAY_STEPS`] steps.
fn prepared(params: &Params, trace: &ServoTrace, period: f64) -> Result<Params, TraceError> {
    let mut p = params.clone();
    if (period / p.controller.tc - 1.0).abs() > SAME_PERIOD {
        p.controller.tc = period;
    }
    if let Some(functions) = &trace.drive_functions {
        functions.apply(&mut p.controller);
        p.validate().map_err(TraceError::DriveFunctions)?;
    }
    affordable(&p, &trace.time_s)?;
    Ok(p)
}

/// A trace's replay as a [`LaneRun`]: its reference and added signal, and where
/// the run starts.
struct TraceRun<'a> {
    /// The record's sample period, s ([`ServoTrace::check`]).
    period: f64,
    time_s: &'a [f64],
    reference: &'a [f64],
    added: Option<&'a [f64]>,
    start: Start,
}

impl<'a> TraceRun<'a> {
    /// The replay of `trace`: from the first recorded position, the whole drive
    /// moving at the velocity of the first two samples.
    fn of(trace: &'a ServoTrace) -> Result<Self, TraceError> {
        let period = trace.check()?;
        let start = Start {
            position: trace.position[0],
            velocity: (trace.position[1] - trace.position[0]) / period,
        };
        Ok(TraceRun {
            period,
            time_s: &trace.time_s,
            reference: &trace.reference,
            added: trace.controller_added.as_deref(),
            start,
        })
    }
}

impl LaneRun for TraceRun<'_> {
    type Out = Replay;

    fn lone(&self, p: &Params) -> Result<Replay, SimError> {
        run_servo(p, self.time_s, self.reference, self.added, self.start)
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Replay, SimError>; L], SimError> {
        run_servo_lanes(
            params,
            self.time_s,
            (self.reference, self.added),
            self.start,
        )
    }
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
    let [one] = run_servo_lanes(std::array::from_ref(p), time_s, (reference, added), start)?;
    one
}

/// [`run_servo`] on `L` models at once, one per lane, lane `l` as a lone run of
/// `params[l]` computes it (a set that diverges fails alone); the sets must share
/// their integration step and control period.
fn run_servo_lanes<const L: usize>(
    params: &[Params; L],
    time_s: &[f64],
    (reference, added): (&[f64], Option<&[f64]>),
    start: Start,
) -> Result<[Result<Replay, SimError>; L], SimError> {
    let mut sim = LaneSimulation::<L>::of(params, common_step(params)?)?;
    for (l, p) in params.iter().enumerate() {
        sim.start(l, moving_state(p, start.position, start.velocity), 0.0);
    }
    let mut controllers = sim.controllers(params)?;
    if start.velocity != 0.0 {
        for (c, p) in controllers.iter_mut().zip(params) {
            c.start_moving(start.velocity / p.ratio());
        }
    }
    let tc = controllers[0].gains().tc;
    let mut out: [Replay; L] = std::array::from_fn(|_| Replay::with_capacity(time_s));
    let mut failed: [Option<SimError>; L] = std::array::from_fn(|_| None);
    let mut null: [NullRecorder; L] = std::array::from_fn(|_| NullRecorder);
    for (k, &r) in reference.iter().enumerate() {
        if let Some(a) = added {
            controllers.iter_mut().for_each(|c| c.set_added(a[k]));
        }
        // One control period: the controllers sample at its first step.
        let run = (&mut controllers, &mut null);
        sim.run_closed_loop(run, &move |_t: f64| r, tc, &mut failed)?;
        for l in (0..L).filter(|&l| failed[l].is_none()) {
            out[l].push(
                &controllers[l],
                params[l].controller.loop_mode,
                params[l].ratio(),
            );
        }
        if failed.iter().all(Option::is_some) {
            break;
        }
    }
    let mut out = out.into_iter();
    Ok(failed.map(|f| {
        let replay = out.next().expect("one per lane");
        f.map_or(Ok(replay), Err)
    }))
}

impl Replay {
    /// An empty replay on the record's times `time_s`.
    fn with_capacity(time_s: &[f64]) -> Replay {
        let n = time_s.len();
        Replay {
            time_s: time_s.to_vec(),
            position: Vec::with_capacity(n),
            table_position: Vec::with_capacity(n),
            force: Vec::with_capacity(n),
            controller_output: Vec::with_capacity(n),
        }
    }

    /// Records what `controller` read and applied at a sample: the loop encoder
    /// (semi-closed loop the motor's × `ratio`), the table encoder, the force and
    /// the controller's output.
    fn push(&mut self, controller: &Controller, mode: LoopMode, ratio: f64) {
        self.position.push(match mode {
            LoopMode::SemiClosed => controller.motor_reading() * ratio,
            LoopMode::FullClosed => controller.table_reading(),
        });
        self.table_position.push(controller.table_reading());
        self.force.push(controller.torque());
        self.controller_output.push(controller.output());
    }
}
