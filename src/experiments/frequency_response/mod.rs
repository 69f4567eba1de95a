//! The frequency-response test as a virtual experiment (paper §4.1, docs/experiments.md (frequency response)).
//!
//! Open loop, motor torque `preload·Rg·Rw + A·sin(2πft)`, table brake `−preload`.
//! Every frequency is an independent nonlinear time simulation. They run in
//! [`LANES`]-wide batches advanced in lockstep ([`LaneSimulation`], vectorised), one
//! batch per rayon worker; a lane whose frequency has settled is refilled at once
//! with the next frequency of the shared queue, so lanes rarely idle. A lane
//! computes bit for bit what a lone simulation of its frequency computes
//! ([`simulate_point`] is the same code with one lane). Gain = 20·log10 of the
//! steady amplitude of the table angle over that of the motor angle × Rg·Rw; its
//! peaks are the resonances (the damped motor-held modes).
//!
//! **Start.** Each run starts from the steady state of the linearised model (exact
//! complex response to the sine, plus the static twist of the preload with the
//! flanks in contact), which removes most of the transient.
//!
//! **Steady state.** The run proceeds in windows of whole drive cycles (at least
//! [`FrequencyTest::window_s`] long). In each window the table and motor angles,
//! sampled ≥ 40 times a cycle, are fitted by least squares with an offset, a
//! quadratic drift (an open-loop sine from rest makes the whole drive drift, and
//! Coulomb friction makes that drift uneven) and sin/cos at the drive frequency. The
//! point is settled when the gain changes by less than `tolerance_db` and each
//! amplitude by less than 10× that in relative terms between two successive windows;
//! after `max_duration_s` the last window is used and the point is marked unsettled.
//!
//! **Backlash.** Per frequency, the fraction of the last window's samples in which
//! each mesh is out of contact (inside its gap) is reported. Where it is not zero the
//! table rattles in the gap and the "gain" is not a property of the drive.

pub mod measured;
pub mod modal;
pub mod periodic_evaluation;
mod record;
mod run;
mod sines;
pub mod time_evaluation;
pub mod time_record;

pub use record::{linear_points, manifest, to_data, Disturbance};
pub(crate) use run::initial_state;
pub use run::simulate_point;

use crate::estimation::peaks::Peak;
use crate::io::experiment_file::Response;
use crate::model::Params;
use crate::sim::SimError;

/// Frequencies advanced together by one worker (two AVX2 registers per state).
pub const LANES: usize = crate::sim::LANES;

/// Conditions of the test (defaults: docs/experiments.md (frequency response)).
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyTest {
    /// Coarse grid, Hz (default 10, 20, …, 600).
    pub frequencies_hz: Vec<f64>,
    /// Sine amplitude of the motor torque, N·m (default 5).
    pub amplitude_nm: f64,
    /// Table brake torque balanced by a motor DC torque, N·m (default 0).
    pub preload_nm: f64,
    /// Refinement step around each coarse peak, Hz (default 1; 0: none).
    pub refine_step_hz: f64,
    /// Half-width of the refined band around each coarse peak, Hz (default 10).
    pub refine_half_width_hz: f64,
    /// Gain change between windows below which a point is settled, dB (0.01).
    pub tolerance_db: f64,
    /// Minimum window length, s (whole cycles; default 0.02).
    pub window_s: f64,
    /// Longest simulation per frequency, s (default 1).
    pub max_duration_s: f64,
    /// Integration step (default: the model's).
    pub dt: Option<f64>,
}

impl Default for FrequencyTest {
    fn default() -> Self {
        FrequencyTest {
            frequencies_hz: (1..=60).map(|i| 10.0 * i as f64).collect(),
            amplitude_nm: 5.0,
            preload_nm: 0.0,
            refine_step_hz: 1.0,
            refine_half_width_hz: 10.0,
            tolerance_db: 0.01,
            window_s: 0.02,
            max_duration_s: 1.0,
            dt: None,
        }
    }
}

/// The result at one frequency.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Point {
    pub frequency_hz: f64,
    pub gain_db: f64,
    /// Phase of the table relative to the motor angle, degrees.
    pub phase_deg: f64,
    /// Steady amplitudes, rad.
    pub motor_amplitude_rad: f64,
    pub table_amplitude_rad: f64,
    /// Fraction of the last window out of contact: spur mesh, drive mesh.
    pub contact_loss: [f64; 2],
    /// Whether the amplitudes settled before `max_duration_s`.
    pub settled: bool,
    /// Whether the table amplitude was below the table encoder's resolution (the
    /// table held inside the gap, say): the gain is then computed with that
    /// resolution as the table amplitude, the floor a measurement would show.
    pub below_resolution: bool,
    /// Simulated time, s.
    pub simulated_s: f64,
}

/// The whole test: the coarse grid, then `refine_step_hz` steps around each local
/// maximum, all in parallel; `progress()` is called after every point. Points come
/// back sorted by frequency.
pub fn sweep(
    p: &Params,
    test: &FrequencyTest,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Point>, SimError> {
    let mut points = run::simulate_all(p, &test.frequencies_hz, test, progress)?;
    points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    if test.refine_step_hz > 0.0 {
        let extra = refinement(&points, test);
        points.extend(run::simulate_all(p, &extra, test, progress)?);
        points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    }
    Ok(points)
}

/// The frequencies to add around each local maximum of the coarse gain.
pub fn refinement(points: &[Point], test: &FrequencyTest) -> Vec<f64> {
    let gains: Vec<(f64, f64)> = points.iter().map(|p| (p.frequency_hz, p.gain_db)).collect();
    let mut extra: Vec<f64> = Vec::new();
    for i in crate::estimation::peaks::local_maxima(&gains) {
        let centre = gains[i].0;
        let n = (test.refine_half_width_hz / test.refine_step_hz).floor() as i64;
        for k in -n..=n {
            let f = centre + k as f64 * test.refine_step_hz;
            let known = |g: f64| (g - f).abs() < 1e-9;
            if f > 0.0
                && !points.iter().any(|p| known(p.frequency_hz))
                && !extra.iter().any(|&g| known(g))
            {
                extra.push(f);
            }
        }
    }
    extra
}

/// Resonances reported by the evaluation of a gain curve (the highest local maxima).
pub const RESONANCES: usize = 4;

/// What the evaluation of a frequency-response file finds: its resonances.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Evaluation {
    /// The highest [`RESONANCES`] local maxima of the gain, each located by the
    /// parabola through it and its neighbours, ascending in frequency.
    pub peaks: Vec<Peak>,
    /// Points of the curve.
    pub points: usize,
}

/// Evaluates a gain curve (frequencies ascending).
pub fn evaluate(frequency_hz: &[f64], gain_db: &[f64]) -> Evaluation {
    let curve: Vec<(f64, f64)> = frequency_hz
        .iter()
        .copied()
        .zip(gain_db.iter().copied())
        .collect();
    Evaluation {
        peaks: crate::estimation::peaks::maxima(&curve, RESONANCES),
        points: curve.len(),
    }
}

/// The gain (dB) and phase (deg) of the linearised model's table over motor at
/// `freqs_hz`, solved in the frequency domain (no backlash, no friction).
pub fn linear(p: &Params, freqs_hz: &[f64]) -> Result<Vec<(f64, f64)>, crate::model::ParamError> {
    linear_of(p, Response::TableOverMotor, freqs_hz)
}

/// The gain (dB) and phase (deg) of the linearised model's `response` at `freqs_hz`
/// (none of a speed loop, which is the controller's closed loop and not the
/// mechanics': `tuning::speed_loop` computes it).
pub fn linear_of(
    p: &Params,
    response: Response,
    freqs_hz: &[f64],
) -> Result<Vec<(f64, f64)>, crate::model::ParamError> {
    use crate::model::linear_response::{Channel, LinearResponse};
    let channel = match response {
        Response::TableOverMotor => Channel::TableOverMotor,
        Response::MotorCompliance => Channel::MotorOverTorque,
        Response::SpeedLoop => return Ok(vec![(f64::NAN, f64::NAN); freqs_hz.len()]),
    };
    Ok(LinearResponse::new(p, channel)?.gain_phase(freqs_hz))
}
