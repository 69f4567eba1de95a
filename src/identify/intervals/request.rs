//! What a profile is asked: the fit, the objective it minimises, the parameters to
//! profile and the level of their intervals — shared by the walk
//! ([`super::profile`]) and the bowl of a rough cost ([`super::surface`]).

use crate::identify::result::IdentifyResult;
use crate::identify::search::settings::Settings;
use crate::model::Params;
use crate::objectives::{Objective, Smoothness};

/// The confidence level of the intervals.
pub const LEVEL: f64 = 0.95;
/// χ²₁ at [`LEVEL`]: the likelihood-ratio statistic at an interval's end.
pub const THRESHOLD: f64 = 3.841_458_820_694_124;
/// The two-sided normal quantile at [`LEVEL`].
pub(super) const Z: f64 = 1.959_963_984_540_054;

/// What is profiled and how each point is fitted.
pub struct Request<'a> {
    /// The fit's result and identified parameter set.
    pub result: &'a IdentifyResult,
    pub params: &'a Params,
    /// The objective the result minimises and the search's settings
    /// ([`crate::identify::run::Identified`]).
    pub objective: &'a dyn Objective,
    pub settings: Settings,
    /// How the objective's cost varies: a rough one ([`Smoothness::Rough`] or
    /// [`Smoothness::Grainy`]) is profiled on a bowl fitted to it ([`super::surface`]).
    pub smoothness: Smoothness,
    /// The parameters to profile (fitted ones).
    pub names: Vec<String>,
    /// Asked between points whether to stop (Ctrl-C).
    pub stop: &'a (dyn Fn() -> bool + Sync),
    /// Called after each fitted point (progress).
    pub on_point: &'a (dyn Fn() + Sync),
}
