//! The fitted model against each experiment's data, for plots and reports: the
//! measured curve, the model at the start values and at the identified ones, in the
//! experiment's own axes. Computed here (it runs the model); drawn by
//! `report::identify`.

use crate::experiments::fluctuation::{self, FluctuationTest};
use crate::experiments::torque_curve::{simulate_torque, TorqueTest};
use crate::io::experiment_file::{Data, Experiment};
use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::Params;
use crate::sim::SimError;

/// What a curve shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    Measured,
    /// The model at the start values.
    Start,
    /// The model at the identified values.
    Fitted,
}

/// One curve of a comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Curve {
    pub label: String,
    pub role: Role,
    pub points: Vec<(f64, f64)>,
}

/// The data of one experiment and the model, in the experiment's axes.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Comparison {
    /// The experiment file.
    pub source: String,
    pub x_label: &'static str,
    pub y_label: &'static str,
    pub curves: Vec<Curve>,
}

/// Why a comparison could not be computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ComparisonError {
    #[error("{source_file}: {error}")]
    Sim {
        source_file: String,
        error: SimError,
    },
    #[error("{source_file}: {error}")]
    Fluctuation {
        source_file: String,
        error: fluctuation::FluctuationError,
    },
}

/// Points of the model's curve over the measured frequency range.
const CURVE_POINTS: usize = 600;
/// Points per curve kept for the deviation of an unbalance test.
const MAX_DEVIATION_POINTS: usize = 3000;

/// The comparison for one experiment (`None` for kinds without one).
pub fn compare(
    source: &str,
    exp: &Experiment,
    start: &Params,
    fitted: &Params,
) -> Result<Option<Comparison>, ComparisonError> {
    Ok(match &exp.data {
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            ..
        } => Some(gain(source, frequency_hz, gain_db, start, fitted)),
        Data::TorqueCurve {
            time_s,
            motor_torque_nm,
            ..
        } => {
            let test = TorqueTest::from_conditions(&exp.manifest.conditions);
            let model =
                simulate_torque(fitted, &test, time_s).map_err(|error| ComparisonError::Sim {
                    source_file: source.into(),
                    error,
                })?;
            Some(Comparison {
                source: source.into(),
                x_label: "time, s",
                y_label: "motor torque, N·m",
                curves: vec![
                    curve("measured", Role::Measured, time_s, motor_torque_nm),
                    curve("identified model", Role::Fitted, time_s, &model),
                ],
            })
        }
        Data::Unbalance { .. } => Some(unbalance(source, exp, fitted)?),
        _ => None,
    })
}

fn curve(label: &str, role: Role, x: &[f64], y: &[f64]) -> Curve {
    Curve {
        label: label.into(),
        role,
        points: x.iter().copied().zip(y.iter().copied()).collect(),
    }
}

/// The measured gain and the linear model's at the start and identified values.
fn gain(
    source: &str,
    frequency_hz: &[f64],
    gain_db: &[f64],
    start: &Params,
    fitted: &Params,
) -> Comparison {
    let (lo, hi) = (frequency_hz[0], frequency_hz[frequency_hz.len() - 1]);
    let model = |p: &Params| -> Vec<(f64, f64)> {
        let Ok(lin) = LinearResponse::new(p, Channel::TableOverMotor) else {
            return Vec::new();
        };
        (0..=CURVE_POINTS)
            .map(|i| lo + (hi - lo) * i as f64 / CURVE_POINTS as f64)
            .map(|f| (f, lin.gain_db(f)))
            .collect()
    };
    let mut measured = curve("measured", Role::Measured, frequency_hz, gain_db);
    measured.points.retain(|(_, g)| g.is_finite());
    Comparison {
        source: source.into(),
        x_label: "frequency, Hz",
        y_label: "gain θt/(θm·Rg·Rw), dB",
        curves: vec![
            measured,
            Curve {
                label: "linear model, start".into(),
                role: Role::Start,
                points: model(start),
            },
            Curve {
                label: "linear model, identified".into(),
                role: Role::Fitted,
                points: model(fitted),
            },
        ],
    }
}

/// The measured deviation over table angle and the identified model's (a full run of
/// the test at the file's conditions), one curve per direction each.
fn unbalance(
    source: &str,
    exp: &Experiment,
    fitted: &Params,
) -> Result<Comparison, ComparisonError> {
    let fail = |error| ComparisonError::Fluctuation {
        source_file: source.into(),
        error,
    };
    let measured = fluctuation::evaluate_experiment(exp).map_err(fail)?;
    let test = FluctuationTest::from_conditions(exp).map_err(fail)?;
    let record =
        fluctuation::run(fitted, &test, |_, _| {}).map_err(|error| ComparisonError::Sim {
            source_file: source.into(),
            error,
        })?;
    let model = fluctuation::evaluate(&record, fitted.ratio()).map_err(fail)?;
    let mut curves = Vec::new();
    for (who, e, role) in [
        ("measured", &measured, Role::Measured),
        ("identified model", &model, Role::Fitted),
    ] {
        for p in &e.passes {
            let every = p.angle_deg.len().div_ceil(MAX_DEVIATION_POINTS).max(1);
            let mut c = curve(
                &format!("{who}, {}", p.direction),
                role,
                &p.angle_deg,
                &p.deviation_arcsec,
            );
            c.points = c.points.into_iter().step_by(every).collect();
            curves.push(c);
        }
    }
    Ok(Comparison {
        source: source.into(),
        x_label: "table angle, deg",
        y_label: "θt − θm·Rg·Rw, arc-sec",
        curves,
    })
}
