//! A body's friction at a steady speed, in one vocabulary the model, the map fit,
//! the objectives and the compensation share: a Coulomb level, a viscous slope and,
//! optionally, a Stribeck rise (docs/model.md §2):
//!
//! ```text
//! T(ω) = sgn(ω)·(coulomb + rise·exp(−(|ω|/speed)^shape)) + viscous·ω
//! ```
//!
//! A body's law meets its registry names in one place, [`Body::names`] — `fm`, `Cm`,
//! `fsm`, `vsm` for the motor, `fw`, `Cw`, `fsw`, `vsw` for the driving shaft, `ft`,
//! `Ct`, `fst`, `vst` for the table, `stribeck_shape` shared — and [`Params::steady`]
//! and [`Params::set_steady`] read and write it typed. A friction map measures the law
//! lumped at the motor, every body's through the ratios (its fit names that law by
//! the literature's Fc, Fv, Fs, vs, delta: `estimation/friction_law`); what a body's
//! own law must be to make it is the objectives' business.

use crate::model::params::Params;

/// A body of the drive, as the registry names its friction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Body {
    Motor,
    Shaft,
    Table,
}

/// The registry's names of a body's friction parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BodyNames {
    /// The Coulomb level.
    pub coulomb: &'static str,
    /// The viscous damping.
    pub viscous: &'static str,
    /// The Stribeck rise above the Coulomb level at rest.
    pub rise: &'static str,
    /// The Stribeck speed.
    pub speed: &'static str,
}

/// The shape exponent δ every body's rise shares.
pub const SHAPE: &str = "stribeck_shape";

impl Body {
    /// The body's friction parameters in the registry.
    pub fn names(self) -> BodyNames {
        let (coulomb, viscous, rise, speed) = match self {
            Body::Motor => ("fm", "Cm", "fsm", "vsm"),
            Body::Shaft => ("fw", "Cw", "fsw", "vsw"),
            Body::Table => ("ft", "Ct", "fst", "vst"),
        };
        BodyNames {
            coulomb,
            viscous,
            rise,
            speed,
        }
    }
}

/// A Stribeck rise: the level above the Coulomb one at rest, the speed at which it has
/// fallen to 1/e, and the shape exponent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rise {
    /// N·m (N), ≥ 0.
    pub rise: f64,
    /// rad/s (m/s), > 0.
    pub speed: f64,
    /// δ, > 0.
    pub shape: f64,
}

/// A body's friction at steady speed (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyFriction {
    /// N·m (N).
    pub coulomb: f64,
    /// N·m·s/rad (N·s/m).
    pub viscous: f64,
    /// `None`: the Coulomb law.
    pub rise: Option<Rise>,
}

impl SteadyFriction {
    /// No friction at all.
    pub const NONE: SteadyFriction = SteadyFriction {
        coulomb: 0.0,
        viscous: 0.0,
        rise: None,
    };

    /// The torque (force) opposing the body at speed `w` ≠ 0 — odd in `w`.
    pub fn effort(&self, w: f64) -> f64 {
        let level = match self.rise {
            Some(r) => self.coulomb + r.rise * (-(w.abs() / r.speed).powf(r.shape)).exp(),
            None => self.coulomb,
        };
        w.signum() * level + self.viscous * w
    }

    /// The values by the registry's names of `body`: Coulomb level, damping, then the
    /// rise, its speed and the shape where a rise is set.
    pub fn named(&self, body: Body) -> Vec<(&'static str, f64)> {
        let n = body.names();
        let mut out = vec![(n.coulomb, self.coulomb), (n.viscous, self.viscous)];
        if let Some(r) = self.rise {
            out.extend([(n.rise, r.rise), (n.speed, r.speed), (SHAPE, r.shape)]);
        }
        out
    }
}

impl Params {
    /// The steady friction of `body` as its parameters state it (a rise of 0: the
    /// Coulomb law).
    pub fn steady(&self, body: Body) -> SteadyFriction {
        let (coulomb, viscous, rise, speed) = match body {
            Body::Motor => (self.fm, self.cm, self.fsm, self.vsm),
            Body::Shaft => (self.fw, self.cw, self.fsw, self.vsw),
            Body::Table => (self.ft, self.ct, self.fst, self.vst),
        };
        SteadyFriction {
            coulomb,
            viscous,
            rise: (rise != 0.0).then_some(Rise {
                rise,
                speed,
                shape: self.stribeck_shape,
            }),
        }
    }

    /// Sets the steady friction of `body`: its Coulomb level, damping and rise (0
    /// without one; the rise's speed and the shared shape are set only with a rise).
    pub fn set_steady(&mut self, body: Body, law: &SteadyFriction) {
        let rise = law.rise.map_or(0.0, |r| r.rise);
        let (coulomb, viscous, own_rise, speed) = match body {
            Body::Motor => (&mut self.fm, &mut self.cm, &mut self.fsm, &mut self.vsm),
            Body::Shaft => (&mut self.fw, &mut self.cw, &mut self.fsw, &mut self.vsw),
            Body::Table => (&mut self.ft, &mut self.ct, &mut self.fst, &mut self.vst),
        };
        (*coulomb, *viscous, *own_rise) = (law.coulomb, law.viscous, rise);
        if let Some(r) = law.rise {
            *speed = r.speed;
            self.stribeck_shape = r.shape;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn a_body_law_round_trips_through_its_registry_names() {
        let mut p = presets::load("worm-gear").unwrap();
        p.topology = crate::model::Topology::SpurGear;
        let law = SteadyFriction {
            coulomb: 0.3,
            viscous: 0.02,
            rise: Some(Rise {
                rise: 0.1,
                speed: 0.5,
                shape: 1.5,
            }),
        };
        for body in [Body::Motor, Body::Shaft, Body::Table] {
            p.set_steady(body, &law);
            assert_eq!(p.steady(body), law);
            for (name, value) in law.named(body) {
                assert_eq!(p.get(name).unwrap(), Some(value), "{name}");
            }
        }
        p.set_steady(Body::Motor, &SteadyFriction::NONE);
        assert_eq!(p.steady(Body::Motor), SteadyFriction::NONE);
        let at = |w: f64| law.effort(w);
        assert!((at(0.5) - (0.3 + 0.1 / std::f64::consts::E + 0.01)).abs() < 1e-15);
        assert_eq!(at(-2.0), -at(2.0));
    }
}
