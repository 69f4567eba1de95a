//! A held parameter's uncertainty as the result file holds it
//! ([`crate::identify::intervals::held`] computes it).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// A parameter the fit held at an assumed value, with the range the user gave it
/// and what moving it does to the fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Held {
    pub name: String,
    /// The value the fit held it at (SI).
    pub value: f64,
    /// Its relative half-width: the parameter lies within value·(1 ± half_width).
    pub half_width: f64,
    /// Each fitted parameter's change when this one is at value·(1 + half_width)
    /// instead of value, the data as they are: the fit follows the held parameter
    /// (a linear step of the fit's own least squares, SI).
    pub shifts: BTreeMap<String, f64>,
}

impl Held {
    /// The standard deviation each fitted parameter takes from this one's range,
    /// drawn uniformly: |shift|/√3.
    pub fn spread(&self, name: &str) -> f64 {
        self.shifts.get(name).map_or(0.0, |s| s.abs() / 3f64.sqrt())
    }
}
