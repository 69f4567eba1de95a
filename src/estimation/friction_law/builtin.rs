//! The four laws of [`Law`] as [`MapLaw`]s: the Coulomb laws solved directly, the
//! Stribeck laws from their starts (`stribeck.rs`) with their own checks
//! (`note.rs`).

use super::covariance::Covariance;
use super::law::{Law, Quantity};
use super::map_law::MapLaw;
use super::note::{self, Note};
use super::stribeck;

impl MapLaw for Law {
    fn name(&self) -> &'static str {
        Law::name(*self)
    }

    fn parameters(&self) -> &'static [&'static str] {
        Law::parameters(*self)
    }

    fn quantities(&self) -> &'static [Quantity] {
        Law::quantities(*self)
    }

    fn evaluate(&self, values: &[f64], v: f64) -> f64 {
        Law::evaluate(*self, values, v)
    }

    fn gradient(&self, values: &[f64], v: f64, out: &mut [f64]) {
        Law::gradient(*self, values, v, out)
    }

    fn is_linear(&self) -> bool {
        !self.is_stribeck()
    }

    fn speeds_needed(&self) -> usize {
        if self.is_stribeck() {
            super::STRIBECK_SPEEDS
        } else {
            1
        }
    }

    fn starts(&self, speed: &[f64], effort: &[f64]) -> Vec<Vec<f64>> {
        stribeck::starts(*self, speed, effort)
    }

    fn checks(&self, values: &[f64], covariance: &Covariance, span: [(f64, f64); 2]) -> Vec<Note> {
        note::stribeck_checks(*self, values, covariance, span)
    }
}
