//! The figures of `rtid tune --plot`: the open loops before and after tuning — the
//! velocity loop alone and the cascade as it runs — as a Bode plot (gain in dB over
//! phase in degrees on one log frequency axis), each loop's margins marked where they
//! are read and named in the legend with their values; and beside it the loops closed
//! (the speed and the position loop's gains over the cascade's sensitivity |S|, its
//! peak named).

use super::figure::{Figure, Series, Style};
use crate::tuning::bode::Bode;
use crate::tuning::closed_loop::Curves;

/// The Bode plot of `curves` (each named in the legend: `velocity loop alone,
/// before`, …), titled `title`.
pub fn open_loop(curves: &[(&str, &Bode)], title: &str) -> Figure {
    let mut gain = Figure::new(title, "frequency, Hz", "|L|, dB").log_x();
    let mut phase = Figure::new("", "", "arg L, degrees (unwrapped)");
    for (who, b) in curves {
        gain = gain.with(Series::new(*who, b.gain_db.clone(), Style::Line));
        phase = phase.with(Series::new(*who, b.phase_deg.clone(), Style::Line));
    }
    for (who, b) in curves {
        if let Some((f, at, pm)) = b.phase_margin {
            let name = format!("{who}: phase margin {} at {} Hz", degrees(pm), hz(f));
            gain = gain.with(Series::new(&name, vec![(f, 0.0)], Style::Markers));
            phase = phase.with(Series::new(&name, vec![(f, at)], Style::Markers));
        }
        if let Some((f, db, at)) = b.gain_margin {
            let name = format!("{who}: gain margin {:.1} dB at {} Hz", -db, hz(f));
            gain = gain.with(Series::new(&name, vec![(f, db)], Style::Markers));
            phase = phase.with(Series::new(&name, vec![(f, at)], Style::Markers));
        }
    }
    let (lo, hi) = span(curves);
    let reference = "0 dB and −180°";
    gain = gain.with(Series::new(
        reference,
        vec![(lo, 0.0), (hi, 0.0)],
        Style::Dashed,
    ));
    phase = phase.with(Series::new(
        reference,
        vec![(lo, -180.0), (hi, -180.0)],
        Style::Dashed,
    ));
    gain.above(phase)
}

/// The closed loops of each setting (`before`, `after`): the closed speed and
/// position loops' gains above, the cascade's sensitivity |S| below, with |S|max named
/// in the legend.
pub fn closed_loops(curves: &[(&str, &Curves)], title: &str) -> Figure {
    let mut gain = Figure::new(title, "frequency, Hz", "|T|, dB").log_x();
    let mut sensitivity = Figure::new("", "", "|S|, dB");
    for (who, c) in curves {
        gain = gain
            .with(Series::new(
                format!("closed speed loop, {who}"),
                c.speed.clone(),
                Style::Line,
            ))
            .with(Series::new(
                format!("closed position loop, {who}"),
                c.position.clone(),
                Style::Line,
            ));
        let peak = c
            .sensitivity
            .iter()
            .copied()
            .fold(
                (0.0, f64::NEG_INFINITY),
                |a, b| if b.1 > a.1 { b } else { a },
            );
        sensitivity = sensitivity.with(Series::new(
            format!(
                "sensitivity, {who}: |S|max {:.1} dB at {} Hz",
                peak.1,
                hz(peak.0)
            ),
            c.sensitivity.clone(),
            Style::Line,
        ));
    }
    let (lo, hi) = curves
        .iter()
        .flat_map(|(_, c)| &c.speed)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    gain = gain.with(Series::new(
        "−3 dB",
        vec![(lo, -3.0), (hi, -3.0)],
        Style::Dashed,
    ));
    gain.above(sensitivity)
}

/// The frequencies the curves span, Hz.
fn span(curves: &[(&str, &Bode)]) -> (f64, f64) {
    curves
        .iter()
        .flat_map(|(_, b)| &b.gain_db)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        })
}

/// `52.3°`.
fn degrees(v: f64) -> String {
    format!("{v:.1}°")
}

/// A frequency with three significant digits, no trailing `.0`: `120`, `8.43`.
fn hz(f: f64) -> String {
    let digits = (2.0 - f.abs().log10().floor()).clamp(0.0, 12.0) as usize;
    let s = format!("{f:.digits$}");
    super::figure::tick_label(s.parse().unwrap_or(f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::tuning::{bode::bode, rule, Setting, Targets};

    #[test]
    fn the_plot_shows_both_loops_and_the_margins() {
        let p = presets::load("two-mass").unwrap();
        let before = Setting::of(&p, &p.controller).unwrap();
        let after = Setting::of(&p, &rule(&p, Targets::default()).unwrap()).unwrap();
        let (b, a) = (bode(&p, &before).unwrap(), bode(&p, &after).unwrap());
        let svg = open_loop(&[("before", &b), ("after", &a)], "two-mass: velocity loop")
            .render()
            .unwrap();
        for s in ["before", "after", "after: phase margin"] {
            assert!(svg.contains(s), "{s}");
        }
        let pm = after.velocity_loop.phase_margin_deg.unwrap();
        assert!(svg.contains(&degrees(pm)), "{pm}");
        assert_eq!(hz(119.44), "119");
        assert_eq!(hz(8.4321), "8.43");
    }

    #[test]
    fn the_closed_loops_plot_names_the_sensitivity_peak() {
        let p = presets::load("two-mass").unwrap();
        let plant = crate::tuning::sampled::DiscretePlant::new(&p).unwrap();
        let c = crate::tuning::closed_loop::curves(&plant, &p.controller, 0.1, 200);
        let peak = crate::tuning::closed_loop::analyse(&plant, &p.controller).sensitivity_peak_db;
        let svg = closed_loops(&[("before", &c)], "two-mass")
            .render()
            .unwrap();
        for s in [
            "closed speed loop, before",
            "closed position loop, before",
            "|S|max",
        ] {
            assert!(svg.contains(s), "{s}");
        }
        assert!(svg.contains(&format!("{peak:.1} dB")), "{peak}");
    }
}
