//! Peak-amplitude match: the dB error of the model's resonance peak heights against
//! measured ones (MODEL.md §6: the internal damping Ciw, Cig from the peak heights).
//!
//! The model's peaks are found as in [`super::resonance`] (same pairing); the height
//! of a lightly damped peak is very sensitive to where it is sampled, so the linear
//! variant locates each maximum to 1e-7 relative and the nonlinear one fits a
//! parabola of half-width 0.5 % around it. Note that the roller preset's first mode
//! has ζ ≈ 7.5e-5 (0.025 Hz half-power width): a measurement on a 1 Hz grid
//! under-estimates such a peak by tens of dB, so compare like with like.

use super::model_peaks::ModelPeaks;
use super::{cost_function, Fidelity, Objective, ObjectiveError};
use crate::experiments::frequency_response::FrequencyTest;
use crate::model::Params;
use crate::peaks::Peak;

/// One scaled residual is this error, dB.
pub const SCALE_DB: f64 = 0.1;
/// The residual of a measured peak the model does not have, dB.
const MISSING_DB: f64 = 40.0;

/// Measured resonance peaks (frequency, height) to match in height.
#[derive(Clone, Debug)]
pub struct PeakAmplitude {
    /// Ascending in frequency.
    pub measured: Vec<Peak>,
    /// Where and how the model's peaks are found.
    pub model: ModelPeaks,
}

impl PeakAmplitude {
    pub fn new(mut measured: Vec<Peak>, fidelity: Fidelity, test: FrequencyTest) -> Self {
        measured.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        let model = ModelPeaks::new(
            measured.first().map_or(10.0, |p| p.frequency_hz),
            measured.last().map_or(600.0, |p| p.frequency_hz),
            fidelity,
            test,
        );
        PeakAmplitude { measured, model }
    }

    /// Locate the nonlinear model's peaks on the measured frequencies `grid_hz`.
    pub fn on_grid(mut self, grid_hz: Vec<f64>) -> Self {
        self.model.grid_hz = Some(grid_hz);
        self
    }
}

impl Objective for PeakAmplitude {
    fn name(&self) -> &'static str {
        "peak_amplitude"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let peaks = self.model.locate(p, self.measured.len())?;
        Ok(self
            .measured
            .iter()
            .enumerate()
            .map(|(k, m)| match peaks.get(k) {
                Some(pk) => (pk.gain_db - m.gain_db) / SCALE_DB,
                None => MISSING_DB / SCALE_DB,
            })
            .collect())
    }

    fn len(&self) -> usize {
        self.measured.len()
    }

    fn scale(&self) -> String {
        format!("{SCALE_DB} dB of each peak height")
    }

    fn detail(&self, r: &[f64]) -> Option<serde_json::Value> {
        Some(serde_json::json!({
            "measured_db": self.measured.iter().map(|p| p.gain_db).collect::<Vec<_>>(),
            "error_db": r.iter().map(|x| x * SCALE_DB).collect::<Vec<_>>(),
        }))
    }
}

cost_function!(PeakAmplitude);
