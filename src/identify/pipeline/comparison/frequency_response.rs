//! A frequency response against the linear model: the gain, and where the file has
//! phase the phase (unwrapped along frequency) and the Nyquist plot — a Bode plot
//! in two figures, and the complex plane where a mode is a circle.

use std::f64::consts::TAU;

use super::curve;
use crate::experiments::frequency_response::measured;
use crate::identify::result::comparison::{Comparison, Curve, Role};
use crate::io::experiment_file::{Experiment, Response};
use crate::model::linear_response::{Channel, LinearResponse};
use crate::model::Params;
use crate::objectives::complex_response::unwrap;
use crate::objectives::{gain_curve, Detail, Fidelity, Source};

/// The comparisons of one frequency response: gain; phase and Nyquist with phase.
pub(super) fn compare(
    source: &str,
    exp: &Experiment,
    start: &Params,
    fitted: &Params,
) -> Vec<Comparison> {
    let (f, g): (Vec<f64>, Vec<f64>) = measured::valid_points(exp).unzip();
    if f.is_empty() {
        return Vec::new();
    }
    let response = measured::form(exp).response;
    let grid = model_grid(&f, response, start, fitted);
    let mut out = vec![gain(source, response, (&f, &g), &grid, start, fitted)];
    if let Some(m) = measured::complex_points(exp, |_| true) {
        // The fitted delay taken out, on the canonical ratio's sign.
        let sign = if measured::form(exp).inverted {
            -1.0
        } else {
            1.0
        };
        let delay = sign * fitted_delay(source, exp, fitted);
        let phase: Vec<f64> = m
            .phase_rad
            .iter()
            .zip(&m.frequency_hz)
            .map(|(p, f)| p + TAU * f * delay)
            .collect();
        out.push(phase_plot(
            source,
            (&m.frequency_hz, &phase),
            &grid,
            response,
            fitted,
        ));
        out.push(nyquist(
            source,
            (&m.ln_gain, &phase),
            &grid,
            response,
            fitted,
        ));
    }
    out
}

/// The models' frequencies over the measured range: log-spaced, refined through
/// each resonance of either model ([`super::grid`]).
fn model_grid(f: &[f64], response: Response, start: &Params, fitted: &Params) -> Vec<f64> {
    let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut grid = Vec::new();
    for p in [start, fitted] {
        let Ok(lin) = LinearResponse::new(p, channel(response)) else {
            continue;
        };
        grid.extend(super::grid::model_grid(lo, hi, |f| {
            lin.at(f).map(|h| h.norm())
        }));
    }
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    grid
}

/// The linear response's channel of a measured response.
fn channel(response: Response) -> Channel {
    match response {
        Response::TableOverMotor => Channel::TableOverMotor,
        // A speed loop is compared by `super::speed_loop`, never here.
        Response::MotorCompliance | Response::SpeedLoop => Channel::MotorOverTorque,
    }
}

/// The model's complex response at `grid` (empty where it cannot be built).
fn model(p: &Params, response: Response, grid: &[f64]) -> Vec<(f64, nalgebra::Complex<f64>)> {
    let Ok(lin) = LinearResponse::new(p, channel(response)) else {
        return Vec::new();
    };
    grid.iter()
        .filter_map(|&f| lin.at(f).map(|h| (f, h)))
        .collect()
}

/// The y label of the gain.
fn gain_label(response: Response) -> &'static str {
    match response {
        Response::TableOverMotor => "gain θt/(θm·Rg·Rw), dB",
        Response::MotorCompliance => "compliance θm/Tm, dB re 1 rad/(N·m)",
        Response::SpeedLoop => "closed speed loop, actual / setpoint speed, dB",
    }
}

/// The measured gain and the linear model's at the start and identified values.
fn gain(
    source: &str,
    response: Response,
    (f, g): (&[f64], &[f64]),
    grid: &[f64],
    start: &Params,
    fitted: &Params,
) -> Comparison {
    let db = |p: &Params| -> Vec<(f64, f64)> {
        model(p, response, grid)
            .into_iter()
            .map(|(f, h)| (f, 20.0 * h.norm().log10()))
            .collect()
    };
    let mut measured = curve("measured", Role::Measured, f, g);
    measured.points.retain(|(_, g)| g.is_finite());
    Comparison {
        source: source.into(),
        x_label: "frequency, Hz".into(),
        y_label: gain_label(response).into(),
        curves: vec![
            measured,
            Curve {
                label: "linear model, start".into(),
                role: Role::Start,
                points: db(start),
            },
            Curve {
                label: "linear model, identified".into(),
                role: Role::Fitted,
                points: db(fitted),
            },
        ],
    }
}

/// The delay the fit found where the file's is unknown (0 otherwise), s.
fn fitted_delay(source: &str, exp: &Experiment, fitted: &Params) -> f64 {
    let src = Source {
        file: source,
        experiment: exp,
    };
    let Ok(o) = (gain_curve::DEFINITION.build)(&src, Fidelity::Linear) else {
        return 0.0;
    };
    let Ok(r) = o.residuals(fitted) else {
        return 0.0;
    };
    match o.detail(fitted, &r) {
        Some(Detail::ComplexResponse {
            fitted_delay_s: Some(d),
            ..
        }) => d,
        _ => 0.0,
    }
}

/// The measured phase (its delay taken out) and the identified model's, degrees,
/// each unwrapped along frequency, the model's on the measured one's branch.
fn phase_plot(
    source: &str,
    (f, phase): (&[f64], &[f64]),
    grid: &[f64],
    response: Response,
    fitted: &Params,
) -> Comparison {
    let measured = unwrap(phase);
    let m = model(fitted, response, grid);
    let mut model_phase = unwrap(&m.iter().map(|(_, h)| h.arg()).collect::<Vec<_>>());
    if let (Some(first), Some(&m0)) = (measured.first(), model_phase.first()) {
        // The model's value at the first measured line, on the measured branch.
        let shift = TAU * ((first - m0) / TAU).round();
        model_phase.iter_mut().for_each(|p| *p += shift);
    }
    let deg = |v: &[f64]| v.iter().map(|p| p.to_degrees()).collect::<Vec<f64>>();
    let grid: Vec<f64> = m.iter().map(|(f, _)| *f).collect();
    Comparison {
        source: source.into(),
        x_label: "frequency, Hz".into(),
        y_label: "phase (unwrapped), °".into(),
        curves: vec![
            curve("measured", Role::Measured, f, &deg(&measured)),
            curve(
                "linear model, identified",
                Role::Fitted,
                &grid,
                &deg(&model_phase),
            ),
        ],
    }
}

/// The measured and the identified complex response in the complex plane.
fn nyquist(
    source: &str,
    (ln_gain, phase): (&[f64], &[f64]),
    grid: &[f64],
    response: Response,
    fitted: &Params,
) -> Comparison {
    let measured: Vec<(f64, f64)> = ln_gain
        .iter()
        .zip(phase)
        .map(|(l, p)| (l.exp() * p.cos(), l.exp() * p.sin()))
        .collect();
    let m: Vec<(f64, f64)> = model(fitted, response, grid)
        .into_iter()
        .map(|(_, h)| (h.re, h.im))
        .collect();
    let part = |v: &[(f64, f64)], k: usize| {
        v.iter()
            .map(|p| if k == 0 { p.0 } else { p.1 })
            .collect::<Vec<f64>>()
    };
    Comparison {
        source: source.into(),
        x_label: "real part".into(),
        y_label: "imaginary part".into(),
        curves: vec![
            curve(
                "measured",
                Role::Measured,
                &part(&measured, 0),
                &part(&measured, 1),
            ),
            curve(
                "linear model, identified",
                Role::Fitted,
                &part(&m, 0),
                &part(&m, 1),
            ),
        ],
    }
}
