//! `rtid experiment frequency-response` and the evaluation of frequency-response files.

use std::path::Path;

use anyhow::bail;

use super::Common;
use crate::cli::progress;
use rtid::experiments::frequency_response::{self as fr, FrequencyTest, Point};
use rtid::io::experiment_file::{self, Data, Experiment, Kind, Manifest};

pub const LONG_ABOUT: &str = "\
Frequency response (paper §4.1): open loop, the motor driven by a sinusoidal torque \
(±5 N·m), 10–600 Hz in 10 Hz steps, refined in 1 Hz steps around each peak. Every \
frequency is an independent nonlinear simulation (in parallel), started from the linear \
steady state and run until the gain changes by less than 0.01 dB between windows of \
whole cycles. Gain = 20·log10(table amplitude / (motor amplitude × Rg·Rw)); its peaks are \
the resonances (damped, motor-held modes; `rtid modes`).

Backlash: with the worm's free play the drive's oscillation falls inside the gap at higher \
frequencies and the table rattles; the fraction of time each mesh is out of contact is \
written per frequency (contact_loss_spur, contact_loss_drive) and a warning names where. \
--preload-nm P brakes the table with P N·m balanced by a motor DC torque P·Rg·Rw, which \
keeps the flanks loaded, as on a real test rig.

Writes frequency_response.json/.csv (frequency_hz, gain_db, phase_deg, contact losses, \
linear_gain_db: the exact linear response solved in the frequency domain) and \
frequency_response.svg with both curves; prints the resonances.

Examples:
  rtid experiment frequency-response --preset worm-gear --out runs/worm
  rtid experiment frequency-response --preset worm-gear --preload-nm 2 --out runs/worm-preloaded
  rtid experiment frequency-response --preset roller-gear-cam --linear --out runs/roller-linear";

/// Arguments of `rtid experiment frequency-response`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Sine amplitude of the motor torque, N·m.
    #[arg(long, value_name = "NM", default_value_t = 5.0)]
    pub amplitude_nm: f64,
    /// Table brake torque balanced by a motor DC torque, N·m (keeps the flanks loaded).
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub preload_nm: f64,
    /// Lowest frequency of the coarse grid, Hz.
    #[arg(long, value_name = "HZ", default_value_t = 10.0)]
    pub from_hz: f64,
    /// Highest frequency of the coarse grid, Hz.
    #[arg(long, value_name = "HZ", default_value_t = 600.0)]
    pub to_hz: f64,
    /// Step of the coarse grid, Hz.
    #[arg(long, value_name = "HZ", default_value_t = 10.0)]
    pub step_hz: f64,
    /// Refinement step around each peak, Hz (0: no refinement).
    #[arg(long, value_name = "HZ", default_value_t = 1.0)]
    pub refine_step_hz: f64,
    /// Only the linear response solved in the frequency domain (no time simulation).
    #[arg(long)]
    pub linear: bool,
    /// Measurement noise: each amplitude ratio × (1 + ε), ε Gaussian with this
    /// standard deviation in percent (0: none).
    #[arg(long, value_name = "PERCENT", default_value_t = 0.0)]
    pub noise_percent: f64,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.model.load()?;
    let finite_positive = |v: f64, flag: &str| -> anyhow::Result<f64> {
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            bail!("{flag} {v}: must be a positive number")
        }
    };
    let (from, to, step) = (
        finite_positive(a.from_hz, "--from-hz")?,
        finite_positive(a.to_hz, "--to-hz")?,
        finite_positive(a.step_hz, "--step-hz")?,
    );
    if to < from {
        bail!("--to-hz {to} is below --from-hz {from}");
    }
    if !(a.refine_step_hz >= 0.0 && a.refine_step_hz.is_finite()) {
        bail!(
            "--refine-step-hz {}: must be zero or positive",
            a.refine_step_hz
        );
    }
    if !a.preload_nm.is_finite() {
        bail!("--preload-nm {}: must be a finite torque", a.preload_nm);
    }
    a.common.create_out()?;
    let count = ((to - from) / step + 1e-9).floor() as usize;
    let test = FrequencyTest {
        frequencies_hz: (0..=count).map(|i| from + step * i as f64).collect(),
        amplitude_nm: finite_positive(a.amplitude_nm, "--amplitude-nm")?,
        preload_nm: a.preload_nm,
        refine_step_hz: a.refine_step_hz,
        ..Default::default()
    };
    let points: Vec<Point> = if a.linear {
        let solve = |freqs: &[f64]| -> anyhow::Result<Vec<Point>> {
            Ok(fr::linear(&p, freqs)?
                .into_iter()
                .zip(freqs)
                .map(|((gain_db, phase_deg), &frequency_hz)| Point {
                    frequency_hz,
                    gain_db,
                    phase_deg,
                    motor_amplitude_rad: f64::NAN,
                    table_amplitude_rad: f64::NAN,
                    contact_loss: [0.0, 0.0],
                    settled: true,
                    below_resolution: false,
                    simulated_s: 0.0,
                })
                .collect())
        };
        let mut points = solve(&test.frequencies_hz)?;
        if test.refine_step_hz > 0.0 {
            let extra = fr::refinement(&points, &test);
            points.extend(solve(&extra)?);
            points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        }
        points
    } else {
        let expected = test.frequencies_hz.len() as u64
            + 6 * (1 + (test.refine_half_width_hz / test.refine_step_hz.max(1e-9)) as u64);
        let bar = progress::bar(expected, "frequencies", a.common.quiet);
        let points = fr::sweep(&p, &test, &|| bar.inc(1))?;
        bar.finish_and_clear();
        points
    };
    warn_about_backlash(&points);
    let freqs: Vec<f64> = points.iter().map(|q| q.frequency_hz).collect();
    let linear_db: Vec<f64> = fr::linear(&p, &freqs)?.into_iter().map(|g| g.0).collect();
    let mut extra = experiment_file::Columns::new();
    extra.insert(
        "contact_loss_spur".into(),
        points.iter().map(|q| q.contact_loss[0]).collect(),
    );
    extra.insert(
        "contact_loss_drive".into(),
        points.iter().map(|q| q.contact_loss[1]).collect(),
    );
    extra.insert(
        "settled".into(),
        points
            .iter()
            .map(|q| f64::from(u8::from(q.settled)))
            .collect(),
    );
    extra.insert(
        "below_resolution".into(),
        points
            .iter()
            .map(|q| f64::from(u8::from(q.below_resolution)))
            .collect(),
    );
    extra.insert("linear_gain_db".into(), linear_db);
    anyhow::ensure!(
        a.noise_percent >= 0.0 && a.noise_percent.is_finite(),
        "--noise-percent {}: must be zero or positive",
        a.noise_percent
    );
    let mut gain_db: Vec<f64> = points.iter().map(|q| q.gain_db).collect();
    rtid::experiments::measurement_noise::perturb_gain_db(&mut gain_db, a.noise_percent, a.seed);
    let data = Data::FrequencyResponse {
        frequency_hz: freqs,
        gain_db,
        phase_rad: Some(points.iter().map(|q| q.phase_deg.to_radians()).collect()),
        extra,
    };
    let mut manifest = Manifest::new(Kind::FrequencyResponse);
    manifest.mechanism = Some(p.name.clone());
    manifest.conditions.torque_amplitude_nm = Some(test.amplitude_nm);
    manifest.conditions.preload_nm = Some(test.preload_nm);
    manifest.notes = Some(format!(
        "{}{}",
        if a.linear {
            "virtual test by rtid: linear response solved in the frequency domain"
        } else {
            "virtual test by rtid: nonlinear time simulation per frequency"
        },
        if a.noise_percent > 0.0 {
            format!(
                "; {} % Gaussian noise on the amplitude ratio (seed {})",
                a.noise_percent, a.seed
            )
        } else {
            String::new()
        }
    ));
    a.common
        .write_and_report("frequency_response", manifest, &data, report)
}

/// Warns on stderr where a mesh lost contact, and where the table did not move.
fn warn_about_backlash(points: &[Point]) {
    for (i, mesh) in ["spur-gear", "drive"].iter().enumerate() {
        let mut open: Vec<&Point> = points.iter().filter(|q| q.contact_loss[i] > 0.0).collect();
        if open.is_empty() {
            continue;
        }
        let lowest = open[0].frequency_hz;
        open.sort_by(|a, b| a.contact_loss[i].total_cmp(&b.contact_loss[i]));
        let median = open[open.len() / 2].contact_loss[i];
        let worst = open[open.len() - 1];
        eprintln!(
            "warning: the {mesh} mesh is out of contact at {} of {} frequencies, from {:.0} Hz \
             (median {:.0} % of the time, up to {:.0} % at {:.0} Hz): each torque reversal \
             crosses the backlash, and where the table rattles in the gap the gain is not a \
             property of the drive; --preload-nm keeps the flanks loaded",
            open.len(),
            points.len(),
            lowest,
            100.0 * median,
            100.0 * worst.contact_loss[i],
            worst.frequency_hz
        );
    }
    let still: Vec<String> = points
        .iter()
        .filter(|q| q.below_resolution)
        .map(|q| format!("{:.0}", q.frequency_hz))
        .collect();
    if !still.is_empty() {
        eprintln!(
            "warning: the table moved less than the table encoder resolves at {} Hz (its friction held it): the gain there is the encoder floor",
            still.join(", ")
        );
    }
}

/// Evaluates a frequency-response experiment: resonances printed (table or JSON),
/// gain plot written to `plot` (with the linear curve when the file has one).
pub fn report(exp: &Experiment, plot: &Path, json: bool) -> anyhow::Result<()> {
    let Data::FrequencyResponse {
        frequency_hz,
        gain_db,
        extra,
        ..
    } = &exp.data
    else {
        bail!(
            "{}: not a frequency-response experiment",
            exp.path.display()
        );
    };
    let peaks = fr::evaluate(frequency_hz, gain_db).peaks;
    let title = format!(
        "{}: frequency response (table / motor × ratio)",
        exp.manifest.mechanism.as_deref().unwrap_or("table")
    );
    let linear = extra.get("linear_gain_db").map(Vec::as_slice);
    rtid::report::frequency_response::gain(frequency_hz, gain_db, linear, &peaks, &title)
        .write(plot)?;
    if json {
        let value = serde_json::json!({
            "kind": "frequency_response",
            "source": exp.path,
            "peaks": peaks,
            "points": frequency_hz.len(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{}: resonances (local maxima of the gain, parabolic interpolation)",
            exp.path.display()
        );
        for p in &peaks {
            println!("  {:8.2} Hz  {:7.2} dB", p.frequency_hz, p.gain_db);
        }
        if peaks.is_empty() {
            println!(
                "  none in {:.0}–{:.0} Hz",
                frequency_hz[0],
                frequency_hz[frequency_hz.len() - 1]
            );
        }
    }
    Ok(())
}
