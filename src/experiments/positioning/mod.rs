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
pub mod ensemble;
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
use crate::sim::batch::LaneRun;
use crate::sim::{LaneSimulation, SimError};
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
    /// Feedback arrangement; `None` (the default): the parameter set's own
    /// (`controller.loop`; semi-closed in the presets, as in the paper).
    pub loop_mode: Option<LoopMode>,
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
            loop_mode: None,
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

    /// The feedback arrangement the test runs `params` in: its own, or the test's.
    pub fn loop_on(&self, params: &Params) -> LoopMode {
        self.loop_mode.unwrap_or(params.controller.loop_mode)
    }
}

/// Runs the cycle on the model. `progress(done, total)` is called after each reading.
pub fn run(
    params: &Params,
    test: &PositioningTest,
    progress: impl FnMut(usize, usize),
) -> Result<Vec<Measurement>, SimError> {
    let lane = [Lane::of(test)];
    let [one] = run_lanes(&[test_params(params, test)], test, lane, progress)?;
    one
}

/// [`run`] for each of `params`, in order, in the kernel's lanes where the sets can
/// share them (`sim::batch`): each result is what `run` gives for its set alone.
pub fn run_batch(
    params: &[Params],
    test: &PositioningTest,
) -> Vec<Result<Vec<Measurement>, SimError>> {
    let sets: Vec<Params> = params.iter().map(|p| test_params(p, test)).collect();
    crate::sim::batch::in_lanes(&sets, &Cycle(test))
}

/// [`run_batch`] with each set's own compensation in the controller
/// (`compensations[i]` for `params[i]`) in place of the test's: the second cycle of
/// settings whose compensation was built from their first (`rtid tune`).
pub fn run_batch_compensated(
    params: &[Params],
    test: &PositioningTest,
    compensations: &[Compensation],
) -> Vec<Result<Vec<Measurement>, SimError>> {
    let sets: Vec<Params> = params.iter().map(|p| test_params(p, test)).collect();
    let each = Compensated {
        test,
        sets: &sets,
        compensations,
    };
    crate::sim::batch::in_lanes(&sets, &each)
}

/// The cycle with each set's compensation, for `sim::batch`: a lane's set is found
/// among `sets` by equality (equal sets have equal cycles, hence equal compensations).
struct Compensated<'a> {
    test: &'a PositioningTest,
    sets: &'a [Params],
    compensations: &'a [Compensation],
}

impl Compensated<'_> {
    fn of(&self, p: &Params) -> Lane {
        let compensation = self
            .sets
            .iter()
            .position(|s| s == p)
            .map_or_else(Compensation::default, |i| self.compensations[i].clone());
        Lane {
            compensation,
            seed: self.test.seed,
        }
    }
}

impl LaneRun for Compensated<'_> {
    type Out = Vec<Measurement>;

    fn lone(&self, p: &Params) -> Result<Vec<Measurement>, SimError> {
        let [one] = run_lanes(std::array::from_ref(p), self.test, [self.of(p)], |_, _| {})?;
        one
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Vec<Measurement>, SimError>; L], SimError> {
        run_lanes(
            params,
            self.test,
            params.each_ref().map(|p| self.of(p)),
            |_, _| {},
        )
    }
}

/// The test's cycle, for `sim::batch`.
struct Cycle<'a>(&'a PositioningTest);

impl LaneRun for Cycle<'_> {
    type Out = Vec<Measurement>;

    fn lone(&self, p: &Params) -> Result<Vec<Measurement>, SimError> {
        run(p, self.0, |_, _| {})
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Vec<Measurement>, SimError>; L], SimError> {
        run_lanes(
            params,
            self.0,
            std::array::from_fn(|_| Lane::of(self.0)),
            |_, _| {},
        )
    }
}

/// `params` with the test's feedback arrangement.
fn test_params(params: &Params, test: &PositioningTest) -> Params {
    let mut p = params.clone();
    p.controller.loop_mode = test.loop_on(params);
    p
}

/// What one lane of a cycle runs with beyond its parameter set: the controller's
/// compensation and the seed of its measurement noise.
#[derive(Clone, Debug, PartialEq)]
struct Lane {
    compensation: Compensation,
    seed: u64,
}

impl Lane {
    /// The test's own compensation and seed.
    fn of(test: &PositioningTest) -> Lane {
        Lane {
            compensation: test.compensation.clone(),
            seed: test.seed,
        }
    }
}

/// The cycle on `L` parameter sets at once (already [`test_params`]), lane by lane
/// as a lone run computes it, each with its compensation and noise seed: one result
/// per set (a set that diverges fails alone). `progress` counts the readings of the
/// cycle.
fn run_lanes<const L: usize>(
    params: &[Params; L],
    test: &PositioningTest,
    lanes: [Lane; L],
    mut progress: impl FnMut(usize, usize),
) -> Result<[Result<Vec<Measurement>, SimError>; L], SimError> {
    let mut sim = LaneSimulation::<L>::of(params, crate::sim::common_step(params)?)?;
    let stops = test.cycle();
    // Start at rest at the first stop, controllers aligned with it.
    for (l, p) in params.iter().enumerate() {
        sim.start(l, rest_state(p, stops[0].0, Preload::None), 0.0);
    }
    let mut controllers = sim.controllers(params)?;
    let seeds = lanes.each_ref().map(|l| l.seed);
    for (c, lane) in controllers.iter_mut().zip(lanes) {
        c.set_compensation(lane.compensation);
    }
    let mut readings = Readings::<L>::new(params, test, seeds);
    let mut failed: [Option<SimError>; L] = std::array::from_fn(|_| None);
    for w in stops.windows(2) {
        let (from, to) = (w[0].0, w[1].0);
        let t0 = sim.time(0);
        let m = Move {
            from,
            to,
            speed: Some(test.speed),
        };
        let duration = (to - from).abs() / test.speed + test.dwell;
        let reference = |t: f64| crate::input::Trajectory::angle(&m, t - t0);
        let run = (&mut controllers, &mut std::array::from_fn(|_| NullRecorder));
        sim.run_closed_loop(run, &reference, duration, &mut failed)?;
        if let Some(at) = w[1].1 {
            readings.take(at, |l| sim.state(l)[THETA_T]);
            progress(readings.out[0].len(), test.readings());
        }
        if failed.iter().all(Option::is_some) {
            break;
        }
    }
    let mut out = readings.out.into_iter();
    Ok(failed.map(|f| {
        let measurements = out.next().expect("one per lane");
        f.map_or(Ok(measurements), Err)
    }))
}

/// The readings of `L` lanes: each lane's table encoder and noise generator.
struct Readings<const L: usize> {
    resolution: [f64; L],
    noise: Normal<f64>,
    rng: [rand::rngs::StdRng; L],
    out: [Vec<Measurement>; L],
}

impl<const L: usize> Readings<L> {
    fn new(params: &[Params; L], test: &PositioningTest, seeds: [u64; L]) -> Self {
        Readings {
            resolution: params
                .each_ref()
                .map(|p| p.controller.table_encoder_resolution),
            // Invariant: Normal refuses only a non-finite σ; `noise` is finite (its
            // field's contract; the command line checks it).
            noise: Normal::new(0.0, test.noise.max(0.0)).expect("a finite σ"),
            rng: seeds.map(rand::rngs::StdRng::seed_from_u64),
            out: std::array::from_fn(|_| Vec::with_capacity(test.readings())),
        }
    }

    /// Every lane's reading at `target`, from its table angle `table(l)`.
    fn take(
        &mut self,
        (target, direction, run): (f64, Direction, u32),
        table: impl Fn(usize) -> f64,
    ) {
        for l in 0..L {
            let reading =
                quantise(table(l), self.resolution[l]) + self.noise.sample(&mut self.rng[l]);
            self.out[l].push(Measurement {
                target,
                direction,
                run,
                deviation: reading - target,
            });
        }
    }
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
    m.conditions.loop_mode = Some(test.loop_on(params));
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

/// Most targets a positioning test takes: beyond, a step in the wrong unit.
pub const MAX_TARGETS: f64 = 1000.0;

/// A target spacing that makes more than [`MAX_TARGETS`] targets.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("over 1000 targets")]
pub struct TooManyTargets;

/// A rotary table's targets, rad: every `step_deg` from 0° to 360° (`rtid experiment
/// positioning --target-step-deg`).
pub fn rotary_targets(step_deg: f64) -> Result<Vec<f64>, TooManyTargets> {
    if 360.0 / step_deg > MAX_TARGETS {
        return Err(TooManyTargets);
    }
    let count = (360.0 / step_deg).floor() as usize;
    Ok((0..=count)
        .map(|i| (step_deg * i as f64).to_radians())
        .collect())
}

/// A linear axis's targets, m: every `step_mm` from 0 to `travel_mm` (`--target-step-mm`,
/// `--travel-mm`).
pub fn linear_targets(step_mm: f64, travel_mm: f64) -> Result<Vec<f64>, TooManyTargets> {
    if travel_mm / step_mm > MAX_TARGETS {
        return Err(TooManyTargets);
    }
    let count = (travel_mm / step_mm + 1e-9).floor() as usize;
    Ok((0..=count).map(|i| step_mm * i as f64 * 1e-3).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn four_sets_in_lanes_read_what_each_reads_alone() {
        let test = PositioningTest {
            targets: vec![0.0, 0.1],
            runs: 2,
            dwell: 0.3,
            noise: 2e-6,
            ..PositioningTest::default()
        };
        let sets: [Params; 4] = std::array::from_fn(|l| {
            let mut p = presets::load("worm-gear").unwrap();
            p.kw *= 1.0 - 0.1 * l as f64;
            p.ft *= 1.0 + 0.5 * l as f64;
            p.controller.kvp *= 1.0 - 0.1 * l as f64;
            test_params(&p, &test)
        });
        let none = || std::array::from_fn(|_| Lane::of(&test));
        let lanes = run_lanes(&sets, &test, none(), |_, _| {}).unwrap();
        for (l, p) in sets.iter().enumerate() {
            let alone = run(p, &test, |_, _| {}).unwrap();
            assert_eq!(lanes[l].as_ref().unwrap(), &alone, "lane {l}");
        }
        assert_ne!(lanes[0], lanes[3], "the sets read differently");
        // An axial bearing ten times stiffer: its mode (4.8 kHz) needs 5 µs steps.
        let mut stiffer = sets.clone();
        stiffer[2].kb *= 10.0;
        let err = run_lanes(&stiffer, &test, none(), |_, _| {}).unwrap_err();
        assert!(err.to_string().contains("lane 2"), "{err}");
    }

    /// Each set's own compensation in the lanes: every set reads what it reads alone
    /// with its compensation in the test.
    #[test]
    fn each_set_runs_its_own_compensation_in_the_lanes() {
        let test = PositioningTest {
            targets: vec![0.0, 90f64.to_radians()],
            runs: 1,
            dwell: 0.2,
            ..PositioningTest::default()
        };
        let sets: Vec<Params> = (0..3)
            .map(|l| {
                let mut p = presets::load("worm-gear").unwrap();
                p.controller.kpp *= 1.0 + 0.2 * l as f64;
                p
            })
            .collect();
        let compensations: Vec<Compensation> = (0..3)
            .map(|l| Compensation {
                backlash: Some(-1e-4 * (l + 1) as f64),
                ..Compensation::default()
            })
            .collect();
        let batch = run_batch_compensated(&sets, &test, &compensations);
        for ((p, c), got) in sets.iter().zip(&compensations).zip(batch) {
            let alone = PositioningTest {
                compensation: c.clone(),
                ..test.clone()
            };
            assert_eq!(got.unwrap(), run(p, &alone, |_, _| {}).unwrap());
        }
    }
}
