//! The model's closed speed loop, setpoint → actual speed, exact on the sampled loop.
//!
//! The velocity loop opened at the torque setpoint, L(z), is
//! [`crate::tuning::sampled`]'s (the drive held over Tc, the encoder's dead time, the
//! backward-difference speed, the PI, the setpoint filters, the output delay as the
//! controller runs them). The setpoint enters where the speed reading leaves, at the
//! speed error r − v, and everything after it is common to both paths, so the reading
//! follows the setpoint as
//!
//! ```text
//! T(z) = L(z) / (1 + L(z)),   z = e^{jωTc}
//! ```
//!
//! — the drive's "actual speed" taken as the controller's own reading (the backward
//! difference of the encoder, with its dead time). Linear: no friction, no backlash, no
//! quantisation, no limits; the offset a measurement runs at keeps the friction
//! steady, which is why the drive runs it.

use nalgebra::Complex;

use crate::io::experiment_file::Conditions;
use crate::model::{ParamError, Params};
use crate::tuning::sampled::{Closure, DiscretePlant, SampledLoop};

/// The closed speed loop of one parameter set.
#[derive(Clone, Debug)]
pub struct ClosedSpeedLoop {
    open: SampledLoop,
}

impl ClosedSpeedLoop {
    /// The loop of `p` (validated) as it runs.
    pub fn new(p: &Params) -> Result<Self, ParamError> {
        p.validate()?;
        let plant = DiscretePlant::new(p)?;
        Ok(ClosedSpeedLoop {
            open: SampledLoop::new(&plant, &p.controller, Closure::Velocity),
        })
    }

    /// T at `hz`; `None` at 0 Hz (the integrator's pole) or where 1 + L vanishes.
    pub fn at(&self, hz: f64) -> Option<Complex<f64>> {
        let l = self.open.at(hz)?;
        let t = l / (l + 1.0);
        t.is_finite().then_some(t)
    }

    /// Whether the loop closed is stable: the closed loop's poles inside the unit
    /// circle (`None` where they are not found) — but for the position's, which no
    /// speed loop feeds back: a pole at z = 1 exactly, counted as on the circle
    /// within 1e-9.
    pub fn stable(&self) -> Option<bool> {
        self.open.spectral_radius(1.0).map(|r| r <= 1.0 + 1e-9)
    }
}

/// `p` as a speed-loop measurement ran it: the speed controller's sample period and
/// gains where the experiment's conditions state them (`loop_period_s`,
/// `controller.Kvp`/`Kvi`), the model's otherwise.
pub fn as_measured(p: &Params, c: &Conditions) -> Params {
    let mut q = p.clone();
    if let Some(tc) = c.loop_period_s {
        q.controller.tc = tc;
    }
    if let Some(f) = &c.controller {
        f.apply(&mut q.controller);
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use std::f64::consts::TAU;

    /// A rigid body 1/(J·s²) held over Tc is θ/u = Tc²(z + 1)/(2J(z − 1)²); the
    /// backward-difference speed (z − 1)/(z·Tc) of it under the PI Kvp + Kvi·Tc·z/(z − 1)
    /// closes to C·P/(1 + C·P): the closed loop written out by hand for a direct drive
    /// without damping, delay or filters.
    #[test]
    fn a_rigid_axis_closes_as_written_out_by_hand() {
        let mut p = presets::load("direct-drive").unwrap();
        p.ct = 0.0;
        p.encoder_delay = 0.0;
        p.controller.filters.clear();
        p.controller.output_delay_periods = 0.0;
        let (tc, j, kvp, kvi) = (p.controller.tc, p.jt, p.controller.kvp, p.controller.kvi);
        let g = p.controller.drive_gain;
        let t = ClosedSpeedLoop::new(&p).unwrap();
        for hz in [1.0, 17.0, 130.0, 900.0, 1900.0] {
            let z = Complex::new(0.0, TAU * hz * tc).exp();
            let speed_per_torque = (z + 1.0) * tc / (z * (z - 1.0) * 2.0 * j);
            let c = (z * kvi * tc / (z - 1.0) + kvp) * g;
            let expected = c * speed_per_torque / (c * speed_per_torque + 1.0);
            let got = t.at(hz).unwrap();
            assert!(
                (got / expected - 1.0).norm() < 1e-9,
                "{hz}: {got} vs {expected}"
            );
        }
    }

    /// The preset's loops are stable and follow a slow setpoint: T → 1.
    #[test]
    fn a_stable_loop_follows_a_slow_setpoint() {
        for name in ["direct-drive", "two-mass", "worm-gear"] {
            let p = presets::load(name).unwrap();
            let t = ClosedSpeedLoop::new(&p).unwrap();
            assert_eq!(t.stable(), Some(true), "{name}");
            let low = t.at(0.01).unwrap();
            assert!((low - 1.0).norm() < 1e-3, "{name}: {low}");
        }
    }
}
