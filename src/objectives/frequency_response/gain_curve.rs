//! Gain-curve residual: the dB error of the model's gain at every measured frequency
//! (where a whole gain curve is given). With [`Fidelity::Nonlinear`] each frequency is
//! one virtual-test simulation (all in parallel) — at the measured conditions the
//! model reproduces a virtual measurement exactly, noise of the stick–slip included;
//! with [`Fidelity::Linear`] the exact linear gain.
//!
//! Points a measurement marks as meaningless (`below_resolution` = 1: the table did
//! not move more than the encoder resolves) are left out.

use std::f64::consts::TAU;

use crate::experiments::frequency_response::measured::{
    self, fits_whole_curve, of_the_mechanics, DB_PER_NEPER,
};
use crate::experiments::frequency_response::FrequencyTest;
use crate::io::experiment_file::{Delay, Experiment, Kind, Response};
use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::{Params, Topology};
use crate::objectives::complex_response::{fit_delay, rms_errors, sigmas, wrap};
use crate::objectives::definition::{Definition, SetupError, Source, Stage};
use crate::objectives::measured_peaks::measured_peaks;
use crate::objectives::model_peaks::{nonlinear_responses, GRID_BAND};
use crate::objectives::resonance::drive_stiffnesses;
use crate::objectives::{Detail, Fidelity, Objective, ObjectiveError, Properties, Smoothness};

const PROPERTIES: Properties = Properties {
    smoothness: Smoothness::Smooth,
    frequency_response: true,
};

/// The whole measured gain curve.
pub static DEFINITION: Definition = Definition {
    name: "gain_curve",
    summary:
        "dB error of the gain at every measured frequency, and of the phase where the file has one",
    reads: &[Kind::FrequencyResponse],
    needs: "a frequency_response experiment",
    properties: PROPERTIES,
    determines: curve_determines,
    default_weight: |exp, stage| {
        (stage == Stage::Search && fits_whole_curve(exp) && of_the_mechanics(exp)).then_some(1.0)
    },
    build: |source, fidelity| Ok(Box::new(GainCurve::of(source, fidelity, |_| true)?)),
    first_estimate: None,
    describe,
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
    determines: |_, p| drive_stiffnesses(p),
    default_weight: |exp, stage| {
        (exp.manifest.kind == Kind::FrequencyResponse
            && stage == Stage::Correction
            && of_the_mechanics(exp))
        .then_some(1.0)
    },
    build: near_peaks,
    first_estimate: None,
    describe,
};

fn near_peaks(source: &Source<'_>, fidelity: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let peaks = measured_peaks(source)?;
    let near = |f: f64| {
        peaks
            .iter()
            .any(|pk| (f - pk.frequency_hz).abs() <= GRID_BAND * pk.frequency_hz)
    };
    Ok(Box::new(GainCurve::of(source, fidelity, near)?))
}

/// What a whole curve determines: table over motor, the drive stiffnesses and, with
/// phase, the meshes' (or the coupling's) dampings; a compliance, the motor's inertia
/// too — a direct drive's, its inertia and damping.
fn curve_determines(exp: &Experiment, p: &Params) -> Vec<&'static str> {
    let response = measured::form(exp).response;
    let mut out = match (response, p.topology) {
        (Response::MotorCompliance, Topology::DirectDrive) => return vec!["Jt", "Ct"],
        (Response::TableOverMotor, Topology::DirectDrive) => return Vec::new(),
        (Response::MotorCompliance, _) => vec!["Jm"],
        (Response::TableOverMotor, _) => Vec::new(),
        (Response::SpeedLoop, _) => return Vec::new(),
    };
    out.extend(drive_stiffnesses(p));
    if measured::has_phase(exp) {
        out.push("Ciw");
        if p.cig.is_some() {
            out.push("Cig");
        }
    }
    out
}

/// One scaled residual is this error, dB (and, on a complex response, the same
/// relative error in phase: 0.1 dB ↔ 0.66°), where the file states no noise.
pub const SCALE_DB: f64 = 0.1;

/// A measured gain curve, and its phase where the file has one.
#[derive(Clone, Debug)]
pub struct GainCurve {
    pub frequency_hz: Vec<f64>,
    /// The drive's ratio, dB.
    pub gain_db: Vec<f64>,
    /// σ of each gain, dB.
    pub sigma_db: Vec<f64>,
    /// The complex response: the residual is then complex ([`crate::objectives::complex_response`]).
    pub complex: Option<Complex>,
    pub response: Response,
    pub fidelity: Fidelity,
    pub test: FrequencyTest,
}

/// The phase of a measured response, its noise and its delay.
#[derive(Clone, Debug)]
pub struct Complex {
    /// Drive's phase, rad (given delay taken out).
    pub phase_rad: Vec<f64>,
    /// σ of ln|H| and of the phase, per line.
    pub sigma_ln: Vec<f64>,
    pub sigma_phase: Vec<f64>,
    /// The delay is fitted; the file's ratio is inverted (sign of its delay term).
    pub fit_delay: bool,
    pub sign: f64,
}

impl GainCurve {
    /// The valid measured points of `source` at frequencies where `keep` holds.
    fn of(
        source: &Source<'_>,
        fidelity: Fidelity,
        keep: impl Fn(f64) -> bool + Copy,
    ) -> Result<GainCurve, SetupError> {
        let exp = source.experiment;
        let form = measured::form(exp);
        if form.response == Response::SpeedLoop {
            return Err(SetupError::Data {
                file: source.file.into(),
                reason: "a speed_loop response is the drive's closed loop, not the \
                         mechanics alone: the speed_loop objective fits it (the default)"
                    .into(),
            });
        }
        if fidelity == Fidelity::Nonlinear && form.response != Response::TableOverMotor {
            return Err(SetupError::Data {
                file: source.file.into(),
                reason: format!(
                    "a {} response is fitted with the linear model only (the nonlinear \
                     virtual test measures the table over the motor): --model linear",
                    form.response.name()
                ),
            });
        }
        let default = SCALE_DB / DB_PER_NEPER;
        let (frequency_hz, gain_db): (Vec<f64>, Vec<f64>) = measured::valid_points(exp)
            .filter(|(f, _)| keep(*f))
            .unzip();
        let complex = measured::complex_points(exp, keep).map(|m| {
            let (sigma_ln, sigma_phase) = sigmas(&m, default);
            Complex {
                phase_rad: m.phase_rad,
                sigma_ln,
                sigma_phase,
                fit_delay: form.delay == Delay::Unknown,
                sign: if form.inverted { -1.0 } else { 1.0 },
            }
        });
        check_orientation(
            source.file,
            form.response,
            &frequency_hz,
            &gain_db,
            complex.as_ref(),
        )?;
        let sigma_db = match &complex {
            Some(c) => c.sigma_ln.iter().map(|s| s * DB_PER_NEPER).collect(),
            None => vec![SCALE_DB; frequency_hz.len()],
        };
        Ok(GainCurve {
            frequency_hz,
            gain_db,
            sigma_db,
            complex,
            response: form.response,
            fidelity,
            test: measured::frequency_test(exp),
        })
    }

    fn channel(&self) -> Channel {
        match self.response {
            Response::TableOverMotor => Channel::TableOverMotor,
            // `of` refuses a speed loop; its closed loop is `objectives::speed_loop`'s.
            Response::MotorCompliance | Response::SpeedLoop => Channel::MotorOverTorque,
        }
    }

    /// The model's gain (dB) and phase (rad) at the measured frequencies.
    pub(crate) fn model(&self, p: &Params) -> Result<Vec<(f64, f64)>, ObjectiveError> {
        match self.fidelity {
            Fidelity::Linear => {
                let lin = LinearResponse::new(p, self.channel())?;
                Ok(self
                    .frequency_hz
                    .iter()
                    .map(|&f| {
                        lin.at(f).map_or((f64::NEG_INFINITY, f64::NAN), |h| {
                            (20.0 * h.norm().log10(), h.arg())
                        })
                    })
                    .collect())
            }
            Fidelity::Nonlinear => Ok(nonlinear_responses(p, &self.test, &self.frequency_hz)?
                .into_iter()
                .map(|(g, ph)| (g, ph.to_radians()))
                .collect()),
        }
    }

    /// The phase errors (model − measured, rad, wrapped) and the delay fitted into
    /// them (0 unless the delay is unknown).
    fn phase_errors(&self, c: &Complex, model: &[(f64, f64)]) -> (Vec<f64>, f64) {
        let raw: Vec<f64> = model
            .iter()
            .zip(&c.phase_rad)
            .map(|((_, m), d)| wrap(m - d))
            .collect();
        if !c.fit_delay {
            return (raw, 0.0);
        }
        let omega: Vec<f64> = self.frequency_hz.iter().map(|f| TAU * f).collect();
        let w: Vec<f64> = c.sigma_phase.iter().map(|s| 1.0 / (s * s)).collect();
        let finite = raw.iter().all(|e| e.is_finite());
        let tau = if finite {
            fit_delay(&raw, &omega, &w, c.sign)
        } else {
            0.0
        };
        let errors = raw
            .iter()
            .zip(&omega)
            .map(|(e, o)| wrap(e - c.sign * o * tau))
            .collect();
        (errors, tau)
    }
}

/// A driven table lags its motor: the phase of table over motor, unwrapped from the
/// lowest line, falls (0 → −180° past each motor-held mode). A compliance falls with
/// frequency like a free mass's (−40 dB per decade, first line to last, whatever
/// modes lie between). A ratio that leads, or rises, is the inverse of the one the
/// manifest names.
fn check_orientation(
    file: &str,
    response: Response,
    frequency_hz: &[f64],
    gain_db: &[f64],
    complex: Option<&Complex>,
) -> Result<(), SetupError> {
    let refuse = |what: String| {
        Err(SetupError::Data {
            file: file.into(),
            reason: format!(
                "{what}: the file holds the inverse ratio? State its reference channel \
                 (conditions.reference: \"{}\") — or its phase has the opposite sign \
                 convention (negate phase_deg)",
                response.output().name()
            ),
        })
    };
    match (response, complex) {
        (Response::TableOverMotor, Some(c)) if c.phase_rad.len() >= 3 => {
            let mut phase = crate::objectives::complex_response::unwrap(&c.phase_rad);
            let shift = TAU * (phase[0] / TAU).round();
            phase.iter_mut().for_each(|p| *p -= shift);
            phase.sort_by(f64::total_cmp);
            let median = phase[phase.len() / 2];
            if median > 10f64.to_radians() {
                return refuse(format!(
                    "the table's phase leads the motor's (median {:+.0}° over the lines), \
                     where a driven table lags its motor",
                    median.to_degrees()
                ));
            }
            Ok(())
        }
        (Response::MotorCompliance, _) if frequency_hz.len() >= 2 => {
            let n = frequency_hz.len();
            let (f0, f1) = (frequency_hz[0], frequency_hz[n - 1]);
            let slope = (gain_db[n - 1] - gain_db[0]) / (f1 / f0).log10();
            if slope > 20.0 {
                return refuse(format!(
                    "the compliance rises with frequency ({slope:+.0} dB per decade over \
                     {f0}–{f1} Hz), where a driven mass's falls"
                ));
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

impl GainCurve {
    /// The delay the phase errors `errors` show when the manifest states none to fit:
    /// `Some` where taking it out would halve their RMS.
    fn unstated_delay(&self, c: &Complex, errors: &[f64]) -> Option<f64> {
        let omega: Vec<f64> = self.frequency_hz.iter().map(|f| TAU * f).collect();
        let w: Vec<f64> = c.sigma_phase.iter().map(|s| 1.0 / (s * s)).collect();
        let tau = fit_delay(errors, &omega, &w, c.sign);
        let rms = |e: &mut dyn Iterator<Item = f64>| {
            (e.zip(&w).map(|(x, w)| w * x * x).sum::<f64>() / w.len().max(1) as f64).sqrt()
        };
        let before = rms(&mut errors.iter().copied());
        let after = rms(&mut errors
            .iter()
            .zip(&omega)
            .map(|(e, o)| wrap(e - c.sign * o * tau)));
        (after < 0.5 * before && tau != 0.0).then_some(tau)
    }
}

/// A scaled residual, or a large finite one where the model is singular.
fn finite_or_large(r: f64) -> f64 {
    if r.is_finite() {
        r
    } else {
        1e3
    }
}

impl Objective for GainCurve {
    fn name(&self) -> &'static str {
        "gain_curve"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let model = self.model(p)?;
        let gains = model
            .iter()
            .zip(&self.gain_db)
            .zip(&self.sigma_db)
            .map(|(((m, _), g), s)| finite_or_large((m - g) / s));
        let Some(c) = &self.complex else {
            return Ok(gains.collect());
        };
        let (errors, _) = self.phase_errors(c, &model);
        let phases = errors
            .iter()
            .zip(&c.sigma_phase)
            .map(|(e, s)| finite_or_large(e / s));
        Ok(gains.chain(phases).collect())
    }

    fn len(&self) -> usize {
        self.frequency_hz.len() * if self.complex.is_some() { 2 } else { 1 }
    }

    fn scale(&self) -> String {
        let stated = self.sigma_db.iter().any(|s| *s != SCALE_DB);
        match (&self.complex, stated) {
            (None, false) => format!("{SCALE_DB} dB of gain at each measured frequency"),
            (None, true) => "the stated σ of the gain at each measured frequency".into(),
            (Some(_), false) => format!(
                "{SCALE_DB} dB of gain and {:.2}° of phase at each measured frequency",
                (SCALE_DB / DB_PER_NEPER).to_degrees()
            ),
            (Some(_), true) => {
                "the stated σ of the gain and of the phase at each measured frequency".into()
            }
        }
    }

    fn detail(&self, p: &Params, r: &[f64]) -> Option<Detail> {
        let c = self.complex.as_ref()?;
        let (gain_rms_db, phase_rms_deg) = rms_errors(r, &c.sigma_ln, &c.sigma_phase);
        let model = self.model(p).ok()?;
        let (errors, fitted) = self.phase_errors(c, &model);
        Some(Detail::ComplexResponse {
            gain_rms_db,
            phase_rms_deg,
            fitted_delay_s: c.fit_delay.then_some(fitted),
            unstated_delay_s: (!c.fit_delay)
                .then(|| self.unstated_delay(c, &errors))
                .flatten(),
        })
    }
}

/// The gain's and phase's RMS errors, and the delay fitted with the model.
fn describe(d: &Detail) -> Option<String> {
    let Detail::ComplexResponse {
        gain_rms_db,
        phase_rms_deg,
        fitted_delay_s,
        ..
    } = d
    else {
        return None;
    };
    Some(format!(
        "  RMS error {gain_rms_db:.3} dB, {phase_rms_deg:.2}°{}",
        fitted_delay_s.map_or(String::new(), |d| format!(
            "; delay fitted {:.1} µs",
            1e6 * d
        ))
    ))
}
