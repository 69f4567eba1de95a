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

/// `lone(p)` for every set of `params`, in order, computed `LANES` at a time by
/// `lanes` where the sets can share lanes. `lanes` gets `LANES` sets (a short group
/// padded with copies of its last set, whose results are dropped) and gives one
/// result per lane; if it fails as a whole (a set it cannot run), its sets run
/// alone.
pub fn in_lanes<T>(
    params: &[Params],
    lone: impl Fn(&Params) -> Result<T, SimError>,
    lanes: impl Fn(&[Params; LANES]) -> Result<[Result<T, SimError>; LANES], SimError>,
) -> Vec<Result<T, SimError>> {
    let mut results: Vec<Option<Result<T, SimError>>> = params.iter().map(|_| None).collect();
    for group in groups(params) {
        for chunk in group.chunks(LANES) {
            let batch = (chunk.len() > 1)
                .then(|| {
                    lanes(&std::array::from_fn(|l| {
                        params[chunk[l.min(chunk.len() - 1)]].clone()
                    }))
                })
                .and_then(Result::ok);
            match batch {
                Some(out) => {
                    for (&i, r) in chunk.iter().zip(out) {
                        results[i] = Some(r);
                    }
                }
                None => {
                    for &i in chunk {
                        results[i] = Some(lone(&params[i]));
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
        let lone = |p: &Params| Ok(p.jt);
        let lanes = |ps: &[Params; LANES]| Ok(ps.clone().map(|p| Ok(p.jt)));
        let expected: Vec<f64> = params.iter().map(|p| p.jt).collect();
        let got: Vec<f64> = in_lanes(&params, lone, lanes)
            .into_iter()
            .map(Result::unwrap)
            .collect();
        assert_eq!(got, expected);
        let failing = |_: &[Params; LANES]| Err(SimError::BadStep { dt: 0.0 });
        let got: Vec<f64> = in_lanes(&params, lone, failing)
            .into_iter()
            .map(Result::unwrap)
            .collect();
        assert_eq!(got, expected);
    }
}
