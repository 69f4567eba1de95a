//! `rtid experiment positioning` and the evaluation of positioning files.

use std::path::Path;

use anyhow::bail;

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use super::{check, Common};
use crate::cli::progress;
use rtid::experiments::iso230::ReportUnits;
use rtid::experiments::{iso230, positioning};
use rtid::io::experiment_file::Experiment;
use rtid::model::{LoopMode, Params};

pub const LONG_ABOUT: &str = "\
ISO 230-2 positioning accuracy and repeatability (paper §4.3): the servo, in semi-closed \
loop by default, approaches targets every 30° from 0° to 360°, 5 times from each side, \
with 1 s dwell; the table encoder (0.0001°) reads each stop. Writes positioning.json/.csv \
(deviation_arcsec per reading) and positioning.svg (the paper's Fig. 10), and prints the \
ISO 230-2 statistics in arc-seconds.

Example:
  rtid experiment positioning --preset worm-gear --out runs/worm
  rtid experiment positioning --preset worm-gear --noise-arcsec 0.5 --seed 7 --out runs/noisy";

/// Arguments of `rtid experiment positioning`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Feedback loop.
    #[arg(
        long = "loop",
        value_name = "semi_closed|full_closed",
        default_value = "semi_closed"
    )]
    pub loop_mode: LoopMode,
    /// Approaches of each target from each side.
    #[arg(long, default_value_t = 5)]
    pub runs: u32,
    /// Spacing of the targets from 0° to 360°, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 30.0)]
    pub target_step_deg: f64,
    /// Dwell before each reading, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0)]
    pub dwell_s: f64,
    /// Table speed of the moves, degrees per minute.
    #[arg(long, value_name = "DEG_PER_MIN", default_value_t = 3600.0)]
    pub speed_deg_per_min: f64,
    /// Rms of Gaussian noise added to each reading, arc-seconds.
    #[arg(long, value_name = "ARCSEC", default_value_t = 0.0)]
    pub noise_arcsec: f64,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.model.load()?;
    if p.axis == rtid::model::Axis::Linear {
        bail!(
            "{}: a linear axis — the virtual ISO 230-2 test turns a table through targets in degrees and is rotary only; a measured positioning file of a linear axis (target_mm, deviation_um…) is evaluated in µm by `rtid evaluate`",
            p.name
        );
    }
    let test = test(&a)?;
    a.common.create_out()?;
    run_positioning(&a, &p, test)
}

/// The test the flags describe, checked before anything runs.
fn test(a: &Args) -> anyhow::Result<positioning::PositioningTest> {
    let step = check::positive(a.target_step_deg, "--target-step-deg")?;
    if a.runs < 2 {
        bail!(
            "--runs {}: ISO 230-2 needs at least 2 runs per direction (5 in the standard test)",
            a.runs
        );
    }
    check::non_negative(a.noise_arcsec, "--noise-arcsec")?;
    let count = (360.0 / step).floor() as usize;
    Ok(positioning::PositioningTest {
        targets: (0..=count)
            .map(|i| (step * i as f64).to_radians())
            .collect(),
        runs: a.runs,
        dwell: check::positive(a.dwell_s, "--dwell-s")?,
        speed: check::positive(a.speed_deg_per_min, "--speed-deg-per-min")?.to_radians() / 60.0,
        noise: a.noise_arcsec / iso230::ARCSEC_PER_RAD,
        seed: a.seed,
        loop_mode: a.loop_mode,
        ..Default::default()
    })
}

fn run_positioning(a: &Args, p: &Params, test: positioning::PositioningTest) -> anyhow::Result<()> {
    let bar = progress::bar(test.readings() as u64, "positioning", a.common.quiet);
    let readings = positioning::run(p, &test, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    a.common.write_and_report(
        "positioning",
        positioning::manifest(p, &test),
        &positioning::to_data(&readings),
        report,
    )
}

/// Evaluates a positioning experiment: ISO 230-2 statistics printed (table or
/// JSON) in the axis's units (arc-seconds, or µm on a linear axis), and the Fig. 10
/// plot written to `plot`.
pub fn report(exp: &Experiment, plot: &Path, json: bool) -> anyhow::Result<()> {
    let Some(readings) = positioning::from_data(&exp.data) else {
        bail!("{}: not a positioning experiment", exp.path.display());
    };
    let units = ReportUnits::of(exp.data.axis().unwrap_or_default());
    let report =
        iso230::evaluate(&readings).map_err(|e| anyhow::anyhow!("{}: {e}", exp.path.display()))?;
    let title = format!(
        "{}: ISO 230-2 positioning",
        exp.manifest.mechanism.as_deref().unwrap_or("table")
    );
    rtid::report::positioning::deviations(&report, &title, units).write(plot)?;
    print_positioning(&report, units, json, &exp.path)
}

/// Prints an ISO 230-2 evaluation, as a table or JSON, in `u`.
fn print_positioning(
    report: &iso230::Iso230Report,
    u: ReportUnits,
    json: bool,
    source: &Path,
) -> anyhow::Result<()> {
    let k = u.deviation_per_si;
    if json {
        let value = serde_json::json!({
            "kind": "positioning",
            "source": source,
            "unit": u.deviation_key,
            "axis": report.axis.scaled(k),
            "targets": report.targets.iter().map(|t| {
                let mut v = serde_json::to_value(t.scaled(k)).expect("serialises");
                v[format!("target_{}", u.target_key)] = serde_json::json!(t.target * u.target_per_si);
                v
            }).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        let unit = if u == ReportUnits::ROTARY {
            "arc-seconds"
        } else {
            "µm"
        };
        println!("{}: ISO 230-2 evaluation, {unit}", source.display());
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
fn axis_table(x: &iso230::AxisStats, d: &str) -> Table {
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
