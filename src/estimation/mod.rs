//! Estimators that work on any record, whichever test made it: the layer the tests of
//! [`crate::experiments`] call, which calls nothing above the model and the files.
//!
//! - frequency responses from raw records: [`welch`] (H1 with Welch averaging and the
//!   coherence), [`stepped_sine`] (demodulation dwell by dwell), [`periodic`] (a
//!   periodic multisine: its design, the record cut into periods, the estimate with
//!   per-line noise and the nonlinear distortion);
//! - what a gain curve shows: [`curve_noise`] (its noise read off the curve), [`peaks`] (the one peak finder), [`extrema`]
//!   (resonances and antiresonances above the noise), [`local_mode_fit`] (frequency
//!   and damping by a local rational fit), [`two_mass_ratios`] (what a two-mass
//!   drive's resonance and antiresonance determine);
//! - signals over angle: [`spectrum`];
//! - [`inverse_dynamics`]: the friction law and inertia of a rigid axis by least
//!   squares (IDIM-LS) from any recorded motion and effort;
//! - [`friction_law`]: Coulomb and Stribeck laws, symmetric or not, fitted to a
//!   friction map (each constant-speed run's mean speed and effort), with standard
//!   errors and the law the data support;
//! - [`least_squares`]: the Levenberg–Marquardt solver every nonlinear least-squares
//!   fit takes its damped step from (the friction laws, the identification's search);
//! - [`information`]: AIC, AICc, BIC, Akaike weights and nested F-tests of fits of the
//!   same data, from plain figures.

pub mod curve_noise;
pub mod extrema;
pub mod friction_law;
pub mod information;
pub mod inverse_dynamics;
pub mod least_squares;
pub mod local_mode_fit;
pub mod peaks;
pub mod periodic;
pub mod spectrum;
pub mod stepped_sine;
pub mod two_mass_ratios;
pub mod welch;
