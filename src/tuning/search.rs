//! The velocity PI and the position gain for target margins (docs/tuning.md).
//!
//! Rules: the PI's corner Kvi/Kvp is a quarter of the crossover, ω_c/4 (its phase
//! lag at ω_c is atan(1/4) = 14°); for a crossover f_c, Kvp makes |L(f_c)| = 1. The
//! crossover is scanned upwards on a log grid from [`LOWEST_CROSSOVER_HZ`] to
//! [`HIGHEST_CROSSOVER`]·Nyquist, and the tuned crossover is the last one whose loop
//! meets both targets (phase margin ≥ target, gain margin ≥ floor; a loop with no
//! phase crossover meets any floor) before the first that fails, refined by bisection
//! between the two. Stopping at the first failure keeps the tuned loop on the
//! connected range of good crossovers from below: a higher crossover that passes again
//! (past a resonance, or once the phase has wrapped) is not taken. The position gain is Kpp = ω_c/4: with the velocity loop read as a
//! first-order lag of bandwidth ω_c, the position loop s² + ω_c·s + ω_c·Kpp is
//! critically damped (no overshoot); [`super::position`] checks the closed position
//! loop for a peak above 0 dB.

use std::f64::consts::TAU;

use nalgebra::Complex;

use super::margins::{log_grid, margins_on, Margins, GRID_POINTS};
use super::open_loop::{VelocityLoop, VelocityPi};
use super::{Targets, TuneError};

/// The lowest crossover tried, Hz.
pub const LOWEST_CROSSOVER_HZ: f64 = 0.5;
/// The highest crossover tried, as a fraction of Nyquist.
pub const HIGHEST_CROSSOVER: f64 = 0.5;
/// Crossovers tried on the scan.
const SCAN_POINTS: usize = 300;
/// Bisection steps between the last good and first failing crossover.
const REFINE_STEPS: usize = 30;
/// The PI corner over the crossover, Kvi/Kvp over ω_c.
pub const PI_CORNER: f64 = 0.25;
/// The position gain over the velocity crossover, Kpp over ω_c.
pub const POSITION_OVER_VELOCITY: f64 = 0.25;

/// The loop's fixed part on its margin grid, evaluated once.
pub struct Grid<'a> {
    lp: &'a VelocityLoop,
    points: Vec<(f64, Complex<f64>)>,
}

impl<'a> Grid<'a> {
    /// The grid from 0.1 Hz to 0.99·Nyquist.
    pub fn new(lp: &'a VelocityLoop) -> Grid<'a> {
        let points = log_grid(0.1, 0.99 * lp.nyquist_hz(), GRID_POINTS)
            .into_iter()
            .filter_map(|f| lp.without_controller(f).map(|v| (f, v)))
            .collect();
        Grid { lp, points }
    }

    /// The margins with the gains `pi`.
    pub fn margins(&self, pi: VelocityPi) -> Margins {
        let values: Vec<(f64, Complex<f64>)> = self
            .points
            .iter()
            .map(|&(f, v)| (f, self.lp.controller(pi, f) * v))
            .collect();
        margins_on(&values, |f| self.lp.at(pi, f))
    }

    /// The gains of the rules above with their crossover at `hz`.
    pub fn gains_at(&self, hz: f64) -> Option<VelocityPi> {
        self.gains_with_corner(hz, PI_CORNER)
    }

    /// The gains with their crossover at `hz` and the PI's corner Kvi/Kvp at
    /// `corner` of it.
    pub fn gains_with_corner(&self, hz: f64, corner: f64) -> Option<VelocityPi> {
        let ratio = corner * TAU * hz;
        let unit = VelocityPi {
            kvp: 1.0,
            kvi: ratio,
        };
        let g = self.lp.at(unit, hz)?.norm();
        (g > 0.0 && g.is_finite()).then(|| VelocityPi {
            kvp: 1.0 / g,
            kvi: ratio / g,
        })
    }
}

/// A velocity loop's tuned gains and margins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Velocity {
    pub pi: VelocityPi,
    pub margins: Margins,
}

/// The largest crossover meeting `targets`, its gains and margins.
pub fn velocity(grid: &Grid, targets: Targets) -> Result<Velocity, TuneError> {
    let meets = |m: &Margins| {
        m.phase_margin_deg
            .is_some_and(|pm| pm >= targets.phase_margin_deg)
            && m.gain_margin_db
                .map_or(true, |gm| gm >= targets.gain_margin_db)
    };
    let at = |hz: f64| {
        grid.gains_at(hz).map(|pi| Velocity {
            pi,
            margins: grid.margins(pi),
        })
    };
    let hi = HIGHEST_CROSSOVER * grid.lp.nyquist_hz();
    let mut best: Option<(f64, Velocity)> = None;
    let mut first_fail: Option<f64> = None;
    let mut closest: Option<Velocity> = None;
    for hz in log_grid(LOWEST_CROSSOVER_HZ, hi, SCAN_POINTS) {
        let Some(v) = at(hz) else { continue };
        if meets(&v.margins) {
            best = Some((hz, v));
        } else if best.is_some() {
            first_fail = Some(hz);
            break;
        }
        let pm = |v: &Velocity| v.margins.phase_margin_deg.unwrap_or(f64::NEG_INFINITY);
        if closest.map_or(true, |c| pm(&v) > pm(&c)) {
            closest = Some(v);
        }
    }
    let Some((mut good, mut result)) = best else {
        return Err(unreachable(targets, closest));
    };
    if let Some(mut bad) = first_fail {
        for _ in 0..REFINE_STEPS {
            let mid = (good * bad).sqrt();
            match at(mid) {
                Some(v) if meets(&v.margins) => (good, result) = (mid, v),
                _ => bad = mid,
            }
        }
    }
    Ok(result)
}

fn unreachable(targets: Targets, closest: Option<Velocity>) -> TuneError {
    let m = closest.map(|v| v.margins).unwrap_or_default();
    TuneError::Unreachable {
        phase_margin_deg: targets.phase_margin_deg,
        gain_margin_db: targets.gain_margin_db,
        best_phase_margin_deg: m.phase_margin_deg,
        best_crossover_hz: m.crossover_hz,
        best_gain_margin_db: m.gain_margin_db,
    }
}

/// The position gain for a velocity loop crossing over at `crossover_hz`, 1/s.
pub fn position_gain(crossover_hz: f64) -> f64 {
    POSITION_OVER_VELOCITY * TAU * crossover_hz
}
