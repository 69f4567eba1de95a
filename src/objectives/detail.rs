//! An objective's residuals in the measurement's own units, for reports and the
//! result file: one variant per shape of detail, each objective describing its own
//! in words (its [`Definition::describe`](super::Definition::describe)).

use serde::{Deserialize, Serialize};

use crate::io::experiment_file::Direction;

/// An objective's residuals in the measurement's own units, for reports.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Detail {
    /// The resonance frequencies, measured and model, and the largest miss, Hz.
    Resonance {
        measured_hz: Vec<f64>,
        model_hz: Vec<f64>,
        max_miss_hz: f64,
    },
    /// The peak heights, measured, and the model's errors, dB.
    PeakHeights {
        measured_db: Vec<f64>,
        error_db: Vec<f64>,
    },
    /// The RMS error of the motor torque, N·m.
    Torque { rms_error_nm: f64 },
    /// The simulation error of a replayed servo trace: force (N or N·m) and position
    /// (m or rad) RMS, and the largest position error.
    Trace {
        force_rms: f64,
        position_rms: f64,
        position_max: f64,
        /// The span (largest − smallest) of the recorded position, m or rad: what the
        /// position error is judged against.
        #[serde(default)]
        position_span: f64,
    },
    /// A complex frequency response: the RMS errors of gain (dB) and phase (deg), the
    /// delay fitted with the model where the file's delay is unknown, s, and where it
    /// is not, a delay its phase errors show all the same (it would halve them).
    ComplexResponse {
        gain_rms_db: f64,
        phase_rms_deg: f64,
        fitted_delay_s: Option<f64>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        unstated_delay_s: Option<f64>,
    },
    /// The unbalance steps: direction, measured and model table angle (deg; `None`
    /// where the model shows no step).
    UnbalanceSteps {
        direction: Vec<Direction>,
        measured_step_deg: Vec<f64>,
        model_step_deg: Vec<Option<f64>>,
    },
}

/// Values as a comma-separated list with `decimals` decimals.
pub(crate) fn list(v: &[f64], decimals: usize) -> String {
    v.iter()
        .map(|x| format!("{x:.decimals$}"))
        .collect::<Vec<_>>()
        .join(", ")
}
