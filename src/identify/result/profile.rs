//! A profile likelihood as the result file holds it ([`crate::identify::intervals::profile`]
//! computes it).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The profile of one parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// Ends of the interval at [`LEVEL`]; `None` for a side open up to the bound.
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    pub level: f64,
    /// `[value, cost]` along the profile, by value (the fit's point included).
    pub points: Vec<[f64; 2]>,
    /// The likelihood-ratio statistic at each point, in the order of `points`.
    pub statistic: Vec<f64>,
    /// Which statistic: the variance estimated from the residuals, or one unit.
    pub variance: Variance,
    /// Where the profile is open: each other fitted parameter that moved along it by
    /// more than 5 %, with the ratio of its largest to its smallest value.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub family: BTreeMap<String, f64>,
    /// Why a side ended before its level or bound (a failed fit, Ctrl-C).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// On a rough cost, the bowl fitted to the cost around the fit that the
    /// interval is read from (`points` are then the evaluated design, not re-fits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<Surface>,
}

/// The quadratic bowl behind a rough cost's profile
/// ([`crate::identify::intervals::surface`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Surface {
    /// The parameter's value at the bowl's minimum, the interval's centre.
    pub minimum: f64,
    /// The bowl's cost there.
    pub cost: f64,
    /// n_eff: the residuals' count over the factor by which their correlation
    /// inflates this parameter's variance.
    pub effective_residuals: f64,
    /// RMS scatter of the evaluated costs about the bowl.
    pub roughness: f64,
    /// Standard deviation of the minimum over resamplings of that scatter.
    pub minimum_spread: f64,
    /// The half-width the statistic alone gives.
    pub statistic_half_width: f64,
    /// `[value, statistic]` of the bowl's profile, for the plot.
    pub curve: Vec<[f64; 2]>,
}

/// The variance behind the statistic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Variance {
    /// Estimated from the residuals: statistic n·ln(cost / cost at the fit).
    Estimated,
    /// One unit of the scaled residuals: statistic cost − cost at the fit. Used
    /// when the residuals cannot estimate it (no more residuals than parameters, or
    /// an RMS residual below [`EXACT_RMS`]).
    Unit,
}
