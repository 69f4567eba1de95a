//! Several objectives as one: the residual vectors stacked, each multiplied by
//! √(weight / count), so that the cost is Σ weight · mean(scaled residual²). The mean
//! keeps a 6000-sample torque curve from drowning two resonance frequencies; the
//! weight (`--weight`) says how much each experiment should count.

use super::{Objective, ObjectiveError, ObjectiveKind, Smoothness};
use crate::model::Params;

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

    /// Each part's own (unweighted) residuals, for reports.
    pub(crate) fn part_residuals(&self, p: &Params) -> Result<Vec<Vec<f64>>, ObjectiveError> {
        self.parts
            .iter()
            .map(|part| part.objective.residuals(p))
            .collect()
    }
}

impl Objective for Joint {
    fn name(&self) -> &'static str {
        "joint"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let mut all = Vec::with_capacity(self.len());
        for part in &self.parts {
            let k = Self::factor(part);
            all.extend(part.objective.residuals(p)?.into_iter().map(|r| k * r));
        }
        Ok(all)
    }

    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        let mut all: Vec<Result<Vec<f64>, ObjectiveError>> = points
            .iter()
            .map(|_| Ok(Vec::with_capacity(self.len())))
            .collect();
        for part in &self.parts {
            let k = Self::factor(part);
            for (acc, r) in all.iter_mut().zip(part.objective.residuals_batch(points)) {
                if let Ok(v) = acc {
                    match r {
                        Ok(r) => v.extend(r.into_iter().map(|r| k * r)),
                        Err(e) => *acc = Err(e),
                    }
                }
            }
        }
        all
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
    use super::*;
    use crate::objectives::sum_of_squares;

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
}
