//! The paper's tests from Python: frequency response, torque curve, fluctuation and
//! unbalance, their settings checked as `rtid experiment`'s flags are.

use pyo3::prelude::*;

use super::{add_note, limit, loop_mode, loop_note, Settings, Work};
use crate::errors::{bad_argument, rtid_error};
use rtid::experiments::fluctuation::{self, FluctuationTest, DEFAULT_UNBALANCE};
use rtid::experiments::frequency_response::{self as fr, FrequencyTest};
use rtid::experiments::measurement_noise as noise;
use rtid::experiments::positioning::iso230::ARCSEC_PER_RAD;
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::Response;
use rtid::limits;
use rtid::model::{Axis, LoopMode, Params};

/// The options of `rtid experiment frequency-response` beside its test.
pub struct FrOptions {
    linear: bool,
    response: Response,
    noise_percent: f64,
    complex_noise_percent: f64,
    seed: u64,
    unstated_delay_s: f64,
}

impl FrOptions {
    pub fn of(s: &Settings) -> PyResult<FrOptions> {
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
    let frequencies_hz = limits::frequency_grid(from, to, step, "from_hz, to_hz, step_hz")
        .map_err(|e| rtid_error(&e))?;
    let refine: f64 = s.get("refine_step_hz")?;
    if refine > 0.0 {
        let around = 2.0 * FrequencyTest::default().refine_half_width_hz / refine;
        limit(
            around,
            limits::MAX_POINTS,
            "frequencies around each resonance",
            "refine_step_hz",
        )?;
    }
    Ok(FrequencyTest {
        frequencies_hz,
        amplitude_nm: s.get("amplitude_nm")?,
        preload_nm: s.get("preload_nm")?,
        refine_step_hz: s.get("refine_step_hz")?,
        ..Default::default()
    })
}

/// `rtid experiment frequency-response`'s run, its settings checked.
pub fn frequency_response(s: &Settings, p: &Params) -> PyResult<Work> {
    let (test, a, p) = (frequency_test(s)?, FrOptions::of(s)?, p.clone());
    Ok(Box::new(move || {
        let points = if a.linear {
            fr::linear_points(&p, &test, a.response).map_err(|e| rtid_error(&e))?
        } else {
            fr::sweep(&p, &test, &|| {}).map_err(|e| rtid_error(&e))?
        };
        let mut data = fr::to_data(&p, &points, a.response).map_err(|e| rtid_error(&e))?;
        let mut manifest = fr::manifest(&p, &test, a.linear, a.response);
        fr::Disturbance {
            noise_percent: a.noise_percent,
            complex_noise_percent: a.complex_noise_percent,
            seed: a.seed,
            unstated_delay_s: a.unstated_delay_s,
        }
        .apply(&mut data, &mut manifest);
        Ok((manifest, data))
    }))
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
    let test = TorqueTest {
        amplitude,
        period: s.get("period_s")?,
        periods: s.get("periods")?,
        loop_mode: loop_mode(s, "loop")?.unwrap_or(LoopMode::FullClosed),
        ..Default::default()
    };
    limit(
        test.duration(),
        limits::MAX_SIMULATED_S,
        "simulated seconds",
        "period_s, periods",
    )?;
    Ok(test)
}

/// `rtid experiment torque-curve`'s run, its settings checked.
pub fn torque(s: &Settings, p: &Params) -> PyResult<Work> {
    let test = torque_test(s, p.axis)?;
    let (noise_percent, seed): (f64, u64) = (s.get("noise_percent")?, s.get("seed")?);
    let p = p.clone();
    Ok(Box::new(move || {
        let mut curve = torque_curve::run(&p, &test, |_, _| {}).map_err(|e| rtid_error(&e))?;
        noise::perturb_by_rms(&mut curve.motor_torque, noise_percent, seed);
        let mut manifest = torque_curve::manifest(&p, &test);
        if noise_percent > 0.0 {
            manifest.notes = Some(format!(
                "{}; {} % (of the RMS) Gaussian noise on the torque (seed {})",
                manifest.notes.unwrap_or_default(),
                noise_percent,
                seed
            ));
        }
        Ok((manifest, torque_curve::to_data(&curve, p.axis)))
    }))
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
    limit(
        test.duration(),
        limits::MAX_SIMULATED_S,
        "simulated seconds",
        "speed_deg_per_min, revolutions, run_in_deg",
    )?;
    Ok(test)
}

/// `rtid experiment fluctuation` and `unbalance`'s run, its settings checked.
pub fn turning(s: &Settings, p: &Params, unbalance: bool) -> PyResult<Work> {
    let test = fluctuation_test(s, p, unbalance)?;
    let (noise_arcsec, seed): (f64, u64) = (s.get("noise_arcsec")?, s.get("seed")?);
    let p = p.clone();
    Ok(Box::new(move || {
        let mut record = fluctuation::run(&p, &test, |_, _| {}).map_err(|e| rtid_error(&e))?;
        noise::perturb_absolute(&mut record.table_angle, noise_arcsec / ARCSEC_PER_RAD, seed);
        let mut manifest = fluctuation::manifest(&p, &test);
        if noise_arcsec > 0.0 {
            manifest.notes = Some(format!(
                "{}; Gaussian noise of {}″ (standard deviation) on the table angle (seed {})",
                manifest.notes.unwrap_or_default(),
                noise_arcsec,
                seed
            ));
        }
        add_note(&mut manifest, loop_note(test.loop_mode, &p));
        Ok((manifest, fluctuation::to_data(&record, test.kind())))
    }))
}
