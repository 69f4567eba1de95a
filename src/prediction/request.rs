//! What `rtid predict` (and `rtid.predict`) asks for, made into a [`Setup`]'s parts:
//! where the draws come from, the held parameters' ranges beside them, and the cases
//! before and after — the command line's choices, in the library so that every caller
//! predicts the same.

use crate::controller::Compensation;
use crate::experiments::positioning::PositioningTest;
use crate::identify::intervals::chosen::{held_ranges, RangeError};
use crate::identify::result::IdentifyResult;
use crate::model::params::ControllerParams;
use crate::model::Params;

use super::draws::{self, Draws, Uncertain};
use super::{Case, DrawSource, PredictError, Test, MIN_DRAWS};

/// Most draws a prediction takes.
pub const MAX_DRAWS: usize = 100_000;

/// The tests a prediction runs, by name.
pub const TESTS: [&str; 2] = ["positioning", "servo"];

/// A prediction as asked for.
#[derive(Clone, Debug)]
pub struct Request<'a> {
    /// The identification.
    pub fit: &'a IdentifyResult,
    /// The model: the base the fit started from, with its values.
    pub params: &'a Params,
    /// The compensation predicted (none: the axis as it is).
    pub compensation: Option<Compensation>,
    /// A tuning's controller settings (none: the model's).
    pub controller: Option<ControllerParams>,
    /// The tests, among [`TESTS`].
    pub tests: Vec<String>,
    /// Normal draws (the bootstrap's number is its replicates').
    pub draws: usize,
    /// Where the draws come from (none: the bootstrap where the fit has replicates).
    pub from: Option<DrawSource>,
    /// Fitted parameters held at their values instead of drawn.
    pub hold: Vec<String>,
    /// Held parameters' ranges given for this prediction: (name, per cent), each one
    /// the fit did not fit; 0 % holds it exactly. The parameter set's own ranges
    /// (`Params::ranges`, a preset's) are carried beside them by default.
    pub uncertain: Vec<(String, f64)>,
    /// Positioning: runs per direction.
    pub runs: u32,
    /// Seed of the normal draws and the ranges' draws.
    pub seed: u64,
}

/// Why a request cannot be made into a prediction.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RequestError {
    #[error("draws {draws}: from {MIN_DRAWS} (an interval) to {MAX_DRAWS}")]
    Draws { draws: usize },
    #[error("hold {name}: not a parameter of the fit ({fitted})")]
    HoldNotFitted { name: String, fitted: String },
    #[error("hold: the bootstrap replicates are drawn as they are (draw from the covariance)")]
    HoldBootstrap,
    #[error("uncertain {0}: the fit's bootstrap replicates draw it already, within the range `identify` gave it")]
    DrawnAlready(String),
    #[error("runs {0}: from 2 (ISO 230-2) to 100")]
    Runs(u32),
    #[error("tests {0}: not a test prediction runs (positioning, servo)")]
    Test(String),
    #[error(transparent)]
    Range(#[from] RangeError),
    #[error(transparent)]
    Draw(#[from] PredictError),
}

/// The draws with the held parameters' ranges, their source, and the cases.
pub fn prepare(r: &Request) -> Result<(DrawSource, Draws, Vec<Case>), RequestError> {
    let (source, d) = source_draws(r)?;
    let uncertain = uncertain(r, &d.names)?;
    let d = d.with_uncertain(&uncertain, r.seed);
    Ok((source, d, cases(r)?))
}

/// The draws: the fit's bootstrap replicates, or normal draws from its covariance.
fn source_draws(r: &Request) -> Result<(DrawSource, Draws), RequestError> {
    if r.draws < MIN_DRAWS || r.draws > MAX_DRAWS {
        return Err(RequestError::Draws { draws: r.draws });
    }
    for name in &r.hold {
        if !r.fit.parameters.contains_key(name) {
            return Err(RequestError::HoldNotFitted {
                name: name.clone(),
                fitted: fitted(r.fit),
            });
        }
    }
    let bootstrap = match r.from {
        Some(DrawSource::Bootstrap) => true,
        Some(DrawSource::Covariance) => false,
        None => r.fit.resampling.as_ref().is_some_and(|s| s.fitted > 1),
    };
    if bootstrap {
        if !r.hold.is_empty() {
            return Err(RequestError::HoldBootstrap);
        }
        return Ok((DrawSource::Bootstrap, draws::from_bootstrap(r.fit)?));
    }
    let d = draws::from_covariance(r.fit, &r.hold, r.draws, r.seed)?;
    Ok((DrawSource::Covariance, d))
}

/// The held parameters' ranges: the fit's (`identify`'s refits at their ends, the
/// fitted parameters moving with them), a range given here replacing its width (0 %
/// holds it exactly); then the parameter set's own ranges of the parameters neither
/// fitted nor carried by the fit, and those given here alone, drawn independently
/// of the fit.
fn uncertain(r: &Request, drawn: &[String]) -> Result<Vec<Uncertain>, RequestError> {
    let given = &r.uncertain;
    if let Some((name, _)) = given.iter().find(|g| r.fit.parameters.contains_key(&g.0)) {
        return Err(RangeError::Fitted { name: name.clone() }.into());
    }
    if let Some((name, _)) = given.iter().find(|g| drawn.contains(&g.0)) {
        return Err(RequestError::DrawnAlready(name.clone()));
    }
    let width = |name: &str| given.iter().find(|g| g.0 == name).map(|g| g.1 / 100.0);
    let mut out: Vec<Uncertain> = (r.fit.held.iter())
        .filter(|h| width(&h.name) != Some(0.0))
        .map(|h| Uncertain::of_fit(h, r.fit, width(&h.name)))
        .collect();
    let by_fit = |n: &String| r.fit.held.iter().any(|h| &h.name == n);
    let fitted: Vec<String> = r.fit.parameters.keys().cloned().collect();
    let own: Vec<(String, f64)> = given.iter().filter(|g| !by_fit(&g.0)).cloned().collect();
    let independent = held_ranges(r.params, &fitted, &own)?;
    out.extend(
        (independent.iter())
            .filter(|(n, ..)| !by_fit(n) && !drawn.contains(n))
            .map(|(n, v, h)| Uncertain::independent(n, *v, *h)),
    );
    Ok(out)
}

fn fitted(fit: &IdentifyResult) -> String {
    fit.parameters
        .keys()
        .cloned()
        .collect::<Vec<_>>()
        .join(", ")
}

/// Before (the model as it is) and after (with the settings) for each test.
fn cases(r: &Request) -> Result<Vec<Case>, RequestError> {
    let p = r.params;
    let mut after = PositioningTest::standard(p.axis);
    if r.runs < 2 || r.runs > 100 {
        return Err(RequestError::Runs(r.runs));
    }
    after.runs = r.runs;
    let before = after.clone();
    if let Some(c) = &r.compensation {
        after.compensation = c.clone();
    }
    let mut out = Vec::new();
    for test in r.tests.iter().map(|t| t.trim()) {
        let (before, after) = match test {
            "positioning" => (
                Test::Positioning {
                    test: before.clone(),
                    axis: p.axis,
                },
                Test::Positioning {
                    test: after.clone(),
                    axis: p.axis,
                },
            ),
            "servo" => (
                Test::Servo {
                    compensation: Default::default(),
                    axis: p.axis,
                },
                Test::Servo {
                    compensation: after.compensation.clone(),
                    axis: p.axis,
                },
            ),
            _ => return Err(RequestError::Test(test.to_string())),
        };
        out.push(Case {
            label: "before".into(),
            test: before,
            controller: None,
        });
        if r.compensation.is_some() || r.controller.is_some() {
            out.push(Case {
                label: "after".into(),
                test: after,
                controller: r.controller.clone(),
            });
        }
    }
    Ok(out)
}
