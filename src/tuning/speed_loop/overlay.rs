//! A measured speed-loop response beside the model's with one or more controller
//! settings — today's and a proposed one (`rtid tune --measured`) — each with its
//! misfit, and the warning that a model which does not explain the measurement (a
//! misfit beyond the record's noise, [`super::measured::MISFIT_CHI2`]) is no ground
//! for the settings proposed on it.

use serde::Serialize;

use super::measured::{model_bode, MeasuredSpeedLoop, Misfit, MISFIT_CHI2};
use crate::model::{ParamError, Params};

/// The measurement and the models.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Overlay {
    /// The experiment file.
    pub source: String,
    pub measured: Curve,
    pub models: Vec<ModelCurve>,
}

/// A response's lines, gains (dB) and phases (deg, unwrapped).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Curve {
    pub frequency_hz: Vec<f64>,
    pub gain_db: Vec<f64>,
    pub phase_deg: Vec<f64>,
}

/// One setting's closed loop at the measured lines, and how well it explains them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelCurve {
    pub label: String,
    pub curve: Curve,
    pub misfit: Misfit,
}

/// `measured` beside the model of each (label, parameter set).
pub fn overlay(
    source: &str,
    measured: &MeasuredSpeedLoop,
    settings: &[(&str, &Params)],
) -> Result<Overlay, ParamError> {
    let (gain_db, phase_deg) = measured.bode();
    let f = &measured.frequency_hz;
    let models = settings
        .iter()
        .map(|(label, p)| {
            let at = model_bode(p, &measured.conditions, f)?;
            let mut curve = Curve {
                frequency_hz: Vec::new(),
                gain_db: Vec::new(),
                phase_deg: Vec::new(),
            };
            for (hz, v) in f.iter().zip(at) {
                if let Some((g, ph)) = v {
                    curve.frequency_hz.push(*hz);
                    curve.gain_db.push(g);
                    curve.phase_deg.push(ph);
                }
            }
            Ok(ModelCurve {
                label: label.to_string(),
                curve,
                misfit: measured.misfit(p)?,
            })
        })
        .collect::<Result<_, ParamError>>()?;
    Ok(Overlay {
        source: source.into(),
        measured: Curve {
            frequency_hz: f.clone(),
            gain_db,
            phase_deg,
        },
        models,
    })
}

/// The warning when the model of `label` does not explain the measurement.
pub fn warning(source: &str, label: &str, m: &Misfit) -> Option<String> {
    (!m.explained).then(|| {
        format!(
            "{source}: the model ({label}) does not explain the measured speed loop: RMS \
             {:.2} dB and {:.1}° over its lines, reduced χ² {:.1} (more than {MISFIT_CHI2}: \
             beyond the record's noise) — settings tuned on this model are not checked \
             against this machine",
            m.gain_rms_db, m.phase_rms_deg, m.reduced_chi2
        )
    })
}
