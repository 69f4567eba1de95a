//! The fitted model against each experiment's data, for plots and reports: the
//! measured curve, the model at the start values and at the identified ones, in the
//! experiment's own axes. Computed here (it runs the model); drawn by
//! `report::identify`.

use crate::identify::result::comparison::{Comparison, Curve, Role};

mod frequency_response;
mod grid;
mod speed_loop;

use crate::experiments::fluctuation::{self, FluctuationTest};
use crate::experiments::servo_trace::{self, ServoTrace, TraceError};
use crate::experiments::torque_curve::{simulate_torque, TorqueTest};
use crate::identify::config::ExperimentSpec;
use crate::io::experiment_file::{Data, Experiment};
use crate::model::params::Axis;
use crate::model::Params;
use crate::sim::SimError;

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
    #[error("{source_file}: {error}")]
    Trace {
        source_file: String,
        error: TraceError,
    },
}

/// Points per curve kept for the deviation of an unbalance test.
const MAX_DEVIATION_POINTS: usize = 3000;

/// The comparisons of every experiment, in order (kinds without one add none).
pub fn compare_all(
    experiments: &[ExperimentSpec],
    start: &Params,
    fitted: &Params,
) -> Result<Vec<Comparison>, ComparisonError> {
    let mut all = Vec::new();
    for e in experiments {
        all.extend(compare(&e.source, &e.experiment, start, fitted)?);
    }
    Ok(all)
}

/// The comparisons of one experiment (none for kinds without one; a servo trace has
/// two: its effort and its following error).
pub fn compare(
    source: &str,
    exp: &Experiment,
    start: &Params,
    fitted: &Params,
) -> Result<Vec<Comparison>, ComparisonError> {
    Ok(match &exp.data {
        Data::FrequencyResponse { .. }
            if crate::tuning::speed_loop::measured::is_speed_loop(exp) =>
        {
            speed_loop::compare(source, exp, start, fitted)
        }
        Data::FrequencyResponse { .. } => frequency_response::compare(source, exp, start, fitted),
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
            vec![Comparison {
                source: source.into(),
                x_label: "time, s".into(),
                y_label: "motor torque, N·m".into(),
                curves: vec![
                    curve("measured", Role::Measured, time_s, motor_torque_nm),
                    curve("identified model", Role::Fitted, time_s, &model),
                ],
            }]
        }
        Data::Unbalance { .. } => vec![unbalance(source, exp, fitted)?],
        Data::ServoTrace(file) => trace(
            source,
            file.axis,
            &ServoTrace::from_record(file, &exp.manifest.conditions),
            start,
            fitted,
        )?,
        _ => Vec::new(),
    })
}

pub(super) fn curve(label: &str, role: Role, x: &[f64], y: &[f64]) -> Curve {
    Curve {
        label: label.into(),
        role,
        points: x.iter().copied().zip(y.iter().copied()).collect(),
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
            let mut c = curve(
                &format!("{who}, {}", p.direction),
                role,
                &p.angle_deg,
                &p.deviation_arcsec,
            );
            c.thin(MAX_DEVIATION_POINTS);
            curves.push(c);
        }
    }
    Ok(Comparison {
        source: source.into(),
        x_label: "table angle, deg".into(),
        y_label: "θt − θm·Rg·Rw, arc-sec".into(),
        curves,
    })
}

/// A servo trace replayed at the start and identified values: the drive's effort
/// over time, and the following error (reference − loop encoder) in arc-seconds or
/// µm, recorded and replayed.
fn trace(
    source: &str,
    axis: Axis,
    trace: &ServoTrace,
    start: &Params,
    fitted: &Params,
) -> Result<Vec<Comparison>, ComparisonError> {
    let replay = |p: &Params| {
        servo_trace::replay(p, trace).map_err(|error| ComparisonError::Trace {
            source_file: source.into(),
            error,
        })
    };
    let (at_start, at_fit) = (replay(start)?, replay(fitted)?);
    let (effort, position_unit, per_si) = match axis {
        Axis::Rotary => (
            "motor torque, N·m",
            "arc-sec",
            180.0 / std::f64::consts::PI * 3600.0,
        ),
        Axis::Linear => ("force, N", "µm", 1e6),
    };
    let t = &trace.time_s;
    let following = |position: &[f64]| -> Vec<f64> {
        trace
            .reference
            .iter()
            .zip(position)
            .map(|(r, q)| (r - q) * per_si)
            .collect()
    };
    let three = |measured: &[f64], start: &[f64], fit: &[f64]| {
        vec![
            curve("measured", Role::Measured, t, measured),
            curve("replayed, start", Role::Start, t, start),
            curve("replayed, identified", Role::Fitted, t, fit),
        ]
    };
    Ok(vec![
        Comparison {
            source: source.into(),
            x_label: "time, s".into(),
            y_label: effort.into(),
            curves: three(&trace.force, &at_start.force, &at_fit.force),
        },
        Comparison {
            source: source.into(),
            x_label: "time, s".into(),
            y_label: format!("following error, {position_unit}"),
            curves: three(
                &following(&trace.position),
                &following(&at_start.position),
                &following(&at_fit.position),
            ),
        },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::servo_trace::{virtual_trace, MoveTo, TrapezoidalMoves};
    use crate::model::presets;

    /// A virtual trace of the worm preset replayed at the preset: the identified
    /// curves are the recorded ones, the following error in arc-seconds; a start
    /// elsewhere differs.
    #[test]
    fn a_servo_trace_compares_its_effort_and_following_error() {
        let p = presets::load("worm-gear").unwrap();
        let moves = TrapezoidalMoves {
            moves: vec![MoveTo {
                target: 0.05,
                speed: 0.1,
            }],
            acceleration: 1.0,
            dwell_s: 0.05,
        };
        let recorded = virtual_trace(&p, &moves, None).unwrap();
        let mut start = p.clone();
        start
            .set("Kw", 2.0 * p.get("Kw").unwrap().unwrap())
            .unwrap();
        let c = trace("t.json", Axis::Rotary, &recorded, &start, &p).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].y_label, "motor torque, N·m");
        assert_eq!(c[1].y_label, "following error, arc-sec");
        for comparison in &c {
            let [measured, at_start, fitted] = &comparison.curves[..] else {
                panic!("three curves: {comparison:?}")
            };
            assert_eq!(measured.points, fitted.points, "{}", comparison.y_label);
            assert_ne!(measured.points, at_start.points, "{}", comparison.y_label);
        }
        let (k, largest) = recorded
            .reference
            .iter()
            .zip(&recorded.position)
            .map(|(r, q)| (r - q).abs())
            .enumerate()
            .fold((0, 0.0), |a, (k, e)| if e > a.1 { (k, e) } else { a });
        let arcsec = c[1].curves[0].points[k].1.abs();
        assert!(
            (arcsec / (largest * 3600.0_f64.to_degrees()) - 1.0).abs() < 1e-9,
            "{arcsec}"
        );
        assert!(largest > 0.0);
    }

    #[test]
    fn thinning_keeps_at_most_the_asked_points_each() {
        let points: Vec<(f64, f64)> = (0..1001).map(|i| (i as f64, 0.0)).collect();
        let c = Comparison {
            source: "s".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            curves: vec![Curve {
                label: "m".into(),
                role: Role::Measured,
                points,
            }],
        }
        .thinned(100);
        assert_eq!(c.curves[0].points.len(), 91);
        assert_eq!(c.curves[0].points[1].0, 11.0);
    }
}
