//! Unbalance-step residual: where the deviation θt − θm·Rg·Rw of the unbalance test
//! steps across the backlash (paper §4.5), model against measurement.
//!
//! Physics: the table, vertical with a mass m at radius e, turns at constant speed ω;
//! the mesh carries Ct·ω + ft·sgn(ω) − Tu(θt). Where the gravity torque
//! m·g·e·sin(θt + ψ) overcomes ft + Ct·ω the mesh load changes sign and the table
//! crosses the backlash: a step of about the lost motion (≈ 33″ for the worm). Each
//! direction shows two steps per revolution, at sin(θt + ψ) = ∓(ft + Ct·|ω|)/(m·g·e);
//! up and down passes sit on opposite sides of the same zero of the gravity torque,
//! so ft + Ct·|ω| moves them apart, ψ moves them together. At 360°/min Ct·ω is
//! 0.0013 N·m for the worm (0.5 % of ft): the step angles determine ft.
//!
//! Measured steps: those [`fluctuation::evaluate`] finds in each pass (at least half
//! the pass's largest), located with [`fluctuation::locate_step`] in a window of
//! ±[`STEP_LOCATE_HALF_WIDTH`] centred on them. Model: the unbalance test at the
//! file's conditions (mass, radius, speed, loop), run only through that window after
//! [`WINDOW_RUN_IN`] of run-in (one short simulation per step, in parallel), its step
//! located in the same window by the same code. Residual per step: (model − measured
//! step angle) / [`SCALE_DEG`]. No step in the model's window (friction above
//! m·g·e, a step of the wrong sign or under half the measured size):
//! [`MISSING_STEP_RESIDUAL`].

use rayon::prelude::*;

use super::definition::{Definition, SetupError, Source};
use super::detail::list;
use super::{Detail, Objective, ObjectiveError, Properties, Smoothness};
use crate::experiments::fluctuation::{
    self, locate_step, pass_samples, run_window, run_window_batch, FluctuationTest, Record,
    STEP_LOCATE_HALF_WIDTH,
};
use crate::io::experiment_file::{Direction, Experiment, Kind};
use crate::model::Params;
use crate::sim::batch::by_point;
use crate::sim::SimError;

/// The unbalance-step objective: closed-loop simulations (rough); determines the
/// table's Coulomb friction ft.
pub static DEFINITION: Definition = Definition {
    name: "unbalance_step",
    summary:
        "error of the table angles where the unbalance test's deviation steps across the backlash",
    reads: &[Kind::Unbalance],
    needs: "an unbalance experiment",
    properties: Properties {
        smoothness: Smoothness::Rough,
        frequency_response: false,
    },
    determines: |_, _| vec!["ft"],
    default_weight: |exp, _| (exp.manifest.kind == Kind::Unbalance).then_some(1.0),
    build,
    first_estimate: None,
    describe,
};

fn build(
    source: &Source<'_>,
    _: crate::objectives::Fidelity,
) -> Result<Box<dyn Objective>, SetupError> {
    let o = UnbalanceStep::new(source.file, source.experiment).map_err(|e| SetupError::Data {
        file: source.file.into(),
        reason: match e {
            ObjectiveError::Data { reason, .. } => reason,
            other => other.to_string(),
        },
    })?;
    Ok(Box::new(o))
}

/// One scaled residual is this much table angle, deg: a twentieth of a degree, 0.009
/// N·m = 3.3 % of ft for the worm preset with 10 kg at 0.1 m (∂θ/∂ft = 1/(m·g·e) rad
/// per N·m = 5.8°/N·m), five times the locating error on the 4 ms encoder-quantised
/// record, about the error with 2″ of table-angle noise.
pub const SCALE_DEG: f64 = 0.05;
/// Table travel before the locating window in the model's run, rad (5°: the step
/// angles then equal the full run's; see the tests).
pub const WINDOW_RUN_IN: f64 = 5.0 * std::f64::consts::PI / 180.0;
/// Table travel commanded beyond the locating window, rad (1°: the table lags the
/// command by the servo's following error, ~0.2° at 360°/min, and the window must be
/// covered to its end).
pub const WINDOW_RUN_OUT: f64 = 1.0 * std::f64::consts::PI / 180.0;
/// The residual of a step the model does not show in the window: the window's
/// width in scale units (200): large against any located miss, finite.
pub const MISSING_STEP_RESIDUAL: f64 = 2.0 * 5.0 / SCALE_DEG;

/// One measured step.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MeasuredStep {
    pub direction: Direction,
    /// Centre of the locating window, rad of x = sense·θt.
    #[serde(skip)]
    pub center: f64,
    /// Located table angle, deg.
    pub angle_deg: f64,
    /// Size (after − before in the order travelled), arc-sec.
    pub size_arcsec: f64,
}

impl MeasuredStep {
    fn sense(&self) -> f64 {
        match self.direction {
            Direction::Up => 1.0,
            Direction::Down => -1.0,
        }
    }
}

/// The measured steps of an unbalance test and the test that made them.
#[derive(Clone, Debug)]
pub struct UnbalanceStep {
    pub steps: Vec<MeasuredStep>,
    pub test: FluctuationTest,
    /// Table travel of the model's run before each locating window, rad (default
    /// [`WINDOW_RUN_IN`]).
    pub run_in: f64,
}

impl UnbalanceStep {
    /// The steps of an unbalance (or fluctuation) experiment file; an error naming
    /// the file when it has no usable conditions or no step.
    pub fn new(file: &str, exp: &Experiment) -> Result<Self, ObjectiveError> {
        let data_err = |reason: String| ObjectiveError::Data {
            what: file.to_string(),
            reason,
        };
        let test = FluctuationTest::from_conditions(exp).map_err(|e| match e {
            fluctuation::FluctuationError::Condition { field, reason, .. } => {
                data_err(format!("{field}: {reason}"))
            }
            other => data_err(other.to_string()),
        })?;
        let evaluation =
            fluctuation::evaluate_experiment(exp).map_err(|e| data_err(e.to_string()))?;
        let record = fluctuation::from_data(&exp.data)
            .ok_or_else(|| data_err("not a fluctuation or unbalance record".into()))?;
        let samples = pass_samples(&record, evaluation.ratio);
        let mut steps = Vec::new();
        for (pass, s) in evaluation.passes.iter().zip(&samples) {
            for st in &pass.steps {
                // Re-locate in a window centred on the step itself: the window the
                // model's step is located in too.
                let center = s.sense * st.angle_deg.to_radians();
                if let Some((x, size)) = locate_step(s, center, STEP_LOCATE_HALF_WIDTH) {
                    steps.push(MeasuredStep {
                        direction: pass.direction,
                        center,
                        angle_deg: (s.sense * x).to_degrees(),
                        size_arcsec: size,
                    });
                }
            }
        }
        if steps.is_empty() {
            return Err(data_err(
                "no step in the deviation θt − θm·ratio: nothing to locate (is the unbalance large enough to overcome the table friction?)"
                    .into(),
            ));
        }
        Ok(UnbalanceStep {
            steps,
            test,
            run_in: WINDOW_RUN_IN,
        })
    }

    /// The model's step angle in each measured step's window, deg (`None`: no step
    /// there).
    pub(crate) fn model_deg(&self, p: &Params) -> Result<Vec<Option<f64>>, ObjectiveError> {
        self.steps
            .par_iter()
            .map(|st| self.model_step(p, st))
            .collect()
    }

    fn model_step(&self, p: &Params, st: &MeasuredStep) -> Result<Option<f64>, ObjectiveError> {
        let (from, to) = self.window(st);
        let record = run_window(p, &self.test, from, to)?;
        Ok(self.located(&record, p, st))
    }

    /// The table angles (rad) from and to which the model runs to find the step
    /// `st`: a run-in before its window, a run-out after.
    fn window(&self, st: &MeasuredStep) -> (f64, f64) {
        let sense = st.sense();
        let h = STEP_LOCATE_HALF_WIDTH;
        let from = sense * (st.center - h - self.run_in);
        let to = sense * (st.center + h + WINDOW_RUN_OUT);
        (from, to)
    }

    /// The step of `record` (a run of `p` through `st`'s window) in `st`'s window,
    /// deg, if it has one of the measured step's sign and at least half its size.
    fn located(&self, record: &Record, p: &Params, st: &MeasuredStep) -> Option<f64> {
        let sense = st.sense();
        let h = STEP_LOCATE_HALF_WIDTH;
        let pass = pass_samples(record, p.ratio())
            .into_iter()
            .find(|s| s.sense == sense)?;
        locate_step(&pass, st.center, h).and_then(|(x, size)| {
            let same = size * st.size_arcsec > 0.0 && size.abs() >= 0.5 * st.size_arcsec.abs();
            same.then(|| (sense * x).to_degrees())
        })
    }

    /// The scaled residuals of the model's step angles `model` (deg).
    fn scaled(&self, model: &[Option<f64>]) -> Vec<f64> {
        model
            .iter()
            .zip(&self.steps)
            .map(|(m, st)| match m {
                Some(a) => (a - st.angle_deg) / SCALE_DEG,
                None => MISSING_STEP_RESIDUAL,
            })
            .collect()
    }
}

impl Objective for UnbalanceStep {
    fn name(&self) -> &'static str {
        "unbalance_step"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(self.scaled(&self.model_deg(p)?))
    }

    /// Each step's window run for all the points together in the kernel's lanes
    /// (the windows in parallel): each point's residuals what it gives alone.
    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        let per_step: Vec<Vec<Result<Record, SimError>>> = self
            .steps
            .par_iter()
            .map(|st| run_window_batch(points, &self.test, self.window(st)))
            .collect();
        by_point(points.len(), per_step)
            .into_iter()
            .zip(points)
            .map(|(records, p)| {
                let model: Vec<Option<f64>> = self
                    .steps
                    .iter()
                    .zip(&records?)
                    .map(|(st, record)| self.located(record, p, st))
                    .collect();
                Ok(self.scaled(&model))
            })
            .collect()
    }

    fn in_lanes(&self) -> bool {
        true
    }

    fn len(&self) -> usize {
        self.steps.len()
    }

    fn scale(&self) -> String {
        format!("{SCALE_DEG}° of table angle per step (model − measured step angle)")
    }

    fn detail(&self, _: &Params, r: &[f64]) -> Option<Detail> {
        let model: Vec<Option<f64>> = r
            .iter()
            .zip(&self.steps)
            .map(|(x, st)| (*x != MISSING_STEP_RESIDUAL).then(|| st.angle_deg + x * SCALE_DEG))
            .collect();
        Some(Detail::UnbalanceSteps {
            direction: self.steps.iter().map(|s| s.direction).collect(),
            measured_step_deg: self.steps.iter().map(|s| s.angle_deg).collect(),
            model_step_deg: model,
        })
    }
}

/// The step angles, measured and model.
fn describe(d: &Detail) -> Option<String> {
    let Detail::UnbalanceSteps {
        measured_step_deg,
        model_step_deg,
        ..
    } = d
    else {
        return None;
    };
    let model: Vec<String> = model_step_deg
        .iter()
        .map(|x| x.map_or("none".into(), |v| format!("{v:.3}")))
        .collect();
    Some(format!(
        "  step angles measured {} °, model {} °",
        list(measured_step_deg, 3),
        model.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::fluctuation::{manifest, run, to_data};
    use crate::model::presets;

    /// A virtual unbalance test of `p` as an experiment (10 kg at 0.1 m).
    fn experiment(p: &Params) -> Experiment {
        let test = FluctuationTest::unbalance(10.0, 0.1);
        let record = run(p, &test, |_, _| {}).unwrap();
        Experiment {
            manifest: manifest(p, &test),
            data: to_data(&record, test.kind()),
            path: "virtual-unbalance.json".into(),
            data_path: None,
        }
    }

    #[test]
    fn zero_at_the_truth_and_the_steps_move_as_the_friction_says() {
        let truth = presets::load("worm-gear").unwrap();
        let mut o = UnbalanceStep::new("virtual", &experiment(&truth)).unwrap();
        // The windowed runs reproduce the full run's step angles within a quarter
        // unit (0.0125°: the sampling phase of the quantised encoders), whatever the
        // run-in beyond the default 5°.
        for deg in [20.0f64, 5.0] {
            o.run_in = deg.to_radians();
            let r = o.residuals(&truth).unwrap();
            assert!(r.iter().all(|x| x.abs() < 0.25), "run-in {deg}°: {r:?}");
        }
        assert_eq!(o.run_in, WINDOW_RUN_IN);
        // Two steps per direction: near 0° and near 180°.
        assert_eq!(o.steps.len(), 4, "{:?}", o.steps);
        let mut more = truth.clone();
        more.ft *= 1.2;
        let r = o.residuals(&more).unwrap();
        // More friction: where the table falls ahead across the backlash (size·sense
        // > 0) the gravity torque must grow further to overcome it, so the step comes
        // later in the direction of travel; where it drops back (the gravity torque
        // falls below the friction) it comes earlier. In table angle both mean
        // residual·sgn(size) > 0, by about Δ asin(ft/(m·g·e)) = 0.30° (6 units).
        for (x, st) in r.iter().zip(&o.steps) {
            let moved = x * st.size_arcsec.signum();
            assert!((3.0..10.0).contains(&moved), "{x} for {st:?}");
        }
        let mut none = truth.clone();
        none.ft = 12.0; // above m·g·e = 9.81 N·m: the table never crosses
        let r = o.residuals(&none).unwrap();
        assert!(r.iter().all(|&x| x == MISSING_STEP_RESIDUAL), "{r:?}");
    }
}
