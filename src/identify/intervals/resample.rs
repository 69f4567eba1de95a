//! Resampling intervals (docs/identification.md): the residual block bootstrap of
//! the whole estimator. Where the cost is rough — a closed-loop simulation with
//! quantised encoders, whose cost has local minima the search stops in — σ²(JᵀJ)⁻¹
//! measures the residuals' scatter only, and a profile walks one local minimum to
//! the next. The bootstrap replicates what made the estimate instead: each
//! replicate's data are the fitted model's response plus the fit's residuals
//! resampled in blocks (the blocks keep their correlation), and the replicate is
//! fitted as the data were — the same search from the same start. The spread of the
//! replicates' values around the fit stands for the spread of the fit around the
//! truth, the search's stops included; their mean offset estimates its bias.
//!
//! In the objectives' scaled residuals r(p) = (model(p) − data) / scale, a
//! replicate's data `model(p̂) − scale·r*` give r(p) − r(p̂) + r*: each replicate is
//! the fitted objective plus a fixed offset, whatever the objective computes.
//! Replicates run in parallel; replicate b's blocks come from a generator seeded by
//! (seed, b), so the result does not depend on the order they finish in. Where the
//! refit is a Nelder–Mead search (one point after another) on an objective that
//! runs in the kernel's lanes, the replicates' searches run side by side on threads
//! of their own, [`crate::sim::LANES`] per worker, their evaluations gathered into
//! lane batches (search/lockstep.rs): each replicate's numbers are those it gets
//! alone.

use crate::identify::result::resampling::{AtBound, Interval, Resampling};
use std::collections::BTreeMap;
use std::ops::Range;

use rand::{rngs::StdRng, Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use crate::identify::error::IdentifyError;
use crate::identify::pipeline::correction::Corrected;
use crate::identify::result::warning::{Coded, Side, Warning};
use crate::identify::result::IdentifyResult;
use crate::identify::run::Replay;
use crate::identify::search::lockstep::side_by_side;
use crate::identify::search::problem::Monitor;
use crate::identify::search::search;
use crate::identify::search::settings::{Method, Settings};
use crate::identify::space::{Bound, ParamSpace};
use crate::model::Params;
use crate::objectives::{sum_of_squares, Objective, ObjectiveError};

pub use super::request::LEVEL;
use super::request::Z;
/// Fewer finished replicates than this give no interval.
pub const MIN_REPLICATES: usize = 5;
/// The share of replicates (and at least two) that ran to a bound of the search for
/// the parameter to be not determined there: on a machine that is not the preset,
/// the torque curve's plateau in the backlash θbw took 4 of 12 replicates to its
/// lower bound while the machine's value lay above all of them.
pub const AT_BOUND: f64 = 0.15;
/// A replicate within this fraction of the bounds' range (in log where they are
/// positive) of a bound ran to it.
const BOUND_NEAR: f64 = 0.025;

/// What is resampled and how each replicate is fitted.
pub struct Request<'a> {
    /// The fit's result and identified parameter set.
    pub result: &'a IdentifyResult,
    pub params: &'a Params,
    /// The objective the result minimises and the search's settings
    /// ([`crate::identify::run::Identified`]).
    pub objective: &'a dyn Objective,
    pub settings: Settings,
    /// A fit by plan's stages ([`Identified::replay`](crate::identify::Identified)):
    /// each replicate runs them as the fit did (`None`: one search of `objective`
    /// with `settings`).
    pub replay: Option<&'a Replay>,
    pub replicates: usize,
    /// Parameters the fit held at assumed values, with their ranges (name, value,
    /// relative half-width): each replicate draws each uniformly within
    /// value·(1 ± half-width) and is fitted with it, so the replicates carry what the
    /// fit absorbs of a held value that is wrong. The drawn values are in the
    /// replicates' values beside the fitted ones.
    pub held: &'a [(String, f64, f64)],
    /// Asked before each replicate whether to stop (Ctrl-C).
    pub stop: &'a (dyn Fn() -> bool + Sync),
    /// Called after each replicate's fit, or each of its stages where it replays a
    /// plan (progress: replicates × [`Replay::steps`] in all).
    pub on_replicate: &'a (dyn Fn() + Sync),
}

/// Why a bootstrap cannot be computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ResampleError {
    #[error("--resample: the fit was stopped before it converged; resample a finished fit")]
    Interrupted,
    #[error("--resample {0}: at least {MIN_REPLICATES} replicates are needed for an interval")]
    TooFew(usize),
    #[error("--resample: {label} has {residuals} residual(s), too few for {MIN_BLOCKS} blocks (of {length}) and no more than the {fitted} fitted parameters, whose residuals cannot stand for its errors (use --profile, or the standard errors, for it)")]
    TooFewResiduals {
        label: String,
        residuals: usize,
        length: usize,
        fitted: usize,
    },
    #[error("--uncertain {0}: {0} is fitted; its uncertainty is the fit's")]
    HeldFitted(String),
    #[error("--resample: the objective cannot be evaluated at the result: {0}")]
    Objective(#[from] ObjectiveError),
}

/// Fewer blocks than this in one experiment's residuals (an objective's, where an
/// experiment feeds several) cannot stand for their errors: the unbalance test's
/// four step angles, a frequency response's two resonances. Such a part's errors are
/// drawn normal instead (a parametric bootstrap of that part; `Problem::blocks`).
pub const MIN_BLOCKS: usize = 10;

/// One search of a replayed plan: the objective it searches (a record's part of
/// the fit's, or the whole), that part's range in the residual vector, its
/// parameters and its search.
struct Step<'s> {
    objective: &'s dyn Objective,
    range: Range<usize>,
    names: &'s [String],
    settings: Settings,
}

/// Why replicate `b` has no values.
fn failed(b: usize, e: IdentifyError) -> String {
    format!("replicate {b}: {e}")
}

/// One replicate's data: the offset of its residuals from the fit's, and its draw
/// of the held parameters.
struct Draw {
    offset: Vec<f64>,
    held: Vec<f64>,
}

/// How one part's errors are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Errors {
    /// The part's residuals in circular blocks of this length.
    Blocks(usize),
    /// Normal errors of this standard deviation (the part's residuals' sum of
    /// squares over their count less the fitted parameters), where they are too few
    /// for blocks.
    Normal(f64),
}

/// The bootstrap of `request.result`.
pub fn resample(request: &Request) -> Result<Resampling, ResampleError> {
    if request.result.interrupted {
        return Err(ResampleError::Interrupted);
    }
    let result = request.result;
    if let Some((name, ..)) = (request.held.iter()).find(|h| result.parameters.contains_key(&h.0)) {
        return Err(ResampleError::HeldFitted(name.clone()));
    }
    let names: Vec<String> = result.parameters.keys().cloned().collect();
    let problem = Problem {
        fit: names.iter().map(|n| result.parameters[n]).collect(),
        initial: names.iter().map(|n| result.initial[n]).collect(),
        bounds: names
            .iter()
            .map(|n| {
                let [lo, hi] = result.bounds[n];
                (n.clone(), Bound { lo, hi })
            })
            .collect(),
        names,
        held: request.held,
        params: request.params,
        objective: request.objective,
        settings: request.settings,
        replay: request.replay,
        parts: parts(result),
    };
    let mut resampling = problem.run(request.replicates, request.stop, request.on_replicate)?;
    problem.bounded(&mut resampling);
    Ok(resampling)
}

/// Adds `resampling` to `result`. Where it gives intervals, they replace the
/// warning that the standard errors of a rough cost are lower bounds.
pub fn attach(result: &mut IdentifyResult, resampling: Resampling) {
    if !resampling.intervals.is_empty() {
        result.warnings.retain(|w| w.0 != Warning::RoughCost);
    }
    result
        .warnings
        .extend(at_bound(&resampling).into_iter().map(Coded));
    result.resampling = Some(resampling);
}

/// The bound that replicates' `values` ran to within `bound`, where at least
/// [`AT_BOUND`] of `fitted` replicates (and two) did; the lower where both.
pub fn ran_to_bound(values: &[f64], bound: Bound, fitted: usize) -> Option<AtBound> {
    let near = |end: f64| {
        (values.iter())
            .filter(|v| (bound.unit(**v) - end).abs() < BOUND_NEAR)
            .count()
    };
    let enough = |count: usize| count >= 2 && count as f64 >= AT_BOUND * fitted as f64;
    let (lower, upper) = (near(0.0), near(1.0));
    let (side, replicates) = match () {
        _ if enough(lower) && lower >= upper => (Side::Lower, lower),
        _ if enough(upper) => (Side::Upper, upper),
        _ => return None,
    };
    Some(AtBound { side, replicates })
}

/// The warnings of replicates that ran to a bound.
fn at_bound(resampling: &Resampling) -> Vec<Warning> {
    (resampling.intervals.iter())
        .filter_map(|(name, i)| {
            let a = i.at_bound?;
            Some(Warning::BootstrapAtBound {
                name: name.clone(),
                side: a.side,
                replicates: a.replicates,
                of: resampling.fitted,
            })
        })
        .collect()
}

/// Each experiment's (and objective's) residual count, named as the result names it.
fn parts(result: &IdentifyResult) -> Vec<(String, usize)> {
    result
        .residuals
        .iter()
        .map(|r| (format!("{} [{}]", r.source, r.objective), r.residuals.len()))
        .collect()
}

/// What one bootstrap needs of a fit.
struct Problem<'a> {
    /// The fitted parameters, their fitted and start values, and bounds.
    names: Vec<String>,
    fit: Vec<f64>,
    initial: Vec<f64>,
    bounds: Vec<(String, Bound)>,
    /// The held parameters' ranges the replicates draw from.
    held: &'a [(String, f64, f64)],
    /// The identified parameter set.
    params: &'a Params,
    objective: &'a dyn Objective,
    settings: Settings,
    replay: Option<&'a Replay>,
    /// Each part of the residual vector, in order: its name and length.
    parts: Vec<(String, usize)>,
}

impl Problem<'_> {
    /// `replicates` replicates, in parallel.
    fn run(
        &self,
        replicates: usize,
        stop: &(dyn Fn() -> bool + Sync),
        on_replicate: &(dyn Fn() + Sync),
    ) -> Result<Resampling, ResampleError> {
        if replicates < MIN_REPLICATES {
            return Err(ResampleError::TooFew(replicates));
        }
        let r0 = self.objective.residuals(self.params)?;
        let segments = self.segments(r0.len());
        let errors = modified(&centre(&r0, &segments), self.names.len());
        let blocks = self.blocks(&errors, &r0, &segments)?;
        let draws: Vec<Draw> = (0..replicates)
            .map(|b| {
                let seed = seed(self.settings.seed, b);
                let draw = draw(&errors, &segments, &blocks, seed);
                Draw {
                    offset: draw.iter().zip(&r0).map(|(d, r)| d - r).collect(),
                    held: self.held_draw(seed),
                }
            })
            .collect();
        let outcomes = match self.replay {
            Some(replay) => self.replayed(replay, &draws, stop, on_replicate),
            None => {
                let replicate = |b: usize, objective: &dyn Objective| {
                    if stop() {
                        return None;
                    }
                    let held = &draws[b].held;
                    let fitted = self.start(held).and_then(|start| {
                        let whole = (objective, draws[b].offset.clone());
                        self.refit(whole, &self.names, start, self.settings)
                    });
                    on_replicate();
                    let values = fitted.and_then(|p| self.values(&p, held));
                    Some(values.map_err(|e| failed(b, e)))
                };
                self.each(self.objective, self.settings, replicates, &replicate)
            }
        };
        Ok(self.summarise(replicates, blocks, outcomes))
    }

    /// `task(b, objective)` for each of `count` replicates: side by side with their
    /// evaluations in lanes where the search is Nelder–Mead from one start (it
    /// evaluates one point after another) on an objective that runs in lanes, else
    /// in parallel.
    fn each<T: Send>(
        &self,
        objective: &dyn Objective,
        settings: Settings,
        count: usize,
        task: &(dyn Fn(usize, &dyn Objective) -> T + Sync),
    ) -> Vec<T> {
        if settings.method == Method::NelderMead && settings.starts == 1 && objective.in_lanes() {
            side_by_side(objective, count, task)
        } else {
            (0..count)
                .into_par_iter()
                .map(|b| task(b, objective))
                .collect()
        }
    }

    /// The fit's plan run again on each replicate's data: each stage's search of its
    /// parameters on its record alone, from where the stages before left them, the
    /// replicates side by side stage after stage; then the joint refinement.
    fn replayed(
        &self,
        replay: &Replay,
        draws: &[Draw],
        stop: &(dyn Fn() -> bool + Sync),
        on_replicate: &(dyn Fn() + Sync),
    ) -> Vec<Option<Result<Vec<f64>, String>>> {
        let Some(steps) = self.steps(replay) else {
            let missing = "the fit's objective has no part for a stage of its plan";
            return vec![Some(Err(missing.into())); draws.len()];
        };
        let mut states: Vec<Option<Result<Params, String>>> = (draws.iter().enumerate())
            .map(|(b, d)| Some(self.start(&d.held).map_err(|e| failed(b, e))))
            .collect();
        for s in &steps {
            let step = |b: usize, objective: &dyn Objective| match &states[b] {
                Some(Ok(state)) if !stop() => {
                    let offset = draws[b].offset[s.range.clone()].to_vec();
                    let fitted =
                        self.refit((objective, offset), s.names, state.clone(), s.settings);
                    on_replicate();
                    Some(fitted.map_err(|e| failed(b, e)))
                }
                Some(Ok(_)) | None => None,
                Some(Err(e)) => Some(Err(e.clone())),
            };
            states = self.each(s.objective, s.settings, draws.len(), &step);
        }
        (states.into_iter().zip(draws))
            .enumerate()
            .map(|(b, (s, d))| {
                let values = |p: Params| self.values(&p, &d.held).map_err(|e| failed(b, e));
                s.map(|s| s.and_then(values))
            })
            .collect()
    }

    /// The searches of `replay`: each stage's on its record's part of the objective,
    /// then the refinement's on the whole (`None` where the objective has no such
    /// part).
    fn steps<'s>(&'s self, replay: &'s Replay) -> Option<Vec<Step<'s>>> {
        let mut steps = Vec::with_capacity(replay.steps());
        for stage in &replay.stages {
            steps.push(Step {
                objective: self.objective.part(stage.part)?,
                range: self.part_range(stage.part),
                names: &stage.names,
                settings: stage.settings,
            });
        }
        if !replay.refined.is_empty() {
            steps.push(Step {
                objective: self.objective,
                range: 0..self.objective.len(),
                names: &replay.refined,
                settings: replay.refinement,
            });
        }
        Some(steps)
    }

    /// A replicate's fitted values `p` in `names`' order, then its `held` draw.
    fn values(&self, p: &Params, held: &[f64]) -> Result<Vec<f64>, IdentifyError> {
        let mut v = Vec::with_capacity(self.names.len() + held.len());
        for name in &self.names {
            let value = p.get(name).map_err(ObjectiveError::from)?;
            v.push(
                value
                    .ok_or_else(|| IdentifyError::NothingEvaluated(format!("{name}: no value")))?,
            );
        }
        v.extend(held);
        Ok(v)
    }

    /// The residual range of the objective's part `i`.
    fn part_range(&self, i: usize) -> Range<usize> {
        let len = |j: usize| self.objective.part(j).map_or(0, |o| o.len());
        let from: usize = (0..i).map(len).sum();
        from..from + len(i)
    }

    /// The parts' ranges in the residual vector of length `n` (one range when the
    /// parts do not add up to it).
    fn segments(&self, n: usize) -> Vec<Range<usize>> {
        if self.parts.iter().map(|p| p.1).sum::<usize>() != n {
            return std::iter::once(0..n).collect();
        }
        let mut at = 0;
        self.parts
            .iter()
            .map(|&(_, l)| {
                at += l;
                at - l..at
            })
            .collect()
    }

    /// How each segment's errors are drawn: the centred residuals `centred` in
    /// blocks, or, where a part has fewer than [`MIN_BLOCKS`], normal errors whose
    /// variance is its residuals' `raw` sum of squares (its mean misfit is an error
    /// too) over their count less the fitted parameters — as if the part alone had
    /// determined them all (the unbalance test's four step angles fix the split of
    /// the frictions), which a part with no more residuals than that cannot give.
    fn blocks(
        &self,
        centred: &[f64],
        raw: &[f64],
        segments: &[Range<usize>],
    ) -> Result<Vec<Errors>, ResampleError> {
        let k = self.names.len();
        (segments.iter().enumerate())
            .map(|(i, s)| {
                let length = block_length(&centred[s.clone()]);
                if s.len() / length >= MIN_BLOCKS {
                    Ok(Errors::Blocks(length))
                } else if s.len() > k {
                    let ss = sum_of_squares(&raw[s.clone()]);
                    Ok(Errors::Normal((ss / (s.len() - k) as f64).sqrt()))
                } else {
                    Err(ResampleError::TooFewResiduals {
                        label: self.part(i),
                        residuals: s.len(),
                        length,
                        fitted: k,
                    })
                }
            })
            .collect()
    }

    /// The intervals cut to the bounds the replicates were fitted within; where at
    /// least [`AT_BOUND`] of the replicates ran to a bound, the bound named.
    fn bounded(&self, resampling: &mut Resampling) {
        let fitted = resampling.fitted;
        for (name, interval) in resampling.intervals.iter_mut() {
            let Some((_, b)) = self.bounds.iter().find(|(n, _)| n == name) else {
                continue;
            };
            interval.lower = interval.lower.max(b.lo);
            interval.upper = interval.upper.min(b.hi);
            let values = resampling
                .values
                .get(name)
                .map_or(&[][..], |v| v.as_slice());
            interval.at_bound = ran_to_bound(values, *b, fitted);
        }
    }

    /// Replicate `seed`'s draw of each held parameter within its range.
    fn held_draw(&self, seed: u64) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(seed ^ 0x6865_6c64);
        (self.held.iter())
            .map(|(_, value, half)| value * (1.0 + half * rng.random_range(-1.0..=1.0)))
            .collect()
    }

    /// Where each replicate starts: the fit's start of the fitted parameters, the
    /// held ones at replicate's draw `held`.
    fn start(&self, held: &[f64]) -> Result<Params, IdentifyError> {
        let mut base = self.params.clone();
        let held = self.held.iter().map(|h| &h.0).zip(held);
        for (name, &v) in self.names.iter().zip(&self.initial).chain(held) {
            base.set(name, v).map_err(ObjectiveError::from)?;
        }
        Ok(base)
    }

    /// The search of `names` from `base` with `settings` on an objective shifted by
    /// an offset (`whole`): the parameter set at its best point.
    fn refit(
        &self,
        whole: (&dyn Objective, Vec<f64>),
        names: &[String],
        base: Params,
        settings: Settings,
    ) -> Result<Params, IdentifyError> {
        let bounds: Vec<(String, Bound)> = (self.bounds.iter())
            .filter(|(n, _)| names.contains(n))
            .cloned()
            .collect();
        let space = ParamSpace::new(base, names, &bounds)?;
        let objective = Corrected {
            linear: whole.0,
            offset: whole.1,
        };
        let settings = Settings {
            max_evaluations: None,
            ..settings
        };
        let monitor = Monitor::default();
        search(&space, &objective, &settings, &monitor, &[], &|_| {});
        let best = monitor.best().map(|b| b.values).ok_or_else(|| {
            IdentifyError::NothingEvaluated(monitor.failure().unwrap_or_default())
        })?;
        Ok(space.params(&best).map_err(ObjectiveError::from)?)
    }

    /// The replicates' values and the intervals they give.
    fn summarise(
        &self,
        asked: usize,
        errors: Vec<Errors>,
        outcomes: Vec<Option<Result<Vec<f64>, String>>>,
    ) -> Resampling {
        let mut notes = Vec::new();
        let stopped = outcomes.iter().filter(|o| o.is_none()).count();
        if stopped > 0 {
            notes.push(format!("{stopped} replicate(s) not run: stopped (Ctrl-C)"));
        }
        let fits: Vec<Vec<f64>> = outcomes
            .into_iter()
            .flatten()
            .filter_map(|o| o.map_err(|e| notes.push(e)).ok())
            .collect();
        let values: BTreeMap<String, Vec<f64>> = (self.names.iter())
            .chain(self.held.iter().map(|h| &h.0))
            .enumerate()
            .map(|(i, n)| (n.clone(), fits.iter().map(|f| f[i]).collect()))
            .collect();
        let intervals = if fits.len() >= MIN_REPLICATES {
            (self.names.iter().zip(&self.fit))
                .map(|(n, &fit)| (n.clone(), interval(fit, &values[n], self.held.is_empty())))
                .collect()
        } else {
            notes.push(format!(
                "{} replicate(s) fitted, fewer than {MIN_REPLICATES}: no interval",
                fits.len()
            ));
            BTreeMap::new()
        };
        Resampling {
            method: self.method(&errors),
            level: LEVEL,
            asked,
            fitted: fits.len(),
            block_lengths: (errors.iter())
                .map(|e| match e {
                    Errors::Blocks(l) => *l,
                    Errors::Normal(_) => 1,
                })
                .collect(),
            intervals,
            values,
            notes,
        }
    }
}

impl Problem<'_> {
    /// What the bootstrap drew: blocks, normal errors where a part had too few
    /// residuals for blocks, and the held parameters' ranges.
    fn method(&self, errors: &[Errors]) -> String {
        let mut method = String::from("residual block bootstrap");
        // The spread as a multiple of the part's residuals' RMS, √(m/(m − k)): the
        // joint objective scales each part, so its own sd is in no unit of the record.
        let k = self.names.len() as f64;
        let normal: Vec<String> = (errors.iter().enumerate())
            .filter_map(|(i, e)| match e {
                Errors::Normal(_) => {
                    let m = self.parts.get(i).map_or(f64::NAN, |p| p.1 as f64);
                    let times = (m / (m - k)).sqrt();
                    Some(format!(
                        "{} (sd {times:.2} × its residuals' RMS)",
                        self.part(i)
                    ))
                }
                Errors::Blocks(_) => None,
            })
            .collect();
        if !normal.is_empty() {
            method += &format!(
                "; normal errors for {}, too few residuals for {MIN_BLOCKS} blocks",
                normal.join(", ")
            );
        }
        if !self.held.is_empty() {
            let ranges: Vec<String> = (self.held.iter())
                .map(|(n, _, h)| format!("{n} ±{} %", crate::names::Num(100.0 * h)))
                .collect();
            method += &format!(
                "; held parameters drawn uniformly within their ranges ({}), each interval the fit ± (|bias| + 1.96 sd): about the replicates' mean and the fit less the bias both",
                ranges.join(", ")
            );
        }
        method
    }

    /// Part `i`'s name (the whole fit where the parts do not add up).
    fn part(&self, i: usize) -> String {
        self.parts.get(i).map_or("the fit".into(), |p| p.0.clone())
    }
}

/// The residuals less each segment's mean (a bootstrap draws errors of mean zero).
fn centre(r: &[f64], segments: &[Range<usize>]) -> Vec<f64> {
    let mut out = r.to_vec();
    for s in segments {
        let mean = r[s.clone()].iter().sum::<f64>() / s.len() as f64;
        out[s.clone()].iter_mut().for_each(|x| *x -= mean);
    }
    out
}

/// Residuals scaled by √(m / (m − k)) for m residuals and k fitted parameters: a
/// fit's residuals are smaller than its errors by that factor on average (the
/// modified residuals of Davison & Hinkley, 1997).
fn modified(r: &[f64], k: usize) -> Vec<f64> {
    let m = r.len() as f64;
    let factor = if m > k as f64 {
        (m / (m - k as f64)).sqrt()
    } else {
        1.0
    };
    r.iter().map(|x| x * factor).collect()
}

/// The block length of residuals `r`: the first lag where their autocorrelation
/// falls below e⁻² (twice the correlation time of an exponential decay), so that
/// blocks carry the correlation and neighbouring blocks are nearly independent;
/// 1 for white residuals, at most a quarter of the record.
pub fn block_length(r: &[f64]) -> usize {
    let n = r.len();
    let c0: f64 = r.iter().map(|x| x * x).sum();
    if n < 8 || c0 <= 0.0 {
        return 1;
    }
    let limit = (n / 4).max(1);
    (1..=limit)
        .find(|&k| {
            let ck: f64 = r[..n - k].iter().zip(&r[k..]).map(|(a, b)| a * b).sum();
            ck / c0 < (-2.0f64).exp()
        })
        .unwrap_or(limit)
}

/// The seed of replicate `b`.
fn seed(seed: u64, b: usize) -> u64 {
    seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (b as u64).wrapping_add(0x7265_7361_6d70)
}

/// A draw of each segment of `r`: circular blocks of its residuals, or normal
/// errors.
fn draw(r: &[f64], segments: &[Range<usize>], errors: &[Errors], seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(r.len());
    for (s, &errors) in segments.iter().zip(errors) {
        let part = &r[s.clone()];
        let n = part.len();
        while out.len() < s.end {
            match errors {
                Errors::Blocks(block) => {
                    let from = rng.random_range(0..n);
                    let take = block.min(s.end - out.len());
                    out.extend((0..take).map(|i| part[(from + i) % n]));
                }
                Errors::Normal(sd) => {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    out.push(sd * z);
                }
            }
        }
    }
    out
}

/// The normal interval of a fit `fit` from its replicates `v`: bias-corrected
/// (`correct`: the fit less the replicates' mean offset), or, where the replicates
/// drew held parameters, the fit ± (|offset| + 1.96 sd): their offset from the fit
/// may then be the held ranges' pull (the interval about their mean) or the fit's
/// bias (about the fit less it), and the replicates cannot tell which — on θbw's
/// cost, a plateau below the machine's value, a fit and its replicates come down
/// it alike, and the interval about their mean excluded the machine's value and
/// the fit's (docs/validation.md). The interval holds both readings.
fn interval(fit: f64, v: &[f64], correct: bool) -> Interval {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let bias = mean - fit;
    let (lower, upper) = if correct {
        (fit - bias - Z * sd, fit - bias + Z * sd)
    } else {
        (fit - bias.abs() - Z * sd, fit + bias.abs() + Z * sd)
    };
    Interval {
        lower,
        upper,
        standard_error: sd,
        bias,
        at_bound: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replicates_that_ran_to_a_bound_are_counted_there() {
        let b = Bound { lo: 8e-6, hi: 8e-4 };
        // θbw on a machine that is not the preset: 4 of 12 at the lower bound.
        let theta = [
            1.55e-5, 1.69e-5, 1.51e-5, 8.02e-6, 8.86e-6, 3.76e-5, 8.02e-6, 1.68e-5, 3.61e-5,
            8.48e-6, 4.91e-5, 1.36e-5,
        ];
        let at = ran_to_bound(&theta, b, 12).unwrap();
        assert_eq!((at.side, at.replicates), (Side::Lower, 4));
        // One replicate at a bound is not enough, nor two of twenty.
        assert_eq!(ran_to_bound(&[8e-6, 1e-4, 2e-4, 3e-4, 1e-4], b, 5), None);
        let mut twenty = vec![1e-4; 18];
        twenty.extend([7.9e-4, 8e-4]);
        assert_eq!(ran_to_bound(&twenty, b, 20), None);
        twenty[0] = 7.95e-4;
        let at = ran_to_bound(&twenty, b, 20).unwrap();
        assert_eq!((at.side, at.replicates), (Side::Upper, 3));
        // Linear bounds (a signed parameter): the same fraction of the range.
        let signed = Bound { lo: -1.0, hi: 1.0 };
        assert!(ran_to_bound(&[-0.99, -0.98, 0.1, 0.2, 0.3], signed, 5).is_some());
        assert_eq!(ran_to_bound(&[-0.9, -0.9, 0.1, 0.2, 0.3], signed, 5), None);
    }
    use crate::model::presets;
    use crate::objectives::sum_of_squares;
    use rand_distr::{Distribution, Normal};

    /// y = (Kw / 1e5)·exp(−t·Kg / 850) on t ∈ [0, 3) s, measured with white Gaussian
    /// errors of one unit: a smooth cost where σ²(JᵀJ)⁻¹ is right.
    struct Decay {
        t: Vec<f64>,
        y: Vec<f64>,
    }

    impl Decay {
        fn model(p: &Params, t: f64) -> f64 {
            let (a, b) = (p.get("Kw").unwrap().unwrap(), p.get("Kg").unwrap().unwrap());
            a / 1e5 * (-t * b / 850.0).exp() * 100.0
        }
    }

    impl Objective for Decay {
        fn name(&self) -> &'static str {
            "decay"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            Ok((self.t.iter().zip(&self.y))
                .map(|(&t, y)| Decay::model(p, t) - y)
                .collect())
        }
        fn len(&self) -> usize {
            self.t.len()
        }
        fn scale(&self) -> String {
            "one unit".into()
        }
    }

    /// Standard errors σ²(JᵀJ)⁻¹ of a two-parameter fit, by central differences.
    fn standard_errors(o: &Decay, p: &Params, names: &[String]) -> [f64; 2] {
        let m = o.len();
        let r = o.residuals(p).unwrap();
        let sigma2 = sum_of_squares(&r) / (m - 2) as f64;
        let columns: Vec<Vec<f64>> = names
            .iter()
            .map(|n| {
                let v = p.get(n).unwrap().unwrap();
                let h = v * 1e-6;
                let (mut up, mut down) = (p.clone(), p.clone());
                up.set(n, v + h).unwrap();
                down.set(n, v - h).unwrap();
                let (ru, rd) = (o.residuals(&up).unwrap(), o.residuals(&down).unwrap());
                ru.iter()
                    .zip(&rd)
                    .map(|(a, b)| (a - b) / (2.0 * h))
                    .collect()
            })
            .collect();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let jtj = nalgebra::Matrix2::new(
            dot(&columns[0], &columns[0]),
            dot(&columns[0], &columns[1]),
            dot(&columns[1], &columns[0]),
            dot(&columns[1], &columns[1]),
        );
        let cov = jtj.try_inverse().unwrap() * sigma2;
        [cov[(0, 0)].sqrt(), cov[(1, 1)].sqrt()]
    }

    /// One data set of [`Decay`] with errors from `seed`, fitted from 1.2× the truth
    /// and bootstrapped with 40 replicates: per parameter (Kg, Kw), the bootstrap
    /// standard error over σ²(JᵀJ)⁻¹'s, and whether the interval holds the truth.
    fn decay_case(seed: u64) -> Vec<(f64, bool)> {
        let truth = presets::load("worm-gear").unwrap();
        let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.015).collect();
        let noise = Normal::new(0.0, 1.0).unwrap();
        let mut rng = StdRng::seed_from_u64(seed);
        let y = t
            .iter()
            .map(|&t| Decay::model(&truth, t) + noise.sample(&mut rng))
            .collect();
        let decay = Decay { t, y };
        let names = vec!["Kg".to_string(), "Kw".to_string()];
        let truths: Vec<f64> = names
            .iter()
            .map(|n| truth.get(n).unwrap().unwrap())
            .collect();
        let initial: Vec<f64> = truths.iter().map(|v| v * 1.2).collect();
        let bounds: Vec<(String, Bound)> = (names.iter().zip(&truths))
            .map(|(n, v)| {
                (
                    n.clone(),
                    Bound {
                        lo: v / 10.0,
                        hi: v * 10.0,
                    },
                )
            })
            .collect();
        let mut start = truth.clone();
        for (n, v) in names.iter().zip(&initial) {
            start.set(n, *v).unwrap();
        }
        let space = ParamSpace::new(start, &names, &bounds).unwrap();
        let settings = Settings {
            starts: 1,
            seed,
            ..Settings::default()
        };
        let monitor = Monitor::default();
        search(&space, &decay, &settings, &monitor, &[], &|_| {});
        let fit = monitor.best().unwrap().values;
        let params = space.params(&fit).unwrap();
        let problem = Problem {
            names: names.clone(),
            fit,
            initial,
            bounds,
            params: &params,
            objective: &decay,
            settings,
            replay: None,
            parts: vec![("decay".into(), 200)],
            held: &[],
        };
        let r = problem.run(40, &|| false, &|| {}).unwrap();
        let se = standard_errors(&decay, &params, &names);
        (names.iter().zip(&truths).zip(se))
            .map(|((name, want), se)| {
                let i = r.intervals[name];
                (i.standard_error / se, i.lower < *want && *want < i.upper)
            })
            .collect()
    }

    #[test]
    fn on_a_smooth_cost_with_white_errors_the_bootstrap_agrees_with_the_standard_errors() {
        // 20 data sets: each bootstrap standard error within the ±3σ of 40
        // replicates' (±34 %) of σ²(JᵀJ)⁻¹'s, their mean within 10 %, and the
        // intervals' coverage of the truth at least 16 of 20 (P(≤ 15) = 0.26 % at
        // 95 %).
        let cases: Vec<Vec<(f64, bool)>> = (0..20).into_par_iter().map(decay_case).collect();
        for p in 0..2 {
            let ratios: Vec<f64> = cases.iter().map(|c| c[p].0).collect();
            assert!(
                ratios.iter().all(|r| (0.66..1.34).contains(r)),
                "{ratios:?}"
            );
            let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
            assert!((0.9..1.1).contains(&mean), "mean ratio {mean}");
            let held = cases.iter().filter(|c| c[p].1).count();
            assert!(
                held >= 16,
                "parameter {p}: {held} of 20 intervals hold the truth"
            );
        }
    }

    #[test]
    fn a_part_too_short_for_blocks_gets_normal_errors_of_its_rms_and_is_named() {
        let p = presets::load("worm-gear").unwrap();
        // Four residuals 0.2, 0.1, 0.1, 0.2 (a misfit of mean 0.15) after fitting one
        // parameter: the errors' variance is their sum of squares over 4 − 1, the
        // mean included.
        let decay = Decay {
            t: vec![0.0, 0.5, 1.0, 1.5],
            y: vec![1.0, 0.5, 0.2, -0.1],
        };
        let r0: Vec<f64> = vec![0.2, 0.1, 0.1, 0.2];
        let problem = Problem {
            names: vec!["Kw".into()],
            fit: vec![3.1e5],
            initial: vec![3.1e5],
            bounds: vec![("Kw".into(), Bound { lo: 1e5, hi: 1e6 })],
            params: &p,
            objective: &decay,
            settings: Settings::default(),
            replay: None,
            parts: vec![("unbalance.json [unbalance_step]".into(), 4)],
            held: &[],
        };
        let segments: Vec<Range<usize>> = std::iter::once(0..4).collect();
        let centred = centre(&r0, &segments);
        let e = problem.blocks(&centred, &r0, &segments).unwrap();
        let Errors::Normal(sd) = e[0] else {
            panic!("{e:?}")
        };
        assert!((sd - (0.1f64 / 3.0).sqrt()).abs() < 1e-15, "{sd}");
        let d = draw(&centred, &segments, &e, 1);
        assert_eq!(d.len(), 4);
        assert!(d.iter().all(|x| !centred.contains(x)), "{d:?}");
        let r = problem.run(6, &|| false, &|| {}).unwrap();
        assert!(
            r.method.contains("normal errors") && r.method.contains("unbalance.json"),
            "{}",
            r.method
        );
        // One residual for one fitted parameter says nothing of the errors.
        let one: Vec<Range<usize>> = std::iter::once(0..1).collect();
        let e = problem
            .blocks(&[0.0], &[0.2], &one)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unbalance.json [unbalance_step] has 1 residual(s)"),
            "{e}"
        );
    }

    #[test]
    fn white_residuals_get_blocks_of_one_and_correlated_ones_longer() {
        let mut rng = StdRng::seed_from_u64(3);
        let white: Vec<f64> = (0..2000).map(|_| rng.random_range(-1.0..1.0)).collect();
        assert_eq!(block_length(&white), 1);
        // AR(1) with φ = 0.9: the autocorrelation 0.9^k falls below e⁻² at k = 19.
        let mut x = 0.0;
        let ar: Vec<f64> = white
            .iter()
            .map(|e| {
                x = 0.9 * x + e;
                x
            })
            .collect();
        let l = block_length(&ar);
        assert!((14..=25).contains(&l), "block length {l}");
    }

    #[test]
    fn a_draw_keeps_each_segment_within_itself() {
        let r: Vec<f64> = (0..30).map(|i| if i < 10 { 1.0 } else { -1.0 }).collect();
        let segments = vec![0..10, 10..30];
        let d = draw(&r, &segments, &[Errors::Blocks(3), Errors::Blocks(4)], 5);
        assert_eq!(d.len(), 30);
        assert!(d[..10].iter().all(|&x| x == 1.0));
        assert!(d[10..].iter().all(|&x| x == -1.0));
    }

    #[test]
    fn the_interval_is_moved_against_the_bias() {
        let i = interval(1.0, &[1.1, 1.2, 1.3], true);
        assert!((i.bias - 0.2).abs() < 1e-12);
        assert!((i.standard_error - 0.1).abs() < 1e-12);
        assert!((i.lower - (0.8 - Z * 0.1)).abs() < 1e-12);
        assert!((i.upper - (0.8 + Z * 0.1)).abs() < 1e-12);
        // Replicates that drew held parameters: about their mean and about the fit
        // less their offset, both.
        let held = interval(1.0, &[1.1, 1.2, 1.3], false);
        assert!((held.lower - (0.8 - Z * 0.1)).abs() < 1e-12);
        assert!((held.upper - (1.2 + Z * 0.1)).abs() < 1e-12);
    }
}
