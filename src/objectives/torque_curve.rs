//! Torque-curve residual: the error of the motor torque of the closed-loop virtual
//! torque test against the measured curve, sample by sample (paper §4.2:
//! Coulomb friction and viscous damping from the torque curve).
//!
//! The model runs the test at the file's conditions (amplitude, period, loop) and is
//! sampled at the measured times. Scale: 1 % of the measured curve's RMS per sample.
//!
//! What a torque curve can separate: the motor sees every friction reflected through
//! the ratios — fm + fw·Rg + ft·Rg·Rw all multiply the sign of the same velocity, and
//! Cm, Cw, Ct likewise add up — so at the test's slow motion a torque curve determines
//! one Coulomb and one viscous sum. Fit one Coulomb and one viscous parameter (the
//! rest fixed), or expect the identifiability warning.

use super::definition::{Definition, SetupError, Source};
use super::{Detail, Objective, ObjectiveError, Properties, Smoothness};
use crate::experiments::torque_curve::{
    from_data, motion_difference, simulate_torque, simulate_torque_batch, MotionDifference,
    TorqueTest,
};
use crate::io::experiment_file::{Axis, Kind};
use crate::model::Params;

/// The torque-curve objective: a closed-loop simulation (rough); determines the motor's
/// Coulomb friction and viscous damping (the table's reach the motor divided by the
/// ratio, 1/90 for the worm, and hardly show in its torque).
pub static DEFINITION: Definition = Definition {
    name: "torque_curve",
    summary: "error of the motor torque of the closed-loop torque test, sample by sample",
    reads: &[Kind::TorqueCurve],
    needs: "a torque_curve experiment",
    properties: Properties {
        smoothness: Smoothness::Rough,
        frequency_response: false,
    },
    determines: |_, _| vec!["fm", "Cm"],
    default_weight: |exp, _| (exp.manifest.kind == Kind::TorqueCurve).then_some(1.0),
    build,
    first_estimate: None,
    describe,
};

fn build(
    source: &Source<'_>,
    _: crate::objectives::Fidelity,
) -> Result<Box<dyn Objective>, SetupError> {
    let exp = source.experiment;
    let Some(curve) = from_data(&exp.data) else {
        return Err(SetupError::Unsupported {
            file: source.file.into(),
            kind: source.kind().name(),
        });
    };
    let test = TorqueTest::from_conditions(&exp.manifest.conditions);
    if let Some(d) = motion_difference(&curve, &test).filter(|d| d.relative_rms > MOTION_TOLERANCE)
    {
        return Err(SetupError::Data {
            file: source.file.into(),
            reason: other_motion(&d, &test, exp.data.axis().unwrap_or(Axis::Rotary)),
        });
    }
    Ok(Box::new(TorqueResidual::new(
        curve.time,
        curve.motor_torque,
        test,
    )))
}

/// The largest RMS difference, relative to the command's RMS, between a recorded
/// position and the test's command for which the objective's simulation of the test
/// is the recorded run: the servo's lag is simulated too (on the worm preset it makes
/// ~8 %), a different amplitude, period or phase makes more.
pub const MOTION_TOLERANCE: f64 = 0.25;

/// Why a curve recorded along another motion cannot feed the objective, naming what
/// differs.
fn other_motion(d: &MotionDifference, test: &TorqueTest, axis: Axis) -> String {
    let (scale, unit) = match axis {
        Axis::Rotary => (1f64.to_degrees(), "°"),
        Axis::Linear => (1e3, " mm"),
    };
    let period = d.recorded_period.map_or("no clear period".into(), |p| {
        format!("a period of about {p:.3} s")
    });
    format!(
        "the recorded motion is not the torque test's: amplitude {:.4}{unit} and {period}, against the test's {:.4}{unit} sine of {} s period (the manifest's conditions) — {:.0} % RMS apart. The torque-curve objective simulates that sine test; to identify from the motion the axis actually ran, write the record as a servo_trace experiment (time_s, reference_position_*, position_*, force_n or torque_nm: docs/experiment-files.md), which is replayed as recorded",
        d.recorded_amplitude * scale,
        test.amplitude * scale,
        test.period,
        100.0 * d.relative_rms
    )
}

/// One scaled residual is this fraction of the measured RMS torque.
pub const SCALE_OF_RMS: f64 = 0.01;

/// A measured torque curve.
#[derive(Clone, Debug)]
pub struct TorqueResidual {
    /// s from the start of the record.
    pub time_s: Vec<f64>,
    pub motor_torque_nm: Vec<f64>,
    pub test: TorqueTest,
    /// N·m per unit of scaled residual.
    pub scale_nm: f64,
}

impl TorqueResidual {
    pub fn new(time_s: Vec<f64>, motor_torque_nm: Vec<f64>, test: TorqueTest) -> Self {
        let n = motor_torque_nm.len().max(1) as f64;
        let rms = (motor_torque_nm.iter().map(|t| t * t).sum::<f64>() / n).sqrt();
        TorqueResidual {
            time_s,
            motor_torque_nm,
            test,
            scale_nm: (SCALE_OF_RMS * rms).max(1e-6),
        }
    }

    /// The model's motor torque at the measured times, N·m.
    pub(crate) fn model_nm(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(simulate_torque(p, &self.test, &self.time_s)?)
    }

    /// (model − measured) / scale.
    fn scaled(&self, model_nm: &[f64]) -> Vec<f64> {
        model_nm
            .iter()
            .zip(&self.motor_torque_nm)
            .map(|(m, t)| (m - t) / self.scale_nm)
            .collect()
    }
}

impl Objective for TorqueResidual {
    fn name(&self) -> &'static str {
        "torque_curve"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(self.scaled(&self.model_nm(p)?))
    }

    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        simulate_torque_batch(points, &self.test, &self.time_s)
            .into_iter()
            .map(|m| Ok(self.scaled(&m?)))
            .collect()
    }

    fn in_lanes(&self) -> bool {
        true
    }

    fn len(&self) -> usize {
        self.time_s.len()
    }

    fn scale(&self) -> String {
        format!(
            "{:.3e} N·m of motor torque per sample (1 % of the RMS)",
            self.scale_nm
        )
    }

    fn detail(&self, _: &Params, r: &[f64]) -> Option<Detail> {
        let n = r.len().max(1) as f64;
        let rms = (r.iter().map(|x| x * x).sum::<f64>() / n).sqrt() * self.scale_nm;
        Some(Detail::Torque { rms_error_nm: rms })
    }
}

/// The torque's RMS error.
fn describe(d: &Detail) -> Option<String> {
    let Detail::Torque { rms_error_nm } = d else {
        return None;
    };
    Some(format!("  RMS error {rms_error_nm:.4} N·m"))
}
