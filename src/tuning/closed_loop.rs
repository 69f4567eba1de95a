//! The loops closed (docs/tuning.md, "The closed loops"): what the drive's and the
//! CNC's commissioning tools show beside the open loops.
//!
//! Exact on the sampled loop ([`super::sampled`]), from the velocity loop alone L_v
//! and the cascade L_c opened at the torque setpoint (the controller's law is
//! u = C·(Kpp·(r − y) − D·y) semi-closed, D the backward-difference speed; the
//! position path alone is L_c − L_v):
//!
//! ```text
//! T_v = L_v/(1 + L_v)            the closed speed loop, ω* → measured speed
//! T_p = (L_c − L_v)/(1 + L_c)    the closed position loop, θref → the position the
//!                                 loop reads (motor × Rg·Rw, or the table)
//! S   = 1/(1 + L_c)              the cascade's sensitivity; |S|max is the inverse of
//!                                 the shortest distance of L_c from −1
//! ```
//!
//! The **equivalent time constant** of the closed speed loop (SINUMERIK's MD32810,
//! the feed-forward's balancing) is that of the first-order lag with T_v's −3 dB
//! bandwidth: 1/(2π·f₋₃dB).
//!
//! [`peak_db`] is the quasi-continuous closed position loop's largest gain
//! (`Setting::position_peak_db`), kept beside the exact figures.

use std::f64::consts::TAU;

use nalgebra::Complex;
use serde::Serialize;

use super::margins::{bisect, log_grid, GRID_POINTS};
use super::open_loop::{VelocityLoop, VelocityPi};
use super::sampled::{Closure, DiscretePlant, SampledLoop};
use super::stability::LOWEST_HZ;
use crate::model::params::ControllerParams;

/// The closed loops' figures of one setting.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ClosedLoop {
    /// The closed speed loop's −3 dB bandwidth, Hz (`None`: not below Nyquist).
    pub speed_bandwidth_hz: Option<f64>,
    /// Its largest gain, dB.
    pub speed_peak_db: f64,
    /// 1/(2π·the speed loop's bandwidth), s: MD32810.
    pub equivalent_time_s: Option<f64>,
    /// The closed position loop's −3 dB bandwidth, Hz, and its largest gain, dB.
    pub position_bandwidth_hz: Option<f64>,
    pub position_peak_db: f64,
    /// The cascade's largest sensitivity |S|, dB, and where, Hz.
    pub sensitivity_peak_db: f64,
    pub sensitivity_peak_hz: f64,
}

/// The closed loops' gains on a grid, for a plot: (Hz, dB).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curves {
    pub speed: Vec<(f64, f64)>,
    pub position: Vec<(f64, f64)>,
    pub sensitivity: Vec<(f64, f64)>,
}

/// Both open loops of one setting, exact on the sampled loop.
struct Loops {
    velocity: SampledLoop,
    cascade: SampledLoop,
}

impl Loops {
    fn new(plant: &DiscretePlant, c: &ControllerParams) -> Loops {
        Loops {
            velocity: SampledLoop::new(plant, c, Closure::Velocity),
            cascade: SampledLoop::new(plant, c, Closure::Cascade),
        }
    }

    /// (T_v, T_p, S) at `hz`.
    fn at(&self, hz: f64) -> Option<[Complex<f64>; 3]> {
        let (lv, lc) = (self.velocity.at(hz)?, self.cascade.at(hz)?);
        let one = Complex::new(1.0, 0.0);
        Some([lv / (one + lv), (lc - lv) / (one + lc), one / (one + lc)])
    }

    fn nyquist_hz(&self) -> f64 {
        self.cascade.nyquist_hz()
    }
}

/// The closed loops' figures of `c` on `plant`, on [`GRID_POINTS`] log-spaced points
/// from [`LOWEST_HZ`] to 0.999·Nyquist, each bandwidth bisected.
pub fn analyse(plant: &DiscretePlant, c: &ControllerParams) -> ClosedLoop {
    let loops = Loops::new(plant, c);
    let grid: Vec<(f64, [Complex<f64>; 3])> =
        log_grid(LOWEST_HZ, 0.999 * loops.nyquist_hz(), GRID_POINTS)
            .into_iter()
            .filter_map(|f| loops.at(f).map(|v| (f, v)))
            .collect();
    let db = |v: Complex<f64>| 20.0 * v.norm().log10();
    let peak = |k: usize| {
        grid.iter()
            .map(|(f, v)| (db(v[k]), *f))
            .fold(
                (f64::NEG_INFINITY, 0.0),
                |a, b| if b.0 > a.0 { b } else { a },
            )
    };
    let bandwidth = |k: usize| {
        let below = |v: &[Complex<f64>; 3]| v[k].norm() < std::f64::consts::FRAC_1_SQRT_2;
        let i = grid.iter().position(|(_, v)| below(v))?;
        if i == 0 {
            return None;
        }
        let gap = |f: f64| {
            loops
                .at(f)
                .map(|v| v[k].norm() - std::f64::consts::FRAC_1_SQRT_2)
        };
        Some(bisect(grid[i - 1].0, grid[i].0, gap))
    };
    let speed_bandwidth_hz = bandwidth(0);
    let (sensitivity_peak_db, sensitivity_peak_hz) = peak(2);
    ClosedLoop {
        speed_bandwidth_hz,
        speed_peak_db: peak(0).0,
        equivalent_time_s: speed_bandwidth_hz.map(|f| 1.0 / (TAU * f)),
        position_bandwidth_hz: bandwidth(1),
        position_peak_db: peak(1).0,
        sensitivity_peak_db,
        sensitivity_peak_hz,
    }
}

/// The closed speed loop's equivalent time constant of `c` on `plant`, s, on a grid
/// of `points` (the velocity loop alone).
pub fn equivalent_time(plant: &DiscretePlant, c: &ControllerParams, points: usize) -> Option<f64> {
    let l = SampledLoop::new(plant, c, Closure::Velocity);
    let gain = |f: f64| {
        l.at(f)
            .map(|v| (v / (Complex::new(1.0, 0.0) + v)).norm() - std::f64::consts::FRAC_1_SQRT_2)
    };
    let grid = log_grid(LOWEST_HZ, 0.999 * l.nyquist_hz(), points);
    let i = grid
        .iter()
        .position(|&f| gain(f).is_some_and(|g| g < 0.0))?;
    (i > 0).then(|| 1.0 / (TAU * bisect(grid[i - 1], grid[i], gain)))
}

/// The closed loops' gains of `c` on `plant` on `points` log-spaced points from
/// `lowest_hz` to 0.99·Nyquist, dB.
pub fn curves(
    plant: &DiscretePlant,
    c: &ControllerParams,
    lowest_hz: f64,
    points: usize,
) -> Curves {
    let loops = Loops::new(plant, c);
    let mut out = Curves::default();
    for f in log_grid(lowest_hz, 0.99 * loops.nyquist_hz(), points) {
        if let Some(v) = loops.at(f) {
            let db = |x: Complex<f64>| 20.0 * x.norm().log10();
            out.speed.push((f, db(v[0])));
            out.position.push((f, db(v[1])));
            out.sensitivity.push((f, db(v[2])));
        }
    }
    out
}

/// The largest gain of the closed position loop with gain `kpp` (1/s), dB, on the
/// log grid from 0.1 Hz to 0.99·Nyquist, quasi-continuous: with the velocity loop's
/// closed-loop response T_v = L/(1 + L) (ω* to the measured speed), the measured
/// position follows ω* through the controller's own summation Tc/(1 − z⁻¹) (the
/// inverse of its backward difference), so L_p(jω) = Kpp·T_v(jω)·Tc/(1 − e^{−jωTc})
/// and T_p = L_p/(1 + L_p). A position loop without overshoot in the frequency
/// domain has no gain above 0 dB.
pub fn peak_db(lp: &VelocityLoop, pi: VelocityPi, kpp: f64) -> f64 {
    let tc = lp.tc();
    log_grid(0.1, 0.99 * lp.nyquist_hz(), GRID_POINTS)
        .into_iter()
        .filter_map(|hz| {
            let l = lp.at(pi, hz)?;
            let tv = l / (l + 1.0);
            let z_inv = Complex::new(0.0, -TAU * hz * tc).exp();
            let lp_ = kpp * tv * tc / (1.0 - z_inv);
            Some(20.0 * (lp_ / (lp_ + 1.0)).norm().log10())
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    /// The direct drive, a rigid body: its speed loop J·s with the PI is a
    /// second-order loop whose bandwidth lies above its crossover, so the equivalent
    /// time constant lies between half and once 1/(2π·f_c); the position loop's
    /// bandwidth lies near Kpp/2π; |S|max is the inverse of the distance of L from
    /// −1, at least 1/(2·sin(PM/2)).
    #[test]
    fn the_direct_drives_closed_loops_are_those_of_a_rigid_body() {
        let p = presets::load("direct-drive").unwrap();
        let plant = DiscretePlant::new(&p).unwrap();
        let c = analyse(&plant, &p.controller);
        let s = crate::tuning::Setting::of(&p, &p.controller).unwrap();
        let fc = s.velocity_loop.crossover_hz.unwrap();
        let t = c.equivalent_time_s.unwrap() * TAU * fc;
        assert!(t > 0.5 && t < 1.0, "{c:?}: T·2π·fc = {t}");
        let kpp_hz = p.controller.kpp / TAU;
        let pb = c.position_bandwidth_hz.unwrap();
        assert!(pb > kpp_hz && pb < 3.0 * kpp_hz, "{c:?}");
        let pm = s.cascade.margins.phase_margin_deg.unwrap().to_radians();
        let bound = -20.0 * (2.0 * (pm / 2.0).sin()).log10();
        assert!(
            c.sensitivity_peak_db >= bound - 0.05,
            "{c:?} against {bound} dB"
        );
        assert!(c.speed_peak_db < 3.0 && c.position_peak_db < 1.0, "{c:?}");
    }
}
