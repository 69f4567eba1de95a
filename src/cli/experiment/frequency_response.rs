//! `rtid experiment frequency-response` and the evaluation of frequency-response files.

use crate::cli::common::plot::Plot;
use std::path::PathBuf;

use anyhow::{bail, Context};

use super::check;
use super::Common;
use crate::cli::common::progress;
use rtid::experiments::frequency_response::measured;
use rtid::experiments::frequency_response::{self as fr, modal, Disturbance, FrequencyTest, Point};
use rtid::io::experiment_file::{Data, Delay, Experiment, Response, ResponseForm};

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
    /// Complex measurement noise, as an analyser's: each complex ratio × (1 + ε_r +
    /// i·ε_i), ε_r and ε_i Gaussian with this standard deviation in percent each — it
    /// moves the gain and the phase alike (0: none).
    #[arg(long, value_name = "PERCENT", default_value_t = 0.0)]
    pub complex_noise_percent: f64,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The ratio measured: `table-over-motor` (the paper's gain) or `motor-compliance`
    /// (motor angle over motor torque, rad/(N·m): a direct drive's only informative
    /// ratio; with --linear).
    #[arg(long, value_enum, default_value = "table-over-motor")]
    pub response: ResponseArg,
    /// A delay of the measurement chain, s: the phase written lags by 2π·f·delay, and
    /// the manifest states it as "unknown" (for a test of the delay's fit).
    #[arg(long, value_name = "S", default_value_t = 0.0)]
    pub unstated_delay_s: f64,
}

/// `--response`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ResponseArg {
    TableOverMotor,
    MotorCompliance,
}

impl From<ResponseArg> for Response {
    fn from(r: ResponseArg) -> Response {
        match r {
            ResponseArg::TableOverMotor => Response::TableOverMotor,
            ResponseArg::MotorCompliance => Response::MotorCompliance,
        }
    }
}

impl Args {
    /// The test the flags describe, checked before anything runs.
    fn test(&self) -> anyhow::Result<FrequencyTest> {
        let (from, to, step) = (
            check::positive(self.from_hz, "--from-hz")?,
            check::positive(self.to_hz, "--to-hz")?,
            check::positive(self.step_hz, "--step-hz")?,
        );
        if to < from {
            bail!("--to-hz {to} is below --from-hz {from}");
        }
        let shortest = 1.0 / FrequencyTest::default().max_duration_s;
        if from < shortest {
            bail!(
                "--from-hz {}: below {shortest} Hz, where a cycle no longer fits the test's time at one frequency",
                rtid::names::Num(from)
            );
        }
        check::non_negative(self.refine_step_hz, "--refine-step-hz")?;
        if self.refine_step_hz > 0.0 {
            let around = 2.0 * FrequencyTest::default().refine_half_width_hz / self.refine_step_hz;
            check::work(
                around,
                check::MAX_POINTS,
                "frequencies around each resonance",
                "--refine-step-hz",
            )?;
        }
        check::finite(self.preload_nm, "--preload-nm")?;
        check::percent(self.noise_percent, "--noise-percent")?;
        check::percent(self.complex_noise_percent, "--complex-noise-percent")?;
        check::non_negative(self.unstated_delay_s, "--unstated-delay-s")?;
        if self.response == ResponseArg::MotorCompliance && !self.linear {
            bail!(
                "--response motor-compliance needs --linear: the nonlinear test measures \
                 the table over the motor"
            );
        }
        Ok(FrequencyTest {
            frequencies_hz: check::frequency_grid(from, to, step)?,
            amplitude_nm: check::positive(self.amplitude_nm, "--amplitude-nm")?,
            preload_nm: self.preload_nm,
            refine_step_hz: self.refine_step_hz,
            ..Default::default()
        })
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let test = a.test()?;
    a.common.create_out()?;
    let response = Response::from(a.response);
    let points = if a.linear {
        fr::linear_points(&p, &test, response)?
    } else {
        let expected = test.frequencies_hz.len() as u64
            + 6 * (1 + (test.refine_half_width_hz / test.refine_step_hz.max(1e-9)) as u64);
        let bar = progress::bar(expected, "frequencies", a.common.quiet);
        let points = fr::sweep(&p, &test, &|| bar.inc(1)).with_context(|| {
            format!(
                "the test at --amplitude-nm {} --preload-nm {}",
                rtid::names::Num(test.amplitude_nm),
                rtid::names::Num(test.preload_nm)
            )
        })?;
        bar.finish_and_clear();
        points
    };
    warn_about_backlash(&points);
    let mut data = fr::to_data(&p, &points, response)?;
    let mut manifest = fr::manifest(&p, &test, a.linear, response);
    Disturbance {
        noise_percent: a.noise_percent,
        complex_noise_percent: a.complex_noise_percent,
        seed: a.seed,
        unstated_delay_s: a.unstated_delay_s,
    }
    .apply(&mut data, &mut manifest);
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
/// gain plot written to `plot` (with the linear curve when the file has one). With a
/// phase, also each resonance's modal parameters ([`modal::modes`]) and the phase and
/// Nyquist plots beside `plot` (`STEM_phase.svg`, `STEM_nyquist.svg`).
pub fn report(exp: &Experiment, plot: &Plot, json: bool) -> anyhow::Result<()> {
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
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("table");
    let title = format!("{mechanism}: frequency response (table / motor × ratio)");
    let linear = extra.get("linear_gain_db").map(Vec::as_slice);
    plot.write(
        &rtid::report::frequency_response::gain(frequency_hz, gain_db, linear, &peaks, &title),
        "",
    )?;
    let complex = complex_evaluation(exp, plot)?;
    if json {
        let mut value = serde_json::json!({
            "kind": "frequency_response",
            "source": exp.path,
            "peaks": peaks,
            "points": frequency_hz.len(),
        });
        if let Some(c) = &complex {
            value["modes"] = rtid::io::json::value(&c.modes.modes)?;
            value["prominent_peaks"] = c.modes.prominent.into();
            value["response"] = c.form.response.name().into();
            value["noise_stated"] = c.noise_stated.into();
            if let [Some(phase), Some(nyquist)] = &c.plots {
                value["phase_plot"] = rtid::io::json::value(phase)?;
                value["nyquist_plot"] = rtid::io::json::value(nyquist)?;
            }
        }
        println!("{}", rtid::io::json::pretty(&value)?);
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
        match &complex {
            Some(c) => print_modes(c),
            None => println!("modal damping needs the phase: this file has none (gain peaks only)"),
        }
    }
    Ok(())
}

/// What the complex response of a file with phase gives: its modes, and the plots
/// written.
struct ComplexEvaluation {
    form: ResponseForm,
    modes: modal::ModeSearch,
    noise_stated: bool,
    /// The phase and Nyquist plots, where plots are written.
    plots: [Option<PathBuf>; 2],
}

/// The modes of the file's complex response (the drive's ratio, as
/// [`measured::complex_points`] gives it) and its phase and Nyquist plots beside
/// `plot`; `None` without a phase, or where no line is resolved (every line flagged
/// below the table encoder's resolution: the warnings say so).
fn complex_evaluation(exp: &Experiment, plot: &Plot) -> anyhow::Result<Option<ComplexEvaluation>> {
    let Some(mut c) = measured::complex_points(exp, |_| true) else {
        return Ok(None);
    };
    if c.frequency_hz.is_empty() {
        return Ok(None);
    }
    let form = measured::form(exp);
    let (integrators, ratio, unit) = match form.response {
        Response::TableOverMotor => (0, "table / motor × ratio", "1"),
        Response::MotorCompliance => (2, "motor angle / motor torque", "rad/(N·m)"),
        Response::SpeedLoop => (0, "actual speed / speed setpoint", "1"),
    };
    let modes = modal::modes(&c, integrators);
    // The plots along ascending frequency.
    let mut order: Vec<usize> = (0..c.frequency_hz.len()).collect();
    order.sort_by(|&a, &b| c.frequency_hz[a].total_cmp(&c.frequency_hz[b]));
    for v in [&mut c.frequency_hz, &mut c.ln_gain, &mut c.phase_rad] {
        *v = order.iter().map(|&k| v[k]).collect();
    }
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("table");
    let [phase, nyquist] = rtid::report::frequency_response::phase_and_nyquist(
        &c.frequency_hz,
        &c.ln_gain,
        &c.phase_rad,
        &format!("{mechanism}: {ratio}"),
        unit,
    );
    // The phase on the gain plot's frequency axis (lines without a phase included).
    let f = match &exp.data {
        Data::FrequencyResponse { frequency_hz, .. } => frequency_hz.as_slice(),
        _ => &c.frequency_hz,
    };
    let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let phase = phase.spanning(lo, hi);
    let plots = [
        plot.write(&phase, "_phase")?,
        plot.write(&nyquist, "_nyquist")?,
    ];
    Ok(Some(ComplexEvaluation {
        form,
        modes,
        noise_stated: c.sigma_ln.is_some() || c.sigma_phase.is_some(),
        plots,
    }))
}

/// The modes as a table.
fn print_modes(c: &ComplexEvaluation) {
    println!(
        "modes ({}: rational fit of the complex response over a band around each \
         resonance, ± one standard error)",
        c.form.response.name()
    );
    if let Delay::Unknown = c.form.delay {
        println!(
            "  the manifest's delay is unknown: it is not taken out of the phase, and a \
             delay's phase lag biases the damping ratios"
        );
    }
    if c.modes.modes.is_empty() {
        println!("  no resonance stands out of the gain");
    }
    if c.modes.prominent > c.modes.modes.len() {
        println!(
            "  {} peaks stand out of the gain's noise: more than a drive's few \
             resonances, the curve is noise-like at its resolution; its {} highest \
             are fitted, and none is a resonance unless its fit says so",
            c.modes.prominent,
            c.modes.modes.len()
        );
    }
    for m in &c.modes.modes {
        let head = format!(
            "  peak {:7.2} Hz  band {:.1}–{:.1} Hz ({} lines)",
            m.peak.frequency_hz, m.band_hz.0, m.band_hz.1, m.lines
        );
        let Some(p) = m.pole else {
            println!("{head}: {}", m.note.as_deref().unwrap_or("no pole pair"));
            continue;
        };
        println!(
            "{head}: f = {:.3} ± {:.3} Hz, ζ = {:.5} ± {:.5}, residual {:.3}",
            p.frequency_hz, p.frequency_se_hz, p.damping_ratio, p.damping_se, m.residual_rms
        );
        if let Some(z) = m.zero {
            println!(
                "    antiresonance (zero pair): f = {:.3} ± {:.3} Hz, ζ = {:.5} ± {:.5}",
                z.frequency_hz, z.frequency_se_hz, z.damping_ratio, z.damping_se
            );
        }
    }
    println!(
        "  residual: {}",
        if c.noise_stated {
            "RMS misfit over the stated noise (≈ 1 when the model explains the band)"
        } else {
            "RMS relative misfit per component (no noise stated: ≈ the complex noise's σ \
             when the model explains the band)"
        }
    );
    if let [Some(phase), Some(nyquist)] = &c.plots {
        println!("  plots: {}, {}", phase.display(), nyquist.display());
    }
}
