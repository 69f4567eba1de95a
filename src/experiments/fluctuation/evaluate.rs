//! The evaluation of a fluctuation or unbalance record (module docs of the parent).

use std::f64::consts::TAU;

use serde::Serialize;

use super::record::from_data;
use super::steps::{find_steps, pass_samples, PassSamples, Step};
use super::{FluctuationError, Record, PEAKS, REVERSAL_THRESHOLD, STEP_WINDOW};
use crate::estimation::spectrum::{self, Peak, Spectrum};
use crate::io::experiment_file::{Direction, Experiment};
use crate::model::presets;

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
            presets::load(name).expect("the guard loaded it").ratio()
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

/// Evaluates a record with `ratio` (module docs).
pub fn evaluate(record: &Record, ratio: f64) -> Result<Evaluation, FluctuationError> {
    if !(ratio > 0.0 && ratio.is_finite()) {
        return Err(FluctuationError::BadRatio { ratio });
    }
    if record.motor_angle.len() != record.table_angle.len() {
        return Err(FluctuationError::Lengths {
            motor: record.motor_angle.len(),
            table: record.table_angle.len(),
        });
    }
    let passes: Vec<Pass> = pass_samples(record, ratio)
        .iter()
        .map(analyse_pass)
        .collect();
    if passes.is_empty() {
        return Err(FluctuationError::NoMotion {
            threshold_deg: REVERSAL_THRESHOLD.to_degrees(),
        });
    }
    let spectrum = mean_spectrum(&passes);
    let step = largest_step(passes.iter().map(|p| p.step));
    Ok(Evaluation {
        ratio,
        pp_arcsec: passes.iter().map(|p| p.pp_arcsec).fold(0.0, f64::max),
        gap_arcsec: gap(&passes),
        dominant: spectrum.peaks(PEAKS),
        spectrum,
        step,
        passes,
    })
}

/// The evaluation of one direction pass: the whole revolutions centred in its travel
/// (the whole travel if under one turn) resampled uniformly in angle, their
/// peak-to-peak, spectrum and steps.
fn analyse_pass(samples: &PassSamples) -> Pass {
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
    let grid_x: Vec<f64> = (0..m).map(|j| x0 + span * j as f64 / m as f64).collect();
    let angle_deg: Vec<f64> = grid_x.iter().map(|x| (sense * x).to_degrees()).collect();
    let step = largest_step((0..m - w).map(|j| Step {
        size_arcsec: dev[j + w] - dev[j],
        angle_deg: 0.5 * (angle_deg[j] + angle_deg[j + w]),
    }));
    Pass {
        direction: samples.direction(),
        steps: find_steps(samples, &grid_x, &dev, w),
        revolutions,
        mean_arcsec: dev.iter().sum::<f64>() / m as f64,
        pp_arcsec: hi - lo,
        dominant: spectrum.peaks(PEAKS),
        spectrum,
        step,
        angle_deg,
        deviation_arcsec: dev,
    }
}

/// The step of largest size (a zero step if there is none).
fn largest_step(steps: impl Iterator<Item = Step>) -> Step {
    steps
        .max_by(|a, b| a.size_arcsec.abs().total_cmp(&b.size_arcsec.abs()))
        .unwrap_or(Step {
            size_arcsec: 0.0,
            angle_deg: 0.0,
        })
}

/// Mean deviation down minus up (`None` unless both directions were run).
fn gap(passes: &[Pass]) -> Option<f64> {
    let mean_of = |dir: Direction| {
        let v: Vec<f64> = passes
            .iter()
            .filter(|p| p.direction == dir)
            .map(|p| p.mean_arcsec)
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    mean_of(Direction::Up)
        .zip(mean_of(Direction::Down))
        .map(|(u, d)| d - u)
}

/// The spectra of the passes that share the longest analysed grid, averaged.
fn mean_spectrum(passes: &[Pass]) -> Spectrum {
    let longest = passes
        .iter()
        .map(|p| &p.spectrum)
        .max_by(|a, b| {
            a.psd
                .len()
                .cmp(&b.psd.len())
                .then(a.order[1].total_cmp(&b.order[1]).reverse())
        })
        .expect("at least one pass: evaluate refuses a record without");
    let same: Vec<&Spectrum> = passes
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
    Spectrum {
        psd: avg(&|s| &s.psd),
        amplitude: avg(&|s| &s.amplitude),
        order: longest.order.clone(),
    }
}
