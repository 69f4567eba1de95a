//! The objectives of a frequency response: its resonances and their peaks (measured
//! and of the model), the gain curve, the complex response with phase, and a drive's
//! closed speed loop.

pub mod complex_response;
pub mod gain_curve;
pub mod measured_peaks;
pub mod model_peaks;
pub mod peak_amplitude;
pub mod resonance;
pub mod speed_loop;
