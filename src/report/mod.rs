//! Presentation: figures (SVG charts) of the tests, identifications and sweeps. The
//! domain modules compute; this module only draws what they computed.

pub mod compensation;
pub mod evaluation;
pub mod figure;
pub mod fluctuation;
pub mod frequency_response;
pub mod frequency_response_time;
pub mod friction_map;
pub mod html;
pub mod identify;
pub mod periodic;
pub mod positioning;
pub mod servo_trace;
pub mod speed_loop;
pub mod sweep;
pub mod torque_curve;
pub mod tuning;
