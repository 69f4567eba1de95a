//! The rotational-fluctuation test (paper §4.4, MODEL.md §5.4) and the unbalance-mass
//! test (§4.5, §5.5) as virtual experiments, and the evaluation both share.
//!
//! Run: the servo (semi-closed loop by default) drives the table at constant speed
//! through `revolutions` whole turns counter-clockwise, then back clockwise, each pass
//! with `run_in` of extra travel at both ends so the speed is steady over the measured
//! turns. Both encoders are recorded every `sample_period`: the motor angle quantised
//! to the motor encoder, the table angle to the table encoder. The unbalance test is the
//! same run with an offset mass on the (vertical) table.
//!
//! Evaluation: deviation `θt − θm·ratio` (ratio = Rg·Rw, table turns per motor turn) as
//! a function of table angle, per direction (docs/experiments.md):
//! 1. passes are split where the table angle turns back by more than
//!    [`REVERSAL_THRESHOLD`]; within a pass only samples that advance the table
//!    beyond every earlier one are kept, so standstill (a dwell, the take-up of lost
//!    motion at a reversal) drops out and the deviation is a function of angle;
//! 2. the analysed range is the whole revolutions centred in the pass's travel (the
//!    whole travel if less than one turn), resampled uniformly in angle by linear
//!    interpolation at a power of two of points no fewer than the samples;
//! 3. peak-to-peak of the deviation there; its spectrum after removing the mean and a
//!    linear trend ([`super::spectrum`]); the step: the largest change of the
//!    deviation across [`STEP_WINDOW`] of table angle.

use std::f64::consts::TAU;
use std::path::PathBuf;

use serde::Serialize;

use super::iso230::ARCSEC_PER_RAD;
use super::spectrum::{self, Peak, Spectrum};
use crate::controller::quantise;
use crate::io::experiment_file::{Data, Direction, Experiment, Kind, Manifest};
use crate::model::idx::{THETA_M, THETA_T};
use crate::model::params::{LoopMode, Params};
use crate::model::rest::{rest_state, Preload};
use crate::model::{presets, NSTATE};
use crate::recorder::Recorder;
use crate::sim::{SimError, Simulation};

/// A pass ends where the table angle turns back by more than this from its extreme,
/// rad (0.05°: far above encoder noise, far below any travel).
pub const REVERSAL_THRESHOLD: f64 = 0.05 * std::f64::consts::PI / 180.0;
/// The angle across which a step of the deviation is measured, rad (0.5°: a tenth of
/// the worm's 5° fluctuation period, while crossing the backlash takes far less).
pub const STEP_WINDOW: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// Half-width of the window in which a step is located precisely ([`locate_step`]),
/// rad (5°: wider than the ~1.5° of rattling across the backlash, far narrower than
/// the ~177° between the two steps of a pass).
pub const STEP_LOCATE_HALF_WIDTH: f64 = 5.0 * std::f64::consts::PI / 180.0;
/// The levels before and after a step are the mean deviation over this much table
/// angle at each end of the locating window, rad (2.5°: a level's error moves the
/// located step by (distance to the window's far end) × error / step size, so the
/// levels average as many samples as the window leaves clear of the step).
pub const STEP_LEVEL_SPAN: f64 = 2.5 * std::f64::consts::PI / 180.0;
/// A change of the deviation counts as one of a pass's steps when it is at least this
/// fraction of the pass's largest step.
pub const STEP_MIN_FRACTION: f64 = 0.5;
/// Unbalance used when neither the parameters nor the caller give one: 10 kg at 0.1 m.
pub const DEFAULT_UNBALANCE: (f64, f64) = (10.0, 0.1);
/// Dominant orders reported.
pub const PEAKS: usize = 5;

/// Conditions of the test (defaults: MODEL.md §5.4).
#[derive(Clone, Debug, PartialEq)]
pub struct FluctuationTest {
    /// Table speed, rad/s (default 180°/min; 360°/min for unbalance).
    pub speed: f64,
    /// Whole revolutions measured in each direction (default 1).
    pub revolutions: u32,
    /// Extra travel at both ends of each pass, rad (default 10°).
    pub run_in: f64,
    /// Recording interval, s (default 4 ms, rounded to whole integration steps).
    pub sample_period: f64,
    /// Standstill before each pass, s (default 0.5).
    pub dwell: f64,
    /// Feedback arrangement (default semi-closed, as in the paper).
    pub loop_mode: LoopMode,
    /// Unbalance mass (kg) and radius (m) on a vertical table; `None` for the
    /// fluctuation test (the parameters' own unbalance, if any, is removed).
    pub unbalance: Option<(f64, f64)>,
}

impl Default for FluctuationTest {
    fn default() -> Self {
        FluctuationTest {
            speed: (180.0f64 / 60.0).to_radians(),
            revolutions: 1,
            run_in: 10f64.to_radians(),
            sample_period: 4e-3,
            dwell: 0.5,
            loop_mode: LoopMode::SemiClosed,
            unbalance: None,
        }
    }
}

impl FluctuationTest {
    /// The unbalance test (MODEL.md §5.5): 360°/min with `mass` kg at `radius` m.
    pub fn unbalance(mass: f64, radius: f64) -> Self {
        FluctuationTest {
            speed: (360.0f64 / 60.0).to_radians(),
            unbalance: Some((mass, radius)),
            ..Default::default()
        }
    }

    /// The test an experiment file describes: speed and loop from its conditions
    /// (defaults of [`FluctuationTest::default`] / [`FluctuationTest::unbalance`]),
    /// and for the unbalance kind the mass and radius, which must be given.
    pub fn from_conditions(exp: &Experiment) -> Result<Self, FluctuationError> {
        let c = &exp.manifest.conditions;
        let bad = |field: &'static str, reason: String| FluctuationError::Condition {
            path: exp.path.clone(),
            field,
            reason,
        };
        let mut test = if exp.manifest.kind == Kind::Unbalance {
            let field = |v: Option<f64>, name: &'static str| match v {
                Some(x) if x > 0.0 && x.is_finite() => Ok(x),
                None => Err(bad(
                    name,
                    "missing: an unbalance test needs the mass and its radius".into(),
                )),
                Some(x) => Err(bad(name, format!("{x} is not a positive number"))),
            };
            FluctuationTest::unbalance(
                field(c.mass_kg, "conditions.mass_kg")?,
                field(c.radius_m, "conditions.radius_m")?,
            )
        } else {
            FluctuationTest::default()
        };
        if let Some(v) = c.speed_deg_per_min {
            if !(v > 0.0 && v.is_finite()) {
                return Err(bad(
                    "conditions.speed_deg_per_min",
                    format!("{v} is not a positive number"),
                ));
            }
            test.speed = v.to_radians() / 60.0;
        }
        if let Some(l) = c.loop_mode {
            test.loop_mode = l;
        }
        Ok(test)
    }

    /// Which experiment this is.
    pub fn kind(&self) -> Kind {
        if self.unbalance.is_some() {
            Kind::Unbalance
        } else {
            Kind::Fluctuation
        }
    }

    /// Travel of one pass, rad.
    fn travel(&self) -> f64 {
        self.revolutions as f64 * TAU + 2.0 * self.run_in
    }

    /// Simulated time, s.
    pub fn duration(&self) -> f64 {
        2.0 * (self.dwell + self.travel() / self.speed) + self.dwell
    }

    /// The commanded table angle at `t`: dwell at −run_in, ramp up, dwell, ramp
    /// back down, dwell.
    fn reference(&self, t: f64) -> f64 {
        let (start, ramp) = (-self.run_in, self.travel() / self.speed);
        let top = start + self.travel();
        let t1 = self.dwell;
        let t2 = t1 + ramp;
        let t3 = t2 + self.dwell;
        if t < t1 {
            start
        } else if t < t2 {
            start + self.speed * (t - t1)
        } else if t < t3 {
            top
        } else {
            (top - self.speed * (t - t3)).max(start)
        }
    }
}

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
pub fn test_params(params: &Params, test: &FluctuationTest) -> Params {
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
pub fn run_window(
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

/// The experiment-file form of a record, of the test's kind.
pub fn to_data(record: &Record, kind: Kind) -> Data {
    let (time_s, motor_angle_rad, table_angle_rad) = (
        record.time.clone(),
        record.motor_angle.clone(),
        record.table_angle.clone(),
    );
    let extra = Default::default();
    if kind == Kind::Unbalance {
        Data::Unbalance {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            extra,
        }
    } else {
        Data::Fluctuation {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            extra,
        }
    }
}

/// The record of a fluctuation or unbalance file (`None` for another kind).
pub fn from_data(data: &Data) -> Option<Record> {
    match data {
        Data::Fluctuation {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            ..
        }
        | Data::Unbalance {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            ..
        } => Some(Record {
            time: time_s.clone(),
            motor_angle: motor_angle_rad.clone(),
            table_angle: table_angle_rad.clone(),
        }),
        _ => None,
    }
}

/// The manifest of a virtual fluctuation or unbalance test.
pub fn manifest(params: &Params, test: &FluctuationTest) -> Manifest {
    let mut m = Manifest::new(test.kind());
    m.mechanism = Some(params.name.clone());
    m.conditions.loop_mode = Some(test.loop_mode);
    m.conditions.speed_deg_per_min = Some(test.speed.to_degrees() * 60.0);
    m.conditions.ratio = Some(params.ratio());
    if let Some((mass, radius)) = test.unbalance {
        m.conditions.mass_kg = Some(mass);
        m.conditions.radius_m = Some(radius);
    }
    m.notes = Some(format!(
        "virtual {} test by rtid: {} revolution(s) each way with {:.1}° run-in, encoders \
         quantised (table {:.6}°), sampled every {} ms",
        test.kind(),
        test.revolutions,
        test.run_in.to_degrees(),
        params.controller.table_encoder_resolution.to_degrees(),
        test.sample_period * 1e3
    ));
    m
}

/// Why a fluctuation or unbalance record cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FluctuationError {
    #[error("{path}: no ratio: the manifest has no `conditions.ratio` and its mechanism {mechanism} is not a preset ({known}); add \"ratio\": Rg·Rw to the conditions")]
    NoRatio {
        path: PathBuf,
        mechanism: String,
        known: String,
    },
    #[error("the ratio {ratio} must be a positive finite number")]
    BadRatio { ratio: f64 },
    #[error("{motor} motor angles but {table} table angles")]
    Lengths { motor: usize, table: usize },
    #[error("the table never moves more than {threshold_deg}° in one sense: nothing to evaluate")]
    NoMotion { threshold_deg: f64 },
    #[error("{path}: {field}: {reason}")]
    Condition {
        path: PathBuf,
        field: &'static str,
        reason: String,
    },
}

/// A step of the deviation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Step {
    /// Change of the deviation across [`STEP_WINDOW`] in the order travelled (later
    /// minus earlier), arc-sec.
    pub size_arcsec: f64,
    /// Table angle at the middle of the window, deg.
    pub angle_deg: f64,
}

/// The evaluation of one direction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Pass {
    pub direction: Direction,
    /// Whole revolutions analysed (0: less than one turn, the whole travel is used).
    pub revolutions: u32,
    /// Analysed table angles, deg (uniform grid, in the order travelled).
    #[serde(skip)]
    pub angle_deg: Vec<f64>,
    /// Deviation θt − θm·ratio there, arc-sec.
    #[serde(skip)]
    pub deviation_arcsec: Vec<f64>,
    /// Mean deviation, arc-sec.
    pub mean_arcsec: f64,
    /// Peak-to-peak deviation, arc-sec.
    pub pp_arcsec: f64,
    /// Spectrum of the detrended deviation, arc-sec²/(cycle/rev).
    #[serde(skip)]
    pub spectrum: Spectrum,
    /// Largest peaks, amplitudes in arc-sec.
    pub dominant: Vec<Peak>,
    /// Largest step.
    pub step: Step,
    /// Every step of at least [`STEP_MIN_FRACTION`] of the largest, at least
    /// 2·[`STEP_LOCATE_HALF_WIDTH`] apart, located precisely ([`locate_step`]), in the
    /// order travelled: an unbalance test shows two per revolution and direction.
    pub steps: Vec<Step>,
}

/// The advance-only samples of one direction pass (module docs, step 1).
#[derive(Clone, Debug, PartialEq)]
pub struct PassSamples {
    /// +1 up (CCW), −1 down (CW).
    pub sense: f64,
    /// sense·θt, rad, strictly increasing.
    pub x: Vec<f64>,
    /// Deviation θt − θm·ratio there, arc-sec.
    pub deviation_arcsec: Vec<f64>,
}

impl PassSamples {
    /// The direction of the pass.
    pub fn direction(&self) -> Direction {
        if self.sense > 0.0 {
            Direction::Up
        } else {
            Direction::Down
        }
    }
}

/// The passes of a record with at least 4 advancing samples each, in the order run.
pub fn pass_samples(record: &Record, ratio: f64) -> Vec<PassSamples> {
    let table = &record.table_angle;
    let mut out = Vec::new();
    for (first, last, sense) in passes(table) {
        let (mut x, mut d) = (Vec::new(), Vec::new());
        let motor = &record.motor_angle[first..=last];
        for (&t, &m) in table[first..=last].iter().zip(motor) {
            let xi = sense * t;
            if x.last().map_or(true, |&l| xi > l) {
                x.push(xi);
                d.push((t - ratio * m) * ARCSEC_PER_RAD);
            }
        }
        if x.len() >= 4 {
            out.push(PassSamples {
                sense,
                x,
                deviation_arcsec: d,
            });
        }
    }
    out
}

/// ∫ of the piecewise-linear interpolant of (x, y) over [a, b] (inside [x₀, xₙ]).
fn integral(x: &[f64], y: &[f64], a: f64, b: f64) -> f64 {
    let at = |v: f64| {
        let k = x.partition_point(|&xi| xi < v).clamp(1, x.len() - 1);
        let (x0, x1) = (x[k - 1], x[k]);
        y[k - 1] + (y[k] - y[k - 1]) * (v - x0) / (x1 - x0)
    };
    let lo = x.partition_point(|&xi| xi <= a);
    let hi = x.partition_point(|&xi| xi < b);
    let mut sum = 0.0;
    let (mut px, mut py) = (a, at(a));
    for k in lo..hi {
        sum += 0.5 * (py + y[k]) * (x[k] - px);
        (px, py) = (x[k], y[k]);
    }
    sum + 0.5 * (py + at(b)) * (b - px)
}

/// A step located precisely: in the window `center` ± `half_width` of a pass (in
/// x = sense·θt, clipped to the samples), the levels before and after are the mean
/// deviation over the first and last [`STEP_LEVEL_SPAN`] of it, and the position is
/// where an ideal step between those levels with the same area under the curve would
/// stand: x_a + ∫(after − d)dx / (after − before). Exact for a sharp step on flat
/// levels; the rattle across the backlash averages out instead of deciding it; and it
/// moves continuously with the data (an optimiser can follow it). Returns (position
/// in x, rad; size after − before, arc-sec), `None` when the window holds less than
/// three level spans (each at most half of `half_width`) or the levels are equal.
pub fn locate_step(pass: &PassSamples, center: f64, half_width: f64) -> Option<(f64, f64)> {
    let (x, d) = (&pass.x, &pass.deviation_arcsec);
    let a = (center - half_width).max(x[0]);
    let b = (center + half_width).min(x[x.len() - 1]);
    let span = STEP_LEVEL_SPAN.min(0.5 * half_width);
    if b - a < 3.0 * span {
        return None;
    }
    let before = integral(x, d, a, a + span) / span;
    let after = integral(x, d, b - span, b) / span;
    let size = after - before;
    if size == 0.0 || !size.is_finite() {
        return None;
    }
    let position = a + ((b - a) * after - integral(x, d, a, b)) / size;
    Some((position.clamp(a, b), size))
}

/// The steps of a pass: the changes across [`STEP_WINDOW`] on the uniform grid
/// (`grid_x`, `dev`) of at least [`STEP_MIN_FRACTION`] of the largest, taken greedily
/// from the largest at least 2·[`STEP_LOCATE_HALF_WIDTH`] apart, each then located
/// with [`locate_step`] on the samples; in the order travelled.
fn find_steps(pass: &PassSamples, grid_x: &[f64], dev: &[f64], w: usize) -> Vec<Step> {
    let m = dev.len();
    let change: Vec<(f64, f64)> = (0..m - w)
        .map(|j| (0.5 * (grid_x[j] + grid_x[j + w]), dev[j + w] - dev[j]))
        .collect();
    let largest = change.iter().fold(0.0f64, |a, c| a.max(c.1.abs()));
    let mut candidates: Vec<&(f64, f64)> = change
        .iter()
        .filter(|c| largest > 0.0 && c.1.abs() >= STEP_MIN_FRACTION * largest)
        .collect();
    candidates.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    let mut centres: Vec<f64> = Vec::new();
    for c in candidates {
        if centres
            .iter()
            .all(|&x| (x - c.0).abs() >= 2.0 * STEP_LOCATE_HALF_WIDTH)
        {
            centres.push(c.0);
        }
    }
    centres.sort_by(f64::total_cmp);
    centres
        .into_iter()
        .filter_map(|c| locate_step(pass, c, STEP_LOCATE_HALF_WIDTH))
        .map(|(x, size)| Step {
            size_arcsec: size,
            angle_deg: (pass.sense * x).to_degrees(),
        })
        .collect()
}

/// The evaluation of a fluctuation or unbalance record.

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Evaluation {
    /// Table turns per motor turn used.
    pub ratio: f64,
    /// One per direction pass, in the order run.
    pub passes: Vec<Pass>,
    /// Largest peak-to-peak of the passes, arc-sec.
    pub pp_arcsec: f64,
    /// Mean deviation down (CW) minus up (CCW), arc-sec: the gap between the two
    /// curves of Fig. 11, in semi-closed loop the lost motion (backlash plus the
    /// elastic wind-up of friction). `None` unless both directions were run.
    pub gap_arcsec: Option<f64>,
    /// Spectrum averaged over the passes of the longest analysed span.
    #[serde(skip)]
    pub spectrum: Spectrum,
    /// Its largest peaks, amplitudes in arc-sec.
    pub dominant: Vec<Peak>,
    /// The largest step over all passes.
    pub step: Step,
}

/// The ratio to evaluate `exp` with: `conditions.ratio`, else the preset named by
/// `mechanism`.
pub fn ratio(exp: &Experiment) -> Result<f64, FluctuationError> {
    let m = &exp.manifest;
    let ratio = match (m.conditions.ratio, m.mechanism.as_deref()) {
        (Some(r), _) => r,
        (None, Some(name)) if presets::load(name).is_ok() => {
            presets::load(name).expect("checked").ratio()
        }
        (None, mechanism) => {
            return Err(FluctuationError::NoRatio {
                path: exp.path.clone(),
                mechanism: mechanism.map_or("(none given)".into(), |s| format!("`{s}`")),
                known: presets::names().collect::<Vec<_>>().join(", "),
            })
        }
    };
    if ratio > 0.0 && ratio.is_finite() {
        Ok(ratio)
    } else {
        Err(FluctuationError::BadRatio { ratio })
    }
}

/// Evaluates a fluctuation or unbalance experiment file.
pub fn evaluate_experiment(exp: &Experiment) -> Result<Evaluation, FluctuationError> {
    let r = ratio(exp)?;
    let record = from_data(&exp.data).ok_or(FluctuationError::NoMotion {
        threshold_deg: REVERSAL_THRESHOLD.to_degrees(),
    })?;
    evaluate(&record, r)
}

/// Splits the table angle into passes: (first index, last index, sense ±1), each
/// ending at its extreme angle.
fn passes(table: &[f64]) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::new();
    let (mut start, mut ext, mut sense) = (0, 0, 0.0);
    for (i, &a) in table.iter().enumerate() {
        if sense == 0.0 {
            let d = a - table[0];
            if d.abs() > REVERSAL_THRESHOLD {
                sense = d.signum();
                ext = i;
            }
        } else if sense * (a - table[ext]) > 0.0 {
            ext = i;
        } else if sense * (table[ext] - a) > REVERSAL_THRESHOLD {
            out.push((start, ext, sense));
            start = ext;
            sense = -sense;
            ext = i;
        }
    }
    if sense != 0.0 {
        out.push((start, ext, sense));
    }
    out
}

/// Evaluates a record with `ratio` (module docs).
pub fn evaluate(record: &Record, ratio: f64) -> Result<Evaluation, FluctuationError> {
    if !(ratio > 0.0 && ratio.is_finite()) {
        return Err(FluctuationError::BadRatio { ratio });
    }
    let table = &record.table_angle;
    if record.motor_angle.len() != table.len() {
        return Err(FluctuationError::Lengths {
            motor: record.motor_angle.len(),
            table: table.len(),
        });
    }
    let mut out = Vec::new();
    for samples in pass_samples(record, ratio) {
        let (x, d, sense) = (&samples.x, &samples.deviation_arcsec, samples.sense);
        let travel = x[x.len() - 1] - x[0];
        let revolutions = (travel / TAU + 1e-9).floor() as u32;
        let span = if revolutions > 0 {
            revolutions as f64 * TAU
        } else {
            travel
        };
        let x0 = x[0] + 0.5 * (travel - span);
        let inside = x.iter().filter(|&&v| v >= x0 && v <= x0 + span).count();
        let m = inside.max(1024).next_power_of_two();
        let dev = spectrum::resample(x, d, x0, span, m);
        let (lo, hi) = dev
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        let mut detrended = dev.clone();
        spectrum::detrend(&mut detrended);
        let spectrum = spectrum::power_spectrum(&detrended, span / TAU);
        let w = ((STEP_WINDOW / (span / m as f64)).round() as usize).clamp(1, m - 1);
        let angle_deg: Vec<f64> = (0..m)
            .map(|j| (sense * (x0 + span * j as f64 / m as f64)).to_degrees())
            .collect();
        let step = (0..m - w)
            .map(|j| Step {
                size_arcsec: dev[j + w] - dev[j],
                angle_deg: 0.5 * (angle_deg[j] + angle_deg[j + w]),
            })
            .max_by(|a, b| a.size_arcsec.abs().total_cmp(&b.size_arcsec.abs()))
            .expect("m > w");
        let grid_x: Vec<f64> = (0..m).map(|j| x0 + span * j as f64 / m as f64).collect();
        let steps = find_steps(&samples, &grid_x, &dev, w);
        out.push(Pass {
            direction: samples.direction(),
            steps,
            revolutions,
            mean_arcsec: dev.iter().sum::<f64>() / m as f64,
            pp_arcsec: hi - lo,
            dominant: spectrum.peaks(PEAKS),
            spectrum,
            step,
            angle_deg,
            deviation_arcsec: dev,
        });
    }
    if out.is_empty() {
        return Err(FluctuationError::NoMotion {
            threshold_deg: REVERSAL_THRESHOLD.to_degrees(),
        });
    }
    let mean_of = |dir: Direction| {
        let v: Vec<f64> = out
            .iter()
            .filter(|p| p.direction == dir)
            .map(|p| p.mean_arcsec)
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let gap_arcsec = mean_of(Direction::Up)
        .zip(mean_of(Direction::Down))
        .map(|(u, d)| d - u);
    // Average the spectra of the passes that share the longest analysed grid.
    let longest = out
        .iter()
        .max_by(|a, b| {
            a.spectrum.psd.len().cmp(&b.spectrum.psd.len()).then(
                a.spectrum.order[1]
                    .total_cmp(&b.spectrum.order[1])
                    .reverse(),
            )
        })
        .expect("not empty")
        .spectrum
        .clone();
    let same: Vec<&Spectrum> = out
        .iter()
        .map(|p| &p.spectrum)
        .filter(|s| s.order == longest.order)
        .collect();
    let n = same.len() as f64;
    let avg = |f: &dyn Fn(&Spectrum) -> &Vec<f64>| -> Vec<f64> {
        (0..longest.order.len())
            .map(|k| same.iter().map(|s| f(s)[k]).sum::<f64>() / n)
            .collect()
    };
    let spectrum = Spectrum {
        psd: avg(&|s| &s.psd),
        amplitude: avg(&|s| &s.amplitude),
        order: longest.order,
    };
    let step = out
        .iter()
        .map(|p| p.step)
        .max_by(|a, b| a.size_arcsec.abs().total_cmp(&b.size_arcsec.abs()))
        .expect("not empty");
    Ok(Evaluation {
        ratio,
        pp_arcsec: out.iter().map(|p| p.pp_arcsec).fold(0.0, f64::max),
        gap_arcsec,
        dominant: spectrum.peaks(PEAKS),
        spectrum,
        step,
        passes: out,
    })
}

/// A readable summary in arc-seconds.
pub fn table(e: &Evaluation, kind: Kind) -> String {
    use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "direction",
        "revolutions",
        "mean ″",
        "peak-to-peak ″",
        "dominant orders (cycles/rev: amplitude ″)",
        "largest step ″ at °",
    ]);
    for p in &e.passes {
        t.add_row([
            p.direction.to_string(),
            p.revolutions.to_string(),
            format!("{:.2}", p.mean_arcsec),
            format!("{:.2}", p.pp_arcsec),
            orders(&p.dominant),
            format!("{:.2} at {:.1}", p.step.size_arcsec, p.step.angle_deg),
        ]);
    }
    let mut s = format!(
        "{t}\nratio {:.6e}; peak-to-peak {:.2}″",
        e.ratio, e.pp_arcsec
    );
    if let Some(g) = e.gap_arcsec {
        s += &format!("; gap between the directions (lost motion) {g:.2}″");
    }
    s += &format!("\ndominant orders (mean spectrum): {}", orders(&e.dominant));
    if kind == Kind::Unbalance {
        s += &format!(
            "\nstep: {:.2}″ at table angle {:.1}°",
            e.step.size_arcsec, e.step.angle_deg
        );
        for p in &e.passes {
            let list: Vec<String> = p
                .steps
                .iter()
                .map(|st| format!("{:.2}″ at {:.3}°", st.size_arcsec, st.angle_deg))
                .collect();
            s += &format!("\nsteps {} (located): {}", p.direction, list.join(", "));
        }
    }
    s
}

fn orders(peaks: &[Peak]) -> String {
    peaks
        .iter()
        .map(|p| format!("{:.0}: {:.2}", p.order, p.amplitude))
        .collect::<Vec<_>>()
        .join(", ")
}

/// At most `max` points of a series, evenly picked (SVG size).
fn thin(points: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    let every = points.len().div_ceil(max).max(1);
    points.into_iter().step_by(every).collect()
}

/// The paper's Fig. 11 / Fig. 14: deviation over table angle, one curve per direction.
pub fn plot_deviation(e: &Evaluation, title: &str, path: &std::path::Path) -> std::io::Result<()> {
    use crate::report::plot::{write, Chart, Series, Style};
    let series: Vec<Series> = e
        .passes
        .iter()
        .map(|p| {
            let name = match p.direction {
                Direction::Up => "CCW (up)",
                Direction::Down => "CW (down)",
            };
            let pts = p
                .angle_deg
                .iter()
                .copied()
                .zip(p.deviation_arcsec.iter().copied());
            Series::new(name, thin(pts.collect(), 4000), Style::Line)
        })
        .collect();
    write(
        path,
        &Chart {
            title,
            x_label: "table angle, deg",
            y_label: "θt − θm·Rg·Rw, arc-sec",
        },
        &series,
    )
}

/// The paper's Fig. 12: the power spectrum up to `max_order` cycles per revolution.
pub fn plot_spectrum(
    e: &Evaluation,
    title: &str,
    max_order: f64,
    path: &std::path::Path,
) -> std::io::Result<()> {
    use crate::report::plot::{write, Chart, Series, Style};
    let pts: Vec<(f64, f64)> = e
        .spectrum
        .order
        .iter()
        .zip(&e.spectrum.psd)
        .filter(|(o, _)| **o > 0.0 && **o <= max_order)
        .map(|(&o, &p)| (o, p))
        .collect();
    write(
        path,
        &Chart {
            title,
            x_label: "cycles per revolution",
            y_label: "power spectral density, arc-sec² per cycle/rev",
        },
        &[Series::new("mean of the directions", pts, Style::Line)],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic record: `revs` turns up then down at constant speed; the table
    /// follows the motor with a fluctuation of order 72 and lags by `lag` in the
    /// direction of motion.
    fn synthetic(revs: f64, lag: f64) -> Record {
        let n = 20_000;
        let top = revs * TAU;
        let (mut time, mut motor, mut table) = (vec![], vec![], vec![]);
        for i in 0..2 * n {
            let (x, sense) = if i < n {
                (top * i as f64 / n as f64, 1.0)
            } else {
                (top * (2 * n - i) as f64 / n as f64, -1.0)
            };
            time.push(i as f64 * 1e-3);
            motor.push(x * 90.0);
            table.push(x + 1e-5 * (72.0 * x).sin() - sense * lag);
        }
        Record {
            time,
            motor_angle: motor,
            table_angle: table,
        }
    }

    #[test]
    fn splits_the_directions_and_finds_order_72_and_the_gap() {
        let e = evaluate(&synthetic(1.2, 5e-5), 1.0 / 90.0).unwrap();
        assert_eq!(e.passes.len(), 2);
        assert_eq!(e.passes[0].direction, Direction::Up);
        assert_eq!(e.passes[1].direction, Direction::Down);
        assert!(e.passes.iter().all(|p| p.revolutions == 1));
        assert!((e.dominant[0].order - 72.0).abs() < 1e-9);
        let a = 1e-5 * ARCSEC_PER_RAD;
        assert!((e.dominant[0].amplitude - a).abs() < 0.01 * a);
        let gap = e.gap_arcsec.unwrap();
        assert!(
            (gap - 2.0 * 5e-5 * ARCSEC_PER_RAD).abs() < 0.01 * gap,
            "{gap}"
        );
    }

    #[test]
    fn a_sharp_step_is_located_where_it_stands_and_its_size_kept() {
        // 33″ at x = 1.2345 rad on flat levels, sampled every 0.02°, the window off
        // centre by 2°: within half a sample interval (linear interpolation puts a
        // jump between two samples in their middle); with ±4″ of rattle over 1.5°
        // after the step: within 0.02°.
        let at = 1.2345;
        let x: Vec<f64> = (0..5000).map(|i| (i as f64 * 0.02).to_radians()).collect();
        let step = |v: f64| if v > at { 33.0 } else { 0.0 };
        let rattle = |v: f64| {
            let u = (v - at).to_degrees();
            if (0.0..1.5).contains(&u) {
                4.0 * (u * 40.0).sin()
            } else {
                0.0
            }
        };
        for (extra, tol) in [(false, 0.0101), (true, 0.02)] {
            let pass = PassSamples {
                sense: 1.0,
                deviation_arcsec: x
                    .iter()
                    .map(|&v| step(v) + if extra { rattle(v) } else { 0.0 })
                    .collect(),
                x: x.clone(),
            };
            let (pos, size) =
                locate_step(&pass, at + 2f64.to_radians(), STEP_LOCATE_HALF_WIDTH).unwrap();
            assert!((pos - at).to_degrees().abs() < tol, "{pos} {extra}");
            assert!((size - 33.0).abs() < 1e-9, "{size}");
        }
    }

    #[test]
    fn standstill_is_an_error_and_a_bad_ratio_too() {
        let still = Record {
            time: vec![0.0, 1.0, 2.0],
            motor_angle: vec![0.0; 3],
            table_angle: vec![0.0; 3],
        };
        assert!(matches!(
            evaluate(&still, 0.1),
            Err(FluctuationError::NoMotion { .. })
        ));
        assert!(matches!(
            evaluate(&synthetic(1.0, 0.0), -1.0),
            Err(FluctuationError::BadRatio { .. })
        ));
    }
}
