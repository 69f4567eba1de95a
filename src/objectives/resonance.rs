//! Resonance-frequency match: the relative error of the model's resonance frequencies
//! against measured ones (paper §4.1, MODEL.md §6).
//!
//! The model's resonances are the peaks of its frequency response — the damped,
//! motor-held modes — never the undamped eigenvalues (fitting those to measured peaks
//! biases Kw by ~6 %, MODEL.md §6). With [`Fidelity::Linear`] they come from the exact
//! linear response with damping; with [`Fidelity::Nonlinear`] from the nonlinear
//! virtual test at the experiment's conditions ([`super::model_peaks`]), sampled on
//! the measured frequencies when there is a measured gain curve.
//!
//! Pairing: the model's `n` highest peaks in the band (n = measured peaks), in
//! ascending frequency, against the measured ones in ascending frequency. A measured
//! peak the model does not have costs a residual of 100 % of its frequency.

use super::model_peaks::ModelPeaks;
use super::{cost_function, Fidelity, Objective, ObjectiveError};
use crate::experiments::frequency_response::FrequencyTest;
use crate::model::Params;

/// One scaled residual is this relative frequency error (0.1 %).
pub const SCALE: f64 = 1e-3;

/// Measured resonance frequencies to match.
#[derive(Clone, Debug)]
pub struct ResonanceMatch {
    /// Hz, ascending.
    pub measured_hz: Vec<f64>,
    /// Where and how the model's resonances are found.
    pub model: ModelPeaks,
}

impl ResonanceMatch {
    pub fn new(mut measured_hz: Vec<f64>, fidelity: Fidelity, test: FrequencyTest) -> Self {
        measured_hz.sort_by(f64::total_cmp);
        let model = ModelPeaks::new(
            measured_hz.first().copied().unwrap_or(10.0),
            measured_hz.last().copied().unwrap_or(600.0),
            fidelity,
            test,
        );
        ResonanceMatch { measured_hz, model }
    }

    /// Locate the nonlinear model's peaks on the measured frequencies `grid_hz`.
    pub fn on_grid(mut self, grid_hz: Vec<f64>) -> Self {
        self.model.grid_hz = Some(grid_hz);
        self
    }

    /// The model's resonances paired with the measured ones (`None`: missing).
    pub fn model_hz(&self, p: &Params) -> Result<Vec<Option<f64>>, ObjectiveError> {
        let peaks = self.model.locate(p, self.measured_hz.len())?;
        Ok((0..self.measured_hz.len())
            .map(|k| peaks.get(k).map(|pk| pk.frequency_hz))
            .collect())
    }
}

impl Objective for ResonanceMatch {
    fn name(&self) -> &'static str {
        "resonance"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(self
            .model_hz(p)?
            .iter()
            .zip(&self.measured_hz)
            .map(|(m, &f)| match m {
                Some(m) => (m - f) / f / SCALE,
                None => 1.0 / SCALE,
            })
            .collect())
    }

    fn len(&self) -> usize {
        self.measured_hz.len()
    }

    fn scale(&self) -> String {
        format!("{} % of each resonance frequency", SCALE * 100.0)
    }

    fn detail(&self, r: &[f64]) -> Option<serde_json::Value> {
        let miss: Vec<f64> = r
            .iter()
            .zip(&self.measured_hz)
            .map(|(x, f)| x * SCALE * f)
            .collect();
        let model: Vec<f64> = miss
            .iter()
            .zip(&self.measured_hz)
            .map(|(m, f)| f + m)
            .collect();
        let max = miss.iter().fold(0.0f64, |a, m| a.max(m.abs()));
        Some(serde_json::json!({
            "measured_hz": self.measured_hz,
            "model_hz": model,
            "max_miss_hz": max,
        }))
    }
}

cost_function!(ResonanceMatch);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_linear_resonances_of_the_model_itself_match_exactly() {
        let p = presets::load("worm-gear").unwrap();
        let peaks = crate::peaks::of_linear_response(&p, 10.0, 600.0, 2).unwrap();
        let hz: Vec<f64> = peaks.iter().map(|pk| pk.frequency_hz).collect();
        let obj = ResonanceMatch::new(hz, Fidelity::Linear, FrequencyTest::default());
        let r = obj.residuals(&p).unwrap();
        assert!(r.iter().all(|x| x.abs() < 1e-3), "{r:?}");
        let mut stiffer = p.clone();
        stiffer.kw *= 1.2;
        let r = obj.residuals(&stiffer).unwrap();
        assert!(
            r.iter().all(|&x| x > 1.0),
            "a stiffer drive resonates higher: {r:?}"
        );
    }
}
