//! The filters a drive puts on its torque (current) setpoint, as its parameters give
//! them (docs/model.md §1 "Servo as real drives have it"): a second-order low-pass or
//! a notch, up to [`MAX_FILTERS`] in series. The controller discretises them
//! (`controller/filters.rs`).

use serde::{Deserialize, Serialize};

/// The most setpoint filters in series the controller runs (drives offer a few
/// current setpoint filters; four here).
pub const MAX_FILTERS: usize = 4;

/// A setpoint filter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SetpointFilter {
    /// 1/(s²/ω² + 2D·s/ω + 1), ω = 2π·`frequency_hz`.
    LowPass {
        frequency_hz: f64,
        /// D, > 0 (0.7: no peak).
        #[serde(default = "default_damping")]
        damping: f64,
    },
    /// (s²/ω² + 2D·g·s/ω + 1)/(s²/ω² + 2D·s/ω + 1), ω = 2π·`centre_hz`, D =
    /// `width_hz`/(2·`centre_hz`) (the −3 dB width of a full notch), g = 10^(depth/20)
    /// the gain at the centre.
    Notch {
        centre_hz: f64,
        width_hz: f64,
        /// The gain at the centre, dB, ≤ 0 (default −∞: a full notch, written as
        /// absent).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        depth_db: Option<f64>,
    },
}

fn default_damping() -> f64 {
    std::f64::consts::FRAC_1_SQRT_2
}

/// Why a filter cannot run at a control period.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FilterError {
    #[error("{count} setpoint filters: a drive has at most {MAX_FILTERS} in series")]
    TooMany { count: usize },
    #[error(
        "setpoint filter {index}: {field} = {value} Hz lies at or above the Nyquist \
         frequency {nyquist} Hz of the control period Tc (1/(2·Tc)): the sampled \
         controller cannot filter there"
    )]
    AboveNyquist {
        index: usize,
        field: &'static str,
        value: f64,
        nyquist: f64,
    },
    #[error("setpoint filter {index}: {field} = {value} must be {what}")]
    Value {
        index: usize,
        field: &'static str,
        value: f64,
        what: &'static str,
    },
}

impl SetpointFilter {
    /// The frequency the filter acts at, Hz, and the field that gives it.
    pub fn frequency(&self) -> (&'static str, f64) {
        match *self {
            SetpointFilter::LowPass { frequency_hz, .. } => ("frequency_hz", frequency_hz),
            SetpointFilter::Notch { centre_hz, .. } => ("centre_hz", centre_hz),
        }
    }

    /// Checks the filter (`index` from 1, for messages) at control period `tc`.
    pub fn check(&self, index: usize, tc: f64) -> Result<(), FilterError> {
        let positive = |field, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(FilterError::Value {
                    index,
                    field,
                    value,
                    what: "positive and finite",
                })
            }
        };
        let (field, f) = self.frequency();
        positive(field, f)?;
        let nyquist = 0.5 / tc;
        if f >= nyquist {
            return Err(FilterError::AboveNyquist {
                index,
                field,
                value: f,
                nyquist,
            });
        }
        match *self {
            SetpointFilter::LowPass { damping, .. } => positive("damping", damping),
            SetpointFilter::Notch {
                width_hz, depth_db, ..
            } => {
                positive("width_hz", width_hz)?;
                match depth_db {
                    Some(d) if !(d.is_finite() && d <= 0.0) => Err(FilterError::Value {
                        index,
                        field: "depth_db",
                        value: d,
                        what: "finite and ≤ 0 (the gain at the centre)",
                    }),
                    _ => Ok(()),
                }
            }
        }
    }
}

/// Checks a drive's filters at control period `tc`.
pub fn check_all(filters: &[SetpointFilter], tc: f64) -> Result<(), FilterError> {
    if filters.len() > MAX_FILTERS {
        return Err(FilterError::TooMany {
            count: filters.len(),
        });
    }
    for (i, f) in filters.iter().enumerate() {
        f.check(i + 1, tc)?;
    }
    Ok(())
}
