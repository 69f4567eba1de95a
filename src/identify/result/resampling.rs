//! A residual block bootstrap as the result file holds it
//! ([`crate::identify::intervals::resample`] computes it).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::identify::result::warning::Side;

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

/// A normal bootstrap interval: ± 1.96 of the replicates' standard deviation
/// about the fit less their mean offset (bias-corrected), or, where they drew held
/// parameters, about both the fit less it and their mean; cut to the search's bounds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    pub lower: f64,
    pub upper: f64,
    /// The replicates' standard deviation: the bootstrap standard error.
    pub standard_error: f64,
    /// The replicates' mean minus the fit: the estimated bias of the fit.
    pub bias: f64,
    /// The bound of the search that replicates ran to, where enough did
    /// ([`crate::identify::intervals::resample::AT_BOUND`]): the records do not
    /// bound the parameter there, and it is not determined.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_bound: Option<AtBound>,
}

/// How many replicates ran to which bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AtBound {
    pub side: Side,
    pub replicates: usize,
}
