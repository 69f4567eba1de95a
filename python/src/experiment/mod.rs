//! `rtid.run_experiment`: the virtual tests `rtid experiment KIND` runs on the model
//! (frequency response, torque curve, fluctuation, unbalance), written as the
//! command line writes them — the same manifest and CSV, numbers to the bit. The
//! settings arrive checked by the wrapper (`rtid/_experiments.py`), named as the
//! flags are, with every default filled in.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::params::PyParams;
use rtid::experiments::fluctuation::{self, FluctuationTest, DEFAULT_UNBALANCE};
use rtid::experiments::frequency_response::{self as fr, FrequencyTest};
use rtid::experiments::measurement_noise as noise;
use rtid::experiments::positioning::iso230::ARCSEC_PER_RAD;
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::{Data, Manifest, Response};
use rtid::model::{Axis, LoopMode, Params};

/// Runs test `kind` on `params` with `settings` and writes it as `STEM.json` and
/// `STEM.csv` in `out`; returns the manifest's path.
#[pyfunction]
pub fn run_experiment(
    py: Python<'_>,
    kind: &str,
    params: PyRef<'_, PyParams>,
    settings: &Bound<'_, PyDict>,
    out: PathBuf,
) -> PyResult<PathBuf> {
    let p = params.inner.clone();
    drop(params);
    let s = Settings(settings);
    let (stem, manifest, data) = match kind {
        "frequency_response" => {
            let (test, a) = (frequency_test(&s)?, FrOptions::of(&s)?);
            let (m, d) = py.detach(|| frequency_response(&p, &test, &a))?;
            ("frequency_response", m, d)
        }
        "torque_curve" => {
            let test = torque_test(&s, p.axis)?;
            let (noise_percent, seed) = (s.get("noise_percent")?, s.get("seed")?);
            let (m, d) = py.detach(|| torque(&p, &test, noise_percent, seed))?;
            ("torque_curve", m, d)
        }
        "fluctuation" | "unbalance" => {
            let test = fluctuation_test(&s, &p, kind == "unbalance")?;
            let (noise_arcsec, seed) = (s.get("noise_arcsec")?, s.get("seed")?);
            let (m, d) = py.detach(|| turning(&p, &test, noise_arcsec, seed))?;
            (
                if kind == "unbalance" {
                    "unbalance"
                } else {
                    "fluctuation"
                },
                m,
                d,
            )
        }
        other => {
            return Err(bad_argument(
                "kind",
                format!("`{other}` is not run from Python yet: run `rtid experiment`"),
            ))
        }
    };
    write(&out, stem, manifest, &data)
}

/// The settings dict, read by name.
struct Settings<'a, 'py>(&'a Bound<'py, PyDict>);

impl Settings<'_, '_> {
    fn get<T: for<'py> FromPyObjectOwned<'py>>(&self, name: &str) -> PyResult<T> {
        match self.0.get_item(name)? {
            Some(v) => v.extract::<T>().map_err(|e| {
                let e: PyErr = e.into();
                bad_argument(name, e)
            }),
            None => Err(bad_argument(name, "missing setting")),
        }
    }
}

/// Where the experiment file is written, as `Common::write_and_report` writes it.
fn write(
    out: &std::path::Path,
    stem: &str,
    mut manifest: Manifest,
    data: &Data,
) -> PyResult<PathBuf> {
    let path = out.join(format!("{stem}.json"));
    manifest.data = Some(format!("{stem}.csv"));
    rtid::write_experiment(&path, &manifest, data).map_err(|e| rtid_error(&e))?;
    Ok(path)
}

/// The loop a test runs in where `loop` overrides the set's, with the note the
/// command line adds to the manifest.
fn loop_note(given: Option<LoopMode>, p: &Params) -> Option<String> {
    let own = p.controller.loop_mode;
    let mode = given.filter(|&m| m != own)?;
    Some(format!(
        "--loop {mode} overrides the parameter set's controller.loop ({own})"
    ))
}

fn loop_mode(s: &Settings, name: &str) -> PyResult<Option<LoopMode>> {
    let given: Option<String> = s.get(name)?;
    given
        .map(|text| text.parse().map_err(|e| with_context(name, &e)))
        .transpose()
}

/// The options of `rtid experiment frequency-response` beside its test.
struct FrOptions {
    linear: bool,
    response: Response,
    noise_percent: f64,
    complex_noise_percent: f64,
    seed: u64,
    unstated_delay_s: f64,
}

impl FrOptions {
    fn of(s: &Settings) -> PyResult<FrOptions> {
        let response = match s.get::<String>("response")?.replace('-', "_").as_str() {
            "table_over_motor" => Response::TableOverMotor,
            "motor_compliance" => Response::MotorCompliance,
            other => {
                return Err(bad_argument(
                    "response",
                    format!(
                        "unknown response `{other}`: expected table_over_motor or motor_compliance"
                    ),
                ))
            }
        };
        let linear: bool = s.get("linear")?;
        if response == Response::MotorCompliance && !linear {
            return Err(bad_argument(
                "response",
                "motor_compliance needs linear=True: the nonlinear test measures the table over the motor",
            ));
        }
        Ok(FrOptions {
            linear,
            response,
            noise_percent: s.get("noise_percent")?,
            complex_noise_percent: s.get("complex_noise_percent")?,
            seed: s.get("seed")?,
            unstated_delay_s: s.get("unstated_delay_s")?,
        })
    }
}

fn frequency_test(s: &Settings) -> PyResult<FrequencyTest> {
    let (from, to, step): (f64, f64, f64) = (s.get("from_hz")?, s.get("to_hz")?, s.get("step_hz")?);
    if to < from {
        return Err(bad_argument(
            "to_hz",
            format!("{to} is below from_hz {from}"),
        ));
    }
    let shortest = 1.0 / FrequencyTest::default().max_duration_s;
    if from < shortest {
        return Err(bad_argument(
            "from_hz",
            format!("{from}: below {shortest} Hz, where a cycle no longer fits the test's time at one frequency"),
        ));
    }
    let count = ((to - from) / step + 1e-9).floor();
    if count + 1.0 > 1e5 {
        return Err(bad_argument(
            "step_hz",
            format!("{} frequencies, above the limit of 1e5", count + 1.0),
        ));
    }
    Ok(FrequencyTest {
        frequencies_hz: (0..=count as usize)
            .map(|i| from + step * i as f64)
            .collect(),
        amplitude_nm: s.get("amplitude_nm")?,
        preload_nm: s.get("preload_nm")?,
        refine_step_hz: s.get("refine_step_hz")?,
        ..Default::default()
    })
}

/// `rtid experiment frequency-response`'s run: the points, the noise, the delay.
fn frequency_response(
    p: &Params,
    test: &FrequencyTest,
    a: &FrOptions,
) -> PyResult<(Manifest, Data)> {
    let points = if a.linear {
        fr::linear_points(p, test, a.response).map_err(|e| rtid_error(&e))?
    } else {
        fr::sweep(p, test, &|| {}).map_err(|e| rtid_error(&e))?
    };
    let mut data = fr::to_data(p, &points, a.response).map_err(|e| rtid_error(&e))?;
    let mut manifest = fr::manifest(p, test, a.linear, a.response);
    fr::Disturbance {
        noise_percent: a.noise_percent,
        complex_noise_percent: a.complex_noise_percent,
        seed: a.seed,
        unstated_delay_s: a.unstated_delay_s,
    }
    .apply(&mut data, &mut manifest);
    Ok((manifest, data))
}

fn torque_test(s: &Settings, axis: Axis) -> PyResult<TorqueTest> {
    let deg: Option<f64> = s.get("amplitude_deg")?;
    let mm: Option<f64> = s.get("amplitude_mm")?;
    let amplitude = match (axis, deg, mm) {
        (Axis::Rotary, deg, None) => deg.unwrap_or(30.0).to_radians(),
        (Axis::Linear, None, mm) => mm.unwrap_or(50.0) * 1e-3,
        (Axis::Rotary, _, Some(_)) => {
            return Err(bad_argument(
                "amplitude_mm",
                "for a linear axis; this axis is rotary (amplitude_deg)",
            ))
        }
        (Axis::Linear, Some(_), _) => {
            return Err(bad_argument(
                "amplitude_deg",
                "for a rotary axis; this axis is linear (amplitude_mm)",
            ))
        }
    };
    Ok(TorqueTest {
        amplitude,
        period: s.get("period_s")?,
        periods: s.get("periods")?,
        loop_mode: loop_mode(s, "loop")?.unwrap_or(LoopMode::FullClosed),
        ..Default::default()
    })
}

/// `rtid experiment torque-curve`'s run.
fn torque(
    p: &Params,
    test: &TorqueTest,
    noise_percent: f64,
    seed: u64,
) -> PyResult<(Manifest, Data)> {
    let mut curve = torque_curve::run(p, test, |_, _| {}).map_err(|e| rtid_error(&e))?;
    noise::perturb_by_rms(&mut curve.motor_torque, noise_percent, seed);
    let mut manifest = torque_curve::manifest(p, test);
    if noise_percent > 0.0 {
        manifest.notes = Some(format!(
            "{}; {} % (of the RMS) Gaussian noise on the torque (seed {})",
            manifest.notes.unwrap_or_default(),
            noise_percent,
            seed
        ));
    }
    Ok((manifest, torque_curve::to_data(&curve, p.axis)))
}

fn fluctuation_test(s: &Settings, p: &Params, unbalance: bool) -> PyResult<FluctuationTest> {
    if p.axis == Axis::Linear {
        return Err(bad_argument(
            "params",
            format!("{}: a linear axis — the test turns a table through whole revolutions: rotary axes only", p.name),
        ));
    }
    let speed: f64 = s.get("speed_deg_per_min")?;
    let mut test = FluctuationTest {
        speed: speed.to_radians() / 60.0,
        revolutions: s.get("revolutions")?,
        run_in: s.get::<f64>("run_in_deg")?.to_radians(),
        sample_period: s.get("sample_period_s")?,
        loop_mode: loop_mode(s, "loop")?,
        ..Default::default()
    };
    if unbalance {
        let (mass, radius): (Option<f64>, Option<f64>) = (s.get("mass_kg")?, s.get("radius_m")?);
        let own = p.unbalance_mass > 0.0 && p.unbalance_radius > 0.0;
        test.unbalance = Some(if own {
            (
                mass.unwrap_or(p.unbalance_mass),
                radius.unwrap_or(p.unbalance_radius),
            )
        } else {
            (
                mass.unwrap_or(DEFAULT_UNBALANCE.0),
                radius.unwrap_or(DEFAULT_UNBALANCE.1),
            )
        });
    }
    if test.duration() > 3600.0 {
        return Err(bad_argument(
            "speed_deg_per_min",
            format!(
                "{:.0} simulated seconds, above the limit of 3600",
                test.duration()
            ),
        ));
    }
    Ok(test)
}

/// `rtid experiment fluctuation` and `unbalance`'s run.
fn turning(
    p: &Params,
    test: &FluctuationTest,
    noise_arcsec: f64,
    seed: u64,
) -> PyResult<(Manifest, Data)> {
    let mut record = fluctuation::run(p, test, |_, _| {}).map_err(|e| rtid_error(&e))?;
    noise::perturb_absolute(&mut record.table_angle, noise_arcsec / ARCSEC_PER_RAD, seed);
    let mut manifest = fluctuation::manifest(p, test);
    if noise_arcsec > 0.0 {
        manifest.notes = Some(format!(
            "{}; Gaussian noise of {}″ (standard deviation) on the table angle (seed {})",
            manifest.notes.unwrap_or_default(),
            noise_arcsec,
            seed
        ));
    }
    if let Some(note) = loop_note(test.loop_mode, p) {
        manifest.notes = Some(match manifest.notes.take() {
            Some(notes) => format!("{notes}; {note}"),
            None => note,
        });
    }
    Ok((manifest, fluctuation::to_data(&record, test.kind())))
}
