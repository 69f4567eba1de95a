//! A sampled loop's margins and its stability decided exactly (docs/tuning.md, "The
//! cascade"): the phase margin at each gain crossover as the angle between L and −1,
//! and the gain margins from the closed loop's poles.
//!
//! The loop closed with its gain times κ changes stability only where a pole crosses
//! the unit circle, that is where L(e^{jωTc}) = −1/κ: at the frequencies where L
//! crosses the negative real axis (0 to Nyquist, Nyquist included), at κ = 1/|L|.
//! Between two such gains the loop is stable or not throughout, and its poles at one
//! gain inside the interval decide which. From the nominal gain (κ = 1):
//!
//! - the **gain margin** is the lowest boundary above 1 past which the loop is
//!   unstable, in dB;
//! - the **gain-reduction margin** the highest boundary below 1 under which it is
//!   unstable (a loop with three integrators — the cascade's position summation, the
//!   velocity PI and the plant's rigid body — is unstable at low enough gain);
//! - a **conditional window**: the loop unstable past its gain margin and stable
//!   again at a higher gain — a conditionally stable loop, reported with the window.
//!
//! Gains are scanned from [`LOWEST_GAIN`] to [`HIGHEST_GAIN`] (±80 dB).

use serde::Serialize;

use super::margins::{bisect, log_grid, margins_with, Margins, Phase, GRID_POINTS};
use super::sampled::SampledLoop;

/// The lowest and highest loop gains scanned, as factors of the nominal.
pub const LOWEST_GAIN: f64 = 1e-4;
pub const HIGHEST_GAIN: f64 = 1e4;
/// The lowest frequency of the margins' grid, Hz: below the lowest crossings of
/// the negative real axis of the cascades rtid tunes.
pub const LOWEST_HZ: f64 = 0.01;

/// How a loop stands against instability.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Stability {
    /// Every closed-loop pole inside the unit circle.
    pub stable: bool,
    /// The largest closed-loop pole magnitude (below 1: stable).
    pub spectral_radius: f64,
    /// The factor by which the gain may fall before the loop is unstable, dB
    /// (`None`: not within −80 dB).
    pub gain_reduction_margin_db: Option<f64>,
    /// Where L meets −1 at that gain, Hz.
    pub gain_reduction_margin_hz: Option<f64>,
    /// A window of gain increase, dB, in which the loop is unstable and above which
    /// it is stable again (conditional stability): `[from, to]`.
    pub conditional_window_db: Option<[f64; 2]>,
}

/// A loop's margins (the gain margin from its poles) and stability.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LoopMargins {
    #[serde(flatten)]
    pub margins: Margins,
    #[serde(flatten)]
    pub stability: Stability,
}

impl LoopMargins {
    /// Whether the loop is stable with at least `phase_deg` of phase margin, `gain_db`
    /// of gain margin both ways, and no conditional window.
    pub fn meets(&self, phase_deg: f64, gain_db: f64) -> bool {
        let s = &self.stability;
        s.stable
            && s.conditional_window_db.is_none()
            && self
                .margins
                .phase_margin_deg
                .is_some_and(|pm| pm >= phase_deg)
            && self.margins.gain_margin_db.map_or(true, |g| g >= gain_db)
            && s.gain_reduction_margin_db.map_or(true, |g| g >= gain_db)
    }
}

/// A boundary of stability: the gain factor and the frequency where L meets −1/κ.
#[derive(Clone, Copy, Debug)]
struct Boundary {
    gain: f64,
    hz: f64,
}

/// The margins and stability of `l` on [`GRID_POINTS`] points from [`LOWEST_HZ`].
pub fn analyse(l: &SampledLoop) -> LoopMargins {
    analyse_on(l, GRID_POINTS)
}

/// [`analyse`] on `points` grid points.
pub fn analyse_on(l: &SampledLoop, points: usize) -> LoopMargins {
    let nyquist = l.nyquist_hz();
    let grid: Vec<_> = log_grid(LOWEST_HZ, 0.999 * nyquist, points)
        .into_iter()
        .filter_map(|f| l.at(f).map(|v| (f, v)))
        .collect();
    let mut margins = margins_with(&grid, |f| l.at(f), Phase::ToMinusOne);
    let boundaries = boundaries(l, &grid);
    let stability = stability(l, &boundaries);
    let above = |b: &&Boundary| b.gain > 1.0;
    // The gain margin: the first boundary above 1 where the loop turns unstable.
    let up = first_unstable(
        l,
        boundaries.iter().filter(above).copied().collect(),
        HIGHEST_GAIN,
    );
    margins.gain_margin_db = up.map(|b| 20.0 * b.gain.log10());
    margins.gain_margin_hz = up.map(|b| b.hz);
    LoopMargins { margins, stability }
}

/// The crossings of the negative real axis, ascending in gain, within the scan.
fn boundaries(l: &SampledLoop, grid: &[(f64, nalgebra::Complex<f64>)]) -> Vec<Boundary> {
    let mut out = Vec::new();
    for pair in grid.windows(2) {
        let ((f0, l0), (f1, l1)) = (pair[0], pair[1]);
        if l0.im * l1.im <= 0.0 && l0.im != l1.im && l0.re < 0.0 && l1.re < 0.0 {
            let hz = bisect(f0, f1, |f| l.at(f).map(|v| v.im));
            if let Some(v) = l.at(hz) {
                out.push(Boundary {
                    gain: 1.0 / v.norm(),
                    hz,
                });
            }
        }
    }
    let nyquist = l.nyquist_hz();
    if let Some(v) = l.at(nyquist).filter(|v| v.re < 0.0) {
        out.push(Boundary {
            gain: 1.0 / v.re.abs(),
            hz: nyquist,
        });
    }
    out.retain(|b| b.gain.is_finite() && b.gain > LOWEST_GAIN && b.gain < HIGHEST_GAIN);
    out.sort_by(|a, b| a.gain.total_cmp(&b.gain));
    out
}

/// Whether the loop is stable with its gain times `gain`.
fn stable_at(l: &SampledLoop, gain: f64) -> bool {
    l.spectral_radius(gain).is_some_and(|r| r < 1.0)
}

/// Walking away from the nominal gain across `boundaries` towards `end` (a gain
/// beyond them all), the first boundary past which the loop is unstable.
fn first_unstable(l: &SampledLoop, mut boundaries: Vec<Boundary>, end: f64) -> Option<Boundary> {
    boundaries.sort_by(|a, b| a.gain.ln().abs().total_cmp(&b.gain.ln().abs()));
    boundaries.iter().enumerate().find_map(|(i, b)| {
        let next = boundaries.get(i + 1).map_or(end, |n| n.gain);
        (!stable_at(l, (b.gain * next).sqrt())).then_some(*b)
    })
}

/// The loop's stability at its nominal gain, its gain-reduction margin and its
/// conditional window.
fn stability(l: &SampledLoop, boundaries: &[Boundary]) -> Stability {
    let radius = l.spectral_radius(1.0).unwrap_or(f64::INFINITY);
    let below: Vec<Boundary> = boundaries
        .iter()
        .filter(|b| b.gain < 1.0)
        .copied()
        .collect();
    let down = first_unstable(l, below, LOWEST_GAIN);
    let above: Vec<Boundary> = boundaries
        .iter()
        .filter(|b| b.gain > 1.0)
        .copied()
        .collect();
    Stability {
        stable: radius < 1.0,
        spectral_radius: radius,
        gain_reduction_margin_db: down.map(|b| -20.0 * b.gain.log10()),
        gain_reduction_margin_hz: down.map(|b| b.hz),
        conditional_window_db: window(l, &above),
    }
}

/// Above the nominal gain: the first interval in which the loop is unstable, if a
/// stable one follows it.
fn window(l: &SampledLoop, above: &[Boundary]) -> Option<[f64; 2]> {
    let mut gains: Vec<f64> = above.iter().map(|b| b.gain).collect();
    gains.push(HIGHEST_GAIN);
    let mut unstable_from: Option<f64> = None;
    for pair in gains.windows(2) {
        let mid = (pair[0] * pair[1]).sqrt();
        match (stable_at(l, mid), unstable_from) {
            (false, None) => unstable_from = Some(pair[0]),
            (true, Some(from)) => {
                return Some([20.0 * from.log10(), 20.0 * pair[0].log10()]);
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::tuning::sampled::{Closure, DiscretePlant};

    /// The preset worm gear's cascade: stable, its gain margin the gain at which its
    /// poles leave the unit circle (checked just below and above it).
    #[test]
    fn the_gain_margin_is_where_the_poles_leave_the_unit_circle() {
        let p = presets::load("worm-gear").unwrap();
        let plant = DiscretePlant::new(&p).unwrap();
        let l = SampledLoop::new(&plant, &p.controller, Closure::Cascade);
        let m = analyse(&l);
        assert!(m.stability.stable, "{m:?}");
        let gm = m.margins.gain_margin_db.unwrap();
        let k = 10f64.powf(gm / 20.0);
        assert!(
            stable_at(&l, 0.999 * k) && !stable_at(&l, 1.001 * k),
            "{m:?}"
        );
        let down = m.stability.gain_reduction_margin_db.unwrap();
        let k = 10f64.powf(-down / 20.0);
        assert!(
            stable_at(&l, 1.001 * k) && !stable_at(&l, 0.999 * k),
            "{m:?}"
        );
        assert!(m.stability.conditional_window_db.is_none());
    }
}
