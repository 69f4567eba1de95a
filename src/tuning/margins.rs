//! Stability margins of an open loop L(jω), found on a log grid and refined by
//! bisection (docs/tuning.md):
//!
//! - a **gain crossover** is where |L| passes 1; the phase margin there is
//!   180° − |φ|, φ the phase of L unwrapped along the grid from its principal value
//!   at the lowest frequency: 180° + φ for a lagging loop (φ < −180°: negative, the
//!   loop has passed −1), and 180° − φ where a resonance's peak crosses with phase
//!   lead (φ > 0: the angle to −1 the other way round); the loop's phase margin is
//!   the smallest over its crossovers, its crossover frequency the lowest one;
//! - a **phase crossover** is where L passes the negative real axis (Im L changes
//!   sign with Re L < 0, no phase unwrapping needed); the gain margin there is
//!   −20·log10|L|; the loop's gain margin is the smallest over the phase crossovers
//!   with |L| < 1 (a crossover with |L| > 1 below the gain crossover, as a PI's
//!   integrator with a lagging plant can make, is a gain-reduction margin and not
//!   reported).
//!
//! A loop without a crossover of a kind has `None` there, never NaN.

use nalgebra::Complex;
use serde::Serialize;

/// Points of the default grid.
pub const GRID_POINTS: usize = 4000;
/// Bisection steps on log f: the bracket shrinks 2⁴⁰-fold.
const BISECTIONS: usize = 40;

/// The margins of one loop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Margins {
    /// Smallest phase margin over the gain crossovers, deg.
    pub phase_margin_deg: Option<f64>,
    /// Where that phase margin is, Hz.
    pub phase_margin_hz: Option<f64>,
    /// The lowest gain crossover, Hz (the loop's bandwidth).
    pub crossover_hz: Option<f64>,
    /// Smallest gain margin over the phase crossovers with |L| < 1, dB.
    pub gain_margin_db: Option<f64>,
    /// Where that gain margin is, Hz.
    pub gain_margin_hz: Option<f64>,
}

/// A log-spaced grid of `n` ≥ 2 frequencies from `lo` to `hi` Hz.
pub fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let (a, b) = (lo.ln(), hi.ln());
    (0..n)
        .map(|i| (a + (b - a) * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// The margins of `l` (L at a frequency in Hz; `None` where undefined) on
/// [`GRID_POINTS`] log-spaced points from `lo` to `hi` Hz.
pub fn margins(l: impl Fn(f64) -> Option<Complex<f64>>, lo: f64, hi: f64) -> Margins {
    let grid: Vec<(f64, Complex<f64>)> = log_grid(lo, hi, GRID_POINTS)
        .into_iter()
        .filter_map(|f| l(f).map(|v| (f, v)))
        .collect();
    margins_on(&grid, l)
}

/// The margins of `l` from its values on `grid` (ascending frequencies), each
/// crossing refined by bisection on `l`.
pub fn margins_on(
    grid: &[(f64, Complex<f64>)],
    l: impl Fn(f64) -> Option<Complex<f64>>,
) -> Margins {
    margins_with(grid, l, Phase::Unwrapped)
}

/// How the phase margin is read at a gain crossover.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// 180° − |φ|, φ unwrapped along the grid from its principal value at the first
    /// point (negative past −180°).
    Unwrapped,
    /// The angle between L and −1, 180° − |φ| with φ wrapped into (−180°, 180°]:
    /// never negative; whether the loop is stable is decided by its poles
    /// ([`super::stability`]). For loops whose low-frequency phase is not that of
    /// the first branch (a cascade's three integrators: −270°).
    ToMinusOne,
}

/// [`margins_on`] with the phase margin read as `phase` says.
pub fn margins_with(
    grid: &[(f64, Complex<f64>)],
    l: impl Fn(f64) -> Option<Complex<f64>>,
    rule: Phase,
) -> Margins {
    let mut m = Margins::default();
    let phase = unwrapped_deg(grid);
    for (i, pair) in grid.windows(2).enumerate() {
        let ((f0, l0), (f1, l1)) = (pair[0], pair[1]);
        if (l0.norm() - 1.0) * (l1.norm() - 1.0) <= 0.0 && l0.norm() != l1.norm() {
            let f = bisect(f0, f1, |f| l(f).map(|v| v.norm() - 1.0));
            let v = l(f).unwrap_or(l0);
            let phi = match rule {
                Phase::Unwrapped => phase[i] + wrap_deg(v.arg().to_degrees() - phase[i]),
                Phase::ToMinusOne => v.arg().to_degrees(),
            };
            let pm = 180.0 - phi.abs();
            m.crossover_hz.get_or_insert(f);
            if m.phase_margin_deg.map_or(true, |old| pm < old) {
                (m.phase_margin_deg, m.phase_margin_hz) = (Some(pm), Some(f));
            }
        }
        if l0.im * l1.im <= 0.0 && l0.im != l1.im && l0.re < 0.0 && l1.re < 0.0 {
            let f = bisect(f0, f1, |f| l(f).map(|v| v.im));
            let v = l(f).unwrap_or(l0);
            if v.norm() < 1.0 {
                let gm = -20.0 * v.norm().log10();
                if m.gain_margin_db.map_or(true, |old| gm < old) {
                    (m.gain_margin_db, m.gain_margin_hz) = (Some(gm), Some(f));
                }
            }
        }
    }
    m
}

/// The phase of each grid value, deg, unwrapped from the principal value at the
/// first.
pub(crate) fn unwrapped_deg(grid: &[(f64, Complex<f64>)]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(grid.len());
    for (_, v) in grid {
        let a = v.arg().to_degrees();
        out.push(match out.last() {
            Some(&prev) => prev + wrap_deg(a - prev),
            None => a,
        });
    }
    out
}

/// The root of `g` between `a` and `b` (signs differ), bisected on log f; stops where
/// `g` is undefined.
pub(crate) fn bisect(mut a: f64, mut b: f64, g: impl Fn(f64) -> Option<f64>) -> f64 {
    let Some(mut ga) = g(a) else { return a };
    for _ in 0..BISECTIONS {
        let mid = (a * b).sqrt();
        let Some(gm) = g(mid) else { break };
        if gm * ga <= 0.0 {
            b = mid;
        } else {
            (a, ga) = (mid, gm);
        }
    }
    (a * b).sqrt()
}

/// An angle in degrees wrapped into (−180, 180].
fn wrap_deg(x: f64) -> f64 {
    let y = x.rem_euclid(360.0);
    if y > 180.0 {
        y - 360.0
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    /// L = K·e^{−sτ}/s: crossover at ω = K, phase margin 90° − K·τ (in degrees), the
    /// first phase crossover at ω = π/(2τ) with |L| = 2Kτ/π.
    fn integrator_with_delay(k: f64, tau: f64) -> impl Fn(f64) -> Option<Complex<f64>> {
        move |hz: f64| {
            let s = Complex::new(0.0, TAU * hz);
            Some(k * (-s * tau).exp() / s)
        }
    }

    #[test]
    fn an_integrator_with_a_delay_has_its_textbook_margins() {
        let (k, tau) = (100.0, 2e-3);
        let m = margins(integrator_with_delay(k, tau), 0.1, 2000.0);
        let pm = 90.0 - (k * tau).to_degrees();
        assert!((m.phase_margin_deg.unwrap() - pm).abs() < 1e-6, "{m:?}");
        assert!((m.crossover_hz.unwrap() - k / TAU).abs() < 1e-6);
        let gm = -20.0 * (2.0 * k * tau / PI).log10();
        assert!(
            (m.gain_margin_db.unwrap() - gm).abs() < 1e-6,
            "{m:?} vs {gm}"
        );
        assert!((m.gain_margin_hz.unwrap() - 1.0 / (4.0 * tau)).abs() < 1e-6);
    }

    #[test]
    fn a_loop_without_crossovers_reports_none() {
        // |L| < 1 everywhere, no delay: phase −90°, never on the negative real axis.
        let m = margins(integrator_with_delay(0.1, 0.0), 1.0, 1000.0);
        assert_eq!(m, Margins::default());
    }

    #[test]
    fn a_resonance_above_the_crossover_sets_the_phase_margin() {
        // L = K/s + a resonant peak crossing 1 again: two gain crossovers, the phase
        // margin is the smaller.
        let w0 = TAU * 300.0;
        let l = move |hz: f64| {
            let s = Complex::new(0.0, TAU * hz);
            let res = w0 * w0 / (s * s + 0.01 * w0 * s + w0 * w0);
            Some(200.0 / s * res * (-s * 2e-4).exp())
        };
        let m = margins(l, 0.1, 2000.0);
        // The first crossover: 200/2π = 31.8 Hz lifted by the resonance's
        // 1/(1 − (f/300)²) ≈ 1.2 %.
        let fc = m.crossover_hz.unwrap();
        assert!((l(fc).unwrap().norm() - 1.0).abs() < 1e-9, "{m:?}");
        assert!(fc > 200.0 / TAU && fc < 1.015 * 200.0 / TAU, "{m:?}");
        assert!(m.phase_margin_hz.unwrap() > 250.0, "{m:?}");
        assert!(m.phase_margin_deg.unwrap() < 90.0 - (200.0 * 2e-4f64).to_degrees());
    }

    #[test]
    fn a_loop_past_minus_one_has_a_negative_phase_margin() {
        // K·e^{−sτ}/s with K·τ = 2 rad: the phase at the crossover is −90° − 114.6°.
        let (k, tau) = (100.0, 2e-2);
        let m = margins(integrator_with_delay(k, tau), 0.1, 2000.0);
        let pm = 90.0 - (k * tau).to_degrees();
        assert!(
            (m.phase_margin_deg.unwrap() - pm).abs() < 1e-6,
            "{m:?} vs {pm}"
        );
    }
}
