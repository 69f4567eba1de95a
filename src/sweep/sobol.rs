//! First-order and total Sobol indices from a Saltelli design ([`super::designs`]).
//!
//! With f_A, f_B, f_{A_B^(i)} the outputs at the rows of A, B and A_B^(i), N base rows
//! and V the variance of all f_A and f_B together (Saltelli et al. 2010, Table 2):
//!
//! ```text
//! S1_i = (1/N)·Σ_j f_B(j)·(f_{A_B^(i)}(j) − f_A(j)) / V          (Saltelli 2010, (b))
//! ST_i = (1/2N)·Σ_j (f_A(j) − f_{A_B^(i)}(j))² / V                (Jansen 1999, (f))
//! ```
//!
//! The output is centred on its mean first (the estimators are shift-invariant in
//! expectation, but S1's variance grows with the mean²).
//!
//! Confidence intervals: `bootstrap` resamples of the N base rows with replacement,
//! the percentile interval at `confidence` (two-sided).

use rand::{Rng, SeedableRng};
use serde::Serialize;

/// The indices of one factor for one output, with their confidence intervals.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SobolIndex {
    /// First-order index S1.
    pub s1: f64,
    pub s1_low: f64,
    pub s1_high: f64,
    /// Total index ST.
    pub st: f64,
    pub st_low: f64,
    pub st_high: f64,
}

/// Why indices cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SobolError {
    #[error("{got} outputs do not fill a Saltelli design of {samples} base rows × ({k} + 2)")]
    Length {
        got: usize,
        samples: usize,
        k: usize,
    },
    #[error("the output does not vary over the design (variance 0): its indices are undefined")]
    NoVariance,
}

/// Point estimates over the base rows `rows` (each index into 0..N, repeats allowed).
fn estimate(y: &[f64], k: usize, rows: &[usize], s1: &mut [f64], st: &mut [f64]) -> bool {
    let n = rows.len() as f64;
    let stride = k + 2;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for &j in rows {
        for v in [y[j * stride], y[j * stride + 1]] {
            sum += v;
            sum2 += v * v;
        }
    }
    let mean = sum / (2.0 * n);
    let var = sum2 / (2.0 * n) - mean * mean;
    if var.is_nan() || var <= 0.0 {
        return false;
    }
    for i in 0..k {
        let (mut a1, mut at) = (0.0, 0.0);
        for &j in rows {
            let (fa, fb, fab) = (y[j * stride], y[j * stride + 1], y[j * stride + 2 + i]);
            a1 += fb * (fab - fa);
            at += (fa - fab) * (fa - fab);
        }
        s1[i] = a1 / n / var;
        st[i] = at / (2.0 * n) / var;
    }
    true
}

/// The indices of each of the `k` factors from outputs `y` in design order.
pub fn indices(
    y: &[f64],
    k: usize,
    samples: usize,
    bootstrap: usize,
    confidence: f64,
    seed: u64,
) -> Result<Vec<SobolIndex>, SobolError> {
    if y.len() != samples * (k + 2) || samples == 0 {
        return Err(SobolError::Length {
            got: y.len(),
            samples,
            k,
        });
    }
    // Centre the output: the estimators are unbiased for any shift of y, but the
    // variance of S1's f_B·(f_AB − f_A) grows with the mean² (as SALib does too).
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let centred: Vec<f64> = y.iter().map(|v| v - mean).collect();
    let y = &centred[..];
    let all: Vec<usize> = (0..samples).collect();
    let (mut s1, mut st) = (vec![0.0; k], vec![0.0; k]);
    if !estimate(y, k, &all, &mut s1, &mut st) {
        return Err(SobolError::NoVariance);
    }
    let mut boot_s1: Vec<Vec<f64>> = vec![Vec::with_capacity(bootstrap); k];
    let mut boot_st: Vec<Vec<f64>> = vec![Vec::with_capacity(bootstrap); k];
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x0b00_7579_7261_7000);
    let mut rows = vec![0; samples];
    let (mut b1, mut bt) = (vec![0.0; k], vec![0.0; k]);
    for _ in 0..bootstrap {
        for r in rows.iter_mut() {
            *r = rng.random_range(0..samples);
        }
        if estimate(y, k, &rows, &mut b1, &mut bt) {
            for i in 0..k {
                boot_s1[i].push(b1[i]);
                boot_st[i].push(bt[i]);
            }
        }
    }
    let alpha = 0.5 * (1.0 - confidence);
    Ok((0..k)
        .map(|i| {
            let (s1_low, s1_high) = percentile_interval(&mut boot_s1[i], alpha, s1[i]);
            let (st_low, st_high) = percentile_interval(&mut boot_st[i], alpha, st[i]);
            SobolIndex {
                s1: s1[i],
                s1_low,
                s1_high,
                st: st[i],
                st_low,
                st_high,
            }
        })
        .collect())
}

/// The (alpha, 1 − alpha) quantiles of `v` (sorted in place); (x, x) when empty.
fn percentile_interval(v: &mut [f64], alpha: f64, x: f64) -> (f64, f64) {
    if v.is_empty() {
        return (x, x);
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let pos = p * (v.len() - 1) as f64;
        let (i, f) = (pos.floor() as usize, pos.fract());
        let j = (i + 1).min(v.len() - 1);
        v[i] + f * (v[j] - v[i])
    };
    (q(alpha), q(1.0 - alpha))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_additive_function_has_equal_first_order_and_total_indices() {
        // y = x0 + 2·x1 on a design of independent uniforms: S = 1/5, 4/5 exactly.
        let (k, n) = (2, 4096);
        let mut y = Vec::new();
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        for _ in 0..n {
            let a: [f64; 2] = [rng.random(), rng.random()];
            let b: [f64; 2] = [rng.random(), rng.random()];
            let f = |x: [f64; 2]| x[0] + 2.0 * x[1];
            y.extend([f(a), f(b), f([b[0], a[1]]), f([a[0], b[1]])]);
        }
        let s = indices(&y, k, n, 200, 0.95, 0).unwrap();
        for (i, want) in [0.2, 0.8].into_iter().enumerate() {
            assert!((s[i].s1 - want).abs() < 0.05, "{:?}", s[i]);
            assert!((s[i].st - want).abs() < 0.05, "{:?}", s[i]);
            assert!(s[i].s1_low <= s[i].s1 && s[i].s1 <= s[i].s1_high);
        }
    }

    #[test]
    fn a_constant_output_is_an_error_not_a_nan() {
        assert_eq!(
            indices(&[1.0; 12], 2, 3, 10, 0.95, 0),
            Err(SobolError::NoVariance)
        );
    }
}
