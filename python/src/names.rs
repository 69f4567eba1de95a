//! The names the package checks arguments against, from the library itself (not a
//! copy that could drift): a manifest's conditions, each kind's columns, the
//! parameters.

use pyo3::prelude::*;

use rtid::io::experiment_file::{Conditions, Kind};

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

/// The closest known name `name` misspells, as the library finds it for its own
/// messages (case, a dropped unit suffix, one edit in five characters).
#[pyfunction]
pub fn misspelling_of(name: &str, known: Vec<String>) -> Option<String> {
    let known: Vec<&str> = known.iter().map(String::as_str).collect();
    rtid::names::misspelling_of(name, &known).map(str::to_string)
}
