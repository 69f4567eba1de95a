//! Tuning of the drive's cascade from its model (docs/tuning.md): the velocity loop's
//! open-loop frequency response on the sampled loop ([`open_loop`]), its stability
//! margins ([`margins`]), notch filters at the resonances ([`notches`]), and the
//! velocity PI and position gain for a target phase margin with a gain-margin floor
//! ([`search`]). [`tune`] puts them together with the margins before and after;
//! [`bode`] gives a setting's open loop as a Bode plot draws it; [`speed_loop`] the
//! closed speed loop's response as a drive measures it, against a measurement.
//!
//! Layer: above `model` and `controller` (it reads the linear response, the modes and
//! the controller's discretised filters), below `experiments` and the command line.

pub mod bode;
pub mod candidates;
pub mod criteria;
pub mod margins;
pub mod notches;
pub mod objective;
pub mod open_loop;
pub mod position;
pub mod sampled;
pub mod search;
pub mod speed_loop;
pub mod stability;
pub mod verify;

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::model::params::{ControllerParams, LoopMode};
use crate::model::{ParamError, Params, SetpointFilter};
use crate::sim::LANES;
pub use candidates::{Candidate, Limits};
pub use criteria::{Criteria, CriteriaError};
pub use margins::Margins;
pub use objective::{Criterion, Objective, Worse};
pub use open_loop::{VelocityLoop, VelocityPi};
pub use stability::{LoopMargins, Stability};

/// What the tuned cascade must keep.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Targets {
    /// Phase margin, deg (default 50).
    pub phase_margin_deg: f64,
    /// Gain margin floor, both ways, dB (default 6).
    pub gain_margin_db: f64,
}

impl Default for Targets {
    fn default() -> Self {
        Targets {
            phase_margin_deg: 50.0,
            gain_margin_db: 6.0,
        }
    }
}

/// How to tune.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Options {
    pub targets: Targets,
    pub objective: Objective,
    pub limits: Limits,
    /// The fraction of the torque limit the move must leave free (0 to 1).
    pub torque_reserve: f64,
}

/// Why a drive could not be tuned.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TuneError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("{}", unreachable_message(*phase_margin_deg, *gain_margin_db, *best_phase_margin_deg, *best_crossover_hz, *best_gain_margin_db))]
    Unreachable {
        phase_margin_deg: f64,
        gain_margin_db: f64,
        best_phase_margin_deg: Option<f64>,
        best_crossover_hz: Option<f64>,
        best_gain_margin_db: Option<f64>,
    },
    #[error("no cascade of the {tried} tried keeps a phase margin of {phase_margin_deg}° and gain margins of {gain_margin_db} dB both ways without a conditional window; {}", best.map_or("none of them is stable".to_string(), |b| format!("the closest: {b}")))]
    CascadeUnreachable {
        phase_margin_deg: f64,
        gain_margin_db: f64,
        tried: usize,
        best: Option<candidates::BestTried>,
    },
    #[error("targets must be finite with a phase margin in (0°, 180°) and a gain margin ≥ 0 dB: got {phase_margin_deg}° and {gain_margin_db} dB")]
    Targets {
        phase_margin_deg: f64,
        gain_margin_db: f64,
    },
    #[error("{option} must be {expected}: got {value}")]
    Option {
        option: &'static str,
        expected: &'static str,
        value: f64,
    },
    #[error("the check of today's settings on the nonlinear model failed: {0}")]
    Today(#[source] CriteriaError),
}

fn unreachable_message(
    pm: f64,
    gm: f64,
    best: Option<f64>,
    at: Option<f64>,
    best_gm: Option<f64>,
) -> String {
    let best = match (best, at) {
        (Some(b), Some(f)) => format!(
            "the best is {b:.1}° at a crossover of {f:.2} Hz (gain margin {})",
            best_gm.map_or("unbounded".into(), |g| format!("{g:.1} dB"))
        ),
        _ => "no gain tried crosses over".into(),
    };
    format!(
        "target phase margin {pm}° with a gain margin ≥ {gm} dB not reachable with the \
         PI corner at a quarter of the crossover: {best}"
    )
}

/// One setting of the cascade and its loops' margins.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Setting {
    #[serde(rename = "Kvp")]
    pub kvp: f64,
    #[serde(rename = "Kvi")]
    pub kvi: f64,
    #[serde(rename = "Kpp")]
    pub kpp: f64,
    pub filters: Vec<SetpointFilter>,
    /// The velocity loop alone, the position loop open (quasi-continuous,
    /// [`open_loop`]).
    pub velocity_loop: Margins,
    /// The cascade as it runs: the position loop closed in the configured loop
    /// type, exact on the sampled loop, with its stability ([`stability`]).
    pub cascade: LoopMargins,
    /// The closed position loop's largest gain, dB ([`position::peak_db`]).
    pub position_peak_db: f64,
}

impl Setting {
    /// The margins of `c` on `p`'s drive.
    pub fn of(p: &Params, c: &ControllerParams) -> Result<Setting, ParamError> {
        let lp = VelocityLoop::new(p, &c.filters)?;
        let pi = VelocityPi {
            kvp: c.kvp,
            kvi: c.kvi,
        };
        let plant = sampled::DiscretePlant::new(p)?;
        let cascade = sampled::SampledLoop::new(&plant, c, sampled::Closure::Cascade);
        Ok(Setting {
            kvp: c.kvp,
            kvi: c.kvi,
            kpp: c.kpp,
            filters: c.filters.clone(),
            velocity_loop: search::Grid::new(&lp).margins(pi),
            cascade: stability::analyse(&cascade),
            position_peak_db: position::peak_db(&lp, pi, c.kpp),
        })
    }
}

/// What the search did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SearchSummary {
    /// Settings tried on the linear cascade, and those that kept the targets.
    pub tried: usize,
    pub within_margins: usize,
    /// Settings weighed on the nonlinear model (today's among them) and those
    /// refused there (a limit cycle, the torque reserve).
    pub screened: usize,
    pub refused: usize,
    /// Settings checked on the standard cycle.
    pub checked: usize,
    /// The chosen setting's score on the screening and on the check (today's: 1).
    pub screen_score: f64,
    pub check_score: f64,
    /// Wall time of the search, s.
    pub wall_s: f64,
}

/// Why a setting is flagged.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TuneWarning {
    /// The proposed setting makes a criterion worse than today's.
    Worse(Worse),
    /// No setting beats today's on the objective: nothing new is proposed.
    NothingBetter { best_check_score: Option<f64> },
    /// Today's cascade does not keep the targets.
    TodayOutsideTargets,
}

/// The drive's settings before and after tuning, and the tuned parameter set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tuned {
    pub targets: Targets,
    pub objective: Objective,
    #[serde(rename = "loop")]
    pub loop_mode: LoopMode,
    /// The resonances the notches sit at.
    pub resonances: Vec<notches::Resonance>,
    pub before: Setting,
    pub after: Setting,
    /// Whether `after` is a new setting (false: today's is kept).
    pub proposes: bool,
    pub search: SearchSummary,
    /// Both settings on the standard cycle, compensated in the controller.
    pub check: Check,
    pub warnings: Vec<TuneWarning>,
    /// Every candidate within the targets as the screening weighed it.
    pub candidates: Vec<Screened>,
    #[serde(skip)]
    pub params: Params,
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

/// Today's and the proposed setting on the nonlinear model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    pub before: Criteria,
    pub after: Criteria,
}

/// How many of the best screened settings are checked on the standard cycle.
const CHECKED: usize = 3;

/// Tunes `p`'s cascade (`p` validated) in its configured loop: candidates that keep
/// the targets on the cascade, weighed on the nonlinear model against today's
/// setting by `options.objective`; `progress(done, total)` after each batch.
pub fn tune(
    p: &Params,
    options: &Options,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Tuned, TuneError> {
    let started = Instant::now();
    check_options(options)?;
    let targets = options.targets;
    let nyquist = 0.5 / p.controller.tc;
    let resonances = notches::resonances(p, notches::MAX_RELATIVE_CENTRE * nyquist)?;
    let filters = notches::notches_with(p, &options.limits)?;
    let (found, tried) = candidates::generate(p, &filters, targets, &options.limits)?;
    let mut sets = vec![p.clone()];
    sets.extend(
        found
            .iter()
            .map(|c| with_controller(p, c.controller(&p.controller, &filters))),
    );
    let mut screened = screen(&sets, progress);
    let today = std::mem::replace(&mut screened[0], Err(CriteriaError::Unscreened))
        .map_err(TuneError::Today)?;
    let ranked = rank(p, options, &screened, &today);
    let table = screened_table(&found, &screened, &ranked);
    let refused = sets.len() - 1 - ranked.len();
    let before_check = criteria::check(p).map_err(TuneError::Today)?;
    let chosen = choose(options.objective, &sets, &ranked, &before_check);
    let before = Setting::of(p, &p.controller)?;
    let mut warnings = Vec::new();
    if !before
        .cascade
        .meets(targets.phase_margin_deg, targets.gain_margin_db)
    {
        warnings.push(TuneWarning::TodayOutsideTargets);
    }
    let (params, after_check, screen_score, check_score, proposes) = match chosen.best {
        Some((i, check, score)) => (
            sets[i].clone(),
            check,
            ranked_score(&ranked, i),
            score,
            true,
        ),
        None => {
            warnings.push(TuneWarning::NothingBetter {
                best_check_score: chosen.best_failed,
            });
            (p.clone(), before_check.clone(), 1.0, 1.0, false)
        }
    };
    warnings.extend(
        objective::worse(&after_check, &before_check)
            .into_iter()
            .map(TuneWarning::Worse),
    );
    let after = Setting::of(&params, &params.controller)?;
    Ok(Tuned {
        targets,
        objective: options.objective,
        loop_mode: p.controller.loop_mode,
        resonances,
        before,
        after,
        proposes,
        search: SearchSummary {
            tried,
            within_margins: found.len(),
            screened: sets.len(),
            refused,
            checked: chosen.checked,
            screen_score,
            check_score,
            wall_s: started.elapsed().as_secs_f64(),
        },
        check: Check {
            before: before_check,
            after: after_check,
        },
        warnings,
        candidates: table,
        params,
    })
}

/// The candidates (`found`, screened from index 1 on) as the JSON lists them.
fn screened_table(
    found: &[Candidate],
    screened: &[Result<Criteria, CriteriaError>],
    ranked: &[(usize, f64)],
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
                (Ok(_), None) => Some("a limit cycle or the torque reserve".to_string()),
                _ => None,
            };
            Screened {
                kvp: c.pi.0,
                kvi: c.pi.1,
                kpp: c.kpp,
                crossover_hz: c.crossover_hz,
                phase_margin_deg: c.cascade.margins.phase_margin_deg,
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

/// The linear rule of rtid's first tuning, one of the search's candidates: notches
/// at the resonances, the velocity PI at the highest crossover whose velocity loop
/// alone keeps `targets`, Kpp = ω_c/4 (docs/tuning.md, "The rule alone").
pub fn rule(p: &Params, targets: Targets) -> Result<ControllerParams, TuneError> {
    let filters = notches::notches(p)?;
    let lp = VelocityLoop::new(p, &filters)?;
    let v = search::velocity(&search::Grid::new(&lp), targets)?;
    Ok(ControllerParams {
        kvp: v.pi.kvp,
        kvi: v.pi.kvi,
        kpp: search::position_gain(v.margins.crossover_hz.unwrap_or(0.0)),
        filters,
        ..p.controller.clone()
    })
}

/// Refuses targets and limits out of range.
fn check_options(o: &Options) -> Result<(), TuneError> {
    let (pm, gm) = (o.targets.phase_margin_deg, o.targets.gain_margin_db);
    if !(pm.is_finite() && pm > 0.0 && pm < 180.0 && gm.is_finite() && gm >= 0.0) {
        return Err(TuneError::Targets {
            phase_margin_deg: pm,
            gain_margin_db: gm,
        });
    }
    let l = &o.limits;
    let positive = |option, v: Option<f64>| match v {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(TuneError::Option {
            option,
            expected: "finite and positive",
            value: v,
        }),
        _ => Ok(()),
    };
    positive("--max-kpp", l.max_kpp)?;
    positive("--max-bandwidth-hz", l.max_bandwidth_hz)?;
    let within = |option, v: f64, lo: f64, hi: f64, expected| {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(())
        } else {
            Err(TuneError::Option {
                option,
                expected,
                value: v,
            })
        }
    };
    within(
        "--notch-depth-db",
        l.notch_depth_db,
        -60.0,
        -1.0,
        "between -60 and -1 dB",
    )?;
    within(
        "--notch-min-width",
        l.notch_min_width,
        0.01,
        1.0,
        "between 0.01 and 1 (of the centre)",
    )?;
    within(
        "--torque-reserve",
        o.torque_reserve,
        0.0,
        0.9,
        "between 0 and 0.9",
    )
}

/// `p` with the controller `c`.
fn with_controller(p: &Params, c: ControllerParams) -> Params {
    Params {
        controller: c,
        ..p.clone()
    }
}

/// Every set's figures on the short cycle, in lane batches run in parallel.
fn screen(
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

/// The candidates (indices into the sets, today's excluded) the nonlinear model
/// admits — no limit cycle, the torque reserve kept —, with their scores: first those
/// that keep every criterion the objective lists ([`Objective::keeps`]), best score
/// first, then the others.
fn rank(
    p: &Params,
    o: &Options,
    screened: &[Result<Criteria, CriteriaError>],
    today: &Criteria,
) -> Vec<(usize, f64)> {
    let effort_cap = (1.0 - o.torque_reserve) * p.controller.torque_limit * p.controller.drive_gain;
    let rest_cap = limit_cycle_threshold(p).max(2.0 * today.servo.table_motion_at_rest);
    let mut out: Vec<(usize, f64, bool)> = screened
        .iter()
        .enumerate()
        .skip(1)
        .filter_map(|(i, c)| {
            let c = c.as_ref().ok()?;
            let admitted = c.servo.table_motion_at_rest <= rest_cap
                && c.servo.move_peak_effort <= effort_cap.max(today.servo.move_peak_effort);
            let keeps = o.objective.keeps(c, today);
            admitted.then(|| (i, o.objective.score(c, today), keeps))
        })
        .collect();
    out.sort_by(|a, b| b.2.cmp(&a.2).then(a.1.total_cmp(&b.1)));
    out.into_iter().map(|(i, score, _)| (i, score)).collect()
}

/// The table's motion at rest that counts as a limit cycle: three table-encoder
/// counts, and at least 1 report unit (1″, 1 µm).
pub fn limit_cycle_threshold(p: &Params) -> f64 {
    let k = crate::experiments::positioning::iso230::ReportUnits::of(p.axis).deviation_per_si;
    (3.0 * p.controller.table_encoder_resolution * k).max(1.0)
}

fn ranked_score(ranked: &[(usize, f64)], i: usize) -> f64 {
    ranked.iter().find(|r| r.0 == i).map_or(1.0, |r| r.1)
}

/// The outcome of checking the best screened settings.
struct Chosen {
    /// The one that beats today's most on the check: index, figures, score.
    best: Option<(usize, Criteria, f64)>,
    /// The lowest check score when none beats today's.
    best_failed: Option<f64>,
    checked: usize,
}

/// Checks the best [`CHECKED`] screened settings that beat today's (score < 1) on
/// the standard cycle, and takes the one that beats today's most there among those
/// that keep every criterion the objective lists, else among all.
fn choose(
    objective: Objective,
    sets: &[Params],
    ranked: &[(usize, f64)],
    today: &Criteria,
) -> Chosen {
    let picked: Vec<usize> = ranked
        .iter()
        .filter(|r| r.1 < 1.0)
        .take(CHECKED)
        .map(|r| r.0)
        .collect();
    let checked: Vec<(usize, Criteria, f64)> = picked
        .par_iter()
        .filter_map(|&i| {
            let c = criteria::check(&sets[i]).ok()?;
            let score = objective.score(&c, today);
            Some((i, c, score))
        })
        .collect();
    let better = |c: &&(usize, Criteria, f64)| c.2 < 1.0;
    let lowest = |keeping: bool| {
        checked
            .iter()
            .filter(better)
            .filter(|c| !keeping || objective.keeps(&c.1, today))
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .cloned()
    };
    let best = lowest(true).or_else(|| lowest(false));
    let best_failed = match best {
        Some(_) => None,
        None => checked.iter().map(|c| c.2).min_by(f64::total_cmp),
    };
    Chosen {
        best,
        best_failed,
        checked: picked.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn quiet(_: usize, _: usize) {}

    #[test]
    fn an_unreachable_phase_margin_is_a_typed_error_with_the_best() {
        // The PI with its corner at a quarter of the crossover lags 14° there, the
        // plant at least its viscous lag: no crossover has 170° left.
        let p = presets::load("worm-gear").unwrap();
        let options = Options {
            targets: Targets {
                phase_margin_deg: 170.0,
                gain_margin_db: 6.0,
            },
            ..Options::default()
        };
        let err = tune(&p, &options, &quiet).unwrap_err();
        let TuneError::Unreachable {
            best_phase_margin_deg: Some(best),
            ..
        } = err
        else {
            panic!("{err}")
        };
        assert!(best < 166.0 && best > 50.0, "{best}");
        assert!(err.to_string().contains("170° "), "{err}");
    }

    #[test]
    fn targets_and_limits_out_of_range_are_refused() {
        let p = presets::load("worm-gear").unwrap();
        for (pm, gm) in [(0.0, 6.0), (190.0, 6.0), (50.0, -1.0), (f64::NAN, 6.0)] {
            let o = Options {
                targets: Targets {
                    phase_margin_deg: pm,
                    gain_margin_db: gm,
                },
                ..Options::default()
            };
            assert!(matches!(
                tune(&p, &o, &quiet),
                Err(TuneError::Targets { .. })
            ));
        }
        let mut o = Options::default();
        o.limits.max_kpp = Some(-1.0);
        let err = tune(&p, &o, &quiet).unwrap_err();
        assert!(err.to_string().contains("--max-kpp"), "{err}");
        let o = Options {
            torque_reserve: 1.5,
            ..Options::default()
        };
        let err = tune(&p, &o, &quiet).unwrap_err();
        assert!(err.to_string().contains("--torque-reserve"), "{err}");
    }
}
