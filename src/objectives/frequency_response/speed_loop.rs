//! The closed speed loop's residual: a drive's measured reference response of its
//! speed loop (actual speed over speed setpoint, `response: "speed_loop"`) against the
//! model inside its speed controller, exact on the sampled loop
//! ([`crate::tuning::speed_loop::model`]), line by line as
//! [`crate::objectives::complex_response`] weighs a complex response: the errors of ln|T| and of
//! the phase, each over its line's σ (from the coherence and the averages, else 1 %).
//!
//! **What it determines.** The loop closes over the PI, the drive gain and the
//! mechanics together: scaling every inertia, stiffness and damping and the gains Kvp
//! and Kvi by one factor leaves T unchanged. A rigid axis's response says Kvp/J and
//! Kvi/J (and Ct/J), not J; a two-mass drive's the same ratios and its coupling's
//! frequencies. So where the manifest carries the gains (`controller.Kvp`, `Kvi`)
//! the inertia is determined; where it does not (a drive's file), the gains are fitted
//! with the inertia held, and the values are relative to it. Fitting both is
//! singular, and the identification's correlations say so.

use crate::io::experiment_file::{Experiment, Kind};
use crate::model::{Params, Topology};
use crate::objectives::definition::{Definition, SetupError, Source, Stage};
use crate::objectives::{Detail, Fidelity, Objective, ObjectiveError, Properties, Smoothness};
use crate::tuning::speed_loop::measured::{is_speed_loop, MeasuredSpeedLoop};

/// The closed speed loop's whole complex response.
pub static DEFINITION: Definition = Definition {
    name: "speed_loop",
    summary: "gain and phase error of the closed speed loop (actual speed over setpoint) at \
              every measured line",
    reads: &[Kind::FrequencyResponse],
    needs: "a frequency_response experiment with response \"speed_loop\"",
    properties: Properties {
        smoothness: Smoothness::Smooth,
        frequency_response: false,
    },
    determines,
    default_weight: |exp, stage| (stage == Stage::Search && is_speed_loop(exp)).then_some(1.0),
    build,
    first_estimate: None,
    describe,
};

/// With the gains stated: the mechanics, the inertia included. Without: the gains
/// and the mechanics' ratios with one inertia held (module docs); the encoder's dead
/// time either way (the loop's delay).
fn determines(exp: &Experiment, p: &Params) -> Vec<&'static str> {
    let stated = exp
        .manifest
        .conditions
        .controller
        .as_ref()
        .is_some_and(|c| c.kvp.is_some() && c.kvi.is_some());
    let mut out = match (p.topology, stated) {
        (Topology::DirectDrive, true) => vec!["Jt"],
        (Topology::DirectDrive, false) => vec!["Kvp", "Kvi"],
        (Topology::TwoMass, true) => vec!["Jm", "Jt", "Kw", "Ciw"],
        (Topology::TwoMass, false) => vec!["Jm", "Kw", "Ciw", "Kvp", "Kvi"],
        (_, true) => vec!["Jm"],
        (_, false) => vec!["Kvp", "Kvi"],
    };
    if matches!(p.topology, Topology::SpurGear | Topology::Direct) {
        out.extend(crate::objectives::resonance::drive_stiffnesses(p));
    }
    out.push("encoder_delay");
    out
}

fn build(source: &Source<'_>, _: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let measured = MeasuredSpeedLoop::of(source.experiment).map_err(|reason| SetupError::Data {
        file: source.file.into(),
        reason: reason.to_string(),
    })?;
    Ok(Box::new(SpeedLoop { measured }))
}

/// A measured speed-loop response.
pub struct SpeedLoop {
    pub measured: MeasuredSpeedLoop,
}

impl Objective for SpeedLoop {
    fn name(&self) -> &'static str {
        "speed_loop"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(self.measured.residuals(p)?)
    }

    fn len(&self) -> usize {
        2 * self.measured.frequency_hz.len()
    }

    fn scale(&self) -> String {
        if self.measured.noise_stated {
            "the σ of gain and phase each line's coherence gives".into()
        } else {
            "1 % of the response in gain and phase at each line".into()
        }
    }

    fn detail(&self, _: &Params, r: &[f64]) -> Option<Detail> {
        let m = self.measured.misfit_of(r);
        Some(Detail::ComplexResponse {
            gain_rms_db: m.gain_rms_db,
            phase_rms_deg: m.phase_rms_deg,
            fitted_delay_s: None,
            unstated_delay_s: None,
        })
    }
}

/// The gain's and phase's RMS errors.
fn describe(d: &Detail) -> Option<String> {
    let Detail::ComplexResponse {
        gain_rms_db,
        phase_rms_deg,
        ..
    } = d
    else {
        return None;
    };
    Some(format!(
        "  RMS error {gain_rms_db:.3} dB, {phase_rms_deg:.2}°"
    ))
}
