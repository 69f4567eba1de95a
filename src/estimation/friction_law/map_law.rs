//! What the map fit needs of a law: [`MapLaw`]. The four laws of [`Law`] are the ones
//! rtid fits by default (`builtin.rs`); a new law is one type with this impl
//! (docs/architecture.md, "adding a friction law").
//!
//! [`Law`]: super::Law

use super::covariance::Covariance;
use super::law::Quantity;
use super::note::Note;

/// A law a friction map can be fitted to: what [`super::fit`] needs of it.
pub trait MapLaw {
    /// The law's name, as in JSON and tables.
    fn name(&self) -> &'static str;

    /// The parameters' names, in the order of the values.
    fn parameters(&self) -> &'static [&'static str];

    /// What each parameter is, in the order of the values: it sets the unit and the
    /// scaling of a nonlinear fit.
    fn quantities(&self) -> &'static [Quantity];

    /// The effort at speed `v` (≠ 0) with `values` in the order of the parameters.
    fn evaluate(&self, values: &[f64], v: f64) -> f64;

    /// The derivatives of [`MapLaw::evaluate`] at `v` with respect to each value, into
    /// `out` (as long as the values).
    fn gradient(&self, values: &[f64], v: f64, out: &mut [f64]);

    /// Whether the effort is linear in the parameters: then the fit is solved
    /// directly, its regressor rows the gradient at zero values. Otherwise it is
    /// fitted by Levenberg–Marquardt from [`MapLaw::starts`].
    fn is_linear(&self) -> bool;

    /// The distinct speeds per direction a fit needs (a nonlinear curve's start,
    /// middle and end: 3).
    fn speeds_needed(&self) -> usize {
        1
    }

    /// The starting values of a nonlinear fit over the runs (`speed`, `effort`), each
    /// in the order of the parameters; the best end is kept (the first of equals).
    fn starts(&self, _speed: &[f64], _effort: &[f64]) -> Vec<Vec<f64>> {
        Vec::new()
    }

    /// Why a converged fit with `values` is still not determined, beyond a parameter
    /// without standard error: the law's own physical checks, given the covariance
    /// and the lowest and highest |speed| of each direction (positive first).
    fn checks(
        &self,
        _values: &[f64],
        _covariance: &Covariance,
        _span: [(f64, f64); 2],
    ) -> Vec<Note> {
        Vec::new()
    }
}
