//! Running the fluctuation and unbalance tests on the model: the servo drives the table
//! through the commanded passes while both encoders are recorded.

use std::f64::consts::TAU;

use super::FluctuationTest;
use crate::controller::quantise;
use crate::model::idx::{THETA_M, THETA_T};
use crate::model::params::Params;
use crate::model::rest::{rest_state, Preload};
use crate::model::NSTATE;
use crate::recorder::Recorder;
use crate::sim::batch::{in_lanes, LaneRun};
use crate::sim::{common_step, LaneSimulation, SimError};

/// Keeps every `every`-th step's encoder readings in vectors reserved up front.
struct Sampler {
    every: u64,
    count: u64,
    motor_quantum: f64,
    table_quantum: f64,
    time: Vec<f64>,
    motor: Vec<f64>,
    table: Vec<f64>,
}

impl Sampler {
    /// Every `every`-th step of a run of `p`, about `samples` of them.
    fn new(p: &Params, every: u64, samples: usize) -> Sampler {
        let counts = p.controller.motor_encoder_counts;
        Sampler {
            every,
            count: 0,
            motor_quantum: if counts > 0.0 { TAU / counts } else { 0.0 },
            table_quantum: p.controller.table_encoder_resolution,
            time: Vec::with_capacity(samples),
            motor: Vec::with_capacity(samples),
            table: Vec::with_capacity(samples),
        }
    }
}

impl Recorder for Sampler {
    #[inline]
    fn record(&mut self, t: f64, y: &[f64; NSTATE], _motor_torque: f64) {
        if self.count % self.every == 0 {
            self.time.push(t);
            self.motor.push(quantise(y[THETA_M], self.motor_quantum));
            self.table.push(quantise(y[THETA_T], self.table_quantum));
        }
        self.count += 1;
    }
}

/// A recorded run: encoder readings over time (rad, s).
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub time: Vec<f64>,
    pub motor_angle: Vec<f64>,
    pub table_angle: Vec<f64>,
}

/// The parameters the test runs with: loop mode and unbalance set.
pub(crate) fn test_params(params: &Params, test: &FluctuationTest) -> Params {
    let mut p = params.clone();
    p.controller.loop_mode = test.loop_on(params);
    let (mass, radius) = test.unbalance.unwrap_or((0.0, 0.0));
    p.unbalance_mass = mass;
    p.unbalance_radius = radius;
    p
}

/// Runs the test on the model. `progress(done, total)` reports simulated seconds.
pub fn run(
    params: &Params,
    test: &FluctuationTest,
    progress: impl FnMut(usize, usize),
) -> Result<Record, SimError> {
    let reference = |t: f64| test.reference(t);
    run_reference(params, test, &reference, test.duration(), progress)
}

/// The test's run through one window of table angle only: at rest at `from` (rad)
/// for the test's dwell, then at the test's speed to `to`, recorded as [`run`] records
/// (same servo, same encoders, same sampling). Start `from` a run-in before the angles
/// of interest, so that the speed is steady there.
pub(crate) fn run_window(
    params: &Params,
    test: &FluctuationTest,
    from: f64,
    to: f64,
) -> Result<Record, SimError> {
    let (reference, duration) = window(test, from, to);
    run_reference(params, test, &reference, duration, |_, _| {})
}

/// The test on each of `params`, in order, in the kernel's lanes where the sets can
/// share them (`sim::batch`): each record is what [`run`] gives for its set alone.
pub fn run_batch(params: &[Params], test: &FluctuationTest) -> Vec<Result<Record, SimError>> {
    let sets: Vec<Params> = params.iter().map(|p| test_params(p, test)).collect();
    let reference = |t: f64| test.reference(t);
    let passes = Passes {
        test,
        reference: &reference,
        duration: test.duration(),
    };
    in_lanes(&sets, &passes)
}

/// The windows of [`run_window`] on each of `params` (`windows[i]` for set i,
/// radians from, to), in the kernel's lanes where the sets and their windows can
/// share them: each record is what `run_window` gives alone.
pub(crate) fn run_window_batch(
    params: &[Params],
    test: &FluctuationTest,
    (from, to): (f64, f64),
) -> Vec<Result<Record, SimError>> {
    let sets: Vec<Params> = params.iter().map(|p| test_params(p, test)).collect();
    let (reference, duration) = window(test, from, to);
    let passes = Passes {
        test,
        reference: &reference,
        duration,
    };
    in_lanes(&sets, &passes)
}

/// The reference of a window: at rest at `from` for the test's dwell, then at the
/// test's speed to `to`; and its duration.
fn window(test: &FluctuationTest, from: f64, to: f64) -> (impl Fn(f64) -> f64 + '_, f64) {
    let sense = (to - from).signum();
    let ramp = (to - from).abs() / test.speed;
    let reference = move |t: f64| {
        if t < test.dwell {
            from
        } else {
            from + sense * test.speed * (t - test.dwell).min(ramp)
        }
    };
    (reference, test.dwell + ramp)
}

/// A run of the test along `reference` (table angle over time, starting at rest at
/// `reference(0)`) for `duration` s, as a [`LaneRun`].
struct Passes<'a> {
    test: &'a FluctuationTest,
    reference: &'a dyn Fn(f64) -> f64,
    duration: f64,
}

impl LaneRun for Passes<'_> {
    type Out = Record;

    fn lone(&self, p: &Params) -> Result<Record, SimError> {
        let [one] = run_lanes(std::array::from_ref(p), self, |_, _| {})?;
        one
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Record, SimError>; L], SimError> {
        run_lanes(params, self, |_, _| {})
    }
}

/// Runs `reference` (table angle over time, starting at rest at `reference(0)`) for
/// `duration` s with the test's loop, unbalance and encoders.
fn run_reference(
    params: &Params,
    test: &FluctuationTest,
    reference: &dyn Fn(f64) -> f64,
    duration: f64,
    progress: impl FnMut(usize, usize),
) -> Result<Record, SimError> {
    let p = test_params(params, test);
    let passes = Passes {
        test,
        reference,
        duration,
    };
    let [one] = run_lanes(std::array::from_ref(&p), &passes, progress)?;
    one
}

/// [`Passes`] on `L` parameter sets at once (already [`test_params`]), lane `l` as a
/// lone run of `params[l]` computes it (a set that diverges fails alone);
/// `progress(done, total)` reports simulated seconds.
fn run_lanes<const L: usize>(
    params: &[Params; L],
    passes: &Passes<'_>,
    mut progress: impl FnMut(usize, usize),
) -> Result<[Result<Record, SimError>; L], SimError> {
    let dt = common_step(params)?;
    let mut sim = LaneSimulation::<L>::of(params, dt)?;
    let start = (passes.reference)(0.0);
    for (l, p) in params.iter().enumerate() {
        sim.start(l, rest_state(p, start, Preload::None), 0.0);
    }
    let mut controllers = sim.controllers(params)?;
    let every = ((passes.test.sample_period / dt).round() as u64).max(1);
    let samples = (passes.duration / dt) as usize / every as usize + 2;
    let mut rec: [Sampler; L] = std::array::from_fn(|l| Sampler::new(&params[l], every, samples));
    let mut failed: [Option<SimError>; L] = std::array::from_fn(|_| None);
    let total = passes.duration.ceil() as usize;
    for second in 0..total {
        let chunk = (passes.duration - second as f64).min(1.0);
        let run = (&mut controllers, &mut rec);
        sim.run_closed_loop(run, &passes.reference, chunk, &mut failed)?;
        progress(second + 1, total);
        if failed.iter().all(Option::is_some) {
            break;
        }
    }
    let mut rec = rec.into_iter();
    Ok(failed.map(|f| {
        let r = rec.next().expect("one per lane");
        let record = Record {
            time: r.time,
            motor_angle: r.motor,
            table_angle: r.table,
        };
        f.map_or(Ok(record), Err)
    }))
}
