//! The exact linear frequency response of the drive (no backlash, no friction, no
//! fluctuation; [`LinearModel`]): the one function behind every linear gain in rtid —
//! the model's resonances in identification and sweeps, the linear curve of a
//! frequency-response file, the initial state of the nonlinear test.
//!
//! For a unit motor torque at ω the coordinates respond with the complex amplitudes
//! X = (K − ω²·M + iω·C)⁻¹·F; a [`Channel`] is the ratio of two of them.

use std::f64::consts::TAU;

use nalgebra::{Complex, DVector};

use super::modes::LinearModel;
use super::params::{ParamError, Params};

/// Which ratio of the response.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Table over motor angle × Rg·Rw (the paper's gain, docs/experiments.md (frequency response)): 1 at low
    /// frequency, peaks at the motor-held modes.
    TableOverMotor,
    /// Motor angle over motor torque (the compliance seen by the motor), rad/(N·m):
    /// antiresonances at the motor-held modes, resonances at the free ones.
    MotorOverTorque,
}

/// The linear response of one parameter set, built once and evaluated at any
/// frequency.
#[derive(Clone, Debug)]
pub struct LinearResponse {
    model: LinearModel,
    force: DVector<Complex<f64>>,
    motor: usize,
    table: usize,
    ratio: f64,
    channel: Channel,
}

impl LinearResponse {
    /// Validates `p` and builds its linear model.
    pub fn new(p: &Params, channel: Channel) -> Result<Self, ParamError> {
        let model = LinearModel::new(p)?;
        let table = model.index("theta_t").expect("every topology has theta_t");
        // A direct drive's motor is its table: one body, table/motor = 1.
        let motor = model.index("theta_m").unwrap_or(table);
        let mut force = DVector::from_element(model.n_dof(), Complex::new(0.0, 0.0));
        force[motor] = Complex::new(1.0, 0.0);
        Ok(LinearResponse {
            model,
            force,
            motor,
            table,
            ratio: p.ratio(),
            channel,
        })
    }

    /// The complex ratio at `hz`; `None` where the system is singular (0 Hz on the
    /// free drive, which has no static stiffness).
    pub fn at(&self, hz: f64) -> Option<Complex<f64>> {
        let x = self.model.response(TAU * hz, &self.force)?;
        Some(match self.channel {
            Channel::TableOverMotor => x[self.table] / (x[self.motor] * self.ratio),
            Channel::MotorOverTorque => x[self.motor],
        })
    }

    /// The gain at `hz`, dB (−∞ where the system is singular).
    pub fn gain_db(&self, hz: f64) -> f64 {
        self.at(hz)
            .map_or(f64::NEG_INFINITY, |h| 20.0 * h.norm().log10())
    }

    /// Gain (dB) and phase (deg) at each of `freqs_hz` (NaN where singular).
    pub fn gain_phase(&self, freqs_hz: &[f64]) -> Vec<(f64, f64)> {
        freqs_hz
            .iter()
            .map(|&hz| match self.at(hz) {
                Some(h) => (20.0 * h.norm().log10(), h.arg().to_degrees()),
                None => (f64::NAN, f64::NAN),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_gain_tends_to_one_at_low_frequency_and_peaks_near_the_held_modes() {
        let p = presets::load("worm-gear").unwrap();
        let r = LinearResponse::new(&p, Channel::TableOverMotor).unwrap();
        assert!(r.gain_db(1.0).abs() < 0.01, "{}", r.gain_db(1.0));
        assert!(r.gain_db(186.9) > r.gain_db(150.0) + 20.0);
    }

    #[test]
    fn the_motor_compliance_dips_at_the_held_mode() {
        let p = presets::load("roller-gear-cam").unwrap();
        let r = LinearResponse::new(&p, Channel::MotorOverTorque).unwrap();
        // Motor held: 166.9 Hz (docs/model.md §11); the compliance has its antiresonance there.
        let g = |hz: f64| r.gain_db(hz);
        assert!(g(166.9) < g(150.0) - 20.0 && g(166.9) < g(185.0) - 20.0);
    }
}
