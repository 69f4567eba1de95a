//! The closed speed loop's Bode plot: the gain over the phase on one logarithmic
//! frequency axis, a curve per response — measured (markers) and the model's with
//! one or more settings (lines) — as `rtid experiment speed-loop`, `rtid compare`
//! and `rtid tune --measured` draw them.

use crate::report::figure::{Figure, Series, Style};

/// One response: its name, its lines (Hz), gains (dB) and phases (deg), and whether
/// it is a measurement (drawn as markers) or a model (a line).
pub struct Curve<'a> {
    pub name: &'a str,
    pub frequency_hz: &'a [f64],
    pub gain_db: &'a [f64],
    pub phase_deg: &'a [f64],
    pub measured: bool,
}

/// Most points a curve keeps in the SVG.
const MAX_POINTS: usize = 1200;

/// The gain above the phase.
pub fn bode(title: &str, curves: &[Curve]) -> Figure {
    let series = |c: &Curve, y: &[f64]| {
        let style = if c.measured {
            Style::Markers
        } else {
            Style::Line
        };
        let points = c
            .frequency_hz
            .iter()
            .zip(y)
            .filter(|(f, v)| **f > 0.0 && v.is_finite())
            .map(|(f, v)| (*f, *v))
            .collect();
        Series::new(c.name, points, style).thinned(MAX_POINTS)
    };
    let mut gain = Figure::new(title, "frequency, Hz", "actual / setpoint speed, dB").log_x();
    let mut phase = Figure::new("", "frequency, Hz", "phase, °").log_x();
    for c in curves {
        gain = gain.with(series(c, c.gain_db));
        phase = phase.with(series(c, c.phase_deg));
    }
    gain.above(phase)
}
