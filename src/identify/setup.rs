//! From experiment files to objectives: which objectives each kind of experiment
//! feeds by default, which parameters a user who names none wants fitted, and the
//! test conditions each simulation must reproduce.

use crate::experiments::frequency_response::FrequencyTest;
use crate::experiments::torque_curve::TorqueTest;
use crate::io::experiment_file::{Data, Experiment, Kind};
use crate::model::{ParamError, Params, Topology};
use crate::objectives::model_peaks::GRID_BAND;
use crate::objectives::{
    gain_curve::GainCurve, peak_amplitude::PeakAmplitude, resonance::ResonanceMatch,
    torque_curve::TorqueResidual, unbalance_step::UnbalanceStep, Fidelity, Joint, Objective,
};
use crate::peaks::{self, Peak};

/// An objective by name (`--objective`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ObjectiveKind {
    /// Relative error of the resonance frequencies.
    Resonance,
    /// dB error of the resonance peak heights.
    PeakAmplitude,
    /// dB error of the gain at every measured frequency.
    GainCurve,
    /// dB error of the gain at the measured frequencies within ±3 % of each
    /// resonance: the peaks' shape, flanks included (the default of the nonlinear
    /// stage of `--model nonlinear`).
    GainNearPeaks,
    /// Error of the motor torque of the torque test.
    TorqueCurve,
    /// Error of the table angles where the unbalance test's deviation steps across
    /// the backlash (the table friction ft).
    UnbalanceStep,
}

/// Why experiments and objectives do not fit together.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum SetupError {
    #[error(
        "{file}: a {kind} experiment cannot feed the {objective:?} objective (it needs {needs})"
    )]
    Mismatch {
        file: String,
        kind: &'static str,
        objective: ObjectiveKind,
        needs: &'static str,
    },
    #[error("{file}: {kind} experiments are not used for identification (use frequency_response, resonance, torque_curve or unbalance)")]
    Unsupported { file: String, kind: &'static str },
    #[error("{file}: {reason}")]
    Data { file: String, reason: String },
    #[error("{file}: no resonance peak found in the gain curve")]
    NoPeaks { file: String },
    #[error("{given} weights for {count} experiments: give one --weight per experiment, in order")]
    Weights { given: usize, count: usize },
    #[error("--weight {0}: weights must be positive and finite")]
    BadWeight(f64),
    #[error(transparent)]
    Param(#[from] ParamError),
}

/// Weight, relative to the resonance frequencies, of the peak heights that the
/// default objectives of a gain curve include: resonance frequencies alone admit two
/// (Kw, Kg) pairs for the worm (the two modes can trade their spur/drive character),
/// and the heights tell them apart. Small, so that the heights of a nonlinear
/// measurement (friction lowers them ~1 dB) hardly pull the frequencies.
pub const DEFAULT_HEIGHT_WEIGHT: f64 = 0.01;

/// The objectives an experiment feeds when `--objective` is not given, with their
/// relative weights.
pub fn default_objectives(kind: Kind) -> Vec<(ObjectiveKind, f64)> {
    match kind {
        Kind::FrequencyResponse => vec![
            (ObjectiveKind::Resonance, 1.0),
            (ObjectiveKind::PeakAmplitude, DEFAULT_HEIGHT_WEIGHT),
        ],
        Kind::Resonance => vec![(ObjectiveKind::Resonance, 1.0)],
        Kind::TorqueCurve => vec![(ObjectiveKind::TorqueCurve, 1.0)],
        Kind::Unbalance => vec![(ObjectiveKind::UnbalanceStep, 1.0)],
        _ => Vec::new(),
    }
}

/// The parameters fitted when `--fit` is not given: the drive stiffnesses from
/// resonances (Kw, and Kg where there is a spur stage), the motor's Coulomb friction
/// and viscous damping from a torque curve (the table's reach the motor divided by
/// the ratio, 1/90 for the worm, and hardly show in its torque), the table's Coulomb
/// friction ft from an unbalance test (where its step stands).
pub fn default_fit(experiments: &[(String, Experiment)], p: &Params) -> Vec<String> {
    let mut fit: Vec<String> = Vec::new();
    let kinds: Vec<Kind> = experiments.iter().map(|(_, e)| e.manifest.kind).collect();
    if kinds
        .iter()
        .any(|k| matches!(k, Kind::FrequencyResponse | Kind::Resonance))
    {
        fit.push("Kw".into());
        if p.topology == Topology::SpurGear {
            fit.push("Kg".into());
        }
    }
    if kinds.contains(&Kind::TorqueCurve) {
        fit.extend(["fm".to_string(), "Cm".to_string()]);
    }
    if kinds.contains(&Kind::Unbalance) {
        fit.push("ft".into());
    }
    fit
}

/// The nonlinear frequency-response test at an experiment's conditions.
pub fn frequency_test(exp: &Experiment) -> FrequencyTest {
    let c = &exp.manifest.conditions;
    let d = FrequencyTest::default();
    FrequencyTest {
        amplitude_nm: c.torque_amplitude_nm.unwrap_or(d.amplitude_nm),
        preload_nm: c.preload_nm.unwrap_or(d.preload_nm),
        ..d
    }
}

/// The measured resonances of an experiment: the manifest's peaks, or the prominent
/// peaks of the gain curve ([`PROMINENCE_DB`]).
pub fn measured_peaks(file: &str, exp: &Experiment) -> Result<Vec<Peak>, SetupError> {
    match &exp.data {
        Data::Resonance {
            peaks_hz,
            peak_gain_db,
        } => Ok(peaks_hz
            .iter()
            .enumerate()
            .map(|(k, &f)| Peak {
                frequency_hz: f,
                gain_db: peak_gain_db
                    .as_ref()
                    .and_then(|g| g.get(k))
                    .copied()
                    .unwrap_or(f64::NAN),
            })
            .collect()),
        Data::FrequencyResponse { .. } => {
            let curve: Vec<(f64, f64)> = valid_points(exp).collect();
            let found = peaks::prominent(&curve, None, PROMINENCE_DB);
            if found.is_empty() {
                return Err(SetupError::NoPeaks { file: file.into() });
            }
            Ok(found)
        }
        _ => Err(SetupError::Unsupported {
            file: file.into(),
            kind: exp.manifest.kind.name(),
        }),
    }
}

/// A local maximum of a measured gain curve counts as a resonance when it stands
/// this far above the lowest point between it and any higher point (or the curve's
/// end) on each side — its topographic prominence. Measurement noise makes many
/// small maxima; a friction-damped worm resonance may stand only ~1.6 dB out.
pub const PROMINENCE_DB: f64 = 1.0;

/// The (frequency, gain) points of a gain curve that are measurements of the drive:
/// points flagged `below_resolution` (the table did not move more than the encoder
/// resolves) are left out.
fn valid_points(exp: &Experiment) -> impl Iterator<Item = (f64, f64)> + '_ {
    let (f, g, flags) = match &exp.data {
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            extra,
            ..
        } => (
            frequency_hz.as_slice(),
            gain_db.as_slice(),
            extra.get("below_resolution"),
        ),
        _ => (&[][..], &[][..], None),
    };
    (0..f.len())
        .filter(move |&i| flags.map_or(true, |c| c.get(i).map_or(true, |&v| v < 0.5)))
        .map(move |i| (f[i], g[i]))
}

/// The objectives an experiment feeds in the nonlinear stage of `--model nonlinear`
/// when `--objective` is not given: a gain curve's points near its resonances instead
/// of the located peaks. On the nonlinear test the top of a friction-flattened peak
/// is irregular (the worm's second resonance is flat within 0.05 dB over 4 Hz, with
/// ±0.03 dB of irregularity from one frequency to the next), so a located peak
/// jitters by ±1 Hz with the parameters; the flanks, which every point of the band
/// constrains, do not.
pub fn default_nonlinear_objectives(kind: Kind) -> Vec<(ObjectiveKind, f64)> {
    match kind {
        Kind::FrequencyResponse => vec![(ObjectiveKind::GainNearPeaks, 1.0)],
        other => default_objectives(other),
    }
}

/// The joint objective of `experiments` (each with its weight), at `fidelity`.
pub fn build(
    experiments: &[(String, Experiment)],
    chosen: Option<&[ObjectiveKind]>,
    weights: &[f64],
    fidelity: Fidelity,
) -> Result<Joint, SetupError> {
    build_with(experiments, chosen, weights, fidelity, default_objectives)
}

/// [`build`] with the objectives of each kind when none are chosen from `defaults`.
pub fn build_with(
    experiments: &[(String, Experiment)],
    chosen: Option<&[ObjectiveKind]>,
    weights: &[f64],
    fidelity: Fidelity,
    defaults: fn(Kind) -> Vec<(ObjectiveKind, f64)>,
) -> Result<Joint, SetupError> {
    if !weights.is_empty() && weights.len() != experiments.len() {
        return Err(SetupError::Weights {
            given: weights.len(),
            count: experiments.len(),
        });
    }
    if let Some(&w) = weights.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
        return Err(SetupError::BadWeight(w));
    }
    let mut joint = Joint::default();
    for (i, (file, exp)) in experiments.iter().enumerate() {
        let kind = exp.manifest.kind;
        let weight = weights.get(i).copied().unwrap_or(1.0);
        let kinds = match chosen {
            Some(c) => c
                .iter()
                .copied()
                .filter(|o| usable(*o, kind))
                .map(|o| (o, 1.0))
                .collect::<Vec<_>>(),
            None => defaults(kind),
        };
        if kinds.is_empty() {
            return match chosen {
                Some(c) => Err(SetupError::Mismatch {
                    file: file.clone(),
                    kind: kind.name(),
                    objective: c[0],
                    needs: needs(c[0]),
                }),
                None => Err(SetupError::Unsupported {
                    file: file.clone(),
                    kind: kind.name(),
                }),
            };
        }
        for (o, w) in kinds {
            joint.push(file.clone(), weight * w, objective(o, file, exp, fidelity)?);
        }
    }
    Ok(joint)
}

fn usable(o: ObjectiveKind, kind: Kind) -> bool {
    match o {
        ObjectiveKind::Resonance => matches!(kind, Kind::FrequencyResponse | Kind::Resonance),
        ObjectiveKind::PeakAmplitude => matches!(kind, Kind::FrequencyResponse | Kind::Resonance),
        ObjectiveKind::GainCurve | ObjectiveKind::GainNearPeaks => kind == Kind::FrequencyResponse,
        ObjectiveKind::TorqueCurve => kind == Kind::TorqueCurve,
        ObjectiveKind::UnbalanceStep => kind == Kind::Unbalance,
    }
}

fn needs(o: ObjectiveKind) -> &'static str {
    match o {
        ObjectiveKind::Resonance | ObjectiveKind::PeakAmplitude => {
            "a frequency_response or resonance experiment"
        }
        ObjectiveKind::GainCurve | ObjectiveKind::GainNearPeaks => {
            "a frequency_response experiment"
        }
        ObjectiveKind::TorqueCurve => "a torque_curve experiment",
        ObjectiveKind::UnbalanceStep => "an unbalance experiment",
    }
}

fn objective(
    o: ObjectiveKind,
    file: &str,
    exp: &Experiment,
    fidelity: Fidelity,
) -> Result<Box<dyn Objective>, SetupError> {
    let test = frequency_test(exp);
    Ok(match o {
        ObjectiveKind::Resonance => {
            let hz = measured_peaks(file, exp)?
                .iter()
                .map(|p| p.frequency_hz)
                .collect();
            let o = ResonanceMatch::new(hz, fidelity, test);
            Box::new(match measured_grid(exp) {
                Some(grid) => o.on_grid(grid),
                None => o,
            })
        }
        ObjectiveKind::PeakAmplitude => {
            let peaks = measured_peaks(file, exp)?;
            if peaks.iter().any(|p| !p.gain_db.is_finite()) {
                return Err(SetupError::Mismatch {
                    file: file.into(),
                    kind: exp.manifest.kind.name(),
                    objective: o,
                    needs: "peak heights (`peak_gain_db` in a resonance manifest)",
                });
            }
            let o = PeakAmplitude::new(peaks, fidelity, test);
            Box::new(match measured_grid(exp) {
                Some(grid) => o.on_grid(grid),
                None => o,
            })
        }
        ObjectiveKind::GainNearPeaks => {
            let peaks = measured_peaks(file, exp)?;
            let (f, g): (Vec<f64>, Vec<f64>) = valid_points(exp)
                .filter(|(f, _)| {
                    peaks
                        .iter()
                        .any(|pk| (f - pk.frequency_hz).abs() <= GRID_BAND * pk.frequency_hz)
                })
                .unzip();
            Box::new(GainCurve {
                frequency_hz: f,
                gain_db: g,
                fidelity,
                test,
            })
        }
        ObjectiveKind::GainCurve => {
            let (f, g): (Vec<f64>, Vec<f64>) = valid_points(exp).unzip();
            Box::new(GainCurve {
                frequency_hz: f,
                gain_db: g,
                fidelity,
                test,
            })
        }
        ObjectiveKind::TorqueCurve => match &exp.data {
            Data::TorqueCurve {
                time_s,
                motor_torque_nm,
                ..
            } => Box::new(TorqueResidual::new(
                time_s.clone(),
                motor_torque_nm.clone(),
                TorqueTest::from_conditions(&exp.manifest.conditions),
            )),
            _ => unreachable!("usable() admits torque_curve only"),
        },
        ObjectiveKind::UnbalanceStep => {
            Box::new(UnbalanceStep::new(file, exp).map_err(|e| SetupError::Data {
                file: file.into(),
                reason: match e {
                    crate::objectives::ObjectiveError::Data { reason, .. } => reason,
                    other => other.to_string(),
                },
            })?)
        }
    })
}

/// The frequencies of a measured gain curve (ascending), on which the nonlinear
/// model's peaks are located like for like; `None` for other kinds.
pub fn measured_grid(exp: &Experiment) -> Option<Vec<f64>> {
    if exp.manifest.kind != Kind::FrequencyResponse {
        return None;
    }
    let mut f: Vec<f64> = valid_points(exp).map(|(f, _)| f).collect();
    f.sort_by(f64::total_cmp);
    Some(f)
}

/// Whether any experiment's objective depends on the frequency-response fidelity.
pub fn has_frequency_response(experiments: &[(String, Experiment)]) -> bool {
    experiments
        .iter()
        .any(|(_, e)| e.manifest.kind == Kind::FrequencyResponse)
}
