//! Where the search started and how each start ended, as the result file holds them.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::identify::result::termination::Termination;

/// One experiment's direct estimate, as used: the fitted parameters it set.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StartEstimate {
    /// The experiment file.
    pub source: String,
    /// The objective that made it.
    pub objective: String,
    /// How, in words (method, filters).
    pub method: String,
    /// Name → estimated value (SI): the fitted parameters it starts.
    pub values: BTreeMap<String, f64>,
}

/// One start of a search, as reported and checkpointed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartRecord {
    pub index: usize,
    /// Physical start values of the fitted parameters.
    pub initial: Vec<f64>,
    /// Physical result values (`None` if interrupted before a result).
    pub result: Option<Vec<f64>>,
    /// The cost at the result (`None`: no finite cost, e.g. nothing evaluated).
    pub cost: Option<f64>,
    pub iterations: u64,
    pub termination: Termination,
}

impl StartRecord {
    /// A start that ran to its end (not interrupted).
    pub fn finished(&self) -> bool {
        !self.termination.interrupted() && self.result.is_some()
    }

    /// The cost, +∞ when there is none.
    pub(crate) fn cost_or_infinity(&self) -> f64 {
        self.cost.unwrap_or(f64::INFINITY)
    }
}
