//! rtid's library front for Python (issue 40): the extension `rtid._rtid`, wrapped by
//! the package `rtid/` (docstrings, argument checks, result objects).
//!
//! Each function makes the library calls the command line makes for the same job, so
//! that Python gets the CLI's numbers; the long ones (simulation, tests,
//! identification, sweep, tuning, prediction) run with the GIL released and stop at
//! Ctrl-C (`interruptible`).

mod commissioning;
mod compensate;
mod curves;
mod errors;
mod evaluate;
mod experiment;
mod identify;
mod import;
mod interruptible;
mod linear;
mod names;
mod params;
mod simulate;
mod sweep;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _rtid(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // NumPy's C API now, not at the first array: imported later, a pending
    // KeyboardInterrupt made the import fail, and rust-numpy panics then.
    numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add("RtidError", m.py().get_type::<errors::RtidError>())?;
    m.add("VERSION", rtid::VERSION)?;
    m.add_class::<params::PyParams>()?;
    m.add_function(wrap_pyfunction!(params::load_params, m)?)?;
    m.add_function(wrap_pyfunction!(params::preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(params::params_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(params::param_names, m)?)?;
    m.add_function(wrap_pyfunction!(linear::state_space, m)?)?;
    m.add_function(wrap_pyfunction!(linear::frequency_response, m)?)?;
    m.add_function(wrap_pyfunction!(experiment::run_experiment, m)?)?;
    m.add_function(wrap_pyfunction!(params::modes, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(import::import_file, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::read_experiment, m)?)?;
    m.add_function(wrap_pyfunction!(identify::identify, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(compensate::compensate, m)?)?;
    m.add_function(wrap_pyfunction!(compensate::sinumerik_program, m)?)?;
    m.add_function(wrap_pyfunction!(compensate::table_csv, m)?)?;
    m.add_function(wrap_pyfunction!(commissioning::tune, m)?)?;
    m.add_function(wrap_pyfunction!(commissioning::sinamics_settings, m)?)?;
    m.add_function(wrap_pyfunction!(commissioning::sinumerik_settings, m)?)?;
    m.add_function(wrap_pyfunction!(commissioning::predict, m)?)?;
    m.add_function(wrap_pyfunction!(commissioning::select, m)?)?;
    m.add_function(wrap_pyfunction!(names::condition_keys, m)?)?;
    m.add_function(wrap_pyfunction!(names::kind_columns, m)?)?;
    m.add_function(wrap_pyfunction!(names::option_names, m)?)?;
    m.add_function(wrap_pyfunction!(names::misspelling_of, m)?)?;
    Ok(())
}
