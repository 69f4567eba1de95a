//! The paper's five tests (MODEL.md §5): virtual experiments and the evaluation of their measured data.

pub mod compare;
pub mod fluctuation;
pub mod frequency_response;
pub mod frequency_response_estimate;
pub mod frequency_response_record;
pub mod inverse_dynamics;
pub mod iso230;
pub mod measurement_noise;
pub mod positioning;
pub mod spectrum;
pub mod stepped_sine;
pub mod torque_curve;
pub mod welch;
