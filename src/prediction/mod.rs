//! The effect of settings predicted on an identified model, with the fit's
//! uncertainty carried through (`rtid predict`): parameter sets drawn from the fit
//! ([`draws`]), a virtual test run on each with and without the settings
//! ([`cases`]), and each output's value at the fit with the interval the draws give.
//!
//! The interval is that of the fitted parameters only: every parameter the fit did not
//! vary keeps its value, and the prediction holds for the model as far as those
//! values hold. [`Prediction::conditional_on`] names them.

pub mod cases;
pub mod draws;
pub mod request;

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::experiments::positioning::ensemble::Ensemble;
use crate::model::{ParamError, Params};
use crate::sim::batch::{by_point, on_valid};
use crate::sim::LANES;
pub use cases::{AtFit, Case, CaseError, Output, Test};
pub use draws::{DrawSource, Draws};

/// Why a prediction could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PredictError {
    #[error("the fit has no standard errors to draw from (a fit without uncertainty, or interrupted): run identify to the end, or use its bootstrap replicates")]
    NoUncertainty,
    #[error("the fit has no bootstrap replicates (run `rtid identify --resample N`)")]
    NoReplicates,
    #[error("`{name}` has no standard error: the data did not determine it, so no interval can carry its uncertainty (hold it at its value with --hold {name}, and read the interval as conditional on it)")]
    NotDetermined { name: String },
    #[error("{rejected} draws fell outside the fit's bounds before enough fell inside: the standard errors are too large for the bounds (a parameter the data barely determine)")]
    OutsideBounds { rejected: usize },
    #[error("the level {0} is not in (0, 1)")]
    Level(f64),
    #[error("parameter set at the fit: {0}")]
    Params(#[from] ParamError),
    #[error("the {case} test at the fit's values: {source}")]
    Nominal { case: String, source: CaseError },
    #[error("{failed} of {total} drawn parameter sets failed to simulate (first: {first}): the fit's uncertainty reaches parameters the model cannot run")]
    Failed {
        failed: usize,
        total: usize,
        first: String,
    },
}

/// One output's prediction: its value at the fit, and the draws' median and central
/// interval (absent with fewer than [`MIN_DRAWS`] completed draws) joined with its
/// reflection about the value at the fit ([`both_ways`]), so that it always holds
/// that value: the fit is itself a parameter set the data allow, and the draws'
/// offset from it may be the fit's offset from the machine, the other way.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Predicted {
    pub name: String,
    pub nominal: f64,
    pub median: Option<f64>,
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    /// Whether the draws' interval alone missed the value at the fit (which the
    /// reflection holds).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub extended: bool,
    /// The test's own spread at the fit, added to the draws' interval (below,
    /// above): the ensemble's range, largest less least, on each side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spread: Option<(f64, f64)>,
}

/// The outputs of one case (a test with or without the settings), in `unit`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CasePrediction {
    /// The test (`positioning`, `servo`).
    pub test: String,
    pub case: String,
    pub unit: String,
    pub values: Vec<Predicted>,
}

/// A prediction.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Prediction {
    pub source: DrawSource,
    /// Central interval's probability (0.95).
    pub level: f64,
    /// Draws asked for, completed (Ctrl-C may stop early), and thrown away outside
    /// the bounds.
    pub asked: usize,
    pub completed: usize,
    pub rejected: usize,
    /// The parameters drawn, and the fitted ones held at their values.
    pub drawn: Vec<String>,
    pub held: Vec<String>,
    /// Runs of the test's ensemble at the fit, whose spread widens the intervals (0:
    /// none).
    #[serde(default)]
    pub ensemble: usize,
    pub cases: Vec<CasePrediction>,
    /// What the interval does not include, and why draws are missing.
    pub notes: Vec<String>,
}

impl Prediction {
    /// The tests predicted, in order, each with its cases.
    pub fn by_test(&self) -> Vec<(&str, Vec<&CasePrediction>)> {
        let mut out: Vec<(&str, Vec<&CasePrediction>)> = Vec::new();
        for c in &self.cases {
            match out.iter_mut().find(|(t, _)| *t == c.test) {
                Some((_, cases)) => cases.push(c),
                None => out.push((&c.test, vec![c])),
            }
        }
        out
    }
}

/// Fewest completed draws that give an interval.
pub const MIN_DRAWS: usize = 10;

/// What a prediction runs on.
pub struct Setup<'a> {
    /// The identified model (the fit's values in it).
    pub params: &'a Params,
    pub draws: &'a Draws,
    pub source: DrawSource,
    pub held: Vec<String>,
    pub level: f64,
    pub cases: &'a [Case],
    /// The test's own ensemble at the fit (issue 58), its spread added to the
    /// intervals; None: the draws' interval alone.
    pub ensemble: Option<Ensemble>,
}

/// Runs every case at the fit and on every drawn set (in parallel), `progress` called
/// after each draw; `stop` ends it early with the draws done.
pub fn predict(
    s: &Setup,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Prediction, PredictError> {
    if !(s.level > 0.0 && s.level < 1.0) {
        return Err(PredictError::Level(s.level));
    }
    let skipped = AtomicUsize::new(0);
    // The fit's runs beside the draws': the cores are not left to the ensemble's
    // last lane batch.
    let (at_fit, runs) = rayon::join(|| at_fit(s), || run_all(s, progress, stop, &skipped));
    let (nominal, spreads): (Vec<_>, Spreads) =
        (at_fit?.into_iter()).map(|a| (a.outputs, a.spread)).unzip();
    let total = runs.len();
    let (done, failures): (Vec<_>, Vec<_>) = runs.into_iter().partition(Result::is_ok);
    let failures: Vec<String> = failures.into_iter().filter_map(Result::err).collect();
    if failures.len() * 10 > total.max(1) {
        return Err(PredictError::Failed {
            failed: failures.len(),
            total,
            first: failures[0].clone(),
        });
    }
    let done: Vec<Vec<Vec<Output>>> = done.into_iter().filter_map(Result::ok).collect();
    let mut notes = Vec::new();
    note_missing(&mut notes, failures.len(), skipped.into_inner(), done.len());
    note_assumed(&mut notes, s.params, &s.draws.names);
    let cases = summarise(s, &nominal, &done, &spreads);
    note_rough(&mut notes, &cases);
    Ok(Prediction {
        source: s.source,
        level: s.level,
        asked: s.draws.sets.len(),
        completed: done.len(),
        rejected: s.draws.rejected,
        drawn: s.draws.names.clone(),
        held: s.held.clone(),
        ensemble: s.ensemble.map_or(0, |e| e.members),
        cases,
        notes,
    })
}

impl Prediction {
    /// The parameters the prediction rests on without their uncertainty: every
    /// registry parameter of `params` neither drawn nor held (their values as given).
    pub fn conditional_on(&self, params: &Params) -> Vec<String> {
        crate::model::registry::PARAMS
            .iter()
            .map(|d| d.name)
            .filter(|n| params.get(n).is_ok())
            .filter(|n| !self.drawn.iter().any(|d| d == n) && !self.held.iter().any(|h| h == n))
            .map(str::to_string)
            .collect()
    }
}

/// Every case on each of the drawn `sets`, the sets of a case run together.
fn run_draws(s: &Setup, sets: &[Vec<f64>]) -> Vec<Result<Vec<Vec<Output>>, String>> {
    let params: Vec<Result<Params, String>> = sets.iter().map(|set| drawn(s, set)).collect();
    on_valid(params, |ps| {
        let cases: Vec<Vec<_>> = (s.cases.par_iter())
            .map(|c| {
                let label = |e: CaseError| format!("{}: {e}", c.label);
                c.run_batch(ps)
                    .into_iter()
                    .map(|r| r.map_err(label))
                    .collect()
            })
            .collect();
        by_point(ps.len(), cases)
    })
}

/// The model with a drawn set's values.
fn drawn(s: &Setup, set: &[f64]) -> Result<Params, String> {
    let mut p = s.params.clone();
    for (name, &v) in s.draws.names.iter().zip(set) {
        p.set(name, v).map_err(|e| e.to_string())?;
    }
    p.validate().map_err(|e| e.to_string())?;
    Ok(p)
}

fn note_missing(notes: &mut Vec<String>, failed: usize, skipped: usize, done: usize) {
    if failed > 0 {
        notes.push(format!(
            "{failed} drawn sets failed to simulate and are left out"
        ));
    }
    if skipped > 0 {
        notes.push(format!("stopped: {skipped} draws not run"));
    }
    if done < MIN_DRAWS {
        notes.push(format!(
            "{done} draws completed, fewer than {MIN_DRAWS}: no interval"
        ));
    }
}

/// Names the parameters the base's notes mark uncertain or assumed (a preset's
/// values not printed in its source, or read ambiguously) that are not drawn: the
/// intervals take them as exact, which they are not.
fn note_assumed(notes: &mut Vec<String>, params: &Params, drawn: &[String]) {
    let assumed: Vec<&str> = params
        .notes
        .iter()
        .filter(|(name, text)| {
            let t = text.to_ascii_lowercase();
            (t.contains("uncertain") || t.contains("assumed"))
                && params.get(name).is_ok_and(|v| v.is_some())
                && !drawn.contains(name)
        })
        .map(|(name, _)| name.as_str())
        .collect();
    if !assumed.is_empty() {
        notes.push(format!(
            "the intervals take as exact {}, which the parameter set's notes mark uncertain or \
             assumed: --uncertain NAME=X% carries a parameter's uncertainty into them",
            assumed.join(", ")
        ));
    }
}

/// Names each output whose value at the fit lay outside the draws' interval (the
/// reflection about it holds it): one folded at a floor, or that jumps with the
/// parameters (where the axis sticks, how it rattles in the backlash) rather than
/// following them smoothly.
fn note_rough(notes: &mut Vec<String>, cases: &[CasePrediction]) {
    let rough: Vec<String> = cases
        .iter()
        .flat_map(|c| {
            (c.values.iter())
                .filter(|v| v.extended)
                .map(move |v| format!("{} {}", v.name, c.case))
        })
        .collect();
    if !rough.is_empty() {
        notes.push(format!(
            "the value at the fit lies outside the draws' interval for {}, which holds it by its \
             reflection about it: these outputs are folded at a floor (any mismatch of a compensation adds to \
             them) or jump with small changes of the parameters (where the axis sticks, how it \
             rattles in the backlash)",
            rough.join(", ")
        ));
    }
}

/// Whether `x` lies outside [lo, hi] by more than rounding (quantised outputs repeat
/// one value exactly, summed in different orders; an overshoot of 0 % against
/// 1e-7 %).
fn outside(x: f64, lo: f64, hi: f64) -> bool {
    let slack = 1e-6 * x.abs().max(lo.abs()).max(hi.abs()).max(1.0);
    x < lo - slack || x > hi + slack
}

/// Each case's spread of its test at the fit (None for a case run once).
type Spreads = Vec<Option<Vec<(f64, f64)>>>;

/// Each case's outputs at the fit and its test's spread there ([`Case::at_fit`]),
/// the cases in parallel; the first case's error in their order.
fn at_fit(s: &Setup) -> Result<Vec<AtFit>, PredictError> {
    let runs: Vec<_> = (s.cases.par_iter())
        .map(|c| {
            c.at_fit(s.params, s.ensemble.as_ref())
                .map_err(|source| PredictError::Nominal {
                    case: c.label.clone(),
                    source,
                })
        })
        .collect();
    runs.into_iter().collect()
}

/// Every draw's outputs, the draws in groups of the kernel's lane count (each case
/// runs a group together), `progress` after each group, none begun after `stop`.
fn run_all(
    s: &Setup,
    progress: &(dyn Fn() + Sync),
    stop: &AtomicBool,
    skipped: &AtomicUsize,
) -> Vec<Result<Vec<Vec<Output>>, String>> {
    s.draws
        .sets
        .par_chunks(LANES)
        .flat_map_iter(|sets| {
            if stop.load(Ordering::Relaxed) {
                skipped.fetch_add(sets.len(), Ordering::Relaxed);
                return Vec::new();
            }
            let runs = run_draws(s, sets);
            // Draws a stop cut short (`crate::interrupt`) were not run, not failed.
            if stop.load(Ordering::Relaxed) || crate::interrupt::requested() {
                skipped.fetch_add(sets.len(), Ordering::Relaxed);
                return Vec::new();
            }
            sets.iter().for_each(|_| progress());
            runs
        })
        .collect()
}

/// Each case's outputs: value at the fit, the draws' median and central interval
/// joined with its reflection about the value at the fit ([`both_ways`]), widened by
/// the test's own spread.
fn summarise(
    s: &Setup,
    nominal: &[Vec<Output>],
    done: &[Vec<Vec<Output>>],
    spreads: &Spreads,
) -> Vec<CasePrediction> {
    s.cases
        .iter()
        .enumerate()
        .map(|(c, case)| CasePrediction {
            test: case.test_name().to_string(),
            case: case.label.clone(),
            unit: case.unit().to_string(),
            values: (nominal[c].iter().enumerate())
                .map(|(k, out)| {
                    let v: Vec<f64> = done.iter().map(|d| d[c][k].value).collect();
                    predicted(out, v, spreads[c].as_ref().map(|v| v[k]), s.level)
                })
                .collect(),
        })
        .collect()
}

/// One output's [`Predicted`] from its value at the fit `out`, the draws' values
/// `v` and the test's spread at the fit.
fn predicted(out: &Output, mut v: Vec<f64>, spread: Option<(f64, f64)>, level: f64) -> Predicted {
    v.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0;
    let at = |q: f64| (v.len() >= MIN_DRAWS).then(|| quantile(&v, q));
    // B, E, M, R, A are magnitudes (B̄ alone is signed): nothing takes them below 0.
    let floor = if out.name == cases::SIGNED {
        f64::NEG_INFINITY
    } else {
        0.0
    };
    let draws = at(tail).zip(at(1.0 - tail));
    let joined = draws.map(|(lo, hi)| both_ways(out.value, lo, hi, floor));
    let (below, above) = spread.unwrap_or((0.0, 0.0));
    Predicted {
        name: out.name.to_string(),
        nominal: out.value,
        median: at(0.5),
        lower: joined.map(|(lo, _)| (lo + below).max(floor.min(lo))),
        upper: joined.map(|(_, hi)| hi + above),
        extended: draws.is_some_and(|(lo, hi)| outside(out.value, lo, hi)),
        spread,
    }
}

/// The draws' central interval [lo, hi] joined with its reflection about the
/// value at the fit `v`, [2v − hi, 2v − lo] (the percentile and the basic bootstrap
/// interval), cut at `floor`. The draws' offset from the fit may stand for the
/// fit's offset from the machine the other way (the basic interval's reading) or
/// not (the percentile's); the draws cannot tell which. On θbw's cost, a plateau
/// below the machine's value and a cliff above it, a fit comes down the plateau
/// and so do its replicates, all to one side of it: the draws' interval alone
/// held 61 of 72 values on six machines, the union 71 (docs/validation.md). An
/// output folded at a floor (the lost motion after a compensation: any mismatch
/// adds to it) has draws all above the fit's value; the reflection reaches the
/// floor. The union always holds `v`.
fn both_ways(v: f64, lo: f64, hi: f64, floor: f64) -> (f64, f64) {
    ((2.0 * v - hi).max(floor).min(lo), (2.0 * v - lo).max(hi))
}

/// The `q` quantile of sorted values, linear between order statistics (type 7).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * q;
    let (i, f) = (h.floor() as usize, h - h.floor());
    let next = sorted[(i + 1).min(sorted.len() - 1)];
    sorted[i] + f * (next - sorted[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_at_an_end_of_the_interval_is_inside() {
        assert!(!outside(36.0 - 1e-12, 36.0, 37.0));
        assert!(outside(35.9, 36.0, 37.0) && outside(37.1, 36.0, 37.0));
    }

    #[test]
    fn the_interval_holds_the_draws_and_their_reflection_about_the_fit() {
        // Draws all below the fit (θbw's plateau): the reflection reaches above it.
        assert_eq!(both_ways(10.0, 6.0, 9.0, f64::NEG_INFINITY), (6.0, 14.0));
        // Draws around the fit: the union is the wider of the two on each side.
        assert_eq!(both_ways(10.0, 9.0, 12.0, f64::NEG_INFINITY), (8.0, 12.0));
        // A magnitude folded at a floor, every draw above the fit: cut at 0.
        assert_eq!(both_ways(0.5, 1.0, 9.0, 0.0), (0.0, 9.0));
    }

    #[test]
    fn a_prediction_holds_its_value_at_the_fit_and_names_a_miss() {
        let out = Output {
            name: "A",
            value: 3.0,
        };
        let draws: Vec<f64> = (0..20).map(|i| 4.0 + i as f64 * 0.5).collect();
        let p = predicted(&out, draws, Some((-0.5, 0.25)), 0.95);
        let (lo, hi) = (p.lower.unwrap(), p.upper.unwrap());
        assert!(p.extended && lo <= 3.0 && hi >= 13.0, "{lo} … {hi}");
        assert_eq!(lo, 0.0, "the reflection of the upper end reaches below 0");
        let few = predicted(&out, vec![4.0; MIN_DRAWS - 1], None, 0.95);
        assert!(few.lower.is_none() && few.upper.is_none() && !few.extended);
    }

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 5.0);
        assert!((quantile(&v, 0.125) - 1.5).abs() < 1e-15);
    }
}
