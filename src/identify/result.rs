//! The result file of `rtid identify` and its checkpoint, both JSON, written
//! atomically.

use std::collections::BTreeMap;
use std::path::Path;

use super::uncertainty::Uncertainty;
use super::{Bound, StartRecord};

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
    pub detail: Option<serde_json::Value>,
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
    /// Name → [lo, hi].
    pub bounds: BTreeMap<String, [f64; 2]>,
    pub method: String,
    /// The frequency-response model: `linear`, `nonlinear`, or `linear, then
    /// nonlinear` (two stages); `nonlinear time simulation` when no experiment is a
    /// frequency response (a torque curve is always simulated).
    pub fidelity: String,
    pub cost: f64,
    pub residuals: Vec<ExperimentResidual>,
    pub evaluations: usize,
    pub wall_time_s: f64,
    pub termination: String,
    pub interrupted: bool,
    pub starts: Vec<StartRecord>,
    pub uncertainty: Option<Uncertainty>,
    /// With `--model auto`: the resonances of the nonlinear virtual test at the result.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nonlinear_check: Option<Vec<NonlinearCheck>>,
    /// What the user should know about this fit (bounds hit, residuals left, failures).
    pub warnings: Vec<String>,
}

impl IdentifyResult {
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        crate::io::atomic::write(path, format!("{text}\n").as_bytes())
    }
}

/// The resonances of the nonlinear virtual test at the identified parameters.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct NonlinearCheck {
    pub source: String,
    pub measured_hz: Vec<f64>,
    pub model_hz: Vec<f64>,
    pub max_miss_hz: f64,
}

/// What `--resume` needs: the problem's identity and the starts done so far.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Checkpoint {
    /// A fingerprint of the problem (experiments, fitted names, bounds, method,
    /// starts, seed): a checkpoint of another problem is refused.
    pub problem: String,
    /// Stage (0: the only or linear stage; 1: the nonlinear polish).
    pub stage: usize,
    pub starts: Vec<StartRecord>,
    /// Result of the finished first stage, if any.
    pub stage0_best: Option<Vec<f64>>,
    pub evaluations: usize,
}

impl Checkpoint {
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        crate::io::atomic::write(path, text.as_bytes())
    }

    pub fn read(path: &Path) -> Result<Checkpoint, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&text)
            .map_err(|e| format!("{}: not an rtid checkpoint: {e}", path.display()))
    }
}

/// Bounds as `name → [lo, hi]`.
pub fn bounds_map(names: &[&str], bounds: &[Bound]) -> BTreeMap<String, [f64; 2]> {
    names
        .iter()
        .zip(bounds)
        .map(|(n, b)| (n.to_string(), [b.lo, b.hi]))
        .collect()
}
