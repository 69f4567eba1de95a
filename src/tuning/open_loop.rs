//! The velocity loop's open-loop frequency response on the sampled loop, opened at the
//! torque setpoint (docs/tuning.md):
//!
//! ```text
//! L(jω) = C_v(z)·F(z)·drive_gain·(θm/T)(jω)·jω·H(jω),   z = e^{jωTc}
//! C_v(z) = Kvp + Kvi·Tc·z/(z − 1)                          velocity PI
//! F(z)   = the setpoint filters in series (Tustin, as the controller runs them)
//! H(jω)  = (1 − e^{−jωTc})/(jωTc)                          zero-order hold
//!        · (1 − e^{−jωTc})/(jωTc)                          backward-difference speed
//!        · e^{−jω·encoder_delay}·e^{−jωTc·output_delay_periods}
//!        · a/(1 − (1 − a)·z⁻¹)                            the current loop's lag,
//!                                                          a = 1 − e^{−Tc/T_i}
//! ```
//!
//! This is the quasi-continuous frequency response of the sampled loop: the plant's
//! continuous response at ω with the hold and the delays, the aliased images of the
//! plant's response (at ω ± k·2π/Tc) neglected. It is exact for the controller's own
//! discrete parts and valid below Nyquist where the plant's response above Nyquist is
//! small.

use std::f64::consts::TAU;

use nalgebra::Complex;

use crate::controller::Biquad;
use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::{ParamError, Params, SetpointFilter};

/// The parts of the velocity loop that do not depend on the PI gains: the plant, the
/// sampling effects and the setpoint filters.
#[derive(Clone, Debug)]
pub struct VelocityLoop {
    plant: LinearResponse,
    tc: f64,
    drive_gain: f64,
    /// Encoder dead time plus the output delay, s.
    delay: f64,
    filters: Vec<Biquad>,
    /// The current loop's lag factor a (0: none).
    lag: f64,
}

/// Velocity PI gains: output·s/rad and output/rad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocityPi {
    pub kvp: f64,
    pub kvi: f64,
}

impl VelocityLoop {
    /// The loop of `p` with the setpoint filters `filters` (in place of `p`'s own).
    pub fn new(p: &Params, filters: &[SetpointFilter]) -> Result<Self, ParamError> {
        let c = &p.controller;
        Ok(VelocityLoop {
            plant: LinearResponse::new(p, Channel::MotorOverTorque)?,
            tc: c.tc,
            drive_gain: c.drive_gain,
            delay: p.encoder_delay + c.output_delay_periods * c.tc,
            filters: filters.iter().map(|f| Biquad::new(f, c.tc)).collect(),
            lag: if c.current_lag_s > 0.0 {
                -(-c.tc / c.current_lag_s).exp_m1()
            } else {
                0.0
            },
        })
    }

    /// The control period, s.
    pub fn tc(&self) -> f64 {
        self.tc
    }

    /// The Nyquist frequency 1/(2·Tc), Hz.
    pub fn nyquist_hz(&self) -> f64 {
        0.5 / self.tc
    }

    /// Everything but C_v at `hz`: F·drive_gain·jω·(θm/T)·H. `None` where the plant is
    /// singular (0 Hz; an undamped resonance met exactly).
    pub fn without_controller(&self, hz: f64) -> Option<Complex<f64>> {
        let compliance = self.plant.at(hz)?;
        let w = TAU * hz;
        let jw = Complex::new(0.0, w);
        let step = Complex::new(1.0, 0.0) - (-jw * self.tc).exp();
        let hold = step / (jw * self.tc);
        let speed = step / (jw * self.tc);
        let delay = (-jw * self.delay).exp();
        let filters = self
            .filters
            .iter()
            .map(|b| {
                let (re, im) = b.response(hz, self.tc);
                Complex::new(re, im)
            })
            .product::<Complex<f64>>();
        let lag = if self.lag > 0.0 {
            let z_inv = (-jw * self.tc).exp();
            self.lag / (1.0 - (1.0 - self.lag) * z_inv)
        } else {
            Complex::new(1.0, 0.0)
        };
        Some(filters * self.drive_gain * jw * compliance * hold * speed * delay * lag)
    }

    /// C_v at `hz`: Kvp + Kvi·Tc·z/(z − 1), z = e^{jωTc}.
    pub fn controller(&self, pi: VelocityPi, hz: f64) -> Complex<f64> {
        let z = Complex::new(0.0, TAU * hz * self.tc).exp();
        pi.kvp + pi.kvi * self.tc * z / (z - 1.0)
    }

    /// L at `hz` with the gains `pi`.
    pub fn at(&self, pi: VelocityPi, hz: f64) -> Option<Complex<f64>> {
        Some(self.controller(pi, hz) * self.without_controller(hz)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn at_low_frequency_the_loop_is_the_pi_over_the_total_inertia() {
        // Two-mass: below the coupling mode the drive is one inertia Jm + Jt with
        // viscous Cm + Ct; the sampling effects are 1 to O(ωTc).
        let p = presets::load("two-mass").unwrap();
        let l = VelocityLoop::new(&p, &[]).unwrap();
        let pi = VelocityPi {
            kvp: 0.024,
            kvi: 0.36,
        };
        let hz = 2.0;
        let s = Complex::new(0.0, TAU * hz);
        let expected = (pi.kvp + pi.kvi / s) / (s * (p.jm + p.jt) + p.cm + p.ct);
        let got = l.at(pi, hz).unwrap();
        assert!((got / expected - 1.0).norm() < 1e-2, "{got} vs {expected}");
    }
}
