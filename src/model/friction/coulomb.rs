//! The paper's Coulomb law (docs/model.md §2): a constant level per body — `fm`, `fw`,
//! `ft` of the registry — that a body at rest must exceed to break away and that
//! opposes it at any sliding speed.

use super::FrictionLaw;

/// The Coulomb levels of motor, shaft and table, N·m (N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coulomb {
    fc: [f64; 3],
}

impl Coulomb {
    /// The law with levels `fc` of motor, shaft and table.
    pub fn new(fc: [f64; 3]) -> Self {
        Coulomb { fc }
    }
}

impl FrictionLaw for Coulomb {
    const CONSTANT_LEVEL: bool = true;

    #[inline(always)]
    fn breakaway(&self, body: usize) -> f64 {
        self.fc[body]
    }

    #[inline(always)]
    fn sliding(&self, body: usize, _speed: f64) -> f64 {
        self.fc[body]
    }
}
