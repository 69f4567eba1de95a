//! The virtual friction map: for each speed, the servo (the drive's own loop, semi- or
//! full-closed) follows a position ramp at that constant motor speed from rest; after
//! `settle` seconds the motor speed and the torque command are averaged over every
//! integration step of the averaging window (the time average), and the run's means
//! and scatters are the map's row. Every speed is an independent simulation (rayon).
//!
//! The window is `average` seconds, lengthened to whole revolutions of the driving
//! shaft when the drive has a gear fluctuation, whose torque averages out only over
//! whole revolutions (a window that would exceed [`MAX_WINDOW_S`] is refused).

use rayon::prelude::*;

use crate::experiments::measurement_noise::perturb_by_rms;
use crate::io::experiment_file::{FrictionMap, Kind, Manifest};
use crate::model::idx::OMEGA_M;
use crate::model::{Params, NSTATE};
use crate::recorder::{NullRecorder, Recorder};
use crate::sim::{SimError, Simulation};

/// The longest averaging window of one speed, s.
pub const MAX_WINDOW_S: f64 = 600.0;

/// The conditions of the virtual friction map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapTest {
    /// Motor speeds, rad/s (m/s on a linear axis), non-zero; both signs for a map.
    pub speeds: Vec<f64>,
    /// Time from the start of each run to the averaging window, s.
    pub settle: f64,
    /// The averaging window, s (lengthened to whole shaft revolutions, see above).
    pub average: f64,
    /// Sampling interval within the window, s; 0 (the default): every integration
    /// step, the exact time average. A sampling interval that is a multiple of the
    /// control period strobes the servo's torque ripple at one phase and biases the
    /// mean (measured on the direct drive: 1.5e-3 of the torque at 1 ms).
    pub sample: f64,
    /// Measurement noise on the torque samples: Gaussian, this percentage of each
    /// run's RMS torque, added to every sample before the run is averaged (as a
    /// recorder's noise is); 0 for none.
    pub noise_percent: f64,
    /// Seed of the noise (run `k` uses `seed + k`).
    pub seed: u64,
}

impl MapTest {
    /// The default speeds of a drive: ±0.2 … ±50 % of its motor speed limit, eight
    /// per direction, spaced evenly in the logarithm.
    pub fn default_speeds(p: &Params) -> Vec<f64> {
        let top = 0.5 * p.controller.speed_limit;
        let ups: Vec<f64> = (0..8)
            .map(|k| top * 250f64.powf((k as f64 - 7.0) / 7.0))
            .collect();
        ups.iter().rev().map(|v| -v).chain(ups.clone()).collect()
    }

    /// The averaging window at motor speed `speed` of drive `p`.
    pub fn window(&self, p: &Params, speed: f64) -> f64 {
        if p.w == 0.0 || p.axis == crate::model::Axis::Linear {
            return self.average;
        }
        // The driving shaft turns Rg times the motor (the motor itself without a spur
        // stage, where Rg is absent).
        let shaft_speed = p.rg.unwrap_or(1.0) * speed;
        let revolution = std::f64::consts::TAU / shaft_speed.abs();
        (self.average / revolution).ceil().max(1.0) * revolution
    }

    /// Simulated seconds of the whole map.
    pub fn duration(&self, p: &Params) -> f64 {
        self.speeds
            .iter()
            .map(|&v| self.settle + self.window(p, v))
            .sum()
    }
}

/// One run's samples: motor speed and torque command.
#[derive(Default)]
struct Samples {
    every: u64,
    count: u64,
    speed: Vec<f64>,
    effort: Vec<f64>,
}

impl Recorder for Samples {
    #[inline]
    fn record(&mut self, _t: f64, y: &[f64; NSTATE], effort: f64) {
        if self.count % self.every == 0 {
            self.speed.push(y[OMEGA_M]);
            self.effort.push(effort);
        }
        self.count += 1;
    }
}

/// The virtual map as `rtid experiment friction-map` writes it: [`run`], each run's
/// mean effort scattered by `scatter_percent` (Gaussian, relative: what a real map
/// shows from run to run beyond the recorder's noise; seed `test.seed` + the runs),
/// and its manifest.
pub fn record(
    p: &Params,
    test: &MapTest,
    scatter_percent: f64,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(Manifest, FrictionMap), SimError> {
    let mut map = run(p, test, progress)?;
    crate::experiments::measurement_noise::perturb_relative(
        &mut map.effort,
        scatter_percent,
        test.seed.wrapping_add(test.speeds.len() as u64),
    );
    let mut m = Manifest::new(Kind::FrictionMap);
    m.mechanism = Some(p.name.clone());
    let mut notes = format!(
        "virtual friction map: the servo ({}) at {} constant motor speeds from rest, settled {} s, averaged over {} s or whole shaft revolutions",
        p.controller.loop_mode,
        test.speeds.len(),
        test.settle,
        test.average
    );
    if test.noise_percent > 0.0 {
        notes += &format!(
            "; {} % (of each run's RMS) Gaussian noise on the torque samples (seed {})",
            test.noise_percent, test.seed
        );
    }
    if scatter_percent > 0.0 {
        notes += &format!("; each run's mean torque scattered by {scatter_percent} % (Gaussian)");
    }
    m.notes = Some(notes);
    Ok((m, map))
}

/// Runs the map: one row per speed, in the order of `test.speeds` (the writer sorts
/// them). `progress(done, total)` after each speed.
pub fn run(
    p: &Params,
    test: &MapTest,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<FrictionMap, SimError> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    let runs: Vec<Samples> = test
        .speeds
        .par_iter()
        .enumerate()
        .map(|(k, &v)| {
            let run = one_speed(p, test, v, test.window(p, v)).map(|mut r| {
                let seed = test.seed.wrapping_add(k as u64);
                perturb_by_rms(&mut r.effort, test.noise_percent, seed);
                r
            });
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(n, test.speeds.len());
            run
        })
        .collect::<Result<_, _>>()?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let std = |v: &[f64]| {
        let m = mean(v);
        (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
    };
    let column = |f: &dyn Fn(&Samples) -> f64| runs.iter().map(f).collect::<Vec<f64>>();
    let mut map = FrictionMap::new(
        p.axis,
        column(&|r| mean(&r.speed)),
        column(&|r| mean(&r.effort)),
    );
    map.speed_std = Some(column(&|r| std(&r.speed)));
    map.effort_std = Some(column(&|r| std(&r.effort)));
    map.samples = Some(column(&|r| r.effort.len() as f64));
    Ok(map)
}

/// The samples of one speed: the ramp followed from rest, settled, then sampled.
fn one_speed(p: &Params, test: &MapTest, speed: f64, window: f64) -> Result<Samples, SimError> {
    let mut sim = Simulation::with_default_step(p)?;
    let mut controller = sim.controller(p)?;
    let table_speed = speed * sim.drive().ratio();
    let ramp = move |t: f64| table_speed * t;
    sim.run_closed_loop(&mut controller, &ramp, test.settle, &mut NullRecorder)?;
    let every = (test.sample / sim.dt()).round().max(1.0) as u64;
    let mut samples = Samples {
        every,
        ..Samples::default()
    };
    sim.run_closed_loop(&mut controller, &ramp, window, &mut samples)?;
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_virtual_map_is_the_models_steady_state() {
        // The direct drive with a Stribeck law and a load: each run's mean torque is
        // the steady-state torque at its mean speed, to the servo's ripple.
        let mut p = presets::load("direct-drive").unwrap();
        (p.fst, p.vst, p.tload) = (0.6, 0.3, 0.2);
        let test = MapTest {
            speeds: vec![-2.0, -0.5, 0.5, 2.0],
            settle: 0.5,
            average: 0.5,
            sample: 0.0,
            noise_percent: 0.0,
            seed: 1,
        };
        let map = run(&p, &test, |_, _| {}).unwrap();
        let model = super::super::model_map(&p, &map.speed).unwrap();
        for (i, model) in model.iter().enumerate() {
            let miss = (map.effort[i] - model).abs() / model.abs();
            assert!(
                miss < 1e-3,
                "speed {}: {} against {model}",
                map.speed[i],
                map.effort[i],
            );
            assert!((map.speed[i] / test.speeds[i] - 1.0).abs() < 1e-3);
        }
    }

    #[test]
    fn the_window_is_whole_shaft_revolutions_with_a_fluctuation() {
        let p = presets::load("worm-gear").unwrap();
        assert!(p.w > 0.0);
        let test = MapTest {
            speeds: vec![1.0],
            settle: 0.5,
            average: 1.0,
            sample: 0.0,
            noise_percent: 0.0,
            seed: 1,
        };
        let shaft = p.rg.unwrap();
        let window = test.window(&p, 1.0);
        let turns = window * shaft / std::f64::consts::TAU;
        assert!(
            (turns - turns.round()).abs() < 1e-9 && window >= 1.0,
            "{turns}"
        );
    }
}
