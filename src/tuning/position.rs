//! The position loop closed around the tuned velocity loop (docs/tuning.md): with the
//! velocity loop's closed-loop response T_v = L/(1 + L) (ω* to the measured speed),
//! the measured position follows ω* through the controller's own summation
//! Tc/(1 − z⁻¹) (the inverse of its backward difference), so
//!
//! ```text
//! L_p(jω) = Kpp·T_v(jω)·Tc/(1 − e^{−jωTc}),    T_p = L_p/(1 + L_p)   (θm,meas/θref)
//! ```
//!
//! [`peak_db`] is the largest |T_p| on the grid, dB: a position loop without overshoot
//! in the frequency domain has none above 0 dB.

use nalgebra::Complex;

use super::margins::{log_grid, GRID_POINTS};
use super::open_loop::{VelocityLoop, VelocityPi};

/// The largest gain of the closed position loop with gain `kpp` (1/s), dB, on the
/// log grid from 0.1 Hz to 0.99·Nyquist.
pub fn peak_db(lp: &VelocityLoop, pi: VelocityPi, kpp: f64) -> f64 {
    let tc = lp.tc();
    log_grid(0.1, 0.99 * lp.nyquist_hz(), GRID_POINTS)
        .into_iter()
        .filter_map(|hz| {
            let l = lp.at(pi, hz)?;
            let tv = l / (l + 1.0);
            let z_inv = Complex::new(0.0, -std::f64::consts::TAU * hz * tc).exp();
            let lp_ = kpp * tv * tc / (1.0 - z_inv);
            Some(20.0 * (lp_ / (lp_ + 1.0)).norm().log10())
        })
        .fold(f64::NEG_INFINITY, f64::max)
}
