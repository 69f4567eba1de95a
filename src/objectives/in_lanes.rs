//! For tests: an objective handed its points in batches, as one that runs in the
//! kernel's lanes is, noting the largest batch.

use std::sync::atomic::{AtomicUsize, Ordering};

use super::{Objective, ObjectiveError};
use crate::model::Params;

/// `inner`, declared to run in lanes.
pub(crate) struct InLanes<O> {
    pub inner: O,
    /// The most points one batch held.
    pub largest: AtomicUsize,
}

impl<O> InLanes<O> {
    pub fn new(inner: O) -> Self {
        InLanes {
            inner,
            largest: AtomicUsize::new(0),
        }
    }

    pub fn largest(&self) -> usize {
        self.largest.load(Ordering::Relaxed)
    }
}

impl<O: Objective> Objective for InLanes<O> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        self.inner.residuals(p)
    }
    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        self.largest.fetch_max(points.len(), Ordering::Relaxed);
        self.inner.residuals_batch(points)
    }
    fn in_lanes(&self) -> bool {
        true
    }
    fn len(&self) -> usize {
        self.inner.len()
    }
    fn scale(&self) -> String {
        self.inner.scale()
    }
}
