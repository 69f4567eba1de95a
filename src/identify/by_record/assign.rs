//! Which record determines which parameter, from the information each record carries
//! about each ([`super::information`]): pure arithmetic on the records' Fisher
//! matrices, no simulation.
//!
//! Each fitted parameter goes to the record with the most information about it (the
//! largest diagonal entry of that record's JᵀJ: the curvature its share of the joint
//! cost has along the parameter, the others held). A record must determine the set
//! it is given on its own: where two of its parameters act as one (their variance
//! inflation factor within the record above [`VIF_LIMIT`], |ρ| ≈ 0.95 for a pair —
//! the torque curve's fm and fw, which it sees as the sum fm + Rg·fw), the one with
//! the most information elsewhere moves to the record that holds it next best and
//! can take it; with none, it is left to the joint refinement. A parameter that the
//! records together cannot tell from the others (its variance inflation factor in
//! the summed information above [`UNDETERMINED_VIF`], or no information at all) is
//! not determined. The refinement then fits jointly every parameter whose
//! information other records share (more than [`SHARED`] of it), and those no
//! record determines alone.

use nalgebra::DMatrix;

/// The variance inflation factor above which a record does not determine a
/// parameter beside the others it is given: 1/(1 − ρ²) = 10 at |ρ| = 0.949, the
/// correlation beyond which `rtid identify` warns that two parameters cannot be
/// separated.
pub const VIF_LIMIT: f64 = 10.0;
/// The variance inflation factor (in all the records' information together) above
/// which a parameter is not determined: |ρ| = 0.99995 with the combination of the
/// others.
pub const UNDETERMINED_VIF: f64 = 1e4;
/// A parameter whose other records hold more than this share of its information is
/// refined jointly after the records' stages.
pub const SHARED: f64 = 0.1;
/// A parameter correlated beyond this (in the summed information) with one refined
/// jointly is refined with it.
pub const COUPLED: f64 = 0.5;

/// One record's information about the fitted parameters.
#[derive(Clone, Debug)]
pub struct RecordInformation {
    /// The record (its file), for the plan.
    pub label: String,
    /// Its JᵀJ over the fitted parameters (ln p, its share of the joint cost).
    pub fisher: DMatrix<f64>,
    /// Whether its cost is rough (a closed-loop simulation).
    pub rough: bool,
}

/// What each record determines.
#[derive(Clone, Debug, PartialEq)]
pub struct Assignment {
    /// Per record (in the order given), the indices of the parameters it determines.
    pub owned: Vec<Vec<usize>>,
    /// Indices of the parameters refined jointly after the stages.
    pub refined: Vec<usize>,
    /// Indices of the parameters no record nor all of them together determine.
    pub undetermined: Vec<usize>,
    /// Per parameter, each record's share of its information (rows: parameters).
    pub shares: Vec<Vec<f64>>,
}

/// The assignment of `n` parameters to `records`.
pub fn assign(n: usize, records: &[RecordInformation]) -> Assignment {
    let shares = shares(n, records);
    let total = summed(n, records);
    let blind: Vec<usize> = (0..n)
        .filter(|&p| shares[p].iter().all(|s| *s == 0.0))
        .collect();
    let seen = all_but(n, &blind);
    let undetermined: Vec<usize> = (0..n)
        .filter(|&p| blind.contains(&p) || vif(&total, &seen, p) > UNDETERMINED_VIF)
        .collect();
    let mut owner: Vec<Option<usize>> = (0..n)
        .map(|p| {
            (!undetermined.contains(&p))
                .then(|| argmax(&shares[p]))
                .flatten()
        })
        .collect();
    // Each pass moves one parameter out of a record that cannot determine its set;
    // a parameter moves at most once per record, so n · records passes end it.
    for _ in 0..n * records.len().max(1) {
        let Some((e, p)) = worst_conflict(records, &owner, &shares) else {
            break;
        };
        // None: kept out of every record, refined jointly.
        owner[p] = next_owner(records, &owner, &shares, e, p);
    }
    let owned = (0..records.len())
        .map(|e| (0..n).filter(|&p| owner[p] == Some(e)).collect())
        .collect();
    let shared: Vec<usize> = (0..n)
        .filter(|p| !undetermined.contains(p))
        .filter(|&p| owner[p].map_or(true, |e| 1.0 - shares[p][e] > SHARED))
        .collect();
    let refined = coupled(&total, shared, &undetermined);
    Assignment {
        owned,
        refined,
        undetermined,
        shares,
    }
}

/// `refined` and every parameter coupled to one of them in the summed information
/// `total` (|ρ| above [`COUPLED`]), until none is added: a refinement that held a
/// parameter the records see in a sum with a refined one would pull the refined one
/// back to where the stage left the sum.
fn coupled(total: &DMatrix<f64>, mut refined: Vec<usize>, undetermined: &[usize]) -> Vec<usize> {
    let n = total.nrows();
    let rho = |a: usize, b: usize| total[(a, b)] / (total[(a, a)] * total[(b, b)]).sqrt();
    while let Some(p) = (0..n).find(|p| {
        !refined.contains(p)
            && !undetermined.contains(p)
            && refined.iter().any(|&q| rho(*p, q).abs() > COUPLED)
    }) {
        refined.push(p);
    }
    refined.sort_unstable();
    refined
}

/// Per parameter, each record's share of the summed diagonal information.
fn shares(n: usize, records: &[RecordInformation]) -> Vec<Vec<f64>> {
    (0..n)
        .map(|p| {
            let d: Vec<f64> = records
                .iter()
                .map(|r| r.fisher[(p, p)].max(0.0))
                .map(|x| if x.is_finite() { x } else { 0.0 })
                .collect();
            let sum: f64 = d.iter().sum();
            d.iter()
                .map(|x| if sum > 0.0 { x / sum } else { 0.0 })
                .collect()
        })
        .collect()
}

/// The records' information summed.
fn summed(n: usize, records: &[RecordInformation]) -> DMatrix<f64> {
    records
        .iter()
        .fold(DMatrix::zeros(n, n), |acc, r| acc + &r.fisher)
}

/// Every index below `n` but those of `but`.
fn all_but(n: usize, but: &[usize]) -> Vec<usize> {
    (0..n).filter(|i| !but.contains(i)).collect()
}

/// The index of the largest positive entry.
fn argmax(v: &[f64]) -> Option<usize> {
    v.iter()
        .enumerate()
        .filter(|(_, x)| **x > 0.0)
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i)
}

/// The variance inflation factor of parameter `p` within the set `set` of the
/// information `f`: how much the others of the set widen its variance, F_pp·(F⁻¹)_pp
/// on the set's block (∞ where the block is singular).
pub(crate) fn vif(f: &DMatrix<f64>, set: &[usize], p: usize) -> f64 {
    let Some(k) = set.iter().position(|&q| q == p) else {
        return 1.0;
    };
    let d: Vec<f64> = set.iter().map(|&q| f[(q, q)]).collect();
    if d.iter().any(|x| !(*x > 0.0 && x.is_finite())) {
        return f64::INFINITY;
    }
    // On the correlation-like matrix D^-½ F D^-½, whose inverse's diagonal is the VIF.
    let c = DMatrix::from_fn(set.len(), set.len(), |i, j| {
        f[(set[i], set[j])] / (d[i] * d[j]).sqrt()
    });
    match c.clone().cholesky() {
        Some(ch) => ch.inverse()[(k, k)],
        None => f64::INFINITY,
    }
}

/// The record and parameter to move first: in a record whose set it cannot
/// determine, the parameter of the largest variance inflation, ties broken towards
/// the one with the most information elsewhere.
fn worst_conflict(
    records: &[RecordInformation],
    owner: &[Option<usize>],
    shares: &[Vec<f64>],
) -> Option<(usize, usize)> {
    let mut worst: Option<(usize, usize, f64, f64)> = None;
    for (e, r) in records.iter().enumerate() {
        let set: Vec<usize> = (0..owner.len()).filter(|&p| owner[p] == Some(e)).collect();
        for &p in &set {
            let v = vif(&r.fisher, &set, p);
            if v <= VIF_LIMIT {
                continue;
            }
            let elsewhere = 1.0 - shares[p][e];
            // Ties (the two of a sum have one inflation) go to the one with more
            // information elsewhere, then to the later one: the first named stays.
            let better = worst.map_or(true, |(_, _, wv, we)| {
                let (v, wv) = (v.min(1e300), wv.min(1e300));
                v > 1.01 * wv || (v >= wv / 1.01 && elsewhere >= we)
            });
            if better {
                worst = Some((e, p, v, elsewhere));
            }
        }
    }
    worst.map(|(e, p, ..)| (e, p))
}

/// Where parameter `p`, leaving record `from`, goes: the other record with the most
/// information about it — at least [`SHARED`] of it — that determines it beside what
/// it holds already; `None` when no other record does (the unbalance test holds
/// 0.2 % of the information about the worm's fw, which the torque curve sees in a
/// sum with fm: the split is left to the joint refinement).
fn next_owner(
    records: &[RecordInformation],
    owner: &[Option<usize>],
    shares: &[Vec<f64>],
    from: usize,
    p: usize,
) -> Option<usize> {
    let mut candidates: Vec<usize> = (0..records.len())
        .filter(|&e| e != from && shares[p][e] >= SHARED)
        .collect();
    candidates.sort_by(|&a, &b| shares[p][b].total_cmp(&shares[p][a]));
    candidates.into_iter().find(|&e| {
        let mut set: Vec<usize> = (0..owner.len()).filter(|&q| owner[q] == Some(e)).collect();
        set.push(p);
        set.iter()
            .all(|&q| vif(&records[e].fisher, &set, q) <= VIF_LIMIT)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(label: &str, f: &[&[f64]]) -> RecordInformation {
        let n = f.len();
        RecordInformation {
            label: label.into(),
            fisher: DMatrix::from_fn(n, n, |i, j| f[i][j]),
            rough: false,
        }
    }

    /// A frequency response that sees two stiffnesses and a torque curve that sees
    /// two frictions: each record its own, nothing shared, no refinement.
    #[test]
    fn separate_records_each_determine_their_own() {
        let frf = record(
            "frf",
            &[
                &[100.0, 20.0, 0.0, 0.0],
                &[20.0, 50.0, 0.0, 0.0],
                &[0.0; 4],
                &[0.0; 4],
            ],
        );
        let torque = record(
            "torque",
            &[
                &[1e-6, 0.0, 0.0, 0.0],
                &[0.0, 0.0, 0.0, 0.0],
                &[0.0, 0.0, 400.0, 100.0],
                &[0.0, 0.0, 100.0, 300.0],
            ],
        );
        let a = assign(4, &[frf, torque]);
        assert_eq!(a.owned, vec![vec![0, 1], vec![2, 3]]);
        assert!(a.refined.is_empty(), "{a:?}");
        assert!(a.undetermined.is_empty());
    }

    /// A torque curve sees only the sum of two frictions (ρ = −0.99), an unbalance
    /// test sees the second one: the second moves there, the first stays; the
    /// torque curve holds most of the second one's information, so it is refined
    /// jointly, and the first with it (the sum couples them).
    #[test]
    fn a_sum_one_record_sees_is_split_by_the_other() {
        let torque = record("torque", &[&[100.0, 99.0], &[99.0, 100.0]]);
        let unbalance = record("unbalance", &[&[0.0, 0.0], &[0.0, 30.0]]);
        let a = assign(2, &[torque, unbalance]);
        assert_eq!(a.owned, vec![vec![0], vec![1]], "{a:?}");
        assert_eq!(a.refined, vec![0, 1]);
    }

    /// The same with an unbalance test that holds under a tenth of the second one's
    /// information: no record takes it, it is left to the joint refinement.
    #[test]
    fn a_record_with_little_information_does_not_take_a_parameter() {
        let torque = record("torque", &[&[100.0, 99.0], &[99.0, 100.0]]);
        let unbalance = record("unbalance", &[&[0.0, 0.0], &[0.0, 0.2]]);
        let a = assign(2, &[torque, unbalance]);
        assert_eq!(a.owned, vec![vec![0], vec![]], "{a:?}");
        assert_eq!(a.refined, vec![0, 1]);
    }

    /// Two parameters only their sum of which any record sees: not determined.
    #[test]
    fn a_combination_no_record_separates_is_not_determined() {
        let one = record("one", &[&[1.0, 1.0], &[1.0, 1.0]]);
        let two = record("two", &[&[4.0, 4.0], &[4.0, 4.0]]);
        let a = assign(2, &[one, two]);
        assert_eq!(a.undetermined, vec![0, 1], "{a:?}");
        assert!(a.owned.iter().all(Vec::is_empty));
    }

    /// A parameter no record moves is not determined; the others are assigned.
    #[test]
    fn a_parameter_without_information_is_not_determined() {
        let one = record("one", &[&[1.0, 0.0], &[0.0, 0.0]]);
        let a = assign(2, &[one]);
        assert_eq!(a.undetermined, vec![1]);
        assert_eq!(a.owned, vec![vec![0]]);
    }

    #[test]
    fn the_variance_inflation_of_a_pair_is_one_over_one_less_rho_squared() {
        let f = DMatrix::from_row_slice(2, 2, &[4.0, 1.8, 1.8, 1.0]);
        let rho: f64 = 1.8 / 2.0;
        assert!((vif(&f, &[0, 1], 0) - 1.0 / (1.0 - rho * rho)).abs() < 1e-12);
        assert_eq!(vif(&f, &[1], 1), 1.0);
    }
}
