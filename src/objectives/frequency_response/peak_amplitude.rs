//! Peak-amplitude match: the dB error of the model's resonance peak heights against
//! measured ones (paper §4.1: the internal damping Ciw, Cig from the peak heights).
//!
//! The model's peaks are found as in [`crate::objectives::resonance`] (same pairing); the height
//! of a lightly damped peak is very sensitive to where it is sampled, so the linear
//! variant locates each maximum to 1e-7 relative and the nonlinear one fits a
//! parabola of half-width 0.5 % around it. Note that the roller preset's first mode
//! has ζ ≈ 7.5e-5 (0.025 Hz half-power width): a measurement on a 1 Hz grid
//! under-estimates such a peak by tens of dB, so compare like with like.

use crate::estimation::peaks::Peak;
use crate::experiments::frequency_response::measured::{self, fits_whole_curve};
use crate::experiments::frequency_response::FrequencyTest;
use crate::io::experiment_file::Kind;
use crate::model::Params;
use crate::objectives::definition::{Definition, SetupError, Source, Stage};
use crate::objectives::detail::list;
use crate::objectives::measured_peaks::measured_peaks;
use crate::objectives::model_peaks::ModelPeaks;
use crate::objectives::{Detail, Fidelity, Objective, ObjectiveError, Properties, Smoothness};

/// Weight, relative to the resonance frequencies, of the peak heights that a gain curve
/// feeds by default: resonance frequencies alone admit two (Kw, Kg) pairs for the worm
/// (the two modes can trade their spur/drive character), and the heights tell them
/// apart. Small, so that the heights of a nonlinear measurement (friction lowers them
/// ~1 dB) hardly pull the frequencies.
pub const DEFAULT_HEIGHT_WEIGHT: f64 = 0.01;

/// The peak-amplitude objective: determines the internal damping of the meshes.
pub static DEFINITION: Definition = Definition {
    name: "peak_amplitude",
    summary: "dB error of the resonance peak heights",
    reads: &[Kind::FrequencyResponse, Kind::Resonance],
    needs: "a frequency_response or resonance experiment",
    properties: Properties {
        smoothness: Smoothness::Smooth,
        frequency_response: true,
    },
    determines: |_, p| {
        if p.cig.is_some() {
            vec!["Ciw", "Cig"]
        } else {
            vec!["Ciw"]
        }
    },
    default_weight: |exp, stage| {
        (exp.manifest.kind == Kind::FrequencyResponse
            && stage == Stage::Search
            && !fits_whole_curve(exp))
        .then_some(DEFAULT_HEIGHT_WEIGHT)
    },
    build,
    first_estimate: None,
    describe,
};

fn build(source: &Source<'_>, fidelity: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let peaks = measured_peaks(source)?;
    if peaks.iter().any(|p| !p.gain_db.is_finite()) {
        return Err(SetupError::Mismatch {
            file: source.file.into(),
            kind: source.kind().name(),
            objective: DEFINITION.name,
            needs: "peak heights (`peak_gain_db` in a resonance manifest)",
        });
    }
    let mut o = PeakAmplitude::new(peaks, fidelity, measured::frequency_test(source.experiment));
    if let Some(band) = measured::band(source.experiment) {
        // The model's peaks in the same band: they pair with the measured ones in order.
        o.model.band = (band.0.max(0.1), band.1);
    }
    Ok(Box::new(match measured::grid(source.experiment) {
        Some(grid) => o.on_grid(grid),
        None => o,
    }))
}

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
    pub(crate) fn on_grid(mut self, grid_hz: Vec<f64>) -> Self {
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

    fn detail(&self, _: &Params, r: &[f64]) -> Option<Detail> {
        Some(Detail::PeakHeights {
            measured_db: self.measured.iter().map(|p| p.gain_db).collect(),
            error_db: r.iter().map(|x| x * SCALE_DB).collect(),
        })
    }
}

/// The peak heights' errors.
fn describe(d: &Detail) -> Option<String> {
    let Detail::PeakHeights { error_db, .. } = d else {
        return None;
    };
    Some(format!("  errors {} dB", list(error_db, 2)))
}
