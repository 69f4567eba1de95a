//! A drive's measured closed speed loop against the model inside its speed
//! controller: the gain and the phase (unwrapped along frequency) at the measured
//! lines, measured, at the start values and at the identified ones.

use super::curve;
use crate::identify::result::comparison::{Comparison, Role};
use crate::io::experiment_file::Experiment;
use crate::model::Params;
use crate::tuning::speed_loop::measured::{model_bode, MeasuredSpeedLoop};

/// The gain and phase comparisons of one speed-loop response (none where the file
/// has no valid line with phase).
pub(super) fn compare(
    source: &str,
    exp: &Experiment,
    start: &Params,
    fitted: &Params,
) -> Vec<Comparison> {
    let Ok(m) = MeasuredSpeedLoop::of(exp) else {
        return Vec::new();
    };
    let (gain, phase) = m.bode();
    let f = &m.frequency_hz;
    let mut plots = [
        ("closed speed loop, actual / setpoint speed, dB", gain),
        ("phase (unwrapped), °", phase),
    ]
    .map(|(label, measured)| Comparison {
        source: source.into(),
        x_label: "frequency, Hz".into(),
        y_label: label.into(),
        curves: vec![curve("measured", Role::Measured, f, &measured)],
    });
    for (label, role, p) in [
        ("closed-loop model, start", Role::Start, start),
        ("closed-loop model, identified", Role::Fitted, fitted),
    ] {
        let Ok(model) = model_bode(p, &m.conditions, f) else {
            continue;
        };
        let at: Vec<(f64, (f64, f64))> = f
            .iter()
            .zip(model)
            .filter_map(|(&f, v)| Some((f, v?)))
            .collect();
        let x: Vec<f64> = at.iter().map(|(f, _)| *f).collect();
        for (plot, k) in plots.iter_mut().zip([0, 1]) {
            let y: Vec<f64> = at
                .iter()
                .map(|(_, v)| if k == 0 { v.0 } else { v.1 })
                .collect();
            plot.curves.push(curve(label, role, &x, &y));
        }
    }
    plots.into()
}
