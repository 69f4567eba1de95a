//! Figures of the frequency-response test (paper Fig. 8): the gain over frequency (a
//! log axis), the linear model's curve where the file carries one, the resonances
//! marked; the phase on the same frequency axis, and the Nyquist plot to equal scale.

use crate::estimation::peaks::Peak;
use crate::report::figure::{Figure, Series, Style};

/// The gain curve (`frequency_hz`, `gain_db`), the linear model's gain at the same
/// frequencies when given, and the resonances.
pub fn gain(
    frequency_hz: &[f64],
    gain_db: &[f64],
    linear_db: Option<&[f64]>,
    peaks: &[Peak],
    title: &str,
) -> Figure {
    let curve = |g: &[f64]| {
        frequency_hz
            .iter()
            .copied()
            .zip(g.iter().copied())
            .collect()
    };
    let mut figure = Figure::new(title, "frequency, Hz", "gain, dB").with(Series::new(
        "gain (simulated or measured)",
        curve(gain_db),
        Style::Line,
    ));
    if let Some(lin) = linear_db {
        figure = figure.with(Series::new("linear model", curve(lin), Style::Dashed));
    }
    figure
        .with(Series::new(
            "resonances",
            peaks.iter().map(|p| (p.frequency_hz, p.gain_db)).collect(),
            Style::Markers,
        ))
        .log_x()
}

/// The phase (rad, any wrapping) over frequency (ascending), drawn in degrees and
/// unwrapped along frequency: a jump of more than 180° between neighbouring lines is
/// taken as a whole turn.
pub fn phase(frequency_hz: &[f64], phase_rad: &[f64], title: &str) -> Figure {
    let unwrapped = crate::objectives::complex_response::unwrap(phase_rad);
    Figure::new(title, "frequency, Hz", "phase, degrees (unwrapped)")
        .with(Series::new(
            "phase (unwrapped along frequency)",
            frequency_hz
                .iter()
                .zip(&unwrapped)
                .map(|(&f, p)| (f, p.to_degrees()))
                .collect(),
            Style::Line,
        ))
        .log_x()
}

/// The Nyquist plot: Im H against Re H, lines joined in frequency order (`ln_gain`:
/// natural log of |H|, `phase_rad`), each line marked; the axes to equal scale (a
/// mode's circle is a circle).
pub fn nyquist(ln_gain: &[f64], phase_rad: &[f64], title: &str, unit: &str) -> Figure {
    let h: Vec<(f64, f64)> = ln_gain
        .iter()
        .zip(phase_rad)
        .map(|(l, p)| {
            let m = l.exp();
            (m * p.cos(), m * p.sin())
        })
        .collect();
    let x = format!("Re H, {unit}");
    let y = format!("Im H, {unit}");
    Figure::new(title, &x, &y)
        .with(Series::new(
            "H (lines in frequency order)",
            h.clone(),
            Style::Line,
        ))
        .with(Series::new("", h, Style::Markers))
        .to_equal_scale()
}

/// The phase plot and the Nyquist plot of a complex response (lines ascending in
/// frequency), titled `what`, H in `unit`.
pub fn phase_and_nyquist(
    frequency_hz: &[f64],
    ln_gain: &[f64],
    phase_rad: &[f64],
    what: &str,
    unit: &str,
) -> [Figure; 2] {
    [
        phase(
            frequency_hz,
            phase_rad,
            &format!("{what}: phase (unwrapped along frequency)"),
        ),
        nyquist(ln_gain, phase_rad, &format!("{what}: Nyquist plot"), unit),
    ]
}
