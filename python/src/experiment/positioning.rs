//! `rtid.run_experiment("positioning", …)`: the ISO 230-2 cycle on the model, as
//! `rtid experiment positioning` runs it — targets from the step and the travel, the
//! standard's runs, the dwell, the noise, a compensation run in the controller — its
//! settings checked as the flags are.

use std::path::Path;

use pyo3::prelude::*;

use super::{limit, loop_mode, loop_note, Settings, Work};
use crate::errors::{bad_argument, rtid_error, with_context};
use rtid::experiments::positioning::{self, iso230::ARCSEC_PER_RAD, PositioningTest};
use rtid::io::compensation_file;
use rtid::limits;
use rtid::model::{Axis, Params};

/// The test the settings describe on `p`'s axis, checked before anything runs, and
/// its run.
pub fn prepare(s: &Settings, p: &Params) -> PyResult<Work> {
    let runs: u32 = s.get("runs")?;
    if runs < 2 {
        return Err(bad_argument(
            "runs",
            format!(
                "{runs}: ISO 230-2 needs at least 2 runs per direction (5 in the standard test)"
            ),
        ));
    }
    let (targets, speed, noise) = match p.axis {
        Axis::Rotary => rotary(s)?,
        Axis::Linear => linear(s)?,
    };
    let readings = 2.0 * targets.len() as f64 * f64::from(runs);
    limit(
        readings,
        limits::MAX_POINTS,
        "readings",
        "runs with the targets",
    )?;
    let loop_mode = loop_mode(s, "loop")?;
    let test = PositioningTest {
        targets,
        runs,
        dwell: s.get("dwell_s")?,
        speed,
        noise,
        seed: s.get("seed")?,
        loop_mode,
        overrun: match p.axis {
            Axis::Rotary => 5f64.to_radians(),
            Axis::Linear => 5e-3,
        },
        compensation: compensation(s, p.axis)?,
    };
    limit(
        test.duration(),
        limits::MAX_SIMULATED_S,
        "simulated seconds",
        "runs, target_step_deg/mm, travel_mm, speed_*, dwell_s",
    )?;
    let p = p.clone();
    Ok(Box::new(move || {
        let readings = positioning::run(&p, &test, |_, _| {}).map_err(|e| rtid_error(&e))?;
        let mut manifest = positioning::manifest(&p, &test);
        super::add_note(&mut manifest, loop_note(loop_mode, &p));
        Ok((manifest, positioning::to_data(&readings, p.axis)))
    }))
}

/// The compensation (compensation.json's text) run in the controller, if given.
fn compensation(s: &Settings, axis: Axis) -> PyResult<rtid::controller::Compensation> {
    let Some(text) = s.get::<Option<String>>("compensation")? else {
        return Ok(Default::default());
    };
    let path = Path::new("the compensation");
    let file =
        compensation_file::parse(&text, path).map_err(|e| with_context("compensation", &e))?;
    file.check_axis(path, axis)
        .map_err(|e| with_context("compensation", &e))?;
    Ok(file.compensation)
}

/// Refuses the settings of the other kind of axis.
fn refuse(s: &Settings, names: &[&str], axis: &str, own: &str) -> PyResult<()> {
    for name in names {
        if s.get::<Option<f64>>(name)?.is_some() {
            return Err(bad_argument(
                name,
                format!("for a {} axis; this axis is {axis} ({own})", other(axis)),
            ));
        }
    }
    Ok(())
}

fn other(axis: &str) -> &'static str {
    if axis == "rotary" {
        "linear"
    } else {
        "rotary"
    }
}

/// Targets, speed and noise of a rotary table (rad, rad/s, rad).
fn rotary(s: &Settings) -> PyResult<(Vec<f64>, f64, f64)> {
    refuse(
        s,
        &[
            "target_step_mm",
            "travel_mm",
            "speed_mm_per_min",
            "noise_um",
        ],
        "rotary",
        "target_step_deg, speed_deg_per_min, noise_arcsec",
    )?;
    let step = s.get::<Option<f64>>("target_step_deg")?.unwrap_or(30.0);
    let speed = s.get::<Option<f64>>("speed_deg_per_min")?.unwrap_or(3600.0);
    let noise = s.get::<Option<f64>>("noise_arcsec")?.unwrap_or(0.0);
    let targets = positioning::rotary_targets(step)
        .map_err(|e| bad_argument("target_step_deg", format!("{step}: {e} in a revolution")))?;
    Ok((targets, speed.to_radians() / 60.0, noise / ARCSEC_PER_RAD))
}

/// Targets, speed and noise of a linear axis (m, m/s, m).
fn linear(s: &Settings) -> PyResult<(Vec<f64>, f64, f64)> {
    refuse(
        s,
        &["target_step_deg", "speed_deg_per_min", "noise_arcsec"],
        "linear",
        "target_step_mm, travel_mm, speed_mm_per_min, noise_um",
    )?;
    let step = s.get::<Option<f64>>("target_step_mm")?.unwrap_or(50.0);
    let travel = s.get::<Option<f64>>("travel_mm")?.unwrap_or(500.0);
    let speed = s.get::<Option<f64>>("speed_mm_per_min")?.unwrap_or(3000.0);
    let noise = s.get::<Option<f64>>("noise_um")?.unwrap_or(0.0);
    let targets = positioning::linear_targets(step, travel).map_err(|e| {
        bad_argument(
            "travel_mm",
            format!("{travel} / target_step_mm {step}: {e}"),
        )
    })?;
    Ok((targets, speed * 1e-3 / 60.0, noise * 1e-6))
}
