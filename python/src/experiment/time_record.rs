//! `rtid.run_experiment("frequency_response_time", …)`: the frequency-response test
//! recorded as raw time series (stepped sine, noise, chirp or periodic multisine), as
//! `rtid experiment frequency-response-time` records it.

use pyo3::prelude::*;

use super::{limit, Settings, Work};
use crate::errors::{bad_argument, rtid_error};
use rtid::estimation::periodic::multisine::LineSet;
use rtid::experiments::frequency_response::time_record::{self as record, Excitation, RecordTest};
use rtid::limits;
use rtid::model::Params;

/// The record the settings describe, checked (and its work estimated) before
/// anything runs, and its run.
pub fn prepare(s: &Settings, p: &Params) -> PyResult<Work> {
    let (from, to): (f64, f64) = (s.get("from_hz")?, s.get("to_hz")?);
    if !(from >= 0.0 && to > from) {
        return Err(bad_argument(
            "from_hz, to_hz",
            format!("{from}, {to}: need 0 ≤ from_hz < to_hz"),
        ));
    }
    let test = RecordTest {
        excitation: excitation(s, from, to)?,
        amplitude_nm: s.get("amplitude_nm")?,
        preload_nm: s.get("preload_nm")?,
        duration_s: s.get("duration_s")?,
        sample_rate_hz: s.get("sample_rate_hz")?,
        table_noise_rad: (s.get::<f64>("noise_arcsec")? / 3600.0).to_radians(),
        seed: s.get("seed")?,
    };
    if to >= test.sample_rate_hz / 2.0 {
        return Err(bad_argument(
            "sample_rate_hz",
            format!(
                "{}: a record sampled at it holds frequencies up to {} Hz (half the rate), below to_hz {to}: sample more than twice as fast as the highest frequency excited",
                test.sample_rate_hz,
                test.sample_rate_hz / 2.0
            ),
        ));
    }
    limit(
        test.duration(),
        limits::MAX_SIMULATED_S,
        "simulated seconds",
        "duration_s (or periods × period_s, frequencies × dwell_s)",
    )?;
    limit(
        test.duration() * test.sample_rate_hz,
        limits::MAX_RECORD_SAMPLES,
        "samples",
        "sample_rate_hz with the record's length",
    )?;
    let p = p.clone();
    Ok(Box::new(move || {
        let rec = record::run(&p, &test, |_, _| {}).map_err(|e| rtid_error(&e))?;
        Ok((record::manifest(&p, &test), record::to_data(&rec)))
    }))
}

/// The excitation the settings describe.
fn excitation(s: &Settings, from: f64, to: f64) -> PyResult<Excitation> {
    let kind: String = s.get("excitation")?;
    Ok(match kind.as_str() {
        "stepped_sine" => {
            let step: f64 = s.get("step_hz")?;
            if from <= 0.0 {
                return Err(bad_argument("from_hz", "a stepped sine starts above 0 Hz"));
            }
            let grid = limits::frequency_grid(from, to, step, "from_hz, to_hz, step_hz");
            Excitation::SteppedSine {
                frequencies_hz: grid.map_err(|e| rtid_error(&e))?,
                dwell_s: s.get("dwell_s")?,
            }
        }
        "noise" => Excitation::Noise {
            seed: s.get("seed")?,
            from_hz: from,
            to_hz: to,
        },
        "chirp" => Excitation::Chirp {
            from_hz: from,
            to_hz: to,
        },
        "multisine" => {
            let periods: usize = s.get("periods")?;
            if periods < 3 {
                return Err(bad_argument(
                    "periods",
                    format!("{periods}: need 3 or more (the first is dropped as transient, and the noise needs two)"),
                ));
            }
            if from <= 0.0 {
                return Err(bad_argument(
                    "from_hz",
                    "a multisine's band starts above 0 Hz",
                ));
            }
            let lines = match s.get::<String>("lines")?.as_str() {
                "full" => LineSet::Full,
                "odd" => LineSet::Odd,
                _ => LineSet::RandomOdd {
                    group: 4,
                    seed: s.get("seed")?,
                },
            };
            Excitation::Multisine {
                period_s: s.get("period_s")?,
                periods,
                from_hz: from,
                to_hz: to,
                lines,
            }
        }
        other => {
            return Err(bad_argument(
                "excitation",
                format!(
                "unknown excitation `{other}`: expected stepped_sine, noise, chirp or multisine"
            ),
            ))
        }
    })
}
