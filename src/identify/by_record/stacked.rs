//! The records' objectives side by side: their residuals concatenated as each gives
//! them. Each is already its record's share of the joint cost (scaled by
//! √(weight / count)), so the sum of squares is the joint cost.

use rayon::prelude::*;

use crate::model::Params;
use crate::objectives::{Objective, ObjectiveError};
use crate::sim::batch::by_point;

/// Objectives whose residuals are concatenated.
pub struct Stacked {
    pub parts: Vec<Box<dyn Objective>>,
}

impl Objective for Stacked {
    fn name(&self) -> &'static str {
        "records"
    }

    /// The parts side by side on the cores; the first part's error in their order.
    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let parts: Vec<_> = self.parts.par_iter().map(|o| o.residuals(p)).collect();
        let parts = parts.into_iter().collect::<Result<Vec<_>, _>>()?;
        Ok(parts.concat())
    }

    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        let parts: Vec<_> = (self.parts.par_iter())
            .map(|o| o.residuals_batch(points))
            .collect();
        by_point(points.len(), parts)
            .into_iter()
            .map(|parts| parts.map(|r| r.concat()))
            .collect()
    }

    fn in_lanes(&self) -> bool {
        self.parts.iter().any(|p| p.in_lanes())
    }

    fn len(&self) -> usize {
        self.parts.iter().map(|p| p.len()).sum()
    }

    fn part(&self, i: usize) -> Option<&dyn Objective> {
        self.parts.get(i).map(|p| p.as_ref())
    }

    fn scale(&self) -> String {
        "Σ weight · mean(scaled residual²) over the records".into()
    }
}
