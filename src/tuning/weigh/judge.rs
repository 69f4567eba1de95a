//! Two settings compared by their ensembles (docs/tuning.md, "The check"): the same
//! tests under the same perturbations, member k of one paired with member k of the
//! other, and a difference claimed only where it stands out of its own spread.
//!
//! For each criterion and for the objective's score, the paired differences
//! d_k = after_k − before_k over the M members give a mean d̄ and the half-width of
//! its 95 % interval, h = t(0.975, M − 1)·s_d/√M (Student's t; h = 0 with one
//! member, whose difference alone then decides). A criterion is **better** when d̄
//! is below −τ and d̄ + h below 0, **worse** when d̄ is above τ and d̄ − h above 0,
//! and otherwise **no different**: the spread covers the difference (τ: 2 % of
//! today's mean and a tenth of the criterion's floor, [`Criterion::tolerance`]).
//! The score of member k is the objective's score of its values against the mean of
//! today's members; the score is linear in the values, so its mean is the score of
//! the means, and today's scores 1 on average. A score within [`SCORE_TOLERANCE`] of
//! today's is no better, however narrow its spread.

use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

use super::criteria::Checked;
use super::objective::{values, Criterion, Objective, Values, ALL};
use crate::experiments::positioning::ensemble::Spread;

/// The smallest change of the score that counts: 2 %, as for each criterion.
pub const SCORE_TOLERANCE: f64 = 0.02;

/// How a setting compares with today's on one criterion or on the score.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Better,
    Worse,
    /// The difference lies within its spread (or within the tolerance).
    NoDifferent,
}

/// One figure of two ensembles, paired member by member.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Compared {
    pub before: Spread,
    pub after: Spread,
    /// The mean of the paired differences after − before.
    pub difference: f64,
    /// The half-width of its 95 % interval.
    pub half_width: f64,
    pub verdict: Verdict,
}

/// A criterion compared.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CriterionCompared {
    pub criterion: Criterion,
    #[serde(flatten)]
    pub compared: Compared,
}

/// A setting's ensemble against today's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Judgement {
    /// Members paired.
    pub members: usize,
    /// The objective's score (today's: 1 on average; below 1 better).
    pub score: Compared,
    /// Every criterion, in the order of [`ALL`].
    pub criteria: Vec<CriterionCompared>,
}

impl Judgement {
    /// The criteria judged worse.
    pub fn worse(&self) -> impl Iterator<Item = &CriterionCompared> {
        self.criteria
            .iter()
            .filter(|c| c.compared.verdict == Verdict::Worse)
    }

    /// Whether no criterion the objective lists is judged worse.
    pub fn keeps(&self, objective: Objective) -> bool {
        self.worse().all(|c| !objective.lists(c.criterion))
    }

    /// The compared figure of `k`.
    pub fn of(&self, k: Criterion) -> &Compared {
        &self.criteria[ALL.iter().position(|&c| c == k).expect("every criterion")].compared
    }
}

/// `after` against `today` (as many members, paired by index) on `objective`.
pub fn judge(objective: Objective, today: &Checked, after: &Checked) -> Judgement {
    let t: Vec<Values> = today.members.iter().map(values).collect();
    let a: Vec<Values> = after.members.iter().map(values).collect();
    let mean = mean_values(&t);
    let score =
        |v: &[Values]| -> Vec<f64> { v.iter().map(|x| objective.score_of(x, &mean)).collect() };
    let criteria = ALL
        .iter()
        .enumerate()
        .map(|(i, &criterion)| {
            let column = |v: &[Values]| v.iter().map(|x| x[i]).collect::<Vec<_>>();
            let (b, c) = (column(&t), column(&a));
            let tolerance = criterion.tolerance(Spread::of(&b).mean);
            CriterionCompared {
                criterion,
                compared: compare(&b, &c, tolerance),
            }
        })
        .collect();
    Judgement {
        members: t.len().min(a.len()),
        score: compare(&score(&t), &score(&a), SCORE_TOLERANCE),
        criteria,
    }
}

/// Each criterion's mean over `members`.
fn mean_values(members: &[Values]) -> Values {
    std::array::from_fn(|i| Spread::of(&members.iter().map(|v| v[i]).collect::<Vec<_>>()).mean)
}

/// `after` against `before`, paired by index, a difference within `tolerance` no
/// difference.
pub fn compare(before: &[f64], after: &[f64], tolerance: f64) -> Compared {
    let d: Vec<f64> = before.iter().zip(after).map(|(b, a)| a - b).collect();
    let spread = Spread::of(&d);
    let half_width = half_width(&spread, d.len());
    let verdict = if spread.mean < -tolerance && spread.mean + half_width < 0.0 {
        Verdict::Better
    } else if spread.mean > tolerance && spread.mean - half_width > 0.0 {
        Verdict::Worse
    } else {
        Verdict::NoDifferent
    };
    Compared {
        before: Spread::of(before),
        after: Spread::of(after),
        difference: spread.mean,
        half_width,
        verdict,
    }
}

/// The half-width of the 95 % interval of the mean of `n` values with `spread`.
fn half_width(spread: &Spread, n: usize) -> f64 {
    if n < 2 {
        return 0.0;
    }
    let t =
        StudentsT::new(0.0, 1.0, (n - 1) as f64).map_or(f64::INFINITY, |d| d.inverse_cdf(0.975));
    t * spread.sd / (n as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_difference_is_claimed_only_out_of_its_spread() {
        let before = [3.7, 3.4, 3.4, 3.4, 4.0, 3.9, 3.6, 2.9];
        // Shifted by 0.8 with a scatter of ±0.1: better.
        let better: Vec<f64> = before
            .iter()
            .enumerate()
            .map(|(i, b)| b - 0.8 + if i % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        let c = compare(&before, &better, 0.1);
        assert_eq!(c.verdict, Verdict::Better, "{c:?}");
        assert!((c.difference + 0.8).abs() < 1e-12);
        // t(0.975, 7) = 2.3646: the half-width of ±0.1 alternating over 8 members.
        let sd = (8.0 * 0.01 / 7.0f64).sqrt();
        assert!(
            (c.half_width - 2.3646 * sd / 8f64.sqrt()).abs() < 1e-4,
            "{c:?}"
        );
        // The same mean shift in a scatter of ±1.5: no different.
        let scattered: Vec<f64> = before
            .iter()
            .enumerate()
            .map(|(i, b)| b - 0.8 + if i % 2 == 0 { 1.5 } else { -1.5 })
            .collect();
        assert_eq!(
            compare(&before, &scattered, 0.1).verdict,
            Verdict::NoDifferent
        );
        // Worse beyond its spread, and a shift within the tolerance is none.
        let worse: Vec<f64> = before.iter().map(|b| b + 0.5).collect();
        assert_eq!(compare(&before, &worse, 0.1).verdict, Verdict::Worse);
        assert_eq!(compare(&before, &worse, 0.6).verdict, Verdict::NoDifferent);
        // One member: its difference decides.
        let one = compare(&[1.0], &[0.5], 0.1);
        assert_eq!((one.verdict, one.half_width), (Verdict::Better, 0.0));
    }
}
