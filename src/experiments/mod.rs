//! The paper's five tests (MODEL.md §5): virtual experiments and the evaluation of their
//! measured data; servo traces of any axis (replay, simulation error, virtual traces) and
//! the friction law fitted to any recorded motion.

pub mod compare;
pub mod fluctuation;
pub mod frequency_response;
pub mod frequency_response_estimate;
pub mod frequency_response_record;
pub mod friction_fit;
pub mod iso230;
pub mod lowpass;
pub mod measurement_noise;
pub mod positioning;
pub mod servo_trace;
pub mod spectrum;
pub mod stepped_sine;
pub mod torque_curve;
pub mod welch;
