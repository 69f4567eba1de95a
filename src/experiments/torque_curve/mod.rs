//! The friction-torque test as a virtual experiment (paper §4.2, Fig. 9;
//! docs/experiments.md, friction torque curve): the servo, in full-closed loop by default, moves the table harmonically,
//! θref(t) = A·sin(2πt/T) with A = 30°, T = 3 s, and the motor torque command over
//! time is the measured curve. Coulomb friction and viscous damping are fitted to it
//! (docs/identification.md); [`simulate_torque`] is the model side of that fit.
//!
//! The run starts at rest at zero angle, where the command already moves at full
//! speed: the first `run_in_periods` (default 1) absorb that start-up transient and
//! are not recorded. Then `periods` periods are recorded every `sample` seconds
//! (default 1 ms), with the time restarted at 0.
//!
//! Evaluation ([`evaluate`]): RMS and peak torque, and the Coulomb friction seen at
//! the motor from the torque jump at each reversal of the table velocity. Near a
//! reversal the motor torque is inertia (J_eff·θ̈, at its extremum there, so
//! symmetric in time), viscous damping (∝ velocity, antisymmetric and zero at the
//! reversal) and Coulomb friction, which flips from +F to −F. A straight line is fitted
//! to the torque on each side, outside a guard interval that excludes the servo's
//! transition through the stick; both lines are extrapolated to the reversal time and
//! F = −sign(velocity before)·(after − before)/2. The symmetric inertia term cancels
//! in the difference; the linear viscous one extrapolates to zero. On the model
//! F = fm + fw·Rg + ft·Rg·Rw (friction of every body referred to the motor).

mod evaluate;
mod record;
mod run;

pub use evaluate::{
    evaluate, idim_fit, motion_difference, MotionDifference, Reversal, TorqueEvalError,
    TorqueReport,
};
pub use record::{from_data, manifest, to_data};
pub use run::{run, run_batch, simulate_torque, simulate_torque_batch};

use crate::input::Harmonic;
use crate::io::experiment_file::{Conditions, Kind};
use crate::model::params::LoopMode;

/// Conditions of the test (defaults: docs/experiments.md (friction torque curve) and docs/experiment-files.md).
#[derive(Clone, Debug, PartialEq)]
pub struct TorqueTest {
    /// Amplitude of the commanded table motion, rad (default 30°).
    pub amplitude: f64,
    /// Period of the commanded table motion, s (default 3).
    pub period: f64,
    /// Recorded periods (default 2).
    pub periods: f64,
    /// Periods simulated before recording, the servo's start-up transient (default 1).
    pub run_in_periods: f64,
    /// Interval between recorded samples, s (default 1 ms; rounded to whole steps).
    pub sample: f64,
    /// Feedback arrangement (default full-closed, as in the paper).
    pub loop_mode: LoopMode,
}

impl Default for TorqueTest {
    fn default() -> Self {
        TorqueTest {
            amplitude: 30f64.to_radians(),
            period: 3.0,
            periods: 2.0,
            run_in_periods: 1.0,
            sample: 1e-3,
            loop_mode: LoopMode::FullClosed,
        }
    }
}

impl TorqueTest {
    /// The test described by an experiment file's conditions (absent ones: defaults).
    pub fn from_conditions(conditions: &Conditions) -> TorqueTest {
        let c = conditions.with_defaults(Kind::TorqueCurve);
        let d = TorqueTest::default();
        TorqueTest {
            // A linear axis's amplitude in m, else the rotary one (default 30°).
            amplitude: c
                .amplitude_m
                .or(c.amplitude_deg.map(f64::to_radians))
                .unwrap_or(d.amplitude),
            period: c.period_s.unwrap_or(d.period),
            loop_mode: c.loop_mode.unwrap_or(d.loop_mode),
            ..d
        }
    }

    /// The commanded table motion.
    pub fn trajectory(&self) -> Harmonic {
        Harmonic {
            amplitude: self.amplitude,
            period: self.period,
        }
    }

    /// The recorded duration, s.
    pub fn duration(&self) -> f64 {
        self.periods * self.period
    }
}

/// The recorded part of a run: times from 0, motor torque command, table angle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TorqueCurve {
    /// s, from the end of the run-in.
    pub time: Vec<f64>,
    /// Motor torque command, N·m.
    pub motor_torque: Vec<f64>,
    /// Table angle, rad.
    pub table_angle: Vec<f64>,
}

impl TorqueCurve {
    /// The motor torque at `t`, linearly interpolated (held beyond the ends).
    pub fn torque_at(&self, t: f64) -> f64 {
        interpolate(&self.time, &self.motor_torque, t)
    }
}

/// Linear interpolation of (x, y) at `t`, x increasing; clamped at the ends.
pub(crate) fn interpolate(x: &[f64], y: &[f64], t: f64) -> f64 {
    if t.is_nan() {
        return f64::NAN;
    }
    let i = x.partition_point(|&v| v <= t);
    if i == 0 {
        return y[0];
    }
    if i == x.len() {
        return y[x.len() - 1];
    }
    let (x0, x1) = (x[i - 1], x[i]);
    if t == x0 {
        return y[i - 1];
    }
    y[i - 1] + (y[i] - y[i - 1]) * (t - x0) / (x1 - x0)
}
