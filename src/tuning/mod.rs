//! Tuning of the drive's cascade from its model (docs/tuning.md): the velocity loop's
//! open-loop frequency response on the sampled loop ([`open_loop`]), its stability
//! margins ([`margins`]), notch filters at the resonances ([`notches`]), and the
//! velocity PI and position gain for a target phase margin with a gain-margin floor
//! ([`search`]); the cascade as it runs, exact on the sampled loop ([`sampled`],
//! [`stability`]), its closed loops ([`closed_loop`]), over a range of machines
//! ([`range`]); the candidates that keep the targets ([`candidates`]), weighed on the
//! nonlinear model against today's setting as ensembles ([`weigh`]). [`tune`] puts
//! them together; [`bode`] gives a setting's loops as a Bode plot draws them;
//! [`speed_loop`] the closed speed loop's response as a drive measures it, against a
//! measurement.
//!
//! Layer: above `model`, `controller` and `experiments::positioning` (it reads the
//! linear response, the modes and the controller's discretised filters, and runs the
//! ISO 230-2 cycle), below the command line.

pub mod bode;
pub mod candidates;
pub mod closed_loop;
pub mod margins;
pub mod notches;
pub mod open_loop;
pub mod options;
pub mod range;
pub mod sampled;
pub mod search;
pub mod speed_loop;
pub mod stability;
pub mod weigh;

use std::time::Instant;

use serde::Serialize;

use crate::experiments::positioning::ensemble::Ensemble;
use crate::model::params::{ControllerParams, LoopMode};
use crate::model::{ParamError, Params, SetpointFilter};
pub use candidates::{Candidate, Limits};
pub use margins::Margins;
pub use open_loop::{VelocityLoop, VelocityPi};
pub use options::{Options, Targets, TuneError};
pub use range::{Range, Vary};
pub use stability::{LoopMargins, Stability};
pub use weigh::criteria::{Checked, Criteria, CriteriaError};
pub use weigh::judge::{Compared, Judgement, Verdict};
pub use weigh::objective::{Criterion, Objective, Worse};
pub use weigh::{criteria, judge, limit_cycle_threshold, objective, verify, Screened};

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
    /// The closed position loop's largest gain, dB ([`closed_loop::peak_db`]).
    pub position_peak_db: f64,
    /// The closed loops, exact on the sampled loop: bandwidths, peaks, |S|max and the
    /// speed loop's equivalent time constant ([`closed_loop`]).
    pub closed_loop: closed_loop::ClosedLoop,
    /// The cascade's margins over the range of machines (`None`: the nominal alone).
    pub over_range: Option<range::OverRange>,
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
            position_peak_db: closed_loop::peak_db(&lp, pi, c.kpp),
            closed_loop: closed_loop::analyse(&plant, c),
            over_range: None,
        })
    }

    /// `base` with this setting's gains and filters.
    pub fn controller(&self, base: &ControllerParams) -> ControllerParams {
        ControllerParams {
            kvp: self.kvp,
            kvi: self.kvi,
            kpp: self.kpp,
            filters: self.filters.clone(),
            ..base.clone()
        }
    }

    /// [`Setting::of`] with its margins at every machine of `machines`.
    pub fn over(
        p: &Params,
        c: &ControllerParams,
        machines: &range::Machines,
    ) -> Result<Setting, ParamError> {
        let mut s = Setting::of(p, c)?;
        if machines.points.len() > 1 {
            let margins = machines.margins(c, margins::GRID_POINTS);
            s.over_range = Some(machines.worst(&margins));
        }
        Ok(s)
    }

    /// Whether the cascade keeps `targets` on the nominal machine and, where it has
    /// them, at every machine of the range.
    pub fn meets(&self, targets: Targets) -> bool {
        let (pm, gm) = (targets.phase_margin_deg, targets.gain_margin_db);
        let worst_ok = self.over_range.as_ref().map_or(true, |w| {
            w.unstable_at.is_empty()
                && w.conditional_at.is_empty()
                && w.phase_margin_deg.as_ref().is_some_and(|p| p.0 >= pm)
                && w.gain_margin_db.as_ref().map_or(true, |g| g.0 >= gm)
                && w.gain_reduction_margin_db
                    .as_ref()
                    .map_or(true, |g| g.0 >= gm)
        });
        self.cascade.meets(pm, gm) && worst_ok
    }
}

/// What the search did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SearchSummary {
    /// Settings tried on the linear cascade, and those that kept the targets (over
    /// the range).
    pub tried: usize,
    pub within_margins: usize,
    /// Machines of the range the margins were checked at (1: the nominal alone), and
    /// its corners the nonlinear screening ran at.
    pub machines: usize,
    pub corners: usize,
    /// Settings weighed on the nonlinear model (today's among them) and those
    /// refused there (a limit cycle, the torque reserve).
    pub screened: usize,
    pub refused: usize,
    /// Settings checked on the standard cycle besides today's, as ensembles of
    /// `members`.
    pub checked: usize,
    pub members: usize,
    /// The chosen setting's score on the screening and its mean over the check's
    /// ensemble (today's: 1), with the half-width of its 95 % interval.
    pub screen_score: f64,
    pub check_score: f64,
    pub check_score_half_width: f64,
    /// Wall time of the search, s.
    pub wall_s: f64,
}

/// Why a setting is flagged.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TuneWarning {
    /// The proposed setting makes a criterion worse than today's beyond its spread
    /// (the ensembles' means).
    Worse(Worse),
    /// No setting beats today's on the objective beyond the spread: nothing new is
    /// proposed (the best checked: its mean score and the half-width of its 95 %
    /// interval).
    NothingBetter {
        best_check_score: Option<f64>,
        half_width: Option<f64>,
    },
    /// Today's cascade does not keep the targets (on the nominal machine, or
    /// somewhere in the range): it is replaced by the best setting that does.
    TodayOutsideTargets { replaced: bool },
    /// A test's peak torque reaches the torque limit (the output saturates).
    TorqueLimit {
        setting: &'static str,
        test: &'static str,
        peak: f64,
        limit: f64,
    },
}

/// The drive's settings before and after tuning, and the tuned parameter set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tuned {
    pub targets: Targets,
    pub objective: Objective,
    #[serde(rename = "loop")]
    pub loop_mode: LoopMode,
    /// The machines the targets held on.
    pub range: Range,
    /// The resonances (of the nominal machine) the notches sit at.
    pub resonances: Vec<notches::Resonance>,
    pub before: Setting,
    pub after: Setting,
    /// Whether `after` is a new setting (false: today's is kept).
    pub proposes: bool,
    pub search: SearchSummary,
    /// Both settings on the standard cycle, compensated in the controller, as
    /// ensembles, and how they compare.
    pub check: Check,
    pub warnings: Vec<TuneWarning>,
    /// Every candidate within the targets as the screening weighed it.
    pub candidates: Vec<Screened>,
    #[serde(skip)]
    pub params: Params,
}

/// Today's and the proposed setting on the nonlinear model, as ensembles.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    /// The ensemble's size and how its members differ.
    pub ensemble: Ensemble,
    pub before: Checked,
    pub after: Checked,
    /// `after` against `before`, member by member.
    pub judgement: Judgement,
}

/// Tunes `p`'s cascade (`p` validated) in its configured loop: candidates that keep
/// the targets on the cascade at every machine of `options.range`, weighed on the
/// nonlinear model against today's setting by `options.objective` (screened, then the
/// best checked as ensembles); `progress(done, total)` after each batch.
pub fn tune(
    p: &Params,
    options: &Options,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Tuned, TuneError> {
    let started = Instant::now();
    options::check(options, p)?;
    let targets = options.targets;
    let machines = range::Machines::new(p, &options.range)?;
    let nyquist = 0.5 / p.controller.tc;
    let resonances = notches::resonances(p, notches::MAX_RELATIVE_CENTRE * nyquist)?;
    let filters = notches::notches_over(p, &options.limits, &machines.params)?;
    let (found, tried) = candidates::generate(p, &filters, targets, &options.limits, &machines)?;
    let mut sets = vec![p.clone()];
    sets.extend(found.iter().map(|c| {
        let tuned = c.controller(&p.controller, &filters);
        with_controller(p, balanced(&machines.plants[0], tuned))
    }));
    let mut screened = weigh::screen(&sets, progress);
    let today_screen = std::mem::replace(&mut screened[0], Err(CriteriaError::Unscreened))
        .map_err(TuneError::Today)?;
    let caps = weigh::Caps::of(p, &today_screen.servo, options.torque_reserve);
    let at_corners = weigh::refusals_at_corners(&sets, &options.range, options.torque_reserve);
    let ranked = weigh::rank(
        options.objective,
        &caps,
        &screened,
        &today_screen,
        &at_corners,
    );
    let table = weigh::screened_table(&found, &screened, &ranked, &caps, &at_corners);
    let before = Setting::over(p, &p.controller, &machines)?;
    let replace = !before.meets(targets);
    let picked: Vec<usize> = ranked
        .iter()
        .filter(|r| r.1 < 1.0 || replace)
        .take(weigh::CHECKED)
        .map(|r| r.0)
        .collect();
    let mut chosen = weigh::choose(
        options.objective,
        &sets,
        &picked,
        &options.ensemble,
        replace,
    )
    .map_err(TuneError::Today)?;
    let best = chosen.best.take();
    let Outcome {
        params,
        after_check,
        judgement,
        screen_score,
        proposes,
        warnings,
    } = outcome(
        p,
        options.objective,
        (&sets, &ranked),
        best,
        &chosen,
        replace,
    );
    let after = Setting::over(&params, &params.controller, &machines)?;
    Ok(Tuned {
        targets,
        objective: options.objective,
        loop_mode: p.controller.loop_mode,
        range: options.range.clone(),
        resonances,
        before,
        after,
        proposes,
        search: SearchSummary {
            tried,
            within_margins: found.len(),
            machines: machines.points.len(),
            corners: options.range.corners().len(),
            screened: sets.len(),
            refused: sets.len() - 1 - ranked.len(),
            checked: chosen.checked,
            members: options.ensemble.members,
            screen_score,
            check_score: judgement.score.after.mean,
            check_score_half_width: judgement.score.half_width,
            wall_s: started.elapsed().as_secs_f64(),
        },
        check: Check {
            ensemble: options.ensemble,
            before: chosen.today,
            after: after_check,
            judgement,
        },
        warnings,
        candidates: table,
        params,
    })
}

/// What `tune` proposes, and the warnings that go with it.
struct Outcome {
    params: Params,
    after_check: Checked,
    judgement: Judgement,
    screen_score: f64,
    proposes: bool,
    warnings: Vec<TuneWarning>,
}

/// The outcome of the check: the best setting that beat today's (`best`), or
/// today's kept; warnings for today's outside the targets (`replace`), for nothing
/// better, for every criterion made worse and for the torque limit.
fn outcome(
    p: &Params,
    objective: Objective,
    (sets, ranked): (&[Params], &[(usize, f64)]),
    best: Option<(usize, Checked, Judgement)>,
    chosen: &weigh::Chosen,
    replace: bool,
) -> Outcome {
    let mut warnings = Vec::new();
    if replace {
        warnings.push(TuneWarning::TodayOutsideTargets {
            replaced: best.is_some(),
        });
    }
    let (params, after_check, judgement, screen_score, proposes) = match best {
        Some((i, checked, judgement)) => (
            sets[i].clone(),
            checked,
            judgement,
            ranked_score(ranked, i),
            true,
        ),
        None => {
            warnings.push(TuneWarning::NothingBetter {
                best_check_score: chosen.best_failed.as_ref().map(|j| j.score.after.mean),
                half_width: chosen.best_failed.as_ref().map(|j| j.score.half_width),
            });
            let same = judge::judge(objective, &chosen.today, &chosen.today);
            (p.clone(), chosen.today.clone(), same, 1.0, false)
        }
    };
    warnings.extend(judgement.worse().map(|c| {
        TuneWarning::Worse(Worse {
            criterion: c.criterion,
            before: c.compared.before.mean,
            after: c.compared.after.mean,
        })
    }));
    warnings.extend(torque_limits(p, &chosen.today, &after_check, proposes));
    Outcome {
        params,
        after_check,
        judgement,
        screen_score,
        proposes,
        warnings,
    }
}

/// The warnings of tests whose peak torque reaches the limit, today's and (when a
/// setting is proposed) the proposed one's, on their unperturbed members.
fn torque_limits(p: &Params, today: &Checked, after: &Checked, proposes: bool) -> Vec<TuneWarning> {
    let limit = p.controller.torque_limit * p.controller.drive_gain;
    let mut out = Vec::new();
    let mut settings = vec![("before", today)];
    if proposes {
        settings.push(("after", after));
    }
    for (setting, c) in settings {
        let Some(first) = c.members.first() else {
            continue;
        };
        let s = &first.servo;
        let step = s.peak_effort.max(s.move_peak_effort);
        for (test, peak) in [("move", s.move_peak_effort), ("step", step)] {
            if peak >= (1.0 - 1e-9) * limit {
                out.push(TuneWarning::TorqueLimit {
                    setting,
                    test,
                    peak,
                    limit,
                });
                break;
            }
        }
    }
    out
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

/// `c` with its symmetrising lag the equivalent time constant of its closed speed
/// loop on `plant`, where the speed feed-forward is on (the CNC balances the
/// feed-forward with it: MD32810); `c` as it is without feed-forward.
fn balanced(plant: &sampled::DiscretePlant, mut c: ControllerParams) -> ControllerParams {
    if c.kvff > 0.0 {
        if let Some(t) = closed_loop::equivalent_time(plant, &c, 1000) {
            c.symmetrising_s = t;
        }
    }
    c
}

/// `p` with the controller `c`.
fn with_controller(p: &Params, c: ControllerParams) -> Params {
    Params {
        controller: c,
        ..p.clone()
    }
}

fn ranked_score(ranked: &[(usize, f64)], i: usize) -> f64 {
    ranked.iter().find(|r| r.0 == i).map_or(1.0, |r| r.1)
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
