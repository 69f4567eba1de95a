//! Where the resonance is: the one peak finder of rtid, for every caller — the
//! evaluators of measured gain curves, the objectives that compare the model's
//! resonances with measured ones, and the sweeps' resonance outputs — so that a sweep
//! and an identification report the same resonance for the same parameters.
//!
//! - [`vertex`]: a peak located by the parabola through a sampled maximum and its two
//!   neighbours;
//! - [`maxima`]: every local maximum of a sampled curve, so located, the highest kept;
//! - [`prominent`]: only the maxima whose topographic prominence (the height above the
//!   lowest point between them and the nearest higher point on each side, or the
//!   curve's end) stands above a floor plus the curve's noise there;
//! - [`of_linear_response`]: the peaks of the model's exact linear gain
//!   ([`LinearResponse`]): a logarithmic grid, then a golden-section search on the
//!   smooth curve around each grid maximum.

use serde::{Deserialize, Serialize};

use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::{ParamError, Params};

/// A resonance: a local maximum of a gain curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Peak {
    pub frequency_hz: f64,
    pub gain_db: f64,
}

/// The vertex of the parabola through three points (x ascending), clamped to
/// [x0, x2]; the highest of the three if the parabola is not concave.
pub fn vertex((x0, y0): (f64, f64), (x1, y1): (f64, f64), (x2, y2): (f64, f64)) -> Peak {
    let d = (x0 - x1) * (x0 - x2) * (x1 - x2);
    let a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
    let b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
    if a >= 0.0 || !a.is_finite() || !b.is_finite() {
        let best = [(x0, y0), (x1, y1), (x2, y2)]
            .into_iter()
            .max_by(|p, q| p.1.total_cmp(&q.1))
            .unwrap_or((x1, y1));
        return Peak {
            frequency_hz: best.0,
            gain_db: best.1,
        };
    }
    let xv = (-b / (2.0 * a)).clamp(x0, x2);
    let c = y1 - a * x1 * x1 - b * x1;
    Peak {
        frequency_hz: xv,
        gain_db: a * xv * xv + b * xv + c,
    }
}

/// Indices of the interior local maxima of a curve sorted by x (higher than the
/// point before, not lower than the point after).
pub fn local_maxima(curve: &[(f64, f64)]) -> Vec<usize> {
    (1..curve.len().saturating_sub(1))
        .filter(|&i| curve[i].1 > curve[i - 1].1 && curve[i].1 >= curve[i + 1].1)
        .collect()
}

/// The `n` highest of `peaks`, ascending in frequency.
pub fn highest(mut peaks: Vec<Peak>, n: usize) -> Vec<Peak> {
    peaks.sort_by(|a, b| b.gain_db.total_cmp(&a.gain_db));
    peaks.truncate(n);
    peaks.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    peaks
}

/// Every local maximum of `curve` (sorted by frequency) located by its [`vertex`], the
/// `n` highest, ascending in frequency.
pub fn maxima(curve: &[(f64, f64)], n: usize) -> Vec<Peak> {
    let found = local_maxima(curve)
        .into_iter()
        .map(|i| vertex(curve[i - 1], curve[i], curve[i + 1]))
        .collect();
    highest(found, n)
}

/// The topographic prominence of the local maximum `i` of `y`: its height above the
/// higher of the two lowest points between it and the nearest higher point on each
/// side (or the end); returns (prominence, index of that lowest point).
pub fn prominence(y: &[f64], i: usize) -> (f64, usize) {
    let base = |range: &mut dyn Iterator<Item = usize>| {
        let mut low = (y[i], i);
        for j in range {
            if y[j] > y[i] {
                break;
            }
            if y[j] < low.0 {
                low = (y[j], j);
            }
        }
        low
    };
    let left = base(&mut (0..i).rev());
    let right = base(&mut (i + 1..y.len()));
    let (low, at) = if left.0 > right.0 { left } else { right };
    (y[i] - low, at)
}

/// The local maxima of `curve` whose prominence is at least `min_prominence` plus
/// twice the noise (one standard deviation, `sigma`, same length as `curve`; `None`
/// for an exact curve) at the peak and at its base, each located by its [`vertex`],
/// ascending in frequency: a noise ripple does not count as a resonance, a low mode
/// beside a higher one does.
pub fn prominent(curve: &[(f64, f64)], sigma: Option<&[f64]>, min_prominence: f64) -> Vec<Peak> {
    let y: Vec<f64> = curve.iter().map(|c| c.1).collect();
    let s = |k: usize| sigma.and_then(|s| s.get(k)).copied().unwrap_or(0.0);
    local_maxima(curve)
        .into_iter()
        .filter(|&i| {
            let (height, at) = prominence(&y, i);
            height >= min_prominence + 2.0 * (s(i) + s(at))
        })
        .map(|i| vertex(curve[i - 1], curve[i], curve[i + 1]))
        .collect()
}

/// The standard error of the frequency of a peak located by [`vertex`] at `at_hz` on
/// `curve` (sorted by frequency), the gain of each line carrying independent noise
/// of `sigma_db`: the vertex's gradient in its three lines' gains, times the noise.
/// `None` where no local maximum's three lines hold `at_hz`.
pub fn vertex_se_hz(curve: &[(f64, f64)], at_hz: f64, sigma_db: f64) -> Option<f64> {
    let distance = |i: usize| (curve[i].0 - at_hz).abs();
    let i = local_maxima(curve)
        .into_iter()
        .filter(|&i| (curve[i - 1].0..=curve[i + 1].0).contains(&at_hz))
        .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))?;
    let three = [curve[i - 1], curve[i], curve[i + 1]];
    // The vertex is rational in the gains: central differences of a hundredth of a
    // millidecibel are exact to many digits.
    let step = 1e-5;
    let moved = |k: usize, dy: f64| {
        let mut q = three;
        q[k].1 += dy;
        vertex(q[0], q[1], q[2]).frequency_hz
    };
    let gradient_squared: f64 = (0..3)
        .map(|k| ((moved(k, step) - moved(k, -step)) / (2.0 * step)).powi(2))
        .sum();
    Some(sigma_db * gradient_squared.sqrt())
}

/// Points of the logarithmic grid on which [`of_linear_response`] looks for maxima.
pub const LINEAR_GRID: usize = 600;

/// The `n` highest local maxima of the model's exact linear gain (table over motor ×
/// ratio) in [lo_hz, hi_hz], ascending in frequency, each located to 1e-7 relative.
pub fn of_linear_response(
    p: &Params,
    lo_hz: f64,
    hi_hz: f64,
    n: usize,
) -> Result<Vec<Peak>, ParamError> {
    let response = LinearResponse::new(p, Channel::TableOverMotor)?;
    Ok(highest(linear_maxima(&response, lo_hz, hi_hz), n))
}

/// Every local maximum of the linear gain in [lo_hz, hi_hz]: the maxima of a
/// [`LINEAR_GRID`]-point logarithmic grid, each refined by golden-section search.
fn linear_maxima(response: &LinearResponse, lo_hz: f64, hi_hz: f64) -> Vec<Peak> {
    let ratio = (hi_hz / lo_hz).powf(1.0 / (LINEAR_GRID - 1) as f64);
    let f: Vec<f64> = (0..LINEAR_GRID)
        .map(|i| lo_hz * ratio.powi(i as i32))
        .collect();
    let curve: Vec<(f64, f64)> = f.iter().map(|&hz| (hz, response.gain_db(hz))).collect();
    local_maxima(&curve)
        .into_iter()
        .map(|i| golden_max(response, f[i - 1], f[i + 1]))
        .collect()
}

/// The maximum of the gain in [a, b] (unimodal there) by golden-section search, to
/// 1e-7 relative.
fn golden_max(response: &LinearResponse, mut a: f64, mut b: f64) -> Peak {
    let g = |hz: f64| response.gain_db(hz);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    while b - a > 1e-7 * b {
        if gc > gd {
            (b, d, gd) = (d, c, gc);
            c = b - r * (b - a);
            gc = g(c);
        } else {
            (a, c, gc) = (c, d, gd);
            d = a + r * (b - a);
            gd = g(d);
        }
    }
    let f = 0.5 * (a + b);
    Peak {
        frequency_hz: f,
        gain_db: g(f),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_vertex_of_a_parabola_is_exact() {
        let y = |x: f64| 3.0 - 0.5 * (x - 1.3) * (x - 1.3);
        let pk = vertex((1.0, y(1.0)), (1.5, y(1.5)), (2.0, y(2.0)));
        assert!((pk.frequency_hz - 1.3).abs() < 1e-12 && (pk.gain_db - 3.0).abs() < 1e-12);
    }

    #[test]
    fn maxima_find_the_vertex_of_a_sampled_peak() {
        let curve: Vec<(f64, f64)> = (0..20)
            .map(|i| {
                let f = 180.0 + i as f64;
                (f, 40.0 - 0.3 * (f - 186.4) * (f - 186.4))
            })
            .collect();
        let p = maxima(&curve, 5);
        assert_eq!(p.len(), 1);
        assert!((p[0].frequency_hz - 186.4).abs() < 1e-9 && (p[0].gain_db - 40.0).abs() < 1e-9);
    }

    #[test]
    fn ripple_is_not_a_peak_but_a_resonance_is() {
        // A resonance at 50 with ripple of ±0.5 dB every other point.
        let curve: Vec<(f64, f64)> = (0..100)
            .map(|i| {
                let f = i as f64;
                let ripple = if i % 2 == 0 { 0.5 } else { -0.5 };
                (f, 20.0 / (1.0 + ((f - 50.0) / 3.0).powi(2)) + ripple)
            })
            .collect();
        let p = prominent(&curve, None, 3.0);
        assert_eq!(p.len(), 1, "{p:?}");
        assert!((p[0].frequency_hz - 50.0).abs() < 1.0, "{p:?}");
        assert!(prominent(&curve, None, 0.5).len() > 10);
        // The ripple as the random error it is: 1 dB of prominence suffices.
        let sigma = vec![0.5; curve.len()];
        assert_eq!(prominent(&curve, Some(&sigma), 1.0).len(), 1);
    }

    /// The vertex's standard error is the spread of the vertices of many noisy
    /// copies of one sampled resonance (a second-order peak, 2 % damping, 1 Hz lines,
    /// noise of 0.01 dB).
    #[test]
    fn a_vertex_s_standard_error_is_its_spread_under_noise() {
        use rand::{rngs::StdRng, SeedableRng};
        use rand_distr::{Distribution, Normal};
        let gain = |f: f64| {
            let r = f / 245.3;
            -10.0 * ((1.0 - r * r).powi(2) + (0.04 * r).powi(2)).log10()
        };
        let exact: Vec<(f64, f64)> = (200..300).map(|k| (k as f64, gain(k as f64))).collect();
        let at = maxima(&exact, 1)[0].frequency_hz;
        // Noise well below the top's curvature (0.25 dB per line²): where it is not,
        // the vertex's error is no longer linear in the gains (at 0.03 dB the spread
        // is 17 % above the standard error; the escalation then escalates sooner).
        let sigma = 0.01;
        let se = vertex_se_hz(&exact, at, sigma).expect("the peak's lines");
        let mut rng = StdRng::seed_from_u64(3);
        let noise = Normal::new(0.0, sigma).unwrap();
        let found: Vec<f64> = (0..4000)
            .map(|_| {
                let noisy: Vec<(f64, f64)> = exact
                    .iter()
                    .map(|&(f, g)| (f, g + noise.sample(&mut rng)))
                    .collect();
                let i = (245 - 200) as usize;
                vertex(noisy[i - 1], noisy[i], noisy[i + 1]).frequency_hz
            })
            .collect();
        let mean = found.iter().sum::<f64>() / found.len() as f64;
        let spread = (found.iter().map(|f| (f - mean).powi(2)).sum::<f64>()
            / (found.len() - 1) as f64)
            .sqrt();
        assert!(
            se > 0.0 && (spread / se - 1.0).abs() < 0.05,
            "se {se}, spread {spread}"
        );
        assert_eq!(vertex_se_hz(&exact, 150.0, sigma), None);
    }

    #[test]
    fn linear_peaks_are_the_maxima_of_the_linear_gain() {
        let p = presets::load("worm-gear").unwrap();
        let r = LinearResponse::new(&p, Channel::TableOverMotor).unwrap();
        let peaks = of_linear_response(&p, 10.0, 600.0, 2).unwrap();
        assert_eq!(peaks.len(), 2, "{peaks:?}");
        for pk in &peaks {
            for d in [-0.01, 0.01] {
                assert!(r.gain_db(pk.frequency_hz + d) < pk.gain_db, "{pk:?}");
            }
        }
        // Near the damped motor-held modes (186.5 and 236.9 Hz undamped).
        assert!((peaks[0].frequency_hz - 186.9).abs() < 0.5, "{peaks:?}");
        assert!((peaks[1].frequency_hz - 234.1).abs() < 1.0, "{peaks:?}");
    }
}
