//! Gain-curve residual: the dB error of the model's gain at every measured frequency
//! (where a whole gain curve is given). With [`Fidelity::Nonlinear`] each frequency is
//! one virtual-test simulation (all in parallel) — at the measured conditions the
//! model reproduces a virtual measurement exactly, noise of the stick–slip included;
//! with [`Fidelity::Linear`] the exact linear gain.
//!
//! Points a measurement marks as meaningless (`below_resolution` = 1: the table did
//! not move more than the encoder resolves) are left out.

use super::model_peaks::nonlinear_gains;
use super::{cost_function, Fidelity, Objective, ObjectiveError};
use crate::experiments::frequency_response::FrequencyTest;
use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::Params;

/// One scaled residual is this error, dB.
pub const SCALE_DB: f64 = 0.1;

/// A measured gain curve.
#[derive(Clone, Debug)]
pub struct GainCurve {
    pub frequency_hz: Vec<f64>,
    pub gain_db: Vec<f64>,
    pub fidelity: Fidelity,
    pub test: FrequencyTest,
}

impl GainCurve {
    /// The model's gain at the measured frequencies, dB.
    pub fn model_db(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        match self.fidelity {
            Fidelity::Linear => {
                let lin = LinearResponse::new(p, Channel::TableOverMotor)?;
                Ok(self.frequency_hz.iter().map(|&f| lin.gain_db(f)).collect())
            }
            Fidelity::Nonlinear => Ok(nonlinear_gains(p, &self.test, &self.frequency_hz)?),
        }
    }
}

impl Objective for GainCurve {
    fn name(&self) -> &'static str {
        "gain_curve"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(self
            .model_db(p)?
            .iter()
            .zip(&self.gain_db)
            .map(|(m, g)| {
                let r = (m - g) / SCALE_DB;
                // A singular frequency of the model: a large, finite residual.
                if r.is_finite() {
                    r
                } else {
                    1e3
                }
            })
            .collect())
    }

    fn len(&self) -> usize {
        self.frequency_hz.len()
    }

    fn scale(&self) -> String {
        format!("{SCALE_DB} dB of gain at each measured frequency")
    }
}

cost_function!(GainCurve);
