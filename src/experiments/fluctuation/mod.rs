//! The rotational-fluctuation test (paper §4.4, docs/experiments.md (rotational fluctuation)) and the unbalance-mass
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
//!    linear trend ([`crate::estimation::spectrum`]); the step: the largest change of the
//!    deviation across [`STEP_WINDOW`] of table angle.

mod evaluate;
mod record;
mod run;
mod steps;
#[cfg(test)]
mod tests;

pub use evaluate::{evaluate, evaluate_experiment, ratio, Evaluation, Pass};
pub use record::{from_data, manifest, to_data};
pub use run::{run, run_batch, Record};
pub(crate) use run::{run_window, run_window_batch};
pub(crate) use steps::pass_samples;
pub use steps::{locate_step, PassSamples, Step};

use std::f64::consts::TAU;
use std::path::PathBuf;

use crate::io::experiment_file::{Experiment, Kind};
use crate::model::params::{LoopMode, Params};

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

/// Conditions of the test (defaults: docs/experiments.md (rotational fluctuation)).
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
    /// Feedback arrangement; `None` (the default): the parameter set's own
    /// (`controller.loop`; semi-closed in the presets, as in the paper).
    pub loop_mode: Option<LoopMode>,
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
            loop_mode: None,
            unbalance: None,
        }
    }
}

impl FluctuationTest {
    /// The unbalance test (docs/experiments.md (unbalance)): 360°/min with `mass` kg at `radius` m.
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
            test.loop_mode = Some(l);
        }
        Ok(test)
    }

    /// The feedback arrangement the test runs `params` in: its own, or the test's.
    pub fn loop_on(&self, params: &Params) -> LoopMode {
        self.loop_mode.unwrap_or(params.controller.loop_mode)
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
