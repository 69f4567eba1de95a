//! How far an identification's searches have got, for a progress bar: the local
//! searches' iterations done out of their iteration budget (starts × `--max-iters`).
//! A start that converges early gives back the rest of its budget at once, so the
//! fraction runs from 0 to 1 and the time left it implies is an upper bound.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use argmin::core::observers::Observe;
use argmin::core::{Error, KV};

/// Iterations planned and done, shared by the searches and the display.
#[derive(Debug, Default)]
pub struct Progress {
    budget: AtomicU64,
    done: AtomicU64,
}

impl Progress {
    /// Iterations done over those planned so far (`None` before any search).
    pub fn fraction(&self) -> Option<f64> {
        let budget = self.budget.load(Ordering::Relaxed);
        let done = self.done.load(Ordering::Relaxed);
        (budget > 0).then(|| (done as f64 / budget as f64).min(1.0))
    }

    /// Iterations done and planned so far.
    pub fn iterations(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed),
            self.budget.load(Ordering::Relaxed),
        )
    }

    /// Adds `iterations` to the budget (a start about to run).
    pub(crate) fn plan(&self, iterations: u64) {
        self.budget.fetch_add(iterations, Ordering::Relaxed);
    }

    /// Counts `iterations` as done.
    pub(crate) fn advance(&self, iterations: u64) {
        self.done.fetch_add(iterations, Ordering::Relaxed);
    }
}

/// An argmin observer that counts each iteration of a search into a [`Progress`].
pub(crate) struct CountIterations(pub Arc<Progress>);

impl<I> Observe<I> for CountIterations {
    fn observe_iter(&mut self, _state: &I, _kv: &KV) -> Result<(), Error> {
        self.0.advance(1);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fraction_is_done_over_planned_and_never_above_one() {
        let p = Progress::default();
        assert_eq!(p.fraction(), None);
        p.plan(100);
        p.advance(25);
        assert_eq!(p.fraction(), Some(0.25));
        p.advance(200);
        assert_eq!(p.fraction(), Some(1.0));
    }
}
