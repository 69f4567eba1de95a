//! `rtid.import_file`: the channels of a file a lab exported (MAT-file, TwinCAT
//! Scope, EPOS Studio, UFF 58, delimited text), as `rtid import --list` reads them.

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::with_context;
use rtid::io::formats::{Abscissa, Samples};

/// The recording: its format, notes, and each channel as a dict (name, unit,
/// samples — `re` and `im` arrays for a complex channel — and abscissa).
#[pyfunction]
pub fn import_file<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let recording = py
        .detach(|| rtid::read_recording(&path, None))
        .map_err(|e| with_context("path", &e))?;
    let channels = PyList::empty(py);
    for c in recording.channels {
        let ch = PyDict::new(py);
        ch.set_item("name", c.name)?;
        ch.set_item("unit", c.unit)?;
        match c.samples {
            Samples::Real(v) => ch.set_item("samples", PyArray1::from_vec(py, v))?,
            Samples::Complex { re, im } => {
                ch.set_item("re", PyArray1::from_vec(py, re))?;
                ch.set_item("im", PyArray1::from_vec(py, im))?;
            }
        }
        let abscissa = PyDict::new(py);
        match c.abscissa {
            Abscissa::Uniform { start, step, unit } => {
                abscissa.set_item("start", start)?;
                abscissa.set_item("step", step)?;
                abscissa.set_item("unit", unit)?;
            }
            Abscissa::Values { values, unit } => {
                abscissa.set_item("values", PyArray1::from_vec(py, values))?;
                abscissa.set_item("unit", unit)?;
            }
            Abscissa::Index => {}
        }
        ch.set_item("abscissa", abscissa)?;
        channels.append(ch)?;
    }
    let out = PyDict::new(py);
    out.set_item("format", recording.format)?;
    out.set_item("notes", recording.notes)?;
    out.set_item("channels", channels)?;
    Ok(out)
}
