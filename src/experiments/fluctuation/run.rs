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
use crate::sim::{SimError, Simulation};

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
    p.controller.loop_mode = test.loop_mode;
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
    let sense = (to - from).signum();
    let ramp = (to - from).abs() / test.speed;
    let reference = |t: f64| {
        if t < test.dwell {
            from
        } else {
            from + sense * test.speed * (t - test.dwell).min(ramp)
        }
    };
    run_reference(params, test, &reference, test.dwell + ramp, |_, _| {})
}

/// Runs `reference` (table angle over time, starting at rest at `reference(0)`) for
/// `duration` s with the test's loop, unbalance and encoders.
fn run_reference(
    params: &Params,
    test: &FluctuationTest,
    reference: &dyn Fn(f64) -> f64,
    duration: f64,
    mut progress: impl FnMut(usize, usize),
) -> Result<Record, SimError> {
    let p = test_params(params, test);
    let mut sim = Simulation::with_default_step(&p)?;
    let start = reference(0.0);
    sim.set_state(rest_state(&p, start, Preload::None));
    let mut controller = sim.controller(&p)?;
    let every = ((test.sample_period / sim.dt()).round() as u64).max(1);
    let samples = (duration / sim.dt()) as usize / every as usize + 2;
    let counts = p.controller.motor_encoder_counts;
    let mut rec = Sampler {
        every,
        count: 0,
        motor_quantum: if counts > 0.0 { TAU / counts } else { 0.0 },
        table_quantum: p.controller.table_encoder_resolution,
        time: Vec::with_capacity(samples),
        motor: Vec::with_capacity(samples),
        table: Vec::with_capacity(samples),
    };
    let total = duration.ceil() as usize;
    for second in 0..total {
        let chunk = (duration - second as f64).min(1.0);
        sim.run_closed_loop(&mut controller, &reference, chunk, &mut rec)?;
        progress(second + 1, total);
    }
    Ok(Record {
        time: rec.time,
        motor_angle: rec.motor,
        table_angle: rec.table,
    })
}
