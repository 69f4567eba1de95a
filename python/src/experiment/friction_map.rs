//! `rtid.run_experiment("friction_map", …)`: the friction map on the model, as
//! `rtid experiment friction-map` runs it (the speeds both ways, the settling, the
//! averaging window, the noise and the run-to-run scatter).

use pyo3::prelude::*;

use super::{limit, Settings, Work};
use crate::errors::{bad_argument, rtid_error};
use rtid::experiments::friction_map::{self, MapTest};
use rtid::io::experiment_file::Data;
use rtid::limits;
use rtid::model::{Axis, Params};

/// The map the settings describe, checked before anything runs, and its run.
pub fn prepare(s: &Settings, p: &Params) -> PyResult<Work> {
    let rpm: Option<Vec<f64>> = s.get("speeds_rpm")?;
    let mm_s: Option<Vec<f64>> = s.get("speeds_mm_s")?;
    let (given, option, si) = match (p.axis, rpm, mm_s) {
        (Axis::Rotary, rpm, None) => (rpm, "speeds_rpm", std::f64::consts::TAU / 60.0),
        (Axis::Linear, None, mm_s) => (mm_s, "speeds_mm_s", 1e-3),
        (Axis::Rotary, _, Some(_)) => {
            return Err(bad_argument(
                "speeds_mm_s",
                "for a linear axis; this axis is rotary (speeds_rpm)",
            ))
        }
        (Axis::Linear, Some(_), _) => {
            return Err(bad_argument(
                "speeds_rpm",
                "for a rotary axis; this axis is linear (speeds_mm_s)",
            ))
        }
    };
    let speeds = match given {
        Some(v) => speeds(&v, option, si)?,
        None => MapTest::default_speeds(p),
    };
    let test = MapTest {
        speeds,
        settle: s.get("settle_s")?,
        average: s.get("average_s")?,
        sample: 0.0,
        noise_percent: s.get("noise_percent")?,
        seed: s.get("seed")?,
    };
    for &v in &test.speeds {
        let window = test.window(p, v);
        if window > friction_map::run::MAX_WINDOW_S {
            return Err(bad_argument(
                option,
                format!(
                    "at {} the averaging window would be {window:.0} s (whole revolutions of the driving shaft, whose gear fluctuation averages out only over them), beyond {} s: give faster speeds",
                    v / si,
                    friction_map::run::MAX_WINDOW_S
                ),
            ));
        }
    }
    limit(
        test.duration(p),
        limits::MAX_SIMULATED_S,
        "simulated seconds",
        "speeds_rpm (speeds_mm_s), settle_s, average_s",
    )?;
    let scatter: f64 = s.get("scatter_percent")?;
    let p = p.clone();
    Ok(Box::new(move || {
        let (manifest, map) =
            friction_map::run::record(&p, &test, scatter, |_, _| {}).map_err(|e| rtid_error(&e))?;
        Ok((manifest, Data::FrictionMap(map)))
    }))
}

/// The speeds given, in SI: each positive one in both directions, a negative one in
/// its own; zero, non-finite and repeated speeds refused naming the setting.
fn speeds(given: &[f64], option: &str, si: f64) -> PyResult<Vec<f64>> {
    if given.is_empty() {
        return Err(bad_argument(
            option,
            "no speed: give at least one, or leave it out",
        ));
    }
    let mut out: Vec<f64> = Vec::new();
    for &v in given {
        if !v.is_finite() || v == 0.0 {
            return Err(bad_argument(
                option,
                format!("{v} is not a speed of a run (finite, not 0)"),
            ));
        }
        let both: &[f64] = if v > 0.0 { &[-1.0, 1.0] } else { &[1.0] };
        for sign in both {
            let speed = sign * v * si;
            if out.contains(&speed) {
                return Err(bad_argument(option, format!("{v} is given twice")));
            }
            out.push(speed);
        }
    }
    out.sort_by(f64::total_cmp);
    Ok(out)
}
