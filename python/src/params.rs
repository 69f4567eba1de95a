//! Parameter sets: `rtid.params(...)`, the dict-like `Params`, and `rtid.modes`.

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error, with_context};
use rtid::io::params_file;
use rtid::{Params, PARAMS};

/// A parameter set: every parameter by its registry name, SI units.
#[pyclass(name = "Params", module = "rtid._rtid", from_py_object)]
#[derive(Clone)]
pub struct PyParams {
    pub inner: Params,
}

#[pymethods]
impl PyParams {
    /// The value of parameter `name` (SI); KeyError when unknown or not of this drive.
    fn __getitem__(&self, name: &str) -> PyResult<f64> {
        match self.inner.get(name) {
            Ok(Some(v)) => Ok(v),
            Ok(None) => Err(PyKeyError::new_err(format!(
                "{name}: not a parameter of this {} drive",
                self.inner.topology
            ))),
            Err(e) => Err(PyKeyError::new_err(e.to_string())),
        }
    }

    /// Sets parameter `name` to `value` (SI), checked as `--set` checks it.
    fn __setitem__(&mut self, name: &str, value: f64) -> PyResult<()> {
        let mut p = self.inner.clone();
        p.set(name, value)
            .and_then(|()| p.validate())
            .map_err(|e| with_context(&format!("{name}={value}"), &e))?;
        self.inner = p;
        Ok(())
    }

    fn __contains__(&self, name: &str) -> bool {
        matches!(self.inner.get(name), Ok(Some(_)))
    }

    fn __len__(&self) -> usize {
        self.keys().len()
    }

    /// The names of the parameters of this drive, in the registry's order.
    fn keys(&self) -> Vec<&'static str> {
        PARAMS
            .iter()
            .filter(|s| s.get(&self.inner).is_some())
            .map(|s| s.name)
            .collect()
    }

    /// Name, value, SI unit (on this axis), meaning and note of each parameter.
    fn describe_rows(&self) -> Vec<(&'static str, f64, &'static str, &'static str, String)> {
        PARAMS
            .iter()
            .filter_map(|s| {
                let v = s.get(&self.inner)?;
                let note = self.inner.notes.get(s.name).cloned().unwrap_or_default();
                Some((s.name, v, s.unit_for(self.inner.axis), s.meaning, note))
            })
            .collect()
    }

    /// The set's name, topology, axis and loop.
    fn header(&self) -> (String, String, String, String) {
        let p = &self.inner;
        (
            p.name.clone(),
            p.topology.to_string(),
            p.axis.name().to_string(),
            p.controller.loop_mode.to_string(),
        )
    }

    /// The parameter file's JSON (`rtid params --json`).
    fn to_json(&self) -> PyResult<String> {
        rtid::io::json::pretty(&self.inner).map_err(|e| rtid_error(&e))
    }

    /// Writes the set as a parameter file (for `--params`).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        params_file::write(&path, &self.inner).map_err(|e| rtid_error(&e))
    }

    fn copy(&self) -> PyParams {
        self.clone()
    }

    /// The servo's loop: `semi_closed` or `full_closed`.
    #[getter(loop_mode)]
    fn get_loop_mode(&self) -> String {
        self.inner.controller.loop_mode.to_string()
    }

    /// Sets the servo's loop (`semi_closed` or `full_closed`).
    #[setter(loop_mode)]
    fn set_loop_mode(&mut self, mode: &str) -> PyResult<()> {
        self.inner.controller.loop_mode = mode.parse().map_err(|e| with_context("loop", &e))?;
        Ok(())
    }

    /// The torque-setpoint filters as the parameter file holds them (JSON).
    fn filters_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner.controller.filters)
            .map_err(|e| bad_argument("filters", e))
    }

    /// Sets the torque-setpoint filters from their JSON (the parameter file's form),
    /// checked as the parameter file's are.
    fn set_filters_json(&mut self, text: &str) -> PyResult<()> {
        let filters = serde_json::from_str(text).map_err(|e| bad_argument("filters", e))?;
        let mut p = self.inner.clone();
        p.controller.filters = filters;
        p.validate().map_err(|e| with_context("filters", &e))?;
        self.inner = p;
        Ok(())
    }

    /// A copy with the controller settings of `tuned` (a tuned set: `rtid.tune`'s
    /// `params`, a `rtid tune -o` file): refused for a drive of another topology or
    /// axis (`--tune`).
    fn with_controller(&self, tuned: PyRef<'_, PyParams>) -> PyResult<PyParams> {
        let mut p = self.inner.clone();
        p.controller = p
            .controller_for(&tuned.inner)
            .map_err(|e| with_context("tuned", &e))?;
        Ok(PyParams { inner: p })
    }
}

/// The set `preset` names or the file `path` holds, with `overrides` set in it.
#[pyfunction]
#[pyo3(signature = (preset=None, path=None, overrides=None))]
pub fn load_params(
    preset: Option<&str>,
    path: Option<PathBuf>,
    overrides: Option<Vec<(String, f64)>>,
) -> PyResult<PyParams> {
    let mut p = match (preset, &path) {
        (Some(name), None) => rtid::preset(name).map_err(|e| with_context("preset", &e))?,
        (None, Some(path)) => params_file::read(path).map_err(|e| with_context("path", &e))?,
        (None, None) => {
            return Err(bad_argument(
                "preset",
                format!(
                    "no mechanism given: name a preset ({}) or a parameter file (path=)",
                    rtid::preset_names().collect::<Vec<_>>().join(", ")
                ),
            ))
        }
        (Some(_), Some(_)) => {
            return Err(bad_argument("path", "give either preset or path, not both"))
        }
    };
    for (name, value) in overrides.unwrap_or_default() {
        p.set(&name, value)
            .map_err(|e| with_context(&format!("{name}={value}"), &e))?;
    }
    p.validate()
        .map_err(|e| with_context("after the overrides", &e))?;
    Ok(PyParams { inner: p })
}

/// The set a parameter file's JSON holds (`Params.to_json`'s text: pickling).
#[pyfunction]
pub fn params_from_json(text: &str) -> PyResult<PyParams> {
    let inner = params_file::parse(text, std::path::Path::new("<parameter JSON>"))
        .map_err(|e| with_context("json", &e))?;
    Ok(PyParams { inner })
}

/// Every parameter's registry name, of any drive (for suggestions of misspelt names).
#[pyfunction]
pub fn param_names() -> Vec<&'static str> {
    PARAMS.iter().map(|s| s.name).collect()
}

/// The shipped presets' names.
#[pyfunction]
pub fn preset_names() -> Vec<&'static str> {
    rtid::preset_names().collect()
}

/// Natural frequencies (Hz) and mode shapes, motor held and free (`rtid modes --json`).
#[pyfunction]
pub fn modes<'py>(py: Python<'py>, params: PyRef<'_, PyParams>) -> PyResult<Bound<'py, PyDict>> {
    let m = rtid::modes(&params.inner).map_err(|e| rtid_error(&e))?;
    let out = PyDict::new(py);
    out.set_item("clamped_hz", PyArray1::from_vec(py, m.clamped_hz))?;
    out.set_item("free_hz", PyArray1::from_vec(py, m.free_hz))?;
    out.set_item(
        "clamped_shapes",
        matrix(py, &m.clamped_shapes, m.clamped_dofs.len())?,
    )?;
    out.set_item(
        "free_shapes",
        matrix(py, &m.free_shapes, m.free_dofs.len())?,
    )?;
    out.set_item("clamped_dofs", m.clamped_dofs)?;
    out.set_item("free_dofs", m.free_dofs)?;
    Ok(out)
}

/// Rows of `columns` values as a 2-D float64 array.
pub fn matrix<'py>(
    py: Python<'py>,
    rows: &[Vec<f64>],
    columns: usize,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), columns])
}

/// `given` (name, relative half-range; 0: held exactly) as the library's overrides
/// (registry name, per cent) of the parameter set's own held ranges (`uncertain=` of
/// identify and predict, `--uncertain NAME=X%`).
pub fn overrides(given: &[(String, f64)]) -> PyResult<Vec<(String, f64)>> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for (name, half) in given {
        let spec = rtid::model::spec(name).map_err(|e| bad_argument("uncertain", e))?;
        if !(*half >= 0.0 && *half < 1.0) {
            return Err(bad_argument(
                "uncertain",
                format!(
                    "{}: {half}: the relative half-range must lie from 0 (held exactly) to below 1",
                    spec.name
                ),
            ));
        }
        out.push((spec.name.to_string(), half * 100.0));
    }
    Ok(out)
}
