//! Several starts of one local search, in parallel (rayon): the given start, then a
//! Latin hypercube in the bounds. Each start's record is handed to a callback as it
//! finishes (to checkpoint); a start finished before a resume is not run again, one
//! interrupted continues from where it had got to.

mod levenberg_marquardt;
pub(crate) mod lockstep;
pub mod problem;
pub mod progress;
pub mod settings;
pub mod solvers;

use rayon::prelude::*;

use crate::identify::result::starts::StartRecord;
use crate::identify::space::ParamSpace;
use crate::objectives::Objective;
use lockstep::side_by_side;
use problem::{Monitor, Problem};
use settings::{Method, Settings};
use solvers::Limits;

/// Runs the starts of `settings` (skipping those `done` already holds as finished),
/// in parallel; `on_done` is called after each start (to checkpoint). Returns every
/// start, in index order. The best point of all evaluations is in `monitor`.
pub fn search(
    space: &ParamSpace,
    objective: &dyn Objective,
    settings: &Settings,
    monitor: &Monitor,
    done: &[StartRecord],
    on_done: &(dyn Fn(&StartRecord) + Sync),
) -> Vec<StartRecord> {
    for d in done.iter().filter(|d| d.finished()) {
        if let (Some(v), Some(c)) = (&d.result, d.cost) {
            monitor.offer(c, v);
        }
    }
    let to_run = (0..settings.starts)
        .filter(|i| !done.iter().any(|d| d.index == *i && d.finished()))
        .count();
    monitor.progress().plan(to_run as u64 * settings.max_iters);
    let start = |objective: &dyn Objective, (index, initial): (usize, Vec<f64>)| {
        if let Some(d) = done.iter().find(|d| d.index == index && d.finished()) {
            return d.clone();
        }
        let record = one_start(space, objective, settings, monitor, index, initial);
        on_done(&record);
        record
    };
    let starts = space.starts(settings.starts, settings.seed);
    // One start runs on the calling thread (a bootstrap's searches side by side,
    // search/lockstep.rs, each on a thread of its own); Nelder–Mead's starts on an
    // objective in lanes side by side, their points in shared batches; other
    // searches' starts in parallel.
    let mut records: Vec<StartRecord> = if starts.len() == 1 {
        starts
            .into_iter()
            .enumerate()
            .map(|s| start(objective, s))
            .collect()
    } else if settings.method == Method::NelderMead && to_run > 1 && objective.in_lanes() {
        let task = |i: usize, o: &dyn Objective| start(o, (i, starts[i].clone()));
        side_by_side(objective, starts.len(), &task)
    } else {
        let each = |s| start(objective, s);
        starts.into_par_iter().enumerate().map(each).collect()
    };
    records.sort_by_key(|r| r.index);
    records
}

/// Start `index` from `initial` — also when an interrupted run of it had got
/// further: a solver continued from its last point takes another path than the one
/// run straight through (a resumed Levenberg–Marquardt ended at Ciw 0.41 against
/// 0.010), so a resumed identification runs an unfinished start again and is the
/// uninterrupted one, bit for bit. The starts that finished are kept.
fn one_start(
    space: &ParamSpace,
    objective: &dyn Objective,
    settings: &Settings,
    monitor: &Monitor,
    index: usize,
    initial: Vec<f64>,
) -> StartRecord {
    let from = initial.clone();
    let problem = Problem::new(space, objective, monitor, settings);
    let limits = Limits {
        max_iters: settings.max_iters,
        simplex_step: settings.simplex_step,
        seed: settings.seed.wrapping_add(index as u64),
    };
    let out = solvers::run(settings.method, problem, space.to_solver(&from), limits);
    // The budget this start did not use: done, as far as the progress is concerned.
    monitor
        .progress()
        .advance(settings.max_iters.saturating_sub(out.iterations));
    let result =
        (!out.x.is_empty()).then(|| space.physical(&nalgebra::DVector::from_vec(out.x.clone())));
    StartRecord {
        index,
        initial,
        result,
        cost: out.cost.is_finite().then_some(out.cost),
        iterations: out.iterations,
        termination: out.termination,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::Bound;
    use crate::model::{presets, Params};
    use crate::objectives::in_lanes::InLanes;
    use crate::objectives::ObjectiveError;

    /// Residuals of Kw and Kg from 3e5 and 900, relative.
    struct Bowl;

    impl Objective for Bowl {
        fn name(&self) -> &'static str {
            "bowl"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            Ok(vec![
                p.kw / 3e5 - 1.0,
                p.kg.unwrap_or(0.0) / 900.0 - 1.0,
                0.0,
            ])
        }
        fn len(&self) -> usize {
            3
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    fn space() -> ParamSpace {
        let base = presets::load("worm-gear").unwrap();
        let names = ["Kw".to_string(), "Kg".to_string()];
        let bounds = [
            ("Kw".to_string(), Bound { lo: 1e5, hi: 1e6 }),
            ("Kg".to_string(), Bound { lo: 1e2, hi: 1e4 }),
        ];
        ParamSpace::new(base, &names, &bounds).unwrap()
    }

    /// Nelder–Mead's starts side by side (their points in shared batches) and the
    /// swarm's particles in batches end where each start ends alone, bit for bit.
    #[test]
    fn starts_and_particles_in_lanes_end_where_they_end_alone() {
        let space = space();
        for method in [Method::NelderMead, Method::Pso] {
            let settings = Settings {
                method,
                starts: 4,
                max_iters: 40,
                ..Settings::default()
            };
            let alone = search(&space, &Bowl, &settings, &Monitor::default(), &[], &|_| {});
            let lanes = InLanes::new(Bowl);
            let together = search(&space, &lanes, &settings, &Monitor::default(), &[], &|_| {});
            assert_eq!(alone, together, "{method:?}");
            let largest = lanes.largest();
            assert!(largest > 1, "{method:?}: batches of {largest} at most");
        }
    }

    /// Every method's iterations, counted by the observer, plus the budget the
    /// converged starts give back, add up to the budget exactly: the bar ends full,
    /// never past it.
    #[test]
    fn the_iterations_done_end_equal_to_the_budget() {
        let space = space();
        for method in [Method::Lsq, Method::Lm, Method::NelderMead, Method::Pso] {
            let monitor = Monitor::default();
            let settings = Settings {
                method,
                starts: 3,
                max_iters: 30,
                ..Settings::default()
            };
            let records = search(&space, &Bowl, &settings, &monitor, &[], &|_| {});
            let (done, budget) = monitor.progress().iterations();
            assert_eq!(budget, 90, "{method:?}");
            assert_eq!(done, budget, "{method:?}: {records:?}");
            assert_eq!(monitor.progress().fraction(), Some(1.0));
        }
    }
}
