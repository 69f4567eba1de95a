//! Gain-curve residual: the dB error of the model's gain at every measured frequency
//! (where a whole gain curve is given). With [`Fidelity::Nonlinear`] each frequency is
//! one virtual-test simulation (all in parallel) — at the measured conditions the
//! model reproduces a virtual measurement exactly, noise of the stick–slip included;
//! with [`Fidelity::Linear`] the exact linear gain.
//!
//! Points a measurement marks as meaningless (`below_resolution` = 1: the table did
//! not move more than the encoder resolves) are left out.

use super::model_peaks::{nonlinear_gains, GRID_BAND};
use super::registry::{Definition, SetupError, Source, Stage};
use super::resonance::drive_stiffnesses;
use super::{measured, Fidelity, Objective, ObjectiveError, Properties, Smoothness};
use crate::experiments::frequency_response::FrequencyTest;
use crate::io::experiment_file::Kind;
use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::Params;

const PROPERTIES: Properties = Properties {
    smoothness: Smoothness::Smooth,
    frequency_response: true,
};

/// The whole measured gain curve.
pub static DEFINITION: Definition = Definition {
    name: "gain_curve",
    summary: "dB error of the gain at every measured frequency",
    reads: &[Kind::FrequencyResponse],
    needs: "a frequency_response experiment",
    properties: PROPERTIES,
    determines: drive_stiffnesses,
    default_weight: |_, _| None,
    build: |source, fidelity| Ok(Box::new(GainCurve::of(source, fidelity, |_| true))),
    first_estimate: None,
};

/// The measured gain within ±[`GRID_BAND`] of each resonance: the peaks' shape,
/// flanks included — the default of the nonlinear correction stage of `--model
/// nonlinear`. On the nonlinear test the top of a friction-flattened peak is irregular
/// (the worm's second resonance is flat within 0.05 dB over 4 Hz, with ±0.03 dB of
/// irregularity from one frequency to the next), so a located peak jitters by ±1 Hz
/// with the parameters; the flanks, which every point of the band constrains, do not.
pub static NEAR_PEAKS: Definition = Definition {
    name: "gain_near_peaks",
    summary: "dB error of the gain at the measured frequencies within ±3 % of each resonance",
    reads: &[Kind::FrequencyResponse],
    needs: "a frequency_response experiment",
    properties: PROPERTIES,
    determines: drive_stiffnesses,
    default_weight: |kind, stage| {
        (kind == Kind::FrequencyResponse && stage == Stage::Correction).then_some(1.0)
    },
    build: near_peaks,
    first_estimate: None,
};

fn near_peaks(source: &Source<'_>, fidelity: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let peaks = measured::peaks(source)?;
    let near = |f: f64| {
        peaks
            .iter()
            .any(|pk| (f - pk.frequency_hz).abs() <= GRID_BAND * pk.frequency_hz)
    };
    Ok(Box::new(GainCurve::of(source, fidelity, near)))
}

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
    /// The valid measured points of `source` at frequencies where `keep` holds.
    fn of(source: &Source<'_>, fidelity: Fidelity, keep: impl Fn(f64) -> bool) -> GainCurve {
        let (frequency_hz, gain_db) = measured::valid_points(source.experiment)
            .filter(|(f, _)| keep(*f))
            .unzip();
        GainCurve {
            frequency_hz,
            gain_db,
            fidelity,
            test: measured::frequency_test(source.experiment),
        }
    }

    /// The model's gain at the measured frequencies, dB.
    pub(crate) fn model_db(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
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
