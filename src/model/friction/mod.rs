//! Friction of the drive's bodies (docs/model.md §2): one stick/slip clamp
//! ([`clamp`]) and the laws it clamps with, each a [`FrictionLaw`] — the level a body
//! at rest must exceed to break away, and the level opposing it while it slides.
//!
//! - [`Coulomb`]: the paper's law, a constant level `fm`, `fw`, `ft` per body;
//! - [`Stribeck`]: the Coulomb level plus a rise that falls off with speed (`fsm`,
//!   `vsm`, … and `stribeck_shape`).
//!
//! What every layer shares of a body's law at steady speed — its Coulomb level,
//! viscous slope and rise, by the registry's names — is [`SteadyFriction`].
//!
//! A drive's parameters compile into one [`DriveFriction`] (the Coulomb law unless a
//! Stribeck rise is set), and the kernel is generic over the law: it runs each law's
//! own path, chosen once per step outside the stepping loop, so the Coulomb path of
//! the paper costs nothing for the others.
//!
//! **Adding a law**: one file here with its struct (compiled from [`Params`]) and its
//! [`FrictionLaw`] impl, a [`DriveFriction`] variant with its arm in
//! [`with_law`], [`DriveFriction::of`] and [`DriveFriction::kind`] below, and the same
//! variant in lanes ([`lanes::LaneFriction`], its `gather`, `lane` and
//! `with_lane_law`); its parameters in the registry
//! (`model/registry.rs`). The kernel, the simulation and every test on the model then
//! run it unchanged (docs/architecture.md).
//!
//! [`Params`]: crate::model::Params

pub(crate) mod clamp;
mod coulomb;
pub mod lanes;
mod steady;
mod stribeck;
#[cfg(test)]
mod tests;

pub use coulomb::Coulomb;
pub use steady::{Body, BodyNames, Rise, SteadyFriction, SHAPE};
pub use stribeck::Stribeck;

use super::params::Params;

/// A friction law as the kernel applies it to each body (motor 0, shaft 1, table 2).
/// The clamp is the same for every law: a body at rest sticks while the torque on it
/// lies within ±[`breakaway`](FrictionLaw::breakaway), and slides against
/// [`sliding`](FrictionLaw::sliding) at its speed otherwise.
pub trait FrictionLaw: Copy + Send + Sync {
    /// Whether the sliding level is the break-away level at every speed (Coulomb): the
    /// kernel then decides the friction torque once per step, at its first stage,
    /// instead of evaluating the law at every stage's speed.
    const CONSTANT_LEVEL: bool;

    /// The level a body at rest must exceed to break away, N·m (N), ≥ 0.
    fn breakaway(&self, body: usize) -> f64;

    /// The level opposing a body sliding at `speed` ≥ 0, N·m (N), ≥ 0.
    fn sliding(&self, body: usize, speed: f64) -> f64;
}

/// `$body` with `$law` bound to the [`FrictionLaw`] of a [`DriveFriction`], one arm per
/// law: the kernel's dispatch to its generic path.
macro_rules! with_law {
    ($friction:expr, $law:ident => $body:expr) => {
        match $friction {
            $crate::model::friction::DriveFriction::Coulomb($law) => $body,
            $crate::model::friction::DriveFriction::Stribeck($law) => $body,
        }
    };
}

/// The friction law of a drive's bodies, compiled from its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriveFriction {
    Coulomb(Coulomb),
    Stribeck(Stribeck),
}

impl DriveFriction {
    /// The law of `p` with the bodies' Coulomb levels `fc` (as the kernel lumps them:
    /// the direct topology's motor carries the shaft's): Stribeck where a rise is set,
    /// else Coulomb.
    pub(crate) fn of(p: &Params, fc: [f64; 3]) -> Self {
        match Stribeck::of(p, fc) {
            Some(law) => DriveFriction::Stribeck(law),
            None => DriveFriction::Coulomb(Coulomb::new(fc)),
        }
    }

    /// Which law this is (its variant's index): lanes of one batch share it
    /// ([`lanes::LaneFriction`]).
    pub(crate) fn kind(&self) -> u8 {
        match self {
            DriveFriction::Coulomb(_) => 0,
            DriveFriction::Stribeck(_) => 1,
        }
    }

    /// The level opposing body `body` sliding at `speed` ≥ 0, N·m (N).
    pub fn sliding(&self, body: usize, speed: f64) -> f64 {
        with_law!(self, law => law.sliding(body, speed))
    }
}
