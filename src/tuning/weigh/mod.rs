//! Settings weighed on the nonlinear model against today's (docs/tuning.md, "The
//! search"): what a machine builder checks of each ([`verify`]: the step and the
//! move; [`criteria`]: with the ISO 230-2 cycle compensated in the controller, and as
//! an ensemble), how the figures are scored ([`objective`]) and how two ensembles
//! compare ([`judge`]); here the steps of the search that use them — the screening
//! of every candidate in lanes, at the range's corners too ([`screen`],
//! [`refusals_at_corners`]), the ranking ([`rank`]) and the check of the best on the
//! standard cycle, as ensembles, against today's ([`choose`]).

pub mod criteria;
pub mod judge;
pub mod objective;
pub mod verify;

use rayon::prelude::*;
use serde::Serialize;

use super::candidates::Candidate;
use super::range::Range;
use crate::experiments::positioning::ensemble::Ensemble;
use crate::experiments::positioning::iso230::ReportUnits;
use crate::model::Params;
use crate::sim::LANES;
use criteria::{Checked, Criteria, CriteriaError};
use judge::{Judgement, Verdict};
use objective::Objective;
use verify::Responses;

/// How many of the best screened settings are checked on the standard cycle.
pub const CHECKED: usize = 3;

/// Every set's figures on the short cycle, in lane batches run in parallel;
/// `progress(done, total)` after each batch.
pub fn screen(
    sets: &[Params],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<Result<Criteria, CriteriaError>> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    sets.par_chunks(LANES)
        .flat_map_iter(|chunk| {
            let out = criteria::screen(chunk);
            let n = done.fetch_add(chunk.len(), std::sync::atomic::Ordering::Relaxed) + chunk.len();
            progress(n, sets.len());
            out
        })
        .collect()
}

/// What the screening refuses: a table that moves at rest (a limit cycle), a move
/// that takes more of the torque limit than the reserve leaves.
#[derive(Clone, Copy, Debug)]
pub struct Caps {
    /// The largest motion at rest, report units.
    pub rest: f64,
    /// The largest peak torque of the move, N·m or N.
    pub effort: f64,
}

impl Caps {
    /// On `p` (today's responses `today`) with `torque_reserve` of the limit kept
    /// free: three table-encoder counts (and 1 report unit) or twice today's motion
    /// at rest; the limit less the reserve, or today's peak.
    pub fn of(p: &Params, today: &Responses, torque_reserve: f64) -> Caps {
        let limit = p.controller.torque_limit * p.controller.drive_gain;
        Caps {
            rest: limit_cycle_threshold(p).max(2.0 * today.table_motion_at_rest),
            effort: ((1.0 - torque_reserve) * limit).max(today.move_peak_effort),
        }
    }

    /// Why `r` is refused, if it is.
    pub fn refuses(&self, r: &Responses) -> Option<&'static str> {
        if r.table_motion_at_rest > self.rest {
            Some("a limit cycle: the table moves at rest")
        } else if r.move_peak_effort > self.effort {
            Some("the torque reserve: the move's peak torque")
        } else {
            None
        }
    }
}

/// The table's motion at rest that counts as a limit cycle: three table-encoder
/// counts, and at least 1 report unit (1″, 1 µm).
pub fn limit_cycle_threshold(p: &Params) -> f64 {
    let k = ReportUnits::of(p.axis).deviation_per_si;
    (3.0 * p.controller.table_encoder_resolution * k).max(1.0)
}

/// For each of `sets` (today's first), why the nonlinear model refuses it at one of
/// the range's corners, if it does: its step and move at each corner, in lanes,
/// against the caps of today's there.
pub fn refusals_at_corners(
    sets: &[Params],
    range: &Range,
    torque_reserve: f64,
) -> Vec<Option<String>> {
    let corners = range.corners();
    let mut out: Vec<Option<String>> = vec![None; sets.len()];
    if corners.is_empty() {
        return out;
    }
    let at: Vec<Result<Params, String>> = sets
        .iter()
        .flat_map(|s| {
            corners
                .iter()
                .map(move |c| range.apply(s, c).map_err(|e| e.to_string()))
        })
        .collect();
    let valid: Vec<Params> = at.iter().filter_map(|r| r.as_ref().ok().cloned()).collect();
    let none: Vec<verify::Compensations> = valid.iter().map(|_| Default::default()).collect();
    let mut responses = verify::responses_each(&valid, &none).into_iter();
    let results: Vec<Result<Responses, String>> = at
        .into_iter()
        .map(|r| match r {
            Ok(_) => responses
                .next()
                .expect("one per valid set")
                .map_err(|e| e.to_string()),
            Err(e) => Err(e),
        })
        .collect();
    let n = corners.len();
    for (c, corner) in corners.iter().enumerate() {
        let name = range.describe(corner);
        let today = results[c].as_ref().ok();
        for (i, refusal) in out.iter_mut().enumerate().skip(1) {
            if refusal.is_some() {
                continue;
            }
            *refusal = match (&results[i * n + c], today) {
                (Err(e), _) => Some(format!("at {name}: {e}")),
                (Ok(r), Some(t)) => Caps::of(&sets[i], t, torque_reserve)
                    .refuses(r)
                    .map(|why| format!("at {name}: {why}")),
                (Ok(_), None) => None,
            };
        }
    }
    out
}

/// The candidates (indices into the sets, today's excluded) the nonlinear model
/// admits — no limit cycle, the torque reserve kept, nothing refused at the range's
/// corners (`refused`) —, with their scores against today's: first those that keep
/// every criterion the objective lists ([`Objective::keeps`]), best score first, then
/// the others.
pub fn rank(
    objective: Objective,
    caps: &Caps,
    screened: &[Result<Criteria, CriteriaError>],
    today: &Criteria,
    refused: &[Option<String>],
) -> Vec<(usize, f64)> {
    let mut out: Vec<(usize, f64, bool)> = screened
        .iter()
        .enumerate()
        .skip(1)
        .filter_map(|(i, c)| {
            let c = c.as_ref().ok()?;
            let admitted = caps.refuses(&c.servo).is_none() && refused[i].is_none();
            let keeps = objective.keeps(c, today);
            admitted.then(|| (i, objective.score(c, today), keeps))
        })
        .collect();
    out.sort_by(|a, b| b.2.cmp(&a.2).then(a.1.total_cmp(&b.1)));
    out.into_iter().map(|(i, score, _)| (i, score)).collect()
}

/// A candidate as the screening weighed it (report units; `score` against today's,
/// `None` where refused, with the reason).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Screened {
    #[serde(rename = "Kvp")]
    pub kvp: f64,
    #[serde(rename = "Kvi")]
    pub kvi: f64,
    #[serde(rename = "Kpp")]
    pub kpp: f64,
    pub crossover_hz: f64,
    pub phase_margin_deg: Option<f64>,
    /// The worst phase margin over the range (the nominal's without one).
    pub worst_phase_margin_deg: Option<f64>,
    #[serde(rename = "A")]
    pub a: Option<f64>,
    #[serde(rename = "R")]
    pub r: Option<f64>,
    pub table_settling_s: Option<f64>,
    pub following_error: Option<f64>,
    pub table_motion_at_rest: Option<f64>,
    pub score: Option<f64>,
    pub refused: Option<String>,
}

/// The candidates (`found`, screened from index 1 on) as the JSON lists them.
pub fn screened_table(
    found: &[Candidate],
    screened: &[Result<Criteria, CriteriaError>],
    ranked: &[(usize, f64)],
    caps: &Caps,
    refused: &[Option<String>],
) -> Vec<Screened> {
    found
        .iter()
        .zip(&screened[1..])
        .enumerate()
        .map(|(i, (c, r))| {
            let ok = r.as_ref().ok();
            let score = ranked.iter().find(|x| x.0 == i + 1).map(|x| x.1);
            let refused = match (r, score) {
                (Err(e), _) => Some(e.to_string()),
                (Ok(c), None) => caps
                    .refuses(&c.servo)
                    .map(str::to_string)
                    .or_else(|| refused[i + 1].clone()),
                _ => None,
            };
            Screened {
                kvp: c.pi.0,
                kvi: c.pi.1,
                kpp: c.kpp,
                crossover_hz: c.crossover_hz,
                phase_margin_deg: c.cascade.margins.phase_margin_deg,
                worst_phase_margin_deg: c
                    .over_range
                    .iter()
                    .filter_map(|m| m.margins.phase_margin_deg)
                    .reduce(f64::min),
                a: ok.map(|c| c.positioning.a),
                r: ok.map(|c| c.positioning.r),
                table_settling_s: ok.and_then(|c| c.servo.table_settling_s),
                following_error: ok.map(|c| c.servo.following_error),
                table_motion_at_rest: ok.map(|c| c.servo.table_motion_at_rest),
                score,
                refused,
            }
        })
        .collect()
}

/// The outcome of checking the best screened settings as ensembles.
pub struct Chosen {
    /// Today's setting's ensemble.
    pub today: Checked,
    /// The chosen one: index into the sets, its ensemble and its judgement against
    /// today's.
    pub best: Option<(usize, Checked, Judgement)>,
    /// The best judgement of those checked when none is chosen.
    pub best_failed: Option<Judgement>,
    /// Settings checked besides today's.
    pub checked: usize,
}

/// Checks today's and the best [`CHECKED`] screened settings (`picked`, indices into
/// `sets`, today's at 0) on the standard cycle as ensembles, and takes the one whose
/// score beats today's beyond its spread, preferring those that make no criterion the
/// objective lists worse; where `replace` (today's outside the targets), the best
/// score of them all.
pub fn choose(
    objective: Objective,
    sets: &[Params],
    picked: &[usize],
    ensemble: &Ensemble,
    replace: bool,
) -> Result<Chosen, CriteriaError> {
    let mut run: Vec<Params> = vec![sets[0].clone()];
    run.extend(picked.iter().map(|&i| sets[i].clone()));
    let mut checked = criteria::check(&run, ensemble).into_iter();
    let today = checked.next().expect("today's is checked")?;
    let judged: Vec<(usize, Checked, Judgement)> = picked
        .iter()
        .zip(checked)
        .filter_map(|(&i, c)| {
            let c = c.ok()?;
            let j = judge::judge(objective, &today, &c);
            Some((i, c, j))
        })
        .collect();
    let lowest = |keep: &dyn Fn(&Judgement) -> bool| {
        judged
            .iter()
            .filter(|c| keep(&c.2))
            .min_by(|a, b| a.2.score.after.mean.total_cmp(&b.2.score.after.mean))
            .cloned()
    };
    let better = |j: &Judgement| j.score.verdict == Verdict::Better;
    let best = lowest(&|j| better(j) && j.keeps(objective))
        .or_else(|| lowest(&better))
        .or_else(|| if replace { lowest(&|_| true) } else { None });
    let best_failed = match best {
        Some(_) => None,
        None => lowest(&|_| true).map(|c| c.2),
    };
    Ok(Chosen {
        today,
        best,
        best_failed,
        checked: picked.len(),
    })
}
