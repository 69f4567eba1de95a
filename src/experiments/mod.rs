//! The paper's five tests (docs/experiments.md): virtual experiments and the evaluation of their
//! measured data; servo traces of any axis (replay, simulation error, virtual traces) and
//! the friction law fitted to any recorded motion.

pub mod compare;
pub mod extrema;
pub mod fluctuation;
pub mod frequency_response;
pub mod frequency_response_estimate;
pub mod frequency_response_record;
pub mod inverse_dynamics;
pub mod iso230;
pub mod line_scatter;
pub mod local_mode_fit;
pub mod measurement_noise;
pub mod multisine;
pub mod nonlinear_distortion;
pub mod periodic_estimate;
pub mod periodic_evaluation;
pub mod periodic_record;
pub mod positioning;
pub mod servo_trace;
pub mod spectrum;
pub mod stepped_sine;
pub mod torque_curve;
pub mod two_mass_ratios;
pub mod welch;
