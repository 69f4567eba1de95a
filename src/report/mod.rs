//! Presentation: figures (SVG charts) of the tests, identifications and sweeps. The
//! domain modules compute; this module only draws what they computed.

pub mod compensation;
pub mod evaluation;
pub mod experiments;
pub mod figure;
pub mod html;
pub mod identify;
pub mod sweep;
pub mod tuning;
pub use experiments::{
    fluctuation, frequency_response, frequency_response_time, friction_map, periodic, positioning,
    servo_trace, speed_loop, torque_curve,
};
