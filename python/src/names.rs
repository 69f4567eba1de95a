//! The names the package checks arguments against, from the library itself (not a
//! copy that could drift): a manifest's conditions, each kind's columns, the
//! parameters.

use pyo3::prelude::*;

use rtid::identify::Method;
use rtid::io::experiment_file::{Conditions, Kind, Response};
use rtid::model::LoopMode;
use rtid::objectives::ObjectiveKind;
use rtid::tuning::Objective;

/// The keys a manifest's `conditions` may hold (docs/experiment-files.md).
#[pyfunction]
pub fn condition_keys() -> Vec<&'static str> {
    Conditions::KEYS.to_vec()
}

/// Each kind's name with the columns its reader and evaluators read, in the order of
/// docs/experiment-files.md.
#[pyfunction]
pub fn kind_columns() -> Vec<(&'static str, Vec<String>)> {
    Kind::all().map(|k| (k.name(), k.columns())).collect()
}

/// The names of the options the package checks, as the library spells them: `loop`,
/// `method` (the search's), `objectives` (the identification's), `outputs` (the
/// sweep's), `objective` (the tuning's), `response`.
#[pyfunction]
pub fn option_names() -> Vec<(&'static str, Vec<String>)> {
    let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        (
            "loop",
            [LoopMode::SemiClosed, LoopMode::FullClosed]
                .map(|m| m.to_string())
                .to_vec(),
        ),
        (
            "method",
            names(&[Method::Lsq, Method::Lm, Method::NelderMead, Method::Pso].map(Method::name)),
        ),
        (
            "objectives",
            ObjectiveKind::all().map(|o| o.name().to_string()).collect(),
        ),
        (
            "outputs",
            names(&rtid::sweep::outputs::ALL.map(|o| o.name())),
        ),
        (
            "objective",
            [
                Objective::Positioning,
                Objective::Following,
                Objective::Settling,
            ]
            .map(|o| o.to_string())
            .to_vec(),
        ),
        (
            "response",
            names(&[Response::TableOverMotor, Response::MotorCompliance].map(Response::name)),
        ),
    ]
}

/// The closest known name `name` misspells, as the library finds it for its own
/// messages (case, a dropped unit suffix, one edit in five characters).
#[pyfunction]
pub fn misspelling_of(name: &str, known: Vec<String>) -> Option<String> {
    let known: Vec<&str> = known.iter().map(String::as_str).collect();
    rtid::names::misspelling_of(name, &known).map(str::to_string)
}
