//! `rtid experiment positioning` and the evaluation of positioning files.

use crate::cli::common::plot::Plot;
use std::path::Path;

use anyhow::bail;

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use super::{check, Common};
use crate::cli::common::progress;
use rtid::experiments::positioning::compensate::{self, Runs};
use rtid::experiments::positioning::iso230::ReportUnits;
use rtid::experiments::positioning::{self, iso230};
use rtid::io::compensation_file;
use rtid::io::experiment_file::Experiment;
use rtid::model::{Axis, LoopMode, Params};

pub const LONG_ABOUT: &str = "\
ISO 230-2 positioning accuracy and repeatability (paper §4.3): the servo, in the \
parameter set's loop (controller.loop; semi-closed in the presets) unless --loop \
overrides it, approaches targets every 30° from 0° to 360°, 5 times from each side, \
with 1 s dwell; the table encoder (0.0001°) reads each stop. Writes positioning.json/.csv \
(deviation_arcsec per reading) and positioning.svg (the paper's Fig. 10), and prints the \
ISO 230-2 statistics in arc-seconds.

On a linear axis (a parameter file with \"axis\": \"linear\") the carriage approaches \
targets every 50 mm over 500 mm at 3000 mm/min (--target-step-mm, --travel-mm, \
--speed-mm-per-min, --noise-um), with 5 mm of overrun; the file is written in mm and µm \
(target_mm, deviation_um) and the statistics are printed in µm.

Examples:
  rtid experiment positioning --preset worm-gear --out runs/worm
  rtid experiment positioning --preset worm-gear --noise-arcsec 0.5 --seed 7 --out runs/noisy
  rtid experiment positioning --params fixtures/real/emps/axis.json --travel-mm 200 --out runs/emps

With --compensation FILE (a compensation.json of `rtid compensate`) the CNC's backlash \
and error-table compensation run in the model's controller — the effect of a \
compensation predicted on the model, not read off a record:
  rtid compensate runs/worm/positioning.json -o runs/worm/compensation.json
  rtid experiment positioning --preset worm-gear --compensation runs/worm/compensation.json --out runs/comp";

/// Arguments of `rtid experiment positioning`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Feedback loop [default: the parameter set's controller.loop].
    #[arg(long = "loop", value_name = "semi_closed|full_closed")]
    pub loop_mode: Option<LoopMode>,
    /// Approaches of each target from each side.
    #[arg(long, default_value_t = 5)]
    pub runs: u32,
    /// Rotary axis: spacing of the targets from 0° to 360°, degrees [default: 30].
    #[arg(long, value_name = "DEG")]
    pub target_step_deg: Option<f64>,
    /// Rotary axis: table speed of the moves, degrees per minute [default: 3600].
    #[arg(long, value_name = "DEG_PER_MIN")]
    pub speed_deg_per_min: Option<f64>,
    /// Rotary axis: rms of Gaussian noise added to each reading, arc-seconds [default: 0].
    #[arg(long, value_name = "ARCSEC")]
    pub noise_arcsec: Option<f64>,
    /// Linear axis: spacing of the targets from 0 to --travel-mm, mm [default: 50].
    #[arg(long, value_name = "MM")]
    pub target_step_mm: Option<f64>,
    /// Linear axis: the travel measured, from 0, mm [default: 500].
    #[arg(long, value_name = "MM")]
    pub travel_mm: Option<f64>,
    /// Linear axis: carriage speed of the moves, mm per minute [default: 3000].
    #[arg(long, value_name = "MM_PER_MIN")]
    pub speed_mm_per_min: Option<f64>,
    /// Linear axis: rms of Gaussian noise added to each reading, µm [default: 0].
    #[arg(long, value_name = "UM")]
    pub noise_um: Option<f64>,
    /// Dwell before each reading, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0)]
    pub dwell_s: f64,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A compensation.json (`rtid compensate`): its backlash and error table run in
    /// the model's controller, added to the commanded position.
    #[arg(long, value_name = "FILE")]
    pub compensation: Option<std::path::PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let test = test(&a, p.axis)?;
    check::work(
        test.duration(),
        check::MAX_SIMULATED_S,
        "simulated seconds",
        "--runs, --target-step-deg/mm, --travel-mm, --speed-*, --dwell-s",
    )?;
    let note = super::loop_override(a.loop_mode, &p, a.common.quiet);
    a.common.create_out()?;
    run_positioning(&a, &p, test, note)
}

/// The test the flags describe on `axis`, checked before anything runs.
fn test(a: &Args, axis: Axis) -> anyhow::Result<positioning::PositioningTest> {
    if a.runs < 2 {
        bail!(
            "--runs {}: ISO 230-2 needs at least 2 runs per direction (5 in the standard test)",
            a.runs
        );
    }
    let (targets, speed, noise) = match axis {
        Axis::Rotary => rotary(a)?,
        Axis::Linear => linear(a)?,
    };
    check::work(
        2.0 * targets.len() as f64 * a.runs as f64,
        check::MAX_POINTS,
        "readings",
        "--runs with the targets",
    )?;
    Ok(positioning::PositioningTest {
        targets,
        runs: a.runs,
        dwell: check::positive(a.dwell_s, "--dwell-s")?,
        speed,
        noise,
        seed: a.seed,
        loop_mode: a.loop_mode,
        overrun: match axis {
            Axis::Rotary => 5f64.to_radians(),
            Axis::Linear => 5e-3,
        },
        compensation: match &a.compensation {
            Some(path) => {
                let file = compensation_file::read(path)?;
                file.check_axis(path, axis)?;
                file.compensation
            }
            None => Default::default(),
        },
    })
}

/// Targets, speed and noise of a rotary table (rad, rad/s, rad).
fn rotary(a: &Args) -> anyhow::Result<(Vec<f64>, f64, f64)> {
    let other = [
        ("--target-step-mm", a.target_step_mm),
        ("--travel-mm", a.travel_mm),
        ("--speed-mm-per-min", a.speed_mm_per_min),
        ("--noise-um", a.noise_um),
    ];
    if let Some((flag, _)) = other.iter().find(|(_, v)| v.is_some()) {
        bail!("{flag} is for a linear axis; this axis is rotary (--target-step-deg, --speed-deg-per-min, --noise-arcsec)");
    }
    let step = check::positive(a.target_step_deg.unwrap_or(30.0), "--target-step-deg")?;
    let speed = check::positive(a.speed_deg_per_min.unwrap_or(3600.0), "--speed-deg-per-min")?;
    let noise = a.noise_arcsec.unwrap_or(0.0);
    check::non_negative(noise, "--noise-arcsec")?;
    let targets = positioning::rotary_targets(step).map_err(|e| {
        anyhow::anyhow!(
            "--target-step-deg {}: {e} in a revolution",
            rtid::names::Num(step)
        )
    })?;
    Ok((
        targets,
        speed.to_radians() / 60.0,
        noise / iso230::ARCSEC_PER_RAD,
    ))
}

/// Targets, speed and noise of a linear axis (m, m/s, m).
fn linear(a: &Args) -> anyhow::Result<(Vec<f64>, f64, f64)> {
    let other = [
        ("--target-step-deg", a.target_step_deg),
        ("--speed-deg-per-min", a.speed_deg_per_min),
        ("--noise-arcsec", a.noise_arcsec),
    ];
    if let Some((flag, _)) = other.iter().find(|(_, v)| v.is_some()) {
        bail!("{flag} is for a rotary axis; this axis is linear (--target-step-mm, --travel-mm, --speed-mm-per-min, --noise-um)");
    }
    let step = check::positive(a.target_step_mm.unwrap_or(50.0), "--target-step-mm")?;
    let travel = check::positive(a.travel_mm.unwrap_or(500.0), "--travel-mm")?;
    let speed = check::positive(a.speed_mm_per_min.unwrap_or(3000.0), "--speed-mm-per-min")?;
    let noise = a.noise_um.unwrap_or(0.0);
    check::non_negative(noise, "--noise-um")?;
    let targets = positioning::linear_targets(step, travel).map_err(|e| {
        anyhow::anyhow!(
            "--travel-mm {} / --target-step-mm {}: {e}",
            rtid::names::Num(travel),
            rtid::names::Num(step)
        )
    })?;
    Ok((targets, speed * 1e-3 / 60.0, noise * 1e-6))
}

/// Runs `test` on `p` and writes it, `note` (the loop's override) in its manifest.
fn run_positioning(
    a: &Args,
    p: &Params,
    test: positioning::PositioningTest,
    note: Option<String>,
) -> anyhow::Result<()> {
    let bar = progress::bar(test.readings() as u64, "positioning", a.common.quiet);
    let readings = positioning::run(p, &test, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    let mut manifest = positioning::manifest(p, &test);
    super::add_note(&mut manifest, note);
    a.common.write_and_report(
        "positioning",
        manifest,
        &positioning::to_data(&readings, p.axis),
        report,
    )
}

/// Evaluates a positioning experiment: ISO 230-2 statistics printed (table or
/// JSON) in the axis's units (arc-seconds, or µm on a linear axis), and the Fig. 10
/// plot written to `plot`.
pub fn report(exp: &Experiment, plot: &Plot, json: bool) -> anyhow::Result<()> {
    report_runs(exp, plot, json, None)
}

/// [`report`] of runs `runs` only (all for `None`).
pub fn report_runs(
    exp: &Experiment,
    plot: &Plot,
    json: bool,
    runs: Option<&Runs>,
) -> anyhow::Result<()> {
    let Some(readings) = positioning::from_data(&exp.data) else {
        bail!("{}: not a positioning experiment", exp.path.display());
    };
    let readings = compensate::select(&readings, runs);
    if readings.is_empty() {
        bail!(
            "{}: no measurement of the runs asked for",
            exp.path.display()
        );
    }
    let units = ReportUnits::of(exp.data.axis().unwrap_or_default());
    let report =
        iso230::evaluate(&readings).map_err(|e| anyhow::anyhow!("{}: {e}", exp.path.display()))?;
    plot_deviations(exp, &report, units, plot, "")?;
    print_positioning(&report, units, json, &exp.path)
}

/// Writes the deviation chart (Fig. 10) of `report`, a record of `exp`, to `plot`,
/// titled "MECHANISM: ISO 230-2 positioning" and `what` (`, compensated`).
pub fn plot_deviations(
    exp: &Experiment,
    report: &iso230::Iso230Report,
    units: ReportUnits,
    plot: &Plot,
    what: &str,
) -> anyhow::Result<()> {
    let title = format!(
        "{}: ISO 230-2 positioning{what}",
        exp.manifest.mechanism.as_deref().unwrap_or("table")
    );
    plot.write(
        &rtid::report::positioning::deviations(report, &title, units),
        "",
    )?;
    Ok(())
}

/// Prints an ISO 230-2 evaluation, as a table or JSON, in `u`.
fn print_positioning(
    report: &iso230::Iso230Report,
    u: ReportUnits,
    json: bool,
    source: &Path,
) -> anyhow::Result<()> {
    if json {
        let source = source.display().to_string();
        let value = rtid::report::evaluation::positioning(report, u, &source)?;
        println!("{}", rtid::io::json::pretty(&value)?);
    } else {
        println!(
            "{}: ISO 230-2 evaluation, {}",
            source.display(),
            u.deviation_name
        );
        println!("{}", table(report, u));
    }
    Ok(())
}

/// A readable ISO 230-2 summary in `u`.
fn table(report: &iso230::Iso230Report, u: ReportUnits) -> String {
    let d = u.deviation;
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        format!("target {}", u.target),
        format!("x̄↑ {d}"),
        format!("x̄↓ {d}"),
        format!("s↑ {d}"),
        format!("s↓ {d}"),
        format!("Bi {d}"),
        format!("R↑i {d}"),
        format!("R↓i {d}"),
        format!("Ri {d}"),
    ]);
    for s in &report.targets {
        let a = s.scaled(u.deviation_per_si);
        t.add_row(
            [
                s.target * u.target_per_si,
                a.mean_up,
                a.mean_down,
                a.s_up,
                a.s_down,
                a.reversal,
                a.repeat_up,
                a.repeat_down,
                a.repeat,
            ]
            .map(|v| format!("{v:.2}")),
        );
    }
    format!(
        "{t}\n{}",
        axis_table(&report.axis.scaled(u.deviation_per_si), d)
    )
}

/// The axis values, already in the unit `d`.
pub fn axis_table(x: &iso230::AxisStats, d: &str) -> Table {
    let mut axis = Table::new();
    axis.load_preset(UTF8_FULL_CONDENSED);
    axis.set_header([
        format!("axis, {d}"),
        "↑".into(),
        "↓".into(),
        "bidirectional".into(),
    ]);
    let both = |name: &str, up: f64, down: f64, bi: f64| {
        [
            name.to_string(),
            format!("{up:.2}"),
            format!("{down:.2}"),
            format!("{bi:.2}"),
        ]
    };
    axis.add_row([
        "reversal B / mean B̄".to_string(),
        "".into(),
        "".into(),
        format!("{:.2} / {:.2}", x.b, x.b_mean),
    ]);
    axis.add_row(both("repeatability R", x.r_up, x.r_down, x.r));
    axis.add_row(both("systematic deviation E", x.e_up, x.e_down, x.e));
    axis.add_row([
        "mean deviation M".to_string(),
        "".into(),
        "".into(),
        format!("{:.2}", x.m),
    ]);
    axis.add_row(both("accuracy A", x.a_up, x.a_down, x.a));
    axis
}
