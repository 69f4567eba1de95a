//! Figures of the experiments, one module per kind: what each test's evaluation
//! computed, drawn.

pub mod fluctuation;
pub mod frequency_response;
pub mod frequency_response_time;
pub mod friction_map;
pub mod periodic;
pub mod positioning;
pub mod servo_trace;
pub mod speed_loop;
pub mod torque_curve;
