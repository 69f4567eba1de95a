//! The linearised drive (docs/model.md §2, §11; `rtid::model::modes::LinearModel`):
//! `rtid.frequency_response`, its complex responses, and `rtid.state_space`, the
//! first-order matrices behind them.

use std::f64::consts::TAU;

use nalgebra::{Complex, DMatrix, DVector};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error};
use crate::params::PyParams;
use rtid::model::linear_response::{Channel, LinearResponse};
use rtid::model::modes::LinearModel;

/// The inputs of the linear model: a torque on the motor, or on the table (N·m; N on
/// a linear axis's carriage).
const INPUTS: [&str; 2] = ["motor_torque", "table_torque"];

/// The coordinate an input acts on.
fn input_dof(model: &LinearModel, input: &str) -> PyResult<usize> {
    let table = model.index("theta_t").expect("every topology has theta_t");
    match input {
        // A direct drive's motor is its table: one body.
        "motor_torque" => Ok(model.index("theta_m").unwrap_or(table)),
        "table_torque" => Ok(table),
        other => Err(bad_argument(
            "input",
            format!("unknown input `{other}`: expected {}", INPUTS.join(" or ")),
        )),
    }
}

/// The names of the states [q, q']: each coordinate and its rate (`theta_t_dot`).
fn state_names(model: &LinearModel) -> Vec<String> {
    let q = model.dofs.iter().map(|d| d.to_string());
    q.clone().chain(q.map(|d| format!("{d}_dot"))).collect()
}

/// The linear model of `params`.
fn model_of(params: &PyParams) -> PyResult<LinearModel> {
    LinearModel::new(&params.inner).map_err(|e| rtid_error(&e))
}

/// (A, B, C, D) of ẋ = A·x + B·u, y = C·x + D·u with x = [q, q'] (the coordinates
/// and their rates), u = the inputs' torques, y = the states; with the names of
/// the states, inputs and outputs.
#[pyfunction]
pub fn state_space<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
) -> PyResult<Bound<'py, PyDict>> {
    let model = model_of(&params)?;
    let n = model.n_dof();
    let a = model.state_matrix();
    let mut b = DMatrix::zeros(2 * n, INPUTS.len());
    for (j, input) in INPUTS.iter().enumerate() {
        let i = input_dof(&model, input)?;
        b[(n + i, j)] += 1.0 / model.m[(i, i)];
    }
    let c = DMatrix::<f64>::identity(2 * n, 2 * n);
    let d = DMatrix::<f64>::zeros(2 * n, INPUTS.len());
    let out = PyDict::new(py);
    for (key, m) in [("A", &a), ("B", &b), ("C", &c), ("D", &d)] {
        out.set_item(key, array2(py, m)?)?;
    }
    let states = state_names(&model);
    out.set_item("states", states.clone())?;
    out.set_item("inputs", INPUTS.to_vec())?;
    out.set_item("outputs", states)?;
    Ok(out)
}

/// A matrix as a 2-D float64 array (row-major).
fn array2<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let rows: Vec<f64> = m.transpose().iter().copied().collect();
    PyArray1::from_vec(py, rows).reshape([m.nrows(), m.ncols()])
}

/// The complex response of `output` to a unit `input` at each of `freqs_hz`:
/// `table_over_motor` (the paper's ratio, `rtid::model::modes::frequency_response`),
/// `motor_compliance` (motor angle over motor torque), a coordinate (`theta_t`, …)
/// or its rate (`theta_t_dot`) over the input. NaN where the system is singular.
#[pyfunction]
pub fn frequency_response<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    freqs_hz: PyReadonlyArray1<'py, f64>,
    input: &str,
    output: &str,
) -> PyResult<Bound<'py, PyArray1<Complex<f64>>>> {
    let freqs = freqs_hz.as_slice()?;
    let limit = rtid::limits::MAX_POINTS;
    rtid::limits::work(freqs.len() as f64, limit, "frequencies", "freqs_hz")
        .map_err(|e| rtid_error(&e))?;
    let model = model_of(&params)?;
    let i = input_dof(&model, input)?;
    let ratio = |channel| -> PyResult<Vec<Complex<f64>>> {
        if input != "motor_torque" {
            return Err(bad_argument(
                "output",
                format!(
                    "{output} is a response to the motor's torque: give input=\"motor_torque\""
                ),
            ));
        }
        let r = LinearResponse::new(&params.inner, channel).map_err(|e| rtid_error(&e))?;
        let nan = Complex::new(f64::NAN, f64::NAN);
        Ok(freqs.iter().map(|&hz| r.at(hz).unwrap_or(nan)).collect())
    };
    let h = match output {
        "table_over_motor" => ratio(Channel::TableOverMotor)?,
        "motor_compliance" => ratio(Channel::MotorOverTorque)?,
        name => {
            let states = state_names(&model);
            let Some(k) = states.iter().position(|s| s == name) else {
                return Err(bad_argument(
                    "output",
                    format!(
                        "unknown output `{name}`: expected table_over_motor, motor_compliance or a state ({})",
                        states.join(", ")
                    ),
                ));
            };
            coordinate(&model, i, k, freqs)
        }
    };
    Ok(PyArray1::from_vec(py, h))
}

/// State `k` of [q, q'] over a unit force on coordinate `i`, by the library's
/// solve of (K − ω²·M + iω·C)·X = F.
fn coordinate(model: &LinearModel, i: usize, k: usize, freqs: &[f64]) -> Vec<Complex<f64>> {
    let n = model.n_dof();
    let mut f = DVector::from_element(n, Complex::new(0.0, 0.0));
    f[i] = Complex::new(1.0, 0.0);
    freqs
        .iter()
        .map(|&hz| {
            let omega = TAU * hz;
            match model.response(omega, &f) {
                Some(x) if k < n => x[k],
                Some(x) => Complex::new(0.0, omega) * x[k - n],
                None => Complex::new(f64::NAN, f64::NAN),
            }
        })
        .collect()
}
