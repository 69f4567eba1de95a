//! Profile likelihood of fitted parameters (docs/identification.md). Each profiled
//! parameter is held at values on a walk outwards from the fit, both ways, and the
//! other fitted parameters are re-optimised at each value. With Gaussian errors of
//! unknown variance the likelihood-ratio statistic of a held value is
//! n·ln(cost / cost at the fit) (n residuals); the 95 % interval is where it stays
//! below χ²₁(0.95) = 3.84. Where the residuals cannot estimate the variance — no
//! more residuals than parameters, or an exact fit of noise-free data — the
//! statistic is Δχ², the change of the sum of squared scaled residuals, with the
//! variance of one unit of them (the measurement error each objective's scale
//! stands for: 0.1 % of a resonance, 0.1 dB). That is not Δcost: the cost weighs
//! each experiment by the mean of its squares, n times less than their sum (on the
//! worm's exact torque curve, 6 000 samples, Δcost = 3.84 put fm's interval at
//! ±41 %). Unlike σ²(JᵀJ)⁻¹ it follows the cost's real shape: a
//! curved valley, a bound, a second minimum. A side where the statistic stays below
//! the level up to the parameter's bound is open (`None`): the data bound the
//! parameter on one side only, and the other parameters that moved along the walk
//! name the family of equally good fits.
//!
//! The cost profiled is the one the result minimises — after nonlinear corrections,
//! the linear response corrected by their last shifts, held fixed — so the walk
//! starts at the fit's cost, each point is one local search of the others (the fit's
//! solver, from the previous point's values), and a linear model's point costs
//! milliseconds. The walks — parameters × two directions — run in parallel.

use crate::identify::result::profile::{Profile, Variance};
use std::collections::BTreeMap;

use rayon::prelude::*;

use crate::identify::error::IdentifyError;
use crate::identify::result::warning::{Side, Warning};
use crate::identify::result::IdentifyResult;
use crate::identify::search::problem::Monitor;
use crate::identify::search::search;
use crate::identify::search::settings::Settings;
use crate::identify::space::{Bound, ParamSpace};
use crate::model::Params;
use crate::objectives::{sum_of_squares, ObjectiveError, Smoothness};

pub use super::request::{Request, LEVEL, THRESHOLD};

/// Points of one walk, at most (refinements of the crossing included).
const MAX_POINTS: usize = 16;
/// Refinements of an interval's end once the walk has crossed it: regula falsi,
/// or bisection where the statistic leaps (a cliff, where the data stop being
/// matched at all, would hold regula falsi at its low side).
const REFINEMENTS: usize = 3;
/// A parameter that changes by more than this factor along an open profile belongs
/// to its family.
const FAMILY_RATIO: f64 = 1.05;

/// Below this RMS scaled residual a fit is exact (noise-free data: 10⁻⁴ of the
/// measurement error an objective's scale stands for), and its residuals estimate
/// no variance.
pub const EXACT_RMS: f64 = 1e-4;

/// A profile point improves on the fit when it lowers the statistic by more than
/// this (less is the search's tolerance, not a missed optimum).
const BETTER_BY: f64 = 0.5;

/// Why profiles cannot be computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProfileError {
    #[error("--profile {0}: not a fitted parameter (fitted: {1})")]
    NotFitted(String, String),
    #[error("--profile: the fit was stopped before it converged; profile a finished fit")]
    Interrupted,
    #[error("--profile: the objective cannot be evaluated at the result: {0}")]
    Objective(#[from] ObjectiveError),
}

/// The profiles of `request.names`, and the warnings they give.
pub fn profiles(
    request: &Request,
) -> Result<(BTreeMap<String, Profile>, Vec<Warning>), ProfileError> {
    let fitted: Vec<String> = request.result.parameters.keys().cloned().collect();
    if request.result.interrupted {
        return Err(ProfileError::Interrupted);
    }
    if let Some(bad) = request.names.iter().find(|n| !fitted.contains(n)) {
        return Err(ProfileError::NotFitted(bad.clone(), fitted.join(", ")));
    }
    let walks: Vec<(String, f64)> = request
        .names
        .iter()
        .flat_map(|n| [(n.clone(), -1.0), (n.clone(), 1.0)])
        .collect();
    let context = Context::new(request)?;
    if request.smoothness != Smoothness::Smooth && context.variance == Variance::Estimated {
        if let Some(out) = super::surface::profiles(request, &context.r0) {
            return Ok((out, Vec::new()));
        }
    }
    let sides: Vec<Walk> = walks
        .par_iter()
        .map(|(name, direction)| context.walk(name, *direction))
        .collect();
    let mut out = BTreeMap::new();
    let mut warnings = Vec::new();
    for (name, pair) in request.names.iter().zip(sides.chunks(2)) {
        let profile = context.assemble(name, &pair[0], &pair[1]);
        warnings.extend(context.warnings(name, &profile, &pair[0], &pair[1]));
        out.insert(name.clone(), profile);
    }
    Ok((out, warnings))
}

/// Adds `profiles` to `result`. Where every fitted parameter's profile was read off
/// a bowl fitted to the rough cost, both ends closed, they replace the warning that
/// the standard errors are lower bounds (as the bootstrap's intervals do).
pub fn attach(result: &mut IdentifyResult, profiles: BTreeMap<String, Profile>) {
    let closed = |p: &Profile| p.surface.is_some() && p.lower.is_some() && p.upper.is_some();
    let covered = (result.parameters.keys()).all(|n| profiles.get(n).is_some_and(closed));
    if covered {
        result.warnings.retain(|w| w.0 != Warning::RoughCost);
    }
    result.profiles = Some(profiles);
}

/// One point of a walk.
#[derive(Clone)]
struct Point {
    /// The walk's coordinate: ln value for a log-bounded parameter, else the value.
    u: f64,
    cost: f64,
    /// What the statistic compares ([`Context::level_of`]).
    level: f64,
    params: Params,
}

/// One direction's walk.
struct Walk {
    points: Vec<Point>,
    /// The interval's end on this side, in the walk's coordinate.
    end: Option<f64>,
    note: Option<String>,
}

/// What every walk shares.
struct Context<'a> {
    request: &'a Request<'a>,
    /// The profiled objective's residuals and cost at the fit.
    r0: Vec<f64>,
    cost0: f64,
    /// [`Context::level_of`] at the fit.
    level0: f64,
    variance: Variance,
    /// Residuals in the fit's cost.
    n: f64,
    /// Each experiment's residual count and the factor n / weight from its share of
    /// the joint residuals back to its scaled residuals' squares.
    parts: Vec<(usize, f64)>,
}

impl<'a> Context<'a> {
    fn new(request: &'a Request<'a>) -> Result<Self, ObjectiveError> {
        let n = request
            .result
            .residuals
            .iter()
            .map(|r| r.residuals.len())
            .sum::<usize>() as f64;
        let r0 = request.objective.residuals(request.params)?;
        let cost0 = sum_of_squares(&r0);
        let k = request.result.parameters.len() as f64;
        let rms = (request.result.residuals.iter())
            .flat_map(|e| &e.residuals)
            .map(|x| x * x)
            .sum::<f64>()
            / n.max(1.0);
        let variance = if n > k && rms >= EXACT_RMS * EXACT_RMS {
            Variance::Estimated
        } else {
            Variance::Unit
        };
        let parts = (request.result.residuals.iter())
            .map(|e| {
                let n = e.residuals.len();
                (
                    n,
                    if e.weight > 0.0 {
                        n as f64 / e.weight
                    } else {
                        0.0
                    },
                )
            })
            .collect();
        let mut context = Context {
            request,
            r0: Vec::new(),
            cost0,
            level0: cost0,
            variance,
            n,
            parts,
        };
        context.level0 = context.level_of(cost0, &r0);
        context.r0 = r0;
        Ok(context)
    }

    /// What the statistic compares at a point of cost `cost` and joint residuals
    /// `r`: the cost (estimated variance), or the experiments' scaled residuals' χ²
    /// (unit variance).
    fn level_of(&self, cost: f64, r: &[f64]) -> f64 {
        match self.variance {
            Variance::Estimated => cost,
            Variance::Unit => self.chi2(r),
        }
    }

    /// Σ of the squared scaled residuals of each experiment from the joint ones
    /// (each scaled by √(weight / n)); in one sum with the mean factor where the
    /// layout differs.
    fn chi2(&self, r: &[f64]) -> f64 {
        let total: usize = self.parts.iter().map(|p| p.0).sum();
        if r.len() != total {
            let weight: f64 = (self.parts.iter().filter(|p| p.1 > 0.0))
                .map(|p| p.0 as f64 / p.1)
                .sum();
            return sum_of_squares(r) * total as f64 / weight.max(f64::MIN_POSITIVE);
        }
        let mut at = 0;
        self.parts
            .iter()
            .map(|&(len, factor)| {
                let part = &r[at..at + len];
                at += len;
                factor * sum_of_squares(part)
            })
            .sum()
    }

    /// The likelihood-ratio statistic of a level against the fit's.
    fn statistic(&self, level: f64) -> f64 {
        self.change(self.level0, level).max(0.0)
    }

    /// The change of the statistic from level `a` to level `b` (signed).
    fn change(&self, a: f64, b: f64) -> f64 {
        match self.variance {
            Variance::Estimated => {
                let tiny = f64::MIN_POSITIVE;
                self.n * (b.max(tiny) / a.max(tiny)).ln()
            }
            Variance::Unit => b - a,
        }
    }

    fn bound(&self, name: &str) -> Bound {
        let [lo, hi] = self.request.result.bounds[name];
        Bound { lo, hi }
    }

    /// The coordinate of the walk and back.
    fn to_u(&self, name: &str, v: f64) -> f64 {
        if self.bound(name).lo > 0.0 {
            v.ln()
        } else {
            v
        }
    }

    fn to_value(&self, name: &str, u: f64) -> f64 {
        if self.bound(name).lo > 0.0 {
            u.exp()
        } else {
            u
        }
    }

    /// The first step of a walk: half a standard error, or 1 % without one.
    fn first_step(&self, name: &str, value: f64) -> f64 {
        let se = self.request.result.standard_error(name);
        let log = self.bound(name).lo > 0.0;
        let scale = if log { 1.0 } else { value.abs().max(1e-12) };
        match se {
            Some(se) if se.is_finite() && se > 0.0 => 0.5 * se / if log { value } else { 1.0 },
            _ => 0.01 * scale,
        }
    }

    /// The other fitted parameters re-fitted with `name` held at `value`, from `warm`.
    fn fit_at(&self, name: &str, value: f64, warm: &Params) -> Result<Point, IdentifyError> {
        let mut base = warm.clone();
        base.set(name, value).map_err(ObjectiveError::from)?;
        let result = self.request.result;
        let others: Vec<String> = result
            .parameters
            .keys()
            .filter(|n| *n != name)
            .cloned()
            .collect();
        let u = self.to_u(name, value);
        if others.is_empty() {
            let r = self.request.objective.residuals(&base)?;
            let cost = sum_of_squares(&r);
            return Ok(Point {
                u,
                cost,
                level: self.level_of(cost, &r),
                params: base,
            });
        }
        let bounds: Vec<(String, Bound)> = others
            .iter()
            .map(|n| {
                let [lo, hi] = result.bounds[n];
                (n.clone(), Bound { lo, hi })
            })
            .collect();
        let space = ParamSpace::new(base, &others, &bounds)?;
        let settings = Settings {
            starts: 1,
            max_evaluations: None,
            ..self.request.settings
        };
        let monitor = Monitor::default();
        search(
            &space,
            self.request.objective,
            &settings,
            &monitor,
            &[],
            &|_| {},
        );
        let best = monitor.best().ok_or_else(|| {
            IdentifyError::NothingEvaluated(monitor.failure().unwrap_or_default())
        })?;
        let params = space.params(&best.values).map_err(ObjectiveError::from)?;
        let level = match self.variance {
            Variance::Estimated => best.cost,
            Variance::Unit => self.chi2(&self.request.objective.residuals(&params)?),
        };
        Ok(Point {
            u,
            cost: best.cost,
            level,
            params,
        })
    }

    /// Walks from the fit in `direction` (±1) until the statistic crosses the
    /// threshold (then refines the crossing), the bound is reached, or a fit fails.
    fn walk(&self, name: &str, direction: f64) -> Walk {
        let v0 = self.request.result.parameters[name];
        let u0 = self.to_u(name, v0);
        let b = self.bound(name);
        let limit = self.to_u(name, if direction < 0.0 { b.lo } else { b.hi });
        let room = (limit - u0).abs();
        let mut walk = Walk {
            points: Vec::new(),
            end: None,
            note: None,
        };
        let mut offset = self.first_step(name, v0).min(room);
        let mut last = Point {
            u: u0,
            cost: self.cost0,
            level: self.level0,
            params: self.request.params.clone(),
        };
        while room > 0.0 && walk.points.len() < MAX_POINTS {
            if (self.request.stop)() {
                walk.note = Some("stopped (Ctrl-C)".into());
                break;
            }
            let u = u0 + direction * offset;
            let point = match self.fit_at(name, self.to_value(name, u), &last.params) {
                Ok(p) => p,
                Err(e) => {
                    walk.note = Some(format!(
                        "the fit at {name} = {} failed: {e}",
                        crate::names::Num(self.to_value(name, u))
                    ));
                    break;
                }
            };
            (self.request.on_point)();
            walk.points.push(point.clone());
            let s = self.statistic(point.level);
            if s >= THRESHOLD {
                walk.end = Some(self.refine(name, &last, &point, &mut walk));
                break;
            }
            if offset >= room {
                break;
            }
            let grow = if s > 0.0 {
                1.2 * (THRESHOLD / s).sqrt()
            } else {
                4.0
            };
            offset = (offset * grow.clamp(1.5, 4.0)).min(room);
            last = point;
        }
        let reached = walk.points.last().map_or(room == 0.0, |p| {
            (p.u - limit).abs() <= 1e-12 * limit.abs().max(1.0)
        });
        if walk.end.is_none() && walk.note.is_none() && !reached {
            walk.note = Some(format!(
                "still below the level at {name} = {} after {MAX_POINTS} fits",
                crate::names::Num(self.to_value(name, last.u))
            ));
        }
        walk
    }

    /// The crossing of the threshold between `below` and `above`, refined (each
    /// trial point is kept in the walk), then interpolated.
    fn refine(&self, name: &str, below: &Point, above: &Point, walk: &mut Walk) -> f64 {
        let (mut lo, mut hi) = (below.clone(), above.clone());
        for _ in 0..REFINEMENTS {
            if (self.request.stop)() || walk.points.len() >= MAX_POINTS {
                break;
            }
            let leap = self.statistic(hi.level) > 4.0 * THRESHOLD;
            let u = if leap {
                0.5 * (lo.u + hi.u)
            } else {
                self.crossing(&lo, &hi)
            };
            match self.fit_at(name, self.to_value(name, u), &lo.params) {
                Ok(p) => {
                    (self.request.on_point)();
                    walk.points.push(p.clone());
                    if self.statistic(p.level) >= THRESHOLD {
                        hi = p;
                    } else {
                        lo = p;
                    }
                }
                Err(_) => break,
            }
        }
        self.crossing(&lo, &hi)
    }

    /// Linear interpolation of the statistic's crossing between two points.
    fn crossing(&self, lo: &Point, hi: &Point) -> f64 {
        let (a, b) = (self.statistic(lo.level), self.statistic(hi.level));
        let t = if b > a {
            ((THRESHOLD - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        lo.u + t * (hi.u - lo.u)
    }

    /// The profile of `name` from its two walks.
    fn assemble(&self, name: &str, down: &Walk, up: &Walk) -> Profile {
        let v0 = self.request.result.parameters[name];
        let mut points: Vec<(f64, f64, f64)> = down
            .points
            .iter()
            .chain(&up.points)
            .map(|p| (self.to_value(name, p.u), p.cost, p.level))
            .chain(std::iter::once((v0, self.cost0, self.level0)))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let lower = down.end.map(|u| self.to_value(name, u));
        let upper = up.end.map(|u| self.to_value(name, u));
        let family = if lower.is_none() || upper.is_none() {
            self.family(name, down, up)
        } else {
            BTreeMap::new()
        };
        Profile {
            lower,
            upper,
            level: LEVEL,
            statistic: points.iter().map(|p| self.statistic(p.2)).collect(),
            variance: self.variance,
            points: points.into_iter().map(|(v, c, _)| [v, c]).collect(),
            family,
            notes: [&down.note, &up.note]
                .into_iter()
                .flatten()
                .cloned()
                .collect(),
            surface: None,
        }
    }

    /// The other fitted parameters that moved by more than [`FAMILY_RATIO`] along
    /// the walks, with their ratio of largest to smallest value.
    fn family(&self, name: &str, down: &Walk, up: &Walk) -> BTreeMap<String, f64> {
        let mut out = BTreeMap::new();
        for other in self.request.result.parameters.keys().filter(|n| *n != name) {
            let values: Vec<f64> = down
                .points
                .iter()
                .chain(&up.points)
                .filter_map(|p| p.params.get(other).ok().flatten())
                .chain(std::iter::once(self.request.result.parameters[other]))
                .map(f64::abs)
                .collect();
            let max = values.iter().copied().fold(0.0, f64::max);
            let min = values.iter().copied().fold(f64::INFINITY, f64::min);
            if min > 0.0 && max / min > FAMILY_RATIO {
                out.insert(other.clone(), max / min);
            }
        }
        out
    }

    /// The warnings of a profile: a side open up to its bound; a point that fits
    /// better than the fit.
    fn warnings(&self, name: &str, p: &Profile, down: &Walk, up: &Walk) -> Vec<Warning> {
        let mut out = Vec::new();
        let b = self.bound(name);
        for (walk, side, bound) in [(down, Side::Lower, b.lo), (up, Side::Upper, b.hi)] {
            if walk.end.is_none() && walk.note.is_none() {
                out.push(Warning::ProfileOpen {
                    name: name.into(),
                    side,
                    bound,
                    family: p.family.clone().into_iter().collect(),
                });
            }
        }
        if let Some(best) = (down.points.iter())
            .chain(&up.points)
            .filter(|q| self.change(q.level, self.level0) > BETTER_BY)
            .min_by(|a, b| a.level.total_cmp(&b.level))
        {
            out.push(Warning::ProfileBetterFit {
                name: name.into(),
                value: self.to_value(name, best.u),
                cost: best.cost,
                fit_cost: self.cost0,
            });
        }
        out
    }
}
