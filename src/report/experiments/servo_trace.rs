//! Figures of a servo trace: the following error and the drive's effort over time,
//! measured and, when the model replayed it, replayed.

use crate::experiments::positioning::iso230::ARCSEC_PER_RAD;
use crate::experiments::servo_trace::{Replay, ServoTrace};
use crate::io::experiment_file::Axis;
use crate::report::figure::{Figure, Series, Style};

/// Points kept per series (a trace has tens of thousands of samples).
const MAX_POINTS: usize = 4000;

/// The following error, reference minus loop encoder, in µm (linear) or arc-seconds
/// (rotary), measured and replayed.
pub fn following_error(trace: &ServoTrace, replay: Option<&Replay>, axis: Axis) -> Figure {
    let (scale, unit) = position_unit(axis);
    let error = |position: &[f64]| -> Vec<(f64, f64)> {
        trace
            .time_s
            .iter()
            .zip(trace.reference.iter().zip(position))
            .map(|(&t, (&r, &q))| (t, (r - q) * scale))
            .collect()
    };
    let mut figure = Figure::new(
        "servo trace: following error",
        "time, s",
        &format!("reference − position, {unit}"),
    )
    .with(Series::new("measured", error(&trace.position), Style::Line).thinned(MAX_POINTS));
    if let Some(run) = replay {
        figure = figure
            .with(Series::new("replayed", error(&run.position), Style::Line).thinned(MAX_POINTS));
    }
    figure
}

/// The drive's force or torque over time, measured and replayed.
pub fn effort(trace: &ServoTrace, replay: Option<&Replay>, axis: Axis) -> Figure {
    let unit = match axis {
        Axis::Linear => "force, N",
        Axis::Rotary => "torque, N·m",
    };
    let over_time = |f: &[f64]| {
        trace
            .time_s
            .iter()
            .copied()
            .zip(f.iter().copied())
            .collect()
    };
    let mut figure = Figure::new("servo trace: drive effort", "time, s", unit)
        .with(Series::new("measured", over_time(&trace.force), Style::Line).thinned(MAX_POINTS));
    if let Some(run) = replay {
        figure = figure
            .with(Series::new("replayed", over_time(&run.force), Style::Line).thinned(MAX_POINTS));
    }
    figure
}

/// The unit positions are reported in, and the factor from SI.
pub fn position_unit(axis: Axis) -> (f64, &'static str) {
    match axis {
        Axis::Linear => (1e6, "µm"),
        Axis::Rotary => (ARCSEC_PER_RAD, "arcsec"),
    }
}
