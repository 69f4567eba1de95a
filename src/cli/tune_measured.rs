//! `rtid tune --measured FILE`: a drive's measured closed speed loop
//! (`response: "speed_loop"`) beside the model's with today's settings and the
//! proposed ones — a Bode plot beside `--plot` and `measured_speed_loop` in the JSON —
//! and a warning, before anything is proposed, where the model does not explain it.

use std::path::Path;

use anyhow::Context;

use crate::cli::common::plot::Plot;
use rtid::report::speed_loop::{bode, Curve};
use rtid::tuning::speed_loop::measured::MeasuredSpeedLoop;
use rtid::tuning::speed_loop::overlay::{self, Overlay};

/// The measurement of `path`, read and checked.
pub fn read(path: &Path) -> anyhow::Result<MeasuredSpeedLoop> {
    let exp = rtid::read_experiment(path)?;
    MeasuredSpeedLoop::of(&exp)
        .map_err(anyhow::Error::msg)
        .with_context(|| format!("--measured {}", path.display()))
}

/// The warning about today's model, for stderr before the search.
pub fn check(
    path: &Path,
    m: &MeasuredSpeedLoop,
    today: &rtid::Params,
) -> anyhow::Result<Option<String>> {
    let misfit = m.misfit(today)?;
    Ok(overlay::warning(
        &path.display().to_string(),
        "today's settings",
        &misfit,
    ))
}

/// The overlay of today's and the proposed settings, its plot written beside `plot`.
pub fn overlay(
    path: &Path,
    m: &MeasuredSpeedLoop,
    today: &rtid::Params,
    proposed: &rtid::Params,
    plot: &Plot,
) -> anyhow::Result<Overlay> {
    let o = overlay::overlay(
        &path.display().to_string(),
        m,
        &[("today's settings", today), ("proposed settings", proposed)],
    )?;
    let mut curves = vec![Curve {
        name: "measured",
        frequency_hz: &o.measured.frequency_hz,
        gain_db: &o.measured.gain_db,
        phase_deg: &o.measured.phase_deg,
        measured: true,
    }];
    curves.extend(o.models.iter().map(|c| Curve {
        name: &c.label,
        frequency_hz: &c.curve.frequency_hz,
        gain_db: &c.curve.gain_db,
        phase_deg: &c.curve.phase_deg,
        measured: false,
    }));
    plot.write(
        &bode("closed speed loop: measured and the model", &curves),
        "-speed-loop",
    )?;
    Ok(o)
}

/// One line per setting: how far its closed loop is from the measurement.
pub fn print(o: &Overlay) {
    println!("measured speed loop {}:", o.source);
    for c in &o.models {
        println!(
            "  {}: RMS {:.2} dB, {:.1}°, reduced χ² {:.1}{}",
            c.label,
            c.misfit.gain_rms_db,
            c.misfit.phase_rms_deg,
            c.misfit.reduced_chi2,
            if c.misfit.explained {
                ""
            } else {
                " (beyond the record's noise)"
            }
        );
    }
}
