//! Nonlinear distortion and noise at the lines a multisine leaves out (Pintelon &
//! Schoukens, *System Identification: A Frequency Domain Approach*, 2nd ed., 2012,
//! ch. 3: the best linear approximation and its detection lines).
//!
//! A linear system answers only at the excited lines. With an **odd** multisine
//! (odd harmonic numbers only) a nonlinearity of even degree (an asymmetry, gravity on
//! a spring) combines an even number of odd lines and lands on the **even** lines; one
//! of odd degree (a hardening spring, saturation, friction) lands on the **odd** lines,
//! excited or not. A random-odd multisine leaves out some odd lines on purpose, so at
//! those the odd-degree distortion is seen alone. Noise is on every line.
//!
//! The periodic distortion and the noise are told apart by the periods: the
//! distortion repeats every period and stays in the mean spectrum X̄_k, the noise does
//! not, and its variance over periods σ̂²_k (of the mean: Σ|X_p − X̄|²/(P(P − 1)))
//! estimates what it leaves in X̄_k. Where there is only (complex Gaussian) noise,
//! each |X̄_k|²/σ̂²_k is F-distributed with 2 and 2(P − 1) degrees of freedom. The
//! noise level changes across a band (it follows the response), so the test statistic
//! is the mean of those per-line ratios, R, taken as F(2L, 2(P − 1)) for L lines — the
//! law it would have if the lines shared one noise estimate, whose tail is the heavier
//! (a conservative choice: fewer false alarms). The distortion is **detected** when R
//! exceeds that F's upper tail at the level of a one-sided normal `distortion_z`
//! (default 3: 0.13 %), through Paulson's normal approximation of the cube root of F
//! (E. Paulson, Ann. Math. Statist. 13, 340–341, 1942; Abramowitz & Stegun 26.6.15).
//! A plain "pooled power over pooled noise above 1 + 3/√L" rule ignores the skew of
//! few-line sums, the uncertainty of σ̂² and the unequal noise across a band, and
//! flagged noise-only even lines in 3 of 38 bands of the synthetic test.
//!
//! Levels are 10·log10 of mean power, the spectra normalised to cosine amplitudes
//! ([`super::record`]): dB re 1 signal unit (rad, A…) of amplitude per line.

use serde::Serialize;

use super::record::PeriodSpectra;

/// One class of non-excited lines of a band.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineClass {
    /// Lines in the class.
    pub lines: usize,
    /// Mean |X̄_k|², dB re 1 unit² (None without lines).
    pub level_db: Option<f64>,
    /// Mean noise variance of X̄_k, σ̂²_k, dB re 1 unit² (None without lines).
    pub noise_db: Option<f64>,
    /// Paulson's normal score of the mean per-line ratio level/noise (module docs;
    /// None without lines).
    pub z_score: Option<f64>,
    /// Whether `z_score` exceeds `distortion_z` (module docs).
    pub detected: bool,
}

/// The distortion levels of one band.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DistortionBand {
    /// Band, Hz: from ≤ f < to (the last band includes `to_hz`).
    pub from_hz: f64,
    pub to_hz: f64,
    /// Excited lines in the band.
    pub excited_lines: usize,
    /// Mean |X̄_k|² at the excited lines, dB re 1 unit² (None without any).
    pub signal_db: Option<f64>,
    /// Non-excited odd lines: odd-degree distortion plus noise.
    pub odd: LineClass,
    /// Even lines: even-degree distortion plus noise.
    pub even: LineClass,
}

/// 10·log10 of a power; 0 becomes −3000 dB (JSON has no infinity).
fn db(power: f64) -> f64 {
    10.0 * power.max(1e-300).log10()
}

/// Octave edges from the lowest excited line `first_hz` up to the highest `last_hz`.
pub fn octave_edges(first_hz: f64, last_hz: f64) -> Vec<f64> {
    let mut edges = vec![first_hz];
    while let Some(&e) = edges.last() {
        if 2.0 * e >= last_hz {
            break;
        }
        edges.push(2.0 * e);
    }
    edges.push(last_hz.max(first_hz));
    edges
}

/// The distortion levels of `x` in the bands between `edges_hz`; `excited` are the
/// excited lines, `spacing_hz` = fs/N, `z` the detection threshold (module docs).
pub fn bands(
    x: &PeriodSpectra,
    excited: &[usize],
    spacing_hz: f64,
    edges_hz: &[f64],
    z: f64,
) -> Vec<DistortionBand> {
    let last = edges_hz.len().saturating_sub(1);
    let strongest = (1..=x.top_line())
        .map(|k| x.mean(k).norm_sqr())
        .fold(0.0, f64::max);
    let floor = NUMERICAL_FLOOR * strongest;
    (0..last)
        .map(|b| {
            let (from, to) = (edges_hz[b], edges_hz[b + 1]);
            let inside = |k: &usize| {
                let f = *k as f64 * spacing_hz;
                f >= from && (f < to || (b + 1 == last && f <= to))
            };
            let lines: Vec<usize> = (1..=x.top_line()).filter(inside).collect();
            let is_excited = |k: &&usize| excited.binary_search(k).is_ok();
            let signal: Vec<usize> = lines.iter().filter(is_excited).copied().collect();
            let rest = lines.iter().filter(|k| !is_excited(k));
            let odd: Vec<usize> = rest.clone().filter(|k| *k % 2 == 1).copied().collect();
            let even: Vec<usize> = rest.filter(|k| *k % 2 == 0).copied().collect();
            DistortionBand {
                from_hz: from,
                to_hz: to,
                excited_lines: signal.len(),
                signal_db: mean(signal.iter().map(|&k| x.mean(k).norm_sqr())).map(db),
                odd: class(x, &odd, z, floor),
                even: class(x, &even, z, floor),
            }
        })
        .collect()
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, count) = values.fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
    (count > 0).then(|| sum / count as f64)
}

/// Powers below this fraction of the strongest line's (−240 dB) are rounding, not
/// distortion: an exactly periodic synthetic signal has σ̂² = 0 and |X̄|² ≈ 1e-30.
const NUMERICAL_FLOOR: f64 = 1e-24;

/// A line's level over its noise counts at most this (120 dB): a line above the
/// numerical floor with no scatter over the periods (a synthetic record) is distortion
/// beyond doubt, and a finite cap keeps the mean and the score finite (f64::MAX here
/// summed to infinity and made the score NaN, written as null).
const MAX_RATIO: f64 = 1e12;

fn class(x: &PeriodSpectra, lines: &[usize], z: f64, floor: f64) -> LineClass {
    let level = mean(lines.iter().map(|&k| x.mean(k).norm_sqr()));
    let noise = mean(lines.iter().map(|&k| x.mean_variance(k)));
    let ratio = mean(lines.iter().map(|&k| {
        let (s, n) = (x.mean(k).norm_sqr(), x.mean_variance(k));
        if s <= floor {
            0.0
        } else if n > 0.0 {
            (s / n).min(MAX_RATIO)
        } else {
            MAX_RATIO
        }
    }));
    let (l, p) = (lines.len() as f64, x.periods() as f64);
    let z_score = ratio.map(|r| paulson_z(r, 2.0 * l, 2.0 * (p - 1.0)));
    LineClass {
        lines: lines.len(),
        level_db: level.map(db),
        noise_db: noise.map(db),
        z_score,
        detected: z_score.is_some_and(|s| s > z),
    }
}

/// The standard normal score of an F(ν₁, ν₂) value `f` by Paulson's approximation:
/// ((1 − b)·f^⅓ − (1 − a)) / √(a + b·f^⅔), a = 2/(9ν₁), b = 2/(9ν₂).
fn paulson_z(f: f64, nu1: f64, nu2: f64) -> f64 {
    let (a, b) = (2.0 / (9.0 * nu1), 2.0 / (9.0 * nu2));
    let c = f.max(0.0).cbrt();
    ((1.0 - b) * c - (1.0 - a)) / (a + b * c * c).sqrt()
}

/// At each excited line, the power of the odd-degree distortion, unit²: the mean
/// over the `neighbours` nearest non-excited odd lines of |X̄_j|² − σ̂²_j (their
/// power less the noise's share), at least 0. For a random-odd multisine the
/// distortion at the left-out odd lines has the level it has at the excited ones (P&S
/// ch. 3), where it is periodic and so invisible in the spread over periods. `None`
/// everywhere unless every excited line is odd and some odd line is left out.
pub fn power_at_excited(
    x: &PeriodSpectra,
    excited: &[usize],
    neighbours: usize,
) -> Vec<Option<f64>> {
    let left_out: Vec<usize> = (1..=x.top_line())
        .step_by(2)
        .filter(|k| excited.binary_search(k).is_err())
        .collect();
    if left_out.is_empty() || neighbours == 0 || excited.iter().any(|k| k % 2 == 0) {
        return vec![None; excited.len()];
    }
    let excess: Vec<f64> = left_out
        .iter()
        .map(|&j| x.mean(j).norm_sqr() - x.mean_variance(j))
        .collect();
    excited
        .iter()
        .map(|&k| {
            let near = nearest(&left_out, k, neighbours);
            let sum: f64 = near.clone().map(|i| excess[i]).sum();
            Some((sum / near.len() as f64).max(0.0))
        })
        .collect()
}

/// Indices into the ascending `lines` of the `count` nearest to `k` (ties: lower).
fn nearest(lines: &[usize], k: usize, count: usize) -> std::ops::Range<usize> {
    let count = count.min(lines.len());
    let (mut lo, mut hi) = {
        let at = lines.partition_point(|&j| j < k);
        (at, at)
    };
    while hi - lo < count {
        let take_low = hi == lines.len() || (lo > 0 && k - lines[lo - 1] <= lines[hi] - k);
        if take_low {
            lo -= 1;
        } else {
            hi += 1;
        }
    }
    lo..hi
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_edges_cover_the_band() {
        assert_eq!(
            octave_edges(11.0, 250.0),
            vec![11.0, 22.0, 44.0, 88.0, 176.0, 250.0]
        );
        assert_eq!(octave_edges(10.0, 15.0), vec![10.0, 15.0]);
    }

    #[test]
    fn paulson_scores_match_known_f_quantiles() {
        // 99 % quantiles, z = 2.326: F(2, 28) = 5.45 (tables); F(40, ∞) = χ²₄₀/40 =
        // 63.69/40; F(2, ∞) = 9.21/2.
        assert!((paulson_z(5.45, 2.0, 28.0) - 2.326).abs() < 0.15);
        assert!((paulson_z(63.69 / 40.0, 40.0, 1e12) - 2.326).abs() < 0.03);
        assert!((paulson_z(9.21 / 2.0, 2.0, 1e12) - 2.326).abs() < 0.15);
        assert!(paulson_z(1.0, 1e9, 1e9).abs() < 1e-3);
        // Lines at the cap (no scatter) give a finite score; decisive but for the
        // fewest periods, where Paulson's score tends to (1 − b)/√b (2.67 for two).
        let cases = [(1.0, 2.0, 2.6), (1000.0, 10.0, 8.0), (1e6, 1e3, 10.0)];
        for (lines, periods, least) in cases {
            let z = paulson_z(MAX_RATIO, 2.0 * lines, 2.0 * (periods - 1.0));
            let what = format!("{lines} lines, {periods} periods: {z}");
            assert!(z.is_finite() && z > least, "{what}");
        }
    }

    #[test]
    fn nearest_lines_expand_around_k() {
        let lines = [1, 7, 13, 19, 25];
        assert_eq!(nearest(&lines, 14, 2), 2..4);
        assert_eq!(nearest(&lines, 14, 3), 1..4);
        assert_eq!(nearest(&lines, 0, 2), 0..2);
        assert_eq!(nearest(&lines, 30, 2), 3..5);
        assert_eq!(nearest(&lines, 30, 9), 0..5);
    }
}
