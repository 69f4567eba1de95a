//! The frequencies a model's frequency response is drawn at: log-spaced over the
//! measured range, and a fine run through each resonance of the model's gain — the
//! peak found between the coarse points (a lightly damped mode's peak is far
//! narrower than their spacing), its half-power bandwidth, and
//! [`PEAK_POINTS`] points within ± [`HALF_POWER_WIDTHS`] bandwidths of it — so that
//! a mode's circle in the Nyquist plot is a circle, not a polygon.

/// Points of the coarse grid over the measured range.
const COARSE_POINTS: usize = 600;
/// Points added through each resonance.
const PEAK_POINTS: usize = 120;
/// The fine run's half-width, in half-power bandwidths.
const HALF_POWER_WIDTHS: f64 = 3.0;
/// Resonances refined at most.
const MAX_PEAKS: usize = 20;
/// Golden-section and bisection steps.
const STEPS: usize = 60;

/// The grid from `lo` to `hi` Hz (ascending, no repeats) for a model of gain `gain`
/// (|H| at a frequency, `None` where undefined): log-spaced where `lo` > 0, even
/// otherwise, refined at the gain's peaks.
pub(super) fn model_grid(lo: f64, hi: f64, gain: impl Fn(f64) -> Option<f64>) -> Vec<f64> {
    let n = COARSE_POINTS;
    let mut grid: Vec<f64> = if lo > 0.0 && hi > lo {
        let (a, b) = (lo.ln(), hi.ln());
        (0..=n)
            .map(|i| (a + (b - a) * i as f64 / n as f64).exp())
            .collect()
    } else {
        (0..=n)
            .map(|i| lo + (hi - lo) * i as f64 / n as f64)
            .collect()
    };
    // The measured range's ends exactly (exp∘ln is not the identity).
    grid[n] = hi;
    let values: Vec<f64> = grid.iter().map(|&f| gain(f).unwrap_or(f64::NAN)).collect();
    let peaks: Vec<usize> = (1..grid.len().saturating_sub(1))
        .filter(|&i| values[i] > values[i - 1] && values[i] >= values[i + 1])
        .take(MAX_PEAKS)
        .collect();
    let mut extra = Vec::new();
    for i in peaks {
        let (f, bandwidth) = resonance(&grid, i, &gain);
        let (a, b) = (
            (f - HALF_POWER_WIDTHS * bandwidth).max(lo),
            (f + HALF_POWER_WIDTHS * bandwidth).min(hi),
        );
        extra.push(f);
        extra.extend((0..=PEAK_POINTS).map(|k| a + (b - a) * k as f64 / PEAK_POINTS as f64));
    }
    grid.extend(extra.into_iter().filter(|f| f.is_finite()));
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    grid
}

/// The peak near the coarse grid's local maximum `i` (golden section between its
/// neighbours) and its half-power bandwidth, Hz.
fn resonance(grid: &[f64], i: usize, gain: &impl Fn(f64) -> Option<f64>) -> (f64, f64) {
    let g = |f: f64| gain(f).unwrap_or(0.0);
    let (mut a, mut b) = (grid[i - 1], grid[i + 1]);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..STEPS {
        let (c, d) = (b - r * (b - a), a + r * (b - a));
        if g(c) >= g(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let peak = 0.5 * (a + b);
    let half = g(peak).max(g(grid[i])) / std::f64::consts::SQRT_2;
    let below = half_power_edge(peak, grid[..i].iter().rev(), half, &g);
    let above = half_power_edge(peak, grid[i + 1..].iter(), half, &g);
    (peak, (above - below).abs())
}

/// Where the gain falls to `half` going from `peak` through `outward` (coarse points
/// in the direction), bisected between the last point above and the first below;
/// the last point where it never falls.
fn half_power_edge<'a>(
    peak: f64,
    outward: impl Iterator<Item = &'a f64>,
    half: f64,
    g: &impl Fn(f64) -> f64,
) -> f64 {
    let mut inside = peak;
    for &f in outward {
        if g(f) < half {
            let mut outside = f;
            for _ in 0..STEPS {
                let mid = 0.5 * (inside + outside);
                if g(mid) < half {
                    outside = mid;
                } else {
                    inside = mid;
                }
            }
            return 0.5 * (inside + outside);
        }
        inside = f;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mode with ζ = 10⁻³ at 123.4 Hz: its half-power band (0.25 Hz) is a tenth of
    /// the coarse grid's spacing there; the grid meets its peak and runs through it.
    #[test]
    fn a_sharp_resonance_is_drawn_through() {
        let (f0, zeta) = (123.4, 1e-3);
        let gain = |f: f64| {
            let r = f / f0;
            Some(1.0 / ((1.0 - r * r).powi(2) + (2.0 * zeta * r).powi(2)).sqrt())
        };
        let grid = model_grid(1.0, 1000.0, gain);
        let top = grid.iter().map(|&f| gain(f).unwrap()).fold(0.0, f64::max);
        assert!((top * 2.0 * zeta - 1.0).abs() < 1e-3, "{top}");
        let bandwidth = 2.0 * zeta * f0;
        let within = grid.iter().filter(|f| (*f - f0).abs() <= bandwidth).count();
        assert!(within >= 30, "{within} points within one bandwidth");
        assert!(grid.windows(2).all(|w| w[0] < w[1]));
        assert_eq!((grid[0], grid[grid.len() - 1]), (1.0, 1000.0));
        // The coarse log grid alone would put at most one point there.
        let coarse = model_grid(1.0, 1000.0, Some);
        assert_eq!(coarse.len(), COARSE_POINTS + 1);
        let near = coarse
            .iter()
            .filter(|f| (*f - f0).abs() <= bandwidth)
            .count();
        assert!(near <= 1, "{near}");
    }
}
