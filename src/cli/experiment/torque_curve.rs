//! `rtid experiment torque-curve` and the evaluation of torque-curve files.

use crate::cli::common::plot::Plot;

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use rtid::experiments::torque_curve::TorqueReport;
use rtid::report::torque_curve as figures;

use super::{check, Common};
use crate::cli::common::progress;
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::{Axis, Experiment};
use rtid::model::{LoopMode, Params};

pub const LONG_ABOUT: &str = "\
Friction torque curve (paper §4.2, Fig. 9): the servo, in full-closed loop by default, \
moves the table harmonically, 30°·sin(2πt/3 s), and the motor torque command over time is \
the measured curve — inertia, viscous damping and Coulomb friction of motor, shaft and \
table, all seen at the motor. The first period (the servo's start-up transient) is not \
recorded; then --periods periods are sampled every 1 ms, time restarted at 0. Writes \
torque_curve.json/.csv (time_s, motor_torque_nm, table_angle_deg), torque_curve.svg \
(torque over time, like Fig. 9) and torque_curve-vs-angle.svg, and prints:

  RMS torque    root mean square of the motor torque, N·m
  peak torque   largest |motor torque|, N·m
  friction      the Coulomb friction torque at the motor, N·m: from the friction law \
T = M·a + Fv·v + Fc·sign(v) + OF fitted over the whole curve against the table angle \
(IDIM-LS); the paper's reading, half the jump of the torque across each reversal of the \
table velocity (lines fitted on either side, outside a guard of T/100, over T·6/100), is \
listed per reversal beside it. On the model it is fm + fw·Rg + ft·Rg·Rw (roller \
gear cam: fm + ft·Rw) — the table's friction reaches the motor divided by the ratio.

On a linear axis the carriage moves 50 mm·sin(2πt/3 s) (--amplitude-mm) and the drive's \
force is the curve: torque_curve.csv then has force_n and table_position_mm, and the values \
are printed in N.

Example:
  rtid experiment torque-curve --preset worm-gear --out runs/worm
  rtid experiment torque-curve --params fixtures/real/emps/axis.json --amplitude-mm 50 --out runs/emps
  rtid experiment torque-curve --preset roller-gear-cam --period-s 6 --periods 3 --json --out runs/roller";

/// Arguments of `rtid experiment torque-curve`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Feedback loop.
    #[arg(
        long = "loop",
        value_name = "semi_closed|full_closed",
        default_value = "full_closed"
    )]
    pub loop_mode: LoopMode,
    /// Rotary axis: amplitude of the commanded table motion, degrees [default: 30].
    #[arg(long, value_name = "DEG")]
    pub amplitude_deg: Option<f64>,
    /// Linear axis: amplitude of the commanded carriage motion, mm [default: 50].
    #[arg(long, value_name = "MM")]
    pub amplitude_mm: Option<f64>,
    /// Period of the commanded table motion, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 3.0)]
    pub period_s: f64,
    /// Periods recorded after the one-period run-in.
    #[arg(long, value_name = "N", default_value_t = 2.0)]
    pub periods: f64,
    /// Measurement noise on the torque: Gaussian, this percentage of the record's RMS.
    #[arg(long, value_name = "PERCENT", default_value_t = 0.0)]
    pub noise_percent: f64,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let test = test(&a, p.axis)?;
    check::work(
        test.duration(),
        check::MAX_SIMULATED_S,
        "simulated seconds",
        "--period-s, --periods",
    )?;
    a.common.create_out()?;
    run_torque_curve(&a, &p, test)
}

/// The test the flags describe, or why they do not describe one (checked before
/// anything runs).
fn test(a: &Args, axis: Axis) -> anyhow::Result<TorqueTest> {
    check::percent(a.noise_percent, "--noise-percent")?;
    let amplitude = match (axis, a.amplitude_deg, a.amplitude_mm) {
        (Axis::Rotary, deg, None) => {
            check::positive(deg.unwrap_or(30.0), "--amplitude-deg")?.to_radians()
        }
        (Axis::Linear, None, mm) => check::positive(mm.unwrap_or(50.0), "--amplitude-mm")? * 1e-3,
        (Axis::Rotary, _, Some(_)) => {
            anyhow::bail!(
                "--amplitude-mm is for a linear axis; this axis is rotary (--amplitude-deg)"
            )
        }
        (Axis::Linear, Some(_), _) => {
            anyhow::bail!(
                "--amplitude-deg is for a rotary axis; this axis is linear (--amplitude-mm)"
            )
        }
    };
    Ok(TorqueTest {
        amplitude,
        period: check::positive(a.period_s, "--period-s")?,
        periods: check::positive(a.periods, "--periods")?,
        loop_mode: a.loop_mode,
        ..Default::default()
    })
}

fn run_torque_curve(a: &Args, p: &Params, test: TorqueTest) -> anyhow::Result<()> {
    let total = (test.run_in_periods + test.periods).ceil() as u64;
    let bar = progress::bar(total, "torque curve", a.common.quiet);
    let mut curve = torque_curve::run(p, &test, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    rtid::experiments::measurement_noise::perturb_by_rms(
        &mut curve.motor_torque,
        a.noise_percent,
        a.seed,
    );
    let mut manifest = torque_curve::manifest(p, &test);
    if a.noise_percent > 0.0 {
        manifest.notes = Some(format!(
            "{}; {} % (of the RMS) Gaussian noise on the torque (seed {})",
            manifest.notes.unwrap_or_default(),
            a.noise_percent,
            a.seed
        ));
    }
    a.common.write_and_report(
        "torque_curve",
        manifest,
        &torque_curve::to_data(&curve, p.axis),
        report,
    )
}

/// Evaluates a torque-curve experiment: RMS, peak and friction printed (table or
/// JSON); torque over time written to `plot`, and, when the file has the table angle,
/// torque over angle beside it (`STEM-vs-angle.svg`).
pub fn report(exp: &Experiment, plot: &Plot, json: bool) -> anyhow::Result<()> {
    let Some(curve) = torque_curve::from_data(&exp.data) else {
        anyhow::bail!("{}: not a torque curve", exp.path.display());
    };
    let test = TorqueTest::from_conditions(&exp.manifest.conditions);
    let linear = exp.data.axis() == Some(Axis::Linear);
    let report = torque_curve::evaluate(&curve, &test)
        .map_err(|e| anyhow::anyhow!("{}: {e}", exp.path.display()))?;
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("table");
    let title = format!("{mechanism}: motor torque");
    plot.write(&figures::over_time(&curve, &report, &title), "")?;
    if let Some(figure) = figures::over_angle(&curve, &title) {
        plot.write(&figure, "-vs-angle")?;
    }
    if json {
        let axis = exp.data.axis().unwrap_or_default();
        let source = exp.path.display().to_string();
        let value = rtid::report::evaluation::torque_curve(&report, axis, &source)?;
        println!("{}", rtid::io::json::pretty(&value)?);
    } else {
        let amplitude = if linear {
            format!("{:.2} mm", test.amplitude * 1e3)
        } else {
            format!("{:.0}°", test.amplitude.to_degrees())
        };
        println!(
            "{}: {} curve, {amplitude} amplitude, {} s period",
            exp.path.display(),
            if linear { "force" } else { "torque" },
            test.period
        );
        println!("{}", table(&report, if linear { "N" } else { "N·m" }));
    }
    Ok(())
}

/// A readable summary, efforts in `unit` (N·m, or N on a linear axis).
fn table(report: &TorqueReport, unit: &str) -> String {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(["torque curve", "value"]);
    t.add_row(["samples".to_string(), report.samples.to_string()]);
    t.add_row([
        "duration, s".to_string(),
        format!("{:.3}", report.duration_s),
    ]);
    t.add_row([format!("RMS, {unit}"), format!("{:.4}", report.rms_nm)]);
    t.add_row([format!("peak, {unit}"), format!("{:.4}", report.peak_nm)]);
    let how = match report.friction_from {
        "inverse_dynamics" => "law over the whole curve",
        _ => "jumps at the reversals",
    };
    t.add_row([
        format!("Coulomb friction at the motor, {unit} ({how})"),
        report
            .friction_nm
            .map_or("– (no usable reversal)".into(), |f| format!("{f:.4}")),
    ]);
    if let Some(law) = &report.inverse_dynamics {
        let rows = [
            ("M (per unit of table acceleration)", law.inertia),
            ("Fv (per unit of table speed)", law.viscous),
            ("Fc", law.coulomb),
            ("OF (offset)", law.offset),
        ];
        for (name, e) in rows {
            t.add_row([
                format!("law: {name}"),
                format!("{:.4e} ± {:.1e}", e.value, e.std_error),
            ]);
        }
    }
    let mut r = Table::new();
    r.load_preset(UTF8_FULL_CONDENSED);
    r.set_header([
        format!("reversal (from {})", report.reversals_from),
        "moving before".into(),
        format!("jump {unit}"),
        format!("friction {unit}"),
    ]);
    for v in &report.reversals {
        r.add_row([
            format!("t = {:.4} s", v.time_s),
            if v.direction_before > 0.0 { "+" } else { "−" }.into(),
            format!("{:.4}", v.jump_nm),
            format!("{:.4}", v.friction_nm),
        ]);
    }
    format!("{t}\n{r}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    #[test]
    fn defaults_are_the_papers_conditions_and_bad_values_are_refused() {
        let cli = Cli::parse_from(["t", "--preset", "worm-gear", "--out", "x"]);
        let t = test(&cli.args, Axis::Rotary).unwrap();
        assert_eq!(t, TorqueTest::default());
        let cli = Cli::parse_from([
            "t",
            "--preset",
            "worm-gear",
            "--out",
            "x",
            "--amplitude-mm",
            "20",
        ]);
        assert_eq!(test(&cli.args, Axis::Linear).unwrap().amplitude, 0.02);
        let refused = test(&cli.args, Axis::Rotary).unwrap_err().to_string();
        assert!(
            refused.contains("--amplitude-mm") && refused.contains("rotary"),
            "{refused}"
        );
        let cli = Cli::parse_from(["t", "--preset", "worm-gear", "--out", "x", "--periods", "0"]);
        assert!(test(&cli.args, Axis::Rotary)
            .unwrap_err()
            .to_string()
            .contains("--periods"));
        let cli = Cli::try_parse_from(["t", "--out", "x", "--loop", "open"]);
        assert!(cli.is_err());
    }
}
