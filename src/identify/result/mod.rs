//! The result file of `rtid identify` (JSON, written atomically) and its parts: plain
//! data, importing none of the steps that produce it.

pub mod comparison;
pub mod held;
pub mod interval;
pub mod profile;
pub mod record_plan;
pub mod resampling;
pub mod starts;
pub mod termination;
pub mod uncertainty;
pub mod warning;

use std::collections::BTreeMap;
use std::path::Path;

use crate::io::provenance::Provenance;
use crate::objectives::Detail;
use comparison::Comparison;
use held::Held;
use profile::Profile;
use record_plan::RecordPlan;
use resampling::Resampling;
use starts::{StartEstimate, StartRecord};
use termination::Termination;
use uncertainty::Uncertainty;
use warning::{Coded, Warning};

/// One experiment's share of the fit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ExperimentResidual {
    /// The experiment file.
    pub source: String,
    /// Objective name.
    pub objective: String,
    pub weight: f64,
    /// What one unit of the scaled residuals means.
    pub scale: String,
    /// Scaled residuals at the result.
    pub residuals: Vec<f64>,
    /// Root mean square of `residuals`.
    pub rms: f64,
    /// The same in the measurement's units where that reads better (Hz, dB, N·m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detail: Option<Detail>,
}

/// The resonances of the nonlinear virtual test at the linear search's result, and
/// how far the linear model's gain is from the measured curve there.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct NonlinearCheck {
    pub source: String,
    pub measured_hz: Vec<f64>,
    /// The standard error of each measured peak's frequency from the curve's noise
    /// (0 where unknown): a miss within [`MISS_SIGMAS`] of them does not count.
    ///
    /// [`MISS_SIGMAS`]: crate::identify::pipeline::escalation::MISS_SIGMAS
    #[serde(default)]
    pub measured_se_hz: Vec<f64>,
    pub model_hz: Vec<f64>,
    pub max_miss_hz: f64,
    /// RMS of the linear model's gain against the measured curve, dB (at the same
    /// parameters, every valid measured frequency).
    #[serde(default)]
    pub linear_misfit_db: f64,
    /// Where the fit used the whole (complex) curve: the linear fit's own peaks,
    /// located on the measured frequencies as the measured ones were, for the reader
    /// (empty otherwise).
    #[serde(default)]
    pub linear_hz: Vec<f64>,
    /// The measured gain's noise, dB, estimated from the curve itself (the spread of
    /// the second differences of the linear model's gain errors, median-based: a
    /// smooth misfit has none); `None` on fewer than 20 lines.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_db: Option<f64>,
    /// The valid measured lines the misfit and the noise come from.
    #[serde(default)]
    pub lines: usize,
}

/// The result of `rtid identify`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct IdentifyResult {
    pub mechanism: String,
    pub experiments: Vec<String>,
    /// Name → identified value (SI).
    pub parameters: BTreeMap<String, f64>,
    /// Name → start value.
    pub initial: BTreeMap<String, f64>,
    /// The direct estimates the start values came from (a servo trace's IDIM-LS).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub start_estimates: Vec<StartEstimate>,
    /// Name → [lo, hi].
    pub bounds: BTreeMap<String, [f64; 2]>,
    pub method: String,
    /// The frequency-response model: `linear`, `nonlinear`, or `linear, then
    /// nonlinear` (two stages); `nonlinear time simulation` when no objective depends
    /// on it (a torque curve is always simulated).
    pub fidelity: String,
    pub cost: f64,
    pub residuals: Vec<ExperimentResidual>,
    pub evaluations: usize,
    pub wall_time_s: f64,
    /// How the best start (or the corrections) ended: a code and a message.
    pub termination: Coded<Termination>,
    pub interrupted: bool,
    pub starts: Vec<StartRecord>,
    pub uncertainty: Option<Uncertainty>,
    /// With several records: which record determined which parameter, and what was
    /// refined jointly ([`crate::identify::by_record`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plan: Option<RecordPlan>,
    /// With `--model auto`: the resonances of the nonlinear virtual test at the linear
    /// search's result — the check that decides whether the nonlinear fit follows.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nonlinear_check: Option<Vec<NonlinearCheck>>,
    /// What the user should know about this fit: a code and a message each.
    pub warnings: Vec<Coded<Warning>>,
    /// With `--profile`: each profiled parameter's likelihood-ratio interval and the
    /// profile behind it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profiles: Option<BTreeMap<String, Profile>>,
    /// With `--resample`: the residual block bootstrap of the fit, its replicates'
    /// values and each fitted parameter's interval.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resampling: Option<Resampling>,
    /// With `--uncertain NAME=X%`: the held parameters' ranges and the fit's
    /// response to each ([`crate::identify::intervals::held`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<Held>,
    /// Each experiment's data against the model at the start and identified values,
    /// in the experiment's axes (thinned for the file), for plots and reports.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub comparisons: Vec<Comparison>,
    /// The command line, the rtid version and the inputs' SHA-256 (written by the
    /// command line; a library caller may leave it out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
}

impl IdentifyResult {
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let text = crate::io::json::pretty(self).map_err(std::io::Error::other)?;
        crate::io::atomic::write(path, format!("{text}\n").as_bytes())
    }

    /// Sets the identified values in `p` (the base the fit started from: a preset, a
    /// parameter file).
    pub fn apply_to(&self, p: &mut crate::model::Params) -> Result<(), crate::model::ParamError> {
        for (name, &value) in &self.parameters {
            p.set(name, value)?;
        }
        Ok(())
    }

    /// The standard error of fitted parameter `name` in its unit, where defined.
    pub fn standard_error(&self, name: &str) -> Option<f64> {
        self.uncertainty
            .as_ref()?
            .standard_errors
            .iter()
            .find(|(n, _)| n == name)?
            .1
    }

    /// Whether a warning with `code` was given.
    pub fn warns(&self, code: &str) -> bool {
        self.warnings.iter().any(|w| w.0.code() == code)
    }
}
