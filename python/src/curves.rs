//! An identification's curves: each experiment's measured data beside the model at
//! the start and the identified values, in the experiment's axes — the command
//! line's comparisons (`rtid::identify::pipeline::comparison`), unthinned, and for a
//! frequency response the linear model's gain — and where the file has one, its
//! phase — at the measured frequencies, so that each curve has a residual.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use rtid::experiments::frequency_response::measured;
use rtid::identify::config::ExperimentSpec;
use rtid::identify::pipeline::comparison;
use rtid::identify::result::comparison::{Comparison, Curve, Role};
use rtid::io::experiment_file::{Data, Response};
use rtid::model::linear_response::{Channel, LinearResponse};
use rtid::Params;

/// The comparisons of every experiment; an experiment whose model cannot be run
/// (a replay diverging at the start values) has none, as on the command line.
pub fn compute(experiments: &[ExperimentSpec], start: &Params, fitted: &Params) -> Vec<Comparison> {
    let mut all = Vec::new();
    for e in experiments {
        if let Data::FrequencyResponse { .. } = &e.experiment.data {
            all.extend(gain(&e.source, &e.experiment, start, fitted));
            all.extend(phase(&e.source, &e.experiment, start, fitted));
        } else if let Ok(c) = comparison::compare(&e.source, &e.experiment, start, fitted) {
            all.extend(c);
        }
    }
    all
}

/// The measured gain, dB, and the linear model's at the measured frequencies.
fn gain(
    source: &str,
    exp: &rtid::Experiment,
    start: &Params,
    fitted: &Params,
) -> Option<Comparison> {
    let (f, g): (Vec<f64>, Vec<f64>) = measured::valid_points(exp).unzip();
    if f.is_empty() {
        return None;
    }
    let response = measured::form(exp).response;
    let channel = match response {
        Response::TableOverMotor => Channel::TableOverMotor,
        Response::MotorCompliance => Channel::MotorOverTorque,
        // The closed loop is not a channel of the mechanics' linear response.
        Response::SpeedLoop => return None,
    };
    let model = |p: &Params| -> Option<Vec<f64>> {
        let lin = LinearResponse::new(p, channel).ok()?;
        Some(f.iter().map(|&hz| lin.gain_db(hz)).collect())
    };
    let mut curves = vec![curve("measured", Role::Measured, &f, &g)];
    if let Some(y) = model(start) {
        curves.push(curve("linear model, start", Role::Start, &f, &y));
    }
    curves.push(curve(
        "linear model, identified",
        Role::Fitted,
        &f,
        &model(fitted)?,
    ));
    let y_label = match response {
        Response::TableOverMotor => "gain, dB",
        Response::MotorCompliance => "motor compliance, dB re 1 rad/(N·m)",
        Response::SpeedLoop => "closed speed loop, dB",
    };
    Some(Comparison {
        source: source.into(),
        x_label: "frequency, Hz".into(),
        y_label: y_label.into(),
        curves,
    })
}

/// The measured phase, degrees (the drive's: the file's stated delay taken out), and
/// the linear model's at the measured frequencies, each model value the turn nearest
/// the measured one (a phase is known modulo 360°).
fn phase(
    source: &str,
    exp: &rtid::Experiment,
    start: &Params,
    fitted: &Params,
) -> Option<Comparison> {
    let c = measured::complex_points(exp, |_| true).filter(|c| !c.frequency_hz.is_empty())?;
    let f = &c.frequency_hz;
    let m: Vec<f64> = c.phase_rad.iter().map(|p| p.to_degrees()).collect();
    let channel = match measured::form(exp).response {
        Response::TableOverMotor => Channel::TableOverMotor,
        Response::MotorCompliance => Channel::MotorOverTorque,
        // The closed speed loop's model is the controller's, not an open channel's:
        // `rtid compare` draws it.
        Response::SpeedLoop => return None,
    };
    let model = |p: &Params| -> Option<Vec<f64>> {
        let lin = LinearResponse::new(p, channel).ok()?;
        let near = |hz: f64, measured: f64| {
            let deg = lin.at(hz)?.arg().to_degrees();
            Some(deg + 360.0 * ((measured - deg) / 360.0).round())
        };
        f.iter().zip(&m).map(|(&hz, &y)| near(hz, y)).collect()
    };
    let mut curves = vec![curve("measured", Role::Measured, f, &m)];
    if let Some(y) = model(start) {
        curves.push(curve("linear model, start", Role::Start, f, &y));
    }
    curves.push(curve(
        "linear model, identified",
        Role::Fitted,
        f,
        &model(fitted)?,
    ));
    Some(Comparison {
        source: source.into(),
        x_label: "frequency, Hz".into(),
        y_label: "phase, deg".into(),
        curves,
    })
}

fn curve(label: &str, role: Role, x: &[f64], y: &[f64]) -> Curve {
    Curve {
        label: label.into(),
        role,
        points: x.iter().copied().zip(y.iter().copied()).collect(),
    }
}

/// The comparisons as Python dicts: `source`, `x_label`, `y_label` and `curves`, each
/// curve `label`, `role` (`measured`, `start`, `fitted`), `x` and `y` arrays.
pub fn to_python<'py>(py: Python<'py>, all: Vec<Comparison>) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for c in all {
        let d = PyDict::new(py);
        d.set_item("source", c.source)?;
        d.set_item("x_label", c.x_label)?;
        d.set_item("y_label", c.y_label)?;
        let curves = PyList::empty(py);
        for k in c.curves {
            let e = PyDict::new(py);
            e.set_item("label", k.label)?;
            let role = match k.role {
                Role::Measured => "measured",
                Role::Start => "start",
                Role::Fitted => "fitted",
            };
            e.set_item("role", role)?;
            let (x, y): (Vec<f64>, Vec<f64>) = k.points.into_iter().unzip();
            e.set_item("x", PyArray1::from_vec(py, x))?;
            e.set_item("y", PyArray1::from_vec(py, y))?;
            curves.append(e)?;
        }
        d.set_item("curves", curves)?;
        list.append(d)?;
    }
    Ok(list)
}
