//! Many parameter sets through one virtual test, in lanes: the sets are grouped by
//! what lanes of one `Kernel<LANES>` must share — the shape of the equations
//! ([`LaneKey`]), the integration step and the control period — and each group runs
//! [`LANES`] sets at a time; a set left alone in its group runs alone. Every set's
//! result is what its lone run gives, bit for bit (the lanes compute exactly the
//! lone trajectories: `tests/lanes.rs`), so a batch changes the time a job takes,
//! never its numbers.

use super::{default_step, SimError, LANES};
use crate::model::{Drive, LaneKey, Params};

/// What lanes of one batch share.
type BatchKey = (LaneKey, u64, u64);

/// A virtual test that runs a parameter set alone or several in lanes, with the
/// same result for each set either way.
pub trait LaneRun {
    type Out;
    /// The test on `p` alone.
    fn lone(&self, p: &Params) -> Result<Self::Out, SimError>;
    /// The test on `L` sets of one [`BatchKey`] at once: one result per set, or an
    /// error that stops them all (a set it cannot run: they then run alone).
    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Self::Out, SimError>; L], SimError>;
}

/// `test.lone(p)` for every set of `params`, in order, computed in lanes where the
/// sets can share them: up to [`LANES`] at a time (two lanes for a pair, alone for
/// a single set; a group of three is padded with a copy of its last set, whose
/// result is dropped).
pub fn in_lanes<R: LaneRun>(params: &[Params], test: &R) -> Vec<Result<R::Out, SimError>> {
    if params.len() < 2 {
        // Nothing to share: spare the grouping its drive and step (an eigenvalue
        // problem) for each lone evaluation of a search.
        return params.iter().map(|p| test.lone(p)).collect();
    }
    let mut results: Vec<Option<Result<R::Out, SimError>>> = params.iter().map(|_| None).collect();
    for group in groups(params) {
        for chunk in group.chunks(LANES) {
            let set = |l: usize| params[chunk[l.min(chunk.len() - 1)]].clone();
            let batch: Option<Vec<_>> = match chunk.len() {
                1 => None,
                2 => test
                    .lanes::<2>(&std::array::from_fn(set))
                    .ok()
                    .map(Vec::from),
                _ => test
                    .lanes::<LANES>(&std::array::from_fn(set))
                    .ok()
                    .map(Vec::from),
            };
            match batch {
                Some(out) => {
                    for (&i, r) in chunk.iter().zip(out) {
                        results[i] = Some(r);
                    }
                }
                None => {
                    for &i in chunk {
                        results[i] = Some(test.lone(&params[i]));
                    }
                }
            }
        }
    }
    results
        .into_iter()
        .map(|r| r.expect("every set is in one group"))
        .collect()
}

/// `batch` applied to the items of `items` that are `Ok`, its results put back in
/// their places among the errors: for a batch of parameter sets some of which could
/// not be made. `batch` gives one result per item it gets, in order.
pub fn on_valid<P, T, E>(
    items: Vec<Result<P, E>>,
    batch: impl FnOnce(&[P]) -> Vec<Result<T, E>>,
) -> Vec<Result<T, E>> {
    let mut errors = Vec::with_capacity(items.len());
    let mut valid = Vec::with_capacity(items.len());
    for item in items {
        match item {
            Ok(p) => {
                valid.push(p);
                errors.push(None);
            }
            Err(e) => errors.push(Some(e)),
        }
    }
    let mut computed = batch(&valid).into_iter();
    errors
        .into_iter()
        .map(|e| match e {
            Some(e) => Err(e),
            None => computed.next().expect("one result per valid item"),
        })
        .collect()
}

/// Each point's results from several tests' batches: `batches` yields, test after
/// test, one result per point, and point `i` gets its results in test order — or the
/// first test's error at it.
pub fn by_point<T, E>(
    points: usize,
    batches: impl IntoIterator<Item = Vec<Result<T, E>>>,
) -> Vec<Result<Vec<T>, E>> {
    let mut each: Vec<Result<Vec<T>, E>> = (0..points).map(|_| Ok(Vec::new())).collect();
    for batch in batches {
        for (acc, r) in each.iter_mut().zip(batch) {
            if let Ok(results) = acc {
                match r {
                    Ok(r) => results.push(r),
                    Err(e) => *acc = Err(e),
                }
            }
        }
    }
    each
}

/// The indices of `params` grouped by [`BatchKey`], in order of first appearance; a
/// set whose key cannot be computed (invalid parameters) is a group of its own, so
/// that its lone run gives its error.
fn groups(params: &[Params]) -> Vec<Vec<usize>> {
    let mut keys: Vec<Option<BatchKey>> = Vec::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, p) in params.iter().enumerate() {
        let key = batch_key(p);
        match key.and_then(|k| keys.iter().position(|other| *other == Some(k))) {
            Some(g) => groups[g].push(i),
            None => {
                keys.push(key);
                groups.push(vec![i]);
            }
        }
    }
    groups
}

/// The shape, default step and control period of `p`, if it is valid.
fn batch_key(p: &Params) -> Option<BatchKey> {
    let drive = Drive::new(p).ok()?;
    let dt = default_step(p).ok()?;
    Some((LaneKey::of(&drive), dt.to_bits(), p.controller.tc.to_bits()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn each_point_gets_its_results_in_test_order_or_its_first_error() {
        let batches: Vec<Vec<Result<i32, &str>>> = vec![
            vec![Ok(1), Err("a at 1"), Ok(3)],
            vec![Ok(10), Err("b at 1"), Err("b at 2")],
        ];
        assert_eq!(
            by_point(3, batches),
            vec![Ok(vec![1, 10]), Err("a at 1"), Err("b at 2")]
        );
    }

    #[test]
    fn sets_group_by_shape_and_step_in_order_and_invalid_ones_stand_alone() {
        let worm = presets::load("worm-gear").unwrap();
        let mut stiffer = worm.clone();
        stiffer.kw *= 1.1;
        let mut gapless = worm.clone();
        gapless.theta_bw = 0.0;
        let mut invalid = worm.clone();
        invalid.jt = -1.0;
        let params = [
            worm.clone(),
            gapless.clone(),
            invalid.clone(),
            stiffer,
            invalid,
            gapless,
            worm,
        ];
        assert_eq!(
            groups(&params),
            vec![vec![0, 3, 6], vec![1, 5], vec![2], vec![4]]
        );
    }

    #[test]
    fn results_come_back_in_order_and_a_failed_batch_runs_alone() {
        let mut params: Vec<Params> = Vec::new();
        for i in 0..6 {
            let mut p = presets::load("worm-gear").unwrap();
            p.jt *= 1.0 + 0.01 * i as f64;
            params.push(p);
        }
        /// Jt of each set, negated when run in lanes (or failing there).
        struct Inertia(bool);
        impl LaneRun for Inertia {
            type Out = f64;
            fn lone(&self, p: &Params) -> Result<f64, SimError> {
                Ok(p.jt)
            }
            fn lanes<const L: usize>(
                &self,
                ps: &[Params; L],
            ) -> Result<[Result<f64, SimError>; L], SimError> {
                if self.0 {
                    return Err(SimError::BadStep { dt: 0.0 });
                }
                Ok(ps.each_ref().map(|p| Ok(-p.jt)))
            }
        }
        let jt: Vec<f64> = params.iter().map(|p| p.jt).collect();
        let got: Vec<f64> = in_lanes(&params[..6], &Inertia(false))
            .into_iter()
            .map(Result::unwrap)
            .collect();
        // 4 in lanes, then a pair in two lanes.
        assert_eq!(got, jt.iter().map(|j| -j).collect::<Vec<_>>());
        let got: Vec<f64> = in_lanes(&params[..5], &Inertia(false))
            .into_iter()
            .map(Result::unwrap)
            .collect();
        assert_eq!(got[4], jt[4], "a set left alone runs alone");
        let got: Vec<f64> = in_lanes(&params, &Inertia(true))
            .into_iter()
            .map(Result::unwrap)
            .collect();
        assert_eq!(got, jt, "a failed batch runs alone");
    }
}
