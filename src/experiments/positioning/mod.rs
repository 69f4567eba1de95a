//! The positioning accuracy and repeatability test as a virtual experiment (paper
//! §4.3, docs/experiments.md (positioning)): the ISO 230-2 standard test cycle run by the servo on the
//! model, read by the table encoder at the end of each dwell.
//!
//! Cycle, per run: start `overrun` below the first target, approach every target in
//! ascending order (direction up), dwell, read; continue `overrun` past the last
//! target, approach every target in descending order (down), dwell, read; return to
//! the start. Moves are ramps at `speed`; the reading is the table encoder's
//! (quantised to its resolution) plus optional Gaussian measurement noise.

pub mod compensate;
pub mod iso230;

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

use crate::controller::{quantise, Compensation};
use crate::input::Move;
use crate::io::experiment_file::{Approaches, Data, Kind, Manifest};
use crate::model::idx::THETA_T;
use crate::model::params::{Axis, LoopMode, Params};
use crate::model::rest::{rest_state, Preload};
use crate::recorder::NullRecorder;
use crate::sim::{SimError, Simulation};
use iso230::{Direction, Measurement, ARCSEC_PER_RAD};

/// Conditions of the test (defaults: docs/experiments.md (positioning)).
#[derive(Clone, Debug, PartialEq)]
pub struct PositioningTest {
    /// Target table angles, rad (default every 30° from 0° to 360°).
    pub targets: Vec<f64>,
    /// Approaches of each target in each direction (default 5).
    pub runs: u32,
    /// Dwell before each reading, s (default 1).
    pub dwell: f64,
    /// Table speed of the moves, rad/s (default 3600°/min).
    pub speed: f64,
    /// Travel beyond the first and last target before reversing, rad (default 5°).
    pub overrun: f64,
    /// Standard deviation of added measurement noise, rad (default 0); finite.
    pub noise: f64,
    /// Seed of the noise generator.
    pub seed: u64,
    /// Feedback arrangement (default semi-closed, as in the paper).
    pub loop_mode: LoopMode,
    /// The controller's compensations (default none).
    pub compensation: Compensation,
}

impl Default for PositioningTest {
    fn default() -> Self {
        PositioningTest {
            targets: (0..=12).map(|i| (30.0 * i as f64).to_radians()).collect(),
            runs: 5,
            dwell: 1.0,
            speed: (3600.0f64 / 60.0).to_radians(),
            overrun: 5f64.to_radians(),
            noise: 0.0,
            seed: 0,
            loop_mode: LoopMode::SemiClosed,
            compensation: Compensation::default(),
        }
    }
}

/// A stop of the cycle: commanded angle, and the reading taken there (target,
/// direction, run), if any.
type Stop = (f64, Option<(f64, Direction, u32)>);

impl PositioningTest {
    /// The standard cycle on `axis`: a rotary table's is the default (every 30°);
    /// a linear axis's every 50 mm over 500 mm at 3000 mm/min, 5 mm beyond the ends
    /// (as `rtid experiment positioning` runs them).
    pub fn standard(axis: Axis) -> Self {
        match axis {
            Axis::Rotary => PositioningTest::default(),
            Axis::Linear => PositioningTest {
                targets: (0..=10).map(|i| 0.05 * i as f64).collect(),
                speed: 3.0 / 60.0,
                overrun: 5e-3,
                ..PositioningTest::default()
            },
        }
    }

    /// The sequence of (commanded angle, reading taken there as which measurement).
    fn cycle(&self) -> Vec<Stop> {
        let mut targets = self.targets.clone();
        targets.sort_by(f64::total_cmp);
        let (first, last) = (targets[0], targets[targets.len() - 1]);
        let mut stops = vec![(first - self.overrun, None)];
        for run in 1..=self.runs {
            for &t in &targets {
                stops.push((t, Some((t, Direction::Up, run))));
            }
            stops.push((last + self.overrun, None));
            for &t in targets.iter().rev() {
                stops.push((t, Some((t, Direction::Down, run))));
            }
            stops.push((first - self.overrun, None));
        }
        stops
    }

    /// Simulated time the cycle takes, s (moves plus dwells).
    pub fn duration(&self) -> f64 {
        let stops = self.cycle();
        stops
            .windows(2)
            .map(|w| (w[1].0 - w[0].0).abs() / self.speed + self.dwell)
            .sum()
    }

    /// Number of readings.
    pub fn readings(&self) -> usize {
        2 * self.targets.len() * self.runs as usize
    }
}

/// Runs the cycle on the model. `progress(done, total)` is called after each reading.
pub fn run(
    params: &Params,
    test: &PositioningTest,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<Measurement>, SimError> {
    let mut p = params.clone();
    p.controller.loop_mode = test.loop_mode;
    let resolution = p.controller.table_encoder_resolution;
    let mut sim = Simulation::with_default_step(&p)?;
    let stops = test.cycle();
    // Start at rest at the first stop, controller aligned with it.
    let start = stops[0].0;
    sim.set_state(rest_state(&p, start, Preload::None));
    let mut controller = sim.controller(&p)?;
    controller.set_compensation(test.compensation.clone());
    // Invariant: Normal refuses only a non-finite σ; `noise` is finite (its field's
    // contract; the command line checks it).
    let noise = Normal::new(0.0, test.noise.max(0.0)).expect("a finite σ");
    let mut rng = rand::rngs::StdRng::seed_from_u64(test.seed);
    let total = test.readings();
    let mut out = Vec::with_capacity(total);
    for w in stops.windows(2) {
        let (from, to) = (w[0].0, w[1].0);
        let t0 = sim.time();
        let m = Move {
            from,
            to,
            speed: Some(test.speed),
        };
        let duration = (to - from).abs() / test.speed + test.dwell;
        let reference = |t: f64| crate::input::Trajectory::angle(&m, t - t0);
        sim.run_closed_loop(&mut controller, &reference, duration, &mut NullRecorder)?;
        if let Some((target, direction, run)) = w[1].1 {
            let reading = quantise(sim.state()[THETA_T], resolution) + noise.sample(&mut rng);
            out.push(Measurement {
                target,
                direction,
                run,
                deviation: reading - target,
            });
            progress(out.len(), total);
        }
    }
    Ok(out)
}

/// The experiment-file form of a positioning test's readings on `axis` (angles in
/// rad, or lengths in m).
pub fn to_data(measurements: &[Measurement], axis: Axis) -> Data {
    let approaches = Approaches {
        target: measurements.iter().map(|m| m.target).collect(),
        direction: measurements.iter().map(|m| m.direction).collect(),
        run: measurements.iter().map(|m| m.run).collect(),
        deviation: measurements.iter().map(|m| m.deviation).collect(),
    };
    Data::positioning(axis, approaches)
}

/// The readings of a positioning experiment file (`None` for another kind): rad on
/// a rotary axis, m on a linear one.
pub fn from_data(data: &Data) -> Option<Vec<Measurement>> {
    let (target, direction, run, deviation) = match data {
        Data::Positioning {
            target_rad,
            direction,
            run,
            deviation_rad,
            ..
        } => (target_rad, direction, run, deviation_rad),
        Data::LinearPositioning {
            target_m,
            direction,
            run,
            deviation_m,
            ..
        } => (target_m, direction, run, deviation_m),
        _ => return None,
    };
    Some(
        (0..target.len())
            .map(|i| Measurement {
                target: target[i],
                direction: direction[i],
                run: run[i],
                deviation: deviation[i],
            })
            .collect(),
    )
}

/// The manifest of a virtual positioning test.
pub fn manifest(params: &Params, test: &PositioningTest) -> Manifest {
    let mut m = Manifest::new(Kind::Positioning);
    m.mechanism = Some(params.name.clone());
    m.conditions.loop_mode = Some(test.loop_mode);
    m.conditions.dwell_s = Some(test.dwell);
    let resolution = params.controller.table_encoder_resolution;
    let (encoder, noise) = match params.axis {
        Axis::Rotary => {
            m.conditions.speed_deg_per_min = Some(test.speed.to_degrees() * 60.0);
            (
                format!("{:.6}°", resolution.to_degrees()),
                format!("{:.3}″", test.noise * ARCSEC_PER_RAD),
            )
        }
        Axis::Linear => (
            if resolution > 0.0 {
                format!("{:.4} µm", resolution * 1e6)
            } else {
                "exact (no quantum)".into()
            },
            format!("{:.3} µm", test.noise * 1e6),
        ),
    };
    m.notes = Some(format!(
        "virtual ISO 230-2 test by rtid: {} targets, {} runs each way, table encoder {encoder} {}{}{}",
        test.targets.len(),
        test.runs,
        if test.noise > 0.0 {
            format!("plus {noise} rms noise (seed {})", test.seed)
        } else {
            "without added noise".into()
        },
        if params.axis == Axis::Linear {
            format!(", speed {:.0} mm/min", test.speed * 6e4)
        } else {
            String::new()
        },
        if test.compensation.is_off() {
            ""
        } else {
            ", with the CNC's compensation (backlash, error table) in the controller"
        }
    ));
    m
}
