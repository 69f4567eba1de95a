//! Searches that evaluate one point after another (Nelder–Mead), run side by side on
//! threads of their own, their evaluations gathered into the kernel's lanes: each
//! search asks for the residuals at its next point and waits; once every running
//! search waits (or a lane batch is full), one of the waiting threads evaluates the
//! points together ([`Objective::residuals_batch`]) and hands each its result. An
//! objective that runs in lanes gives each point what it gives alone, bit for bit,
//! so every search follows the path it follows alone: the batching changes the time,
//! not the numbers. Batches run concurrently, one per waiting thread that finds a
//! full one.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Duration;

use crate::model::Params;
use crate::objectives::{Objective, ObjectiveError};
use crate::sim::LANES;

/// How long a waiting thread sleeps before it evaluates what waits anyway: the
/// guard against callers the count of running searches does not know of (an
/// evaluation from a thread pool's task), never reached in the bootstrap's use.
const PATIENCE: Duration = Duration::from_millis(20);

/// The most searches [`side_by_side`] runs at once per worker thread: four lane
/// batches' worth.
const SEATS_PER_WORKER: usize = 4 * LANES;

/// `objective` shared by `searches` threads, its evaluations gathered into batches
/// of up to `width` points. Each thread holds a [`Seat`] while it runs searches.
pub struct Lockstep<'a> {
    objective: &'a dyn Objective,
    width: usize,
    shared: Mutex<Shared>,
    changed: Condvar,
}

type Residuals = Result<Vec<f64>, ObjectiveError>;

#[derive(Default)]
struct Shared {
    /// Threads that may still ask for evaluations.
    searches: usize,
    /// Points waiting for a batch, with their tickets.
    waiting: Vec<(u64, Params)>,
    /// Points in batches being evaluated.
    evaluating: usize,
    /// Results not yet collected, by ticket.
    done: HashMap<u64, Residuals>,
    next_ticket: u64,
    /// A batch's evaluation panicked: nothing more will be evaluated.
    broken: bool,
}

impl<'a> Lockstep<'a> {
    pub fn new(objective: &'a dyn Objective, searches: usize, width: usize) -> Self {
        Lockstep {
            objective,
            width: width.max(1),
            shared: Mutex::new(Shared {
                searches,
                ..Shared::default()
            }),
            changed: Condvar::new(),
        }
    }

    /// The calling thread's place among the searches: dropped (also when the
    /// thread unwinds), it runs no more, and the others stop waiting for it.
    pub fn seat(&self) -> Seat<'_, 'a> {
        Seat(self)
    }

    /// The residuals at each of `points`, evaluated in batches with the other
    /// searches' points.
    fn evaluate(&self, points: &[Params]) -> Vec<Residuals> {
        let mut shared = self.lock();
        let tickets: Vec<u64> = points
            .iter()
            .map(|p| {
                let ticket = shared.next_ticket;
                shared.next_ticket += 1;
                shared.waiting.push((ticket, p.clone()));
                ticket
            })
            .collect();
        self.changed.notify_all();
        let mut patient = true;
        loop {
            if tickets.iter().all(|t| shared.done.contains_key(t)) {
                let mut results = Vec::with_capacity(tickets.len());
                for t in &tickets {
                    results.push(shared.done.remove(t).expect("present"));
                }
                return results;
            }
            if shared.broken {
                return tickets.iter().map(|_| Err(broken())).collect();
            }
            if let Some(batch) = self.take_batch(&mut shared, patient) {
                shared = self.run_batch(shared, batch);
                patient = true;
                continue;
            }
            let (guard, wait) = self
                .changed
                .wait_timeout(shared, PATIENCE)
                .unwrap_or_else(|e| e.into_inner());
            shared = guard;
            patient = !wait.timed_out();
        }
    }

    /// The next batch to evaluate, if one is due: a full one, or whatever waits
    /// when every search waits (or when `patient` is false: the wait timed out).
    fn take_batch(&self, shared: &mut Shared, patient: bool) -> Option<Vec<(u64, Params)>> {
        let waiting = shared.waiting.len();
        let all_wait = waiting + shared.evaluating >= shared.searches;
        if waiting == 0 || (waiting < self.width && !all_wait && patient) {
            return None;
        }
        let n = waiting.min(self.width);
        shared.evaluating += n;
        Some(shared.waiting.drain(..n).collect())
    }

    /// Evaluates `batch` with the lock released, then files the results.
    fn run_batch<'g>(
        &'g self,
        shared: MutexGuard<'g, Shared>,
        batch: Vec<(u64, Params)>,
    ) -> MutexGuard<'g, Shared> {
        drop(shared);
        let (tickets, points): (Vec<u64>, Vec<Params>) = batch.into_iter().unzip();
        let guard = Breaks(self);
        let results = self.objective.residuals_batch(&points);
        std::mem::forget(guard);
        let mut shared = self.lock();
        shared.evaluating -= tickets.len();
        shared.done.extend(tickets.into_iter().zip(results));
        self.changed.notify_all();
        shared
    }

    fn lock(&self) -> MutexGuard<'_, Shared> {
        self.shared.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A thread's place among the searches of a [`Lockstep`].
pub struct Seat<'l, 'a>(&'l Lockstep<'a>);

impl Drop for Seat<'_, '_> {
    fn drop(&mut self) {
        self.0.lock().searches -= 1;
        self.0.changed.notify_all();
    }
}

/// Marks the lockstep broken and wakes every waiting thread if dropped: while a
/// batch unwinds from a panic (so that the others do not wait for it forever).
struct Breaks<'l, 'a>(&'l Lockstep<'a>);

impl Drop for Breaks<'_, '_> {
    fn drop(&mut self) {
        self.0.lock().broken = true;
        self.0.changed.notify_all();
    }
}

fn broken() -> ObjectiveError {
    ObjectiveError::Data {
        what: "lockstep evaluation".into(),
        reason: "another search's evaluation failed with a panic".into(),
    }
}

impl Objective for Lockstep<'_> {
    fn name(&self) -> &'static str {
        self.objective.name()
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        self.evaluate(std::slice::from_ref(p))
            .pop()
            .expect("one point, one result")
    }

    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        self.evaluate(points)
    }

    fn len(&self) -> usize {
        self.objective.len()
    }

    fn scale(&self) -> String {
        self.objective.scale()
    }
}

/// `task(i, objective)` for i in 0..`count`, on threads of their own (all of them
/// at once, up to [`SEATS_PER_WORKER`] per worker thread of rayon's pool), the
/// objective's evaluations gathered into lane batches ([`Lockstep`]): each task's
/// result is the one it gets alone. A batch holds up to as many points as spread
/// the running searches over the workers, at most [`LANES`] (two each for four
/// searches on two cores: two batches at once, not one of four; twelve searches,
/// three full batches). Every task starts at once so that the last ones do not run
/// alone, a batch of their own each on one core, after the others have finished.
pub(crate) fn side_by_side<T: Send>(
    objective: &dyn Objective,
    count: usize,
    task: &(dyn Fn(usize, &dyn Objective) -> T + Sync),
) -> Vec<T> {
    let workers = rayon::current_num_threads();
    let threads = (workers * SEATS_PER_WORKER).min(count).max(1);
    let width = threads.div_ceil(workers).min(LANES);
    let lockstep = Lockstep::new(objective, threads, width);
    let next = AtomicUsize::new(0);
    let mut outcomes: Vec<(usize, T)> = std::thread::scope(|s| {
        let spawned: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let _seat = lockstep.seat();
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= count {
                            break;
                        }
                        mine.push((i, task(i, &lockstep)));
                    }
                    mine
                })
            })
            .collect();
        spawned
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    outcomes.sort_by_key(|o| o.0);
    outcomes.into_iter().map(|o| o.1).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    /// r = (Kw, Kg), counting the batches and their sizes.
    struct Counted {
        batches: AtomicUsize,
        largest: AtomicUsize,
    }

    impl Objective for Counted {
        fn name(&self) -> &'static str {
            "counted"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            Ok(vec![p.kw, p.kg.unwrap_or(0.0)])
        }
        fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
            self.batches.fetch_add(1, Ordering::Relaxed);
            self.largest.fetch_max(points.len(), Ordering::Relaxed);
            points.iter().map(|p| self.residuals(p)).collect()
        }
        fn len(&self) -> usize {
            2
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    #[test]
    fn searches_side_by_side_get_their_own_results_in_shared_batches() {
        let o = Counted {
            batches: AtomicUsize::new(0),
            largest: AtomicUsize::new(0),
        };
        let base = presets::load("worm-gear").unwrap();
        let lockstep = Lockstep::new(&o, 4, 4);
        // Four threads, each 50 sequential evaluations of its own points; one
        // leaves after 10.
        std::thread::scope(|s| {
            for t in 0..4 {
                let (lockstep, base) = (&lockstep, &base);
                s.spawn(move || {
                    let _seat = lockstep.seat();
                    let n = if t == 3 { 10 } else { 50 };
                    for i in 0..n {
                        let mut p = base.clone();
                        p.kw = (1000 * t + i) as f64;
                        let r = lockstep.residuals(&p).unwrap();
                        assert_eq!(r[0], p.kw, "thread {t}, evaluation {i}");
                    }
                });
            }
        });
        let batches = o.batches.load(Ordering::Relaxed);
        assert_eq!(o.largest.load(Ordering::Relaxed), 4, "full batches");
        // 160 evaluations: 10 batches of four, then 40 of three; a thread kept from
        // running longer than the patience makes a smaller one, so the bound is
        // loose: gathered at all, two points a batch on average.
        assert!((50..=80).contains(&batches), "{batches} batches");
    }
}
