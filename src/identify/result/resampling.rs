//! A residual block bootstrap as the result file holds it
//! ([`crate::identify::intervals::resample`] computes it).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The bootstrap of a fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Resampling {
    /// `residual block bootstrap`.
    pub method: String,
    pub level: f64,
    /// Replicates asked for and fitted.
    pub asked: usize,
    pub fitted: usize,
    /// The block length of each experiment's residuals, samples.
    pub block_lengths: Vec<usize>,
    /// Each fitted parameter's interval (absent with fewer than [`MIN_REPLICATES`]).
    pub intervals: BTreeMap<String, Interval>,
    /// Each fitted parameter's value in each fitted replicate, in replicate order.
    pub values: BTreeMap<String, Vec<f64>>,
    /// Why replicates are missing (a failed fit, Ctrl-C).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// A bias-corrected normal bootstrap interval: the fit minus the replicates' mean
/// offset, ± 1.96 of their standard deviation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    pub lower: f64,
    pub upper: f64,
    /// The replicates' standard deviation: the bootstrap standard error.
    pub standard_error: f64,
    /// The replicates' mean minus the fit: the estimated bias of the fit.
    pub bias: f64,
}
