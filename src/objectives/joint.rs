//! Several objectives as one: the residual vectors stacked, each multiplied by
//! √(weight / count), so that the cost is Σ weight · mean(scaled residual²). The mean
//! keeps a 6000-sample torque curve from drowning two resonance frequencies; the
//! weight (`--weight`) says how much each experiment should count.

use std::sync::Mutex;

use rayon::prelude::*;

use super::{sum_of_squares, Objective, ObjectiveError, ObjectiveKind, Smoothness};
use crate::model::Params;
use crate::sim::batch::by_point;

/// One weighted part of a joint objective.
pub struct Part {
    /// Where the data came from (file name), for reports.
    pub source: String,
    pub weight: f64,
    /// Which objective it is (its declared properties).
    pub kind: ObjectiveKind,
    pub objective: Box<dyn Objective>,
}

/// A weighted sum of objectives.
#[derive(Default)]
pub struct Joint {
    pub parts: Vec<Part>,
    /// The point of lowest cost evaluated so far, with its parts' residuals: the
    /// identified point's report reads them instead of running every test again.
    lowest: Mutex<Option<Lowest>>,
}

/// A point and each part's residuals there.
struct Lowest {
    params: Params,
    parts: Vec<Vec<f64>>,
    cost: f64,
}

impl Joint {
    pub fn push(
        &mut self,
        source: impl Into<String>,
        weight: f64,
        kind: ObjectiveKind,
        objective: Box<dyn Objective>,
    ) {
        self.parts.push(Part {
            source: source.into(),
            weight,
            kind,
            objective,
        });
    }

    /// Whether any part is rough ([`Smoothness::Rough`] or [`Smoothness::Grainy`]).
    pub fn rough(&self) -> bool {
        self.parts
            .iter()
            .any(|p| p.kind.properties().smoothness != Smoothness::Smooth)
    }

    fn factor(part: &Part) -> f64 {
        (part.weight / part.objective.len().max(1) as f64).sqrt()
    }

    /// The joint residuals from each part's own: what [`Objective::residuals`] of the
    /// joint returns, without evaluating it again.
    pub(crate) fn stack(&self, parts: &[Vec<f64>]) -> Vec<f64> {
        self.parts
            .iter()
            .zip(parts)
            .flat_map(|(part, r)| {
                let k = Self::factor(part);
                r.iter().map(move |x| k * x)
            })
            .collect()
    }

    /// Each part's own (unweighted) residuals, for reports: those kept where `p` is
    /// the lowest point evaluated (the search's result), else evaluated.
    pub(crate) fn part_residuals(&self, p: &Params) -> Result<Vec<Vec<f64>>, ObjectiveError> {
        if let Ok(lowest) = self.lowest.lock() {
            if let Some(l) = lowest.as_ref().filter(|l| l.params == *p) {
                return Ok(l.parts.clone());
            }
        }
        self.parts
            .iter()
            .map(|part| part.objective.residuals(p))
            .collect()
    }

    /// The joint residuals at `p` from its parts' `parts`, the point kept if its
    /// cost is the lowest so far.
    fn stacked(&self, p: &Params, parts: Vec<Vec<f64>>) -> Vec<f64> {
        let all = self.stack(&parts);
        let cost = sum_of_squares(&all);
        if let Ok(mut lowest) = self.lowest.lock() {
            if cost.is_finite() && lowest.as_ref().map_or(true, |l| cost < l.cost) {
                *lowest = Some(Lowest {
                    params: p.clone(),
                    parts,
                    cost,
                });
            }
        }
        all
    }
}

impl Objective for Joint {
    fn name(&self) -> &'static str {
        "joint"
    }

    /// The parts side by side on the cores (a torque curve's one long run beside an
    /// unbalance test's windows); the first part's error in their order.
    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let parts: Vec<_> = (self.parts.par_iter())
            .map(|part| part.objective.residuals(p))
            .collect();
        let parts = parts.into_iter().collect::<Result<_, _>>()?;
        Ok(self.stacked(p, parts))
    }

    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        let parts: Vec<_> = (self.parts.par_iter())
            .map(|p| p.objective.residuals_batch(points))
            .collect();
        by_point(points.len(), parts)
            .into_iter()
            .zip(points)
            .map(|(parts, p)| Ok(self.stacked(p, parts?)))
            .collect()
    }

    fn in_lanes(&self) -> bool {
        self.parts.iter().any(|p| p.objective.in_lanes())
    }

    fn len(&self) -> usize {
        self.parts.iter().map(|p| p.objective.len()).sum()
    }

    fn scale(&self) -> String {
        "Σ weight · mean(scaled residual²) over the experiments".into()
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;

    use super::*;

    struct Constant(Vec<f64>);
    impl Objective for Constant {
        fn name(&self) -> &'static str {
            "constant"
        }
        fn residuals(&self, _: &Params) -> Result<Vec<f64>, ObjectiveError> {
            Ok(self.0.clone())
        }
        fn len(&self) -> usize {
            self.0.len()
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    #[test]
    fn the_joint_cost_is_the_weighted_sum_of_mean_squares() {
        let p = crate::model::presets::load("worm-gear").unwrap();
        let mut j = Joint::default();
        let kind = ObjectiveKind::named("resonance").unwrap();
        j.push("a", 2.0, kind, Box::new(Constant(vec![1.0, 3.0])));
        j.push("b", 0.5, kind, Box::new(Constant(vec![4.0; 8])));
        let cost = sum_of_squares(&j.residuals(&p).unwrap());
        assert!((cost - (2.0 * 5.0 + 0.5 * 16.0)).abs() < 1e-12, "{cost}");
        let parts = j.part_residuals(&p).unwrap();
        assert_eq!(j.stack(&parts), j.residuals(&p).unwrap());
    }

    /// Residuals Kw / 3e5 − 1 and 1, counting its evaluations.
    struct Counted(Arc<AtomicUsize>);
    impl Objective for Counted {
        fn name(&self) -> &'static str {
            "counted"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            self.0.fetch_add(1, Ordering::Relaxed);
            Ok(vec![p.kw / 3e5 - 1.0, 1.0])
        }
        fn len(&self) -> usize {
            2
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    /// The identified point's report reads the parts kept at the lowest point
    /// evaluated — the numbers an evaluation gives — and evaluates any other point.
    #[test]
    fn the_lowest_point_s_parts_are_kept_not_evaluated_again() {
        let base = crate::model::presets::load("worm-gear").unwrap();
        let at = |kw: f64| Params { kw, ..base.clone() };
        let count = Arc::new(AtomicUsize::new(0));
        let mut j = Joint::default();
        let kind = ObjectiveKind::named("resonance").unwrap();
        j.push("a", 1.0, kind, Box::new(Counted(Arc::clone(&count))));
        let batch = j.residuals_batch(&[at(2e5), at(2.9e5), at(4e5)]);
        j.residuals(&at(3.5e5)).unwrap();
        assert_eq!(count.load(Ordering::Relaxed), 4);
        let kept = j.part_residuals(&at(2.9e5)).unwrap();
        assert_eq!(count.load(Ordering::Relaxed), 4, "the lowest point kept");
        assert_eq!(kept, vec![vec![2.9e5 / 3e5 - 1.0, 1.0]]);
        assert_eq!(j.stack(&kept), *batch[1].as_ref().unwrap());
        let other = j.part_residuals(&at(3.5e5)).unwrap();
        assert_eq!(count.load(Ordering::Relaxed), 5, "another point evaluated");
        assert_eq!(other, vec![vec![3.5e5 / 3e5 - 1.0, 1.0]]);
    }
}
