//! The Stribeck law (docs/model.md §2): a sliding body meets
//! f(ω) = fc + rise·exp(−(|ω|/vs)^δ) — its Coulomb level plus a rise that falls off
//! with speed — and a body at rest breaks away only when the torque on it exceeds the
//! static level fc + rise. Parameters `fsm`, `fsw`, `fst` (the rises), `vsm`, `vsw`,
//! `vst` (the speeds) and `stribeck_shape` (δ) of the registry, with the Coulomb
//! levels `fm`, `fw`, `ft`. The kernel decides stick and direction at a step's first
//! stage and evaluates f at every stage's velocity (the level changes within a step,
//! its sign does not).

use super::FrictionLaw;
use crate::model::params::{Params, Topology};

/// The Stribeck law of motor, shaft and table (docs/model.md §2): per body the Coulomb
/// level, the rise above it at rest and 1/vs; one shape exponent δ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stribeck {
    coulomb: [f64; 3],
    rise: [f64; 3],
    inv_speed: [f64; 3],
    shape: f64,
    /// The static level fc + rise: what the clamp compares with.
    fs: [f64; 3],
}

impl Stribeck {
    /// The law of `p` with the bodies' Coulomb levels `fc` (as the kernel lumps them:
    /// the direct topology's motor carries the shaft's); `None` when every rise is 0.
    /// The shaft's rise applies to the spur-gear topology only.
    pub(crate) fn of(p: &Params, fc: [f64; 3]) -> Option<Self> {
        let spur = p.topology == Topology::SpurGear;
        let rise = [p.fsm, if spur { p.fsw } else { 0.0 }, p.fst];
        if rise.iter().all(|r| *r == 0.0) {
            return None;
        }
        let speed = [p.vsm, if spur { p.vsw } else { 0.0 }, p.vst];
        let inv_speed = [0, 1, 2].map(|b| if rise[b] > 0.0 { 1.0 / speed[b] } else { 0.0 });
        Some(Stribeck {
            coulomb: fc,
            rise,
            inv_speed,
            shape: p.stribeck_shape,
            fs: [0, 1, 2].map(|b| fc[b] + rise[b]),
        })
    }

    /// The friction of body `b` sliding at `speed` ≥ 0: fc + rise·exp(−(speed/vs)^δ).
    #[inline(always)]
    pub(crate) fn level(&self, b: usize, speed: f64) -> f64 {
        self.coulomb[b] + self.rise[b] * decay(speed * self.inv_speed[b], self.shape)
    }
}

/// exp(−x^δ), with δ = 2 and δ = 1 spared the power.
#[inline(always)]
fn decay(x: f64, shape: f64) -> f64 {
    let power = if shape == 2.0 {
        x * x
    } else if shape == 1.0 {
        x
    } else {
        x.powf(shape)
    };
    (-power).exp()
}

impl FrictionLaw for Stribeck {
    const CONSTANT_LEVEL: bool = false;

    #[inline(always)]
    fn breakaway(&self, body: usize) -> f64 {
        self.fs[body]
    }

    #[inline(always)]
    fn sliding(&self, body: usize, speed: f64) -> f64 {
        self.level(body, speed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stribeck_level_falls_from_static_to_coulomb() {
        let mut p = crate::model::presets::load("direct-drive").unwrap();
        (p.ft, p.fst, p.vst) = (2.0, 1.0, 0.1);
        let law = Stribeck::of(&p, [0.0, 0.0, 2.0]).unwrap();
        assert_eq!(law.level(2, 0.0), 3.0);
        assert!((law.level(2, 0.1) - (2.0 + (-1.0f64).exp())).abs() < 1e-15);
        assert_eq!(law.level(2, 10.0), 2.0);
        p.stribeck_shape = 1.0;
        let law = Stribeck::of(&p, [0.0, 0.0, 2.0]).unwrap();
        assert!((law.level(2, 0.2) - (2.0 + (-2.0f64).exp())).abs() < 1e-15);
        p.stribeck_shape = 0.5;
        let law = Stribeck::of(&p, [0.0, 0.0, 2.0]).unwrap();
        assert!((law.level(2, 0.4) - (2.0 + (-2.0f64).exp())).abs() < 1e-15);
        p.fst = 0.0;
        assert!(Stribeck::of(&p, [0.0, 0.0, 2.0]).is_none());
    }
}
