//! Resonance-frequency match: the relative error of the model's resonance frequencies
//! against measured ones (paper §4.1; docs/model.md).
//!
//! The model's resonances are the peaks of its frequency response — the damped,
//! motor-held modes — never the undamped eigenvalues (fitting those to measured peaks
//! biases Kw by ~6 %). With [`Fidelity::Linear`] they come from the exact
//! linear response with damping; with [`Fidelity::Nonlinear`] from the nonlinear
//! virtual test at the experiment's conditions ([`crate::objectives::model_peaks`]), sampled on
//! the measured frequencies when there is a measured gain curve.
//!
//! Pairing: the model's `n` highest peaks in the band (n = measured peaks), in
//! ascending frequency, against the measured ones in ascending frequency. A measured
//! peak the model does not have costs a residual of 100 % of its frequency.

use crate::experiments::frequency_response::measured::{self, fits_whole_curve};
use crate::experiments::frequency_response::FrequencyTest;
use crate::io::experiment_file::Kind;
use crate::model::Params;
use crate::objectives::definition::{Definition, SetupError, Source, Stage};
use crate::objectives::detail::list;
use crate::objectives::measured_peaks::measured_peaks;
use crate::objectives::model_peaks::ModelPeaks;
use crate::objectives::{Detail, Fidelity, Objective, ObjectiveError, Properties, Smoothness};

/// The resonance objective: fed by default by every frequency response and resonance
/// list; determines the drive stiffnesses.
pub static DEFINITION: Definition = Definition {
    name: "resonance",
    summary: "relative error of the resonance frequencies",
    reads: &[Kind::FrequencyResponse, Kind::Resonance],
    needs: "a frequency_response or resonance experiment",
    properties: Properties {
        smoothness: Smoothness::Smooth,
        frequency_response: true,
    },
    determines: |_, p| drive_stiffnesses(p),
    default_weight: |exp, stage| match (exp.manifest.kind, stage) {
        (Kind::FrequencyResponse, Stage::Search) if !fits_whole_curve(exp) => Some(1.0),
        (Kind::Resonance, _) => Some(1.0),
        _ => None,
    },
    build,
    first_estimate: None,
    describe,
};

/// The drive stiffnesses: Kw, and Kg where there is a spur stage.
pub(super) fn drive_stiffnesses(p: &Params) -> Vec<&'static str> {
    if p.kg.is_some() {
        vec!["Kw", "Kg"]
    } else {
        vec!["Kw"]
    }
}

fn build(source: &Source<'_>, fidelity: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let hz = measured_peaks(source)?
        .iter()
        .map(|p| p.frequency_hz)
        .collect();
    let mut o = ResonanceMatch::new(hz, fidelity, measured::frequency_test(source.experiment));
    if let Some(band) = measured::band(source.experiment) {
        // The model's peaks in the same band: they pair with the measured ones in order.
        o.model.band = (band.0.max(0.1), band.1);
    }
    Ok(Box::new(match measured::grid(source.experiment) {
        Some(grid) => o.on_grid(grid),
        None => o,
    }))
}

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
    pub(crate) fn on_grid(mut self, grid_hz: Vec<f64>) -> Self {
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

    fn detail(&self, _: &Params, r: &[f64]) -> Option<Detail> {
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
        Some(Detail::Resonance {
            measured_hz: self.measured_hz.clone(),
            model_hz: model,
            max_miss_hz: max,
        })
    }
}

/// The measured and model resonances.
fn describe(d: &Detail) -> Option<String> {
    let Detail::Resonance {
        measured_hz,
        model_hz,
        ..
    } = d
    else {
        return None;
    };
    Some(format!(
        "  measured {} Hz, model {} Hz",
        list(measured_hz, 2),
        list(model_hz, 2)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_linear_resonances_of_the_model_itself_match_exactly() {
        let p = presets::load("worm-gear").unwrap();
        let peaks = crate::estimation::peaks::of_linear_response(&p, 10.0, 600.0, 2).unwrap();
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
