//! `rtid experiment fluctuation` and the evaluation of fluctuation and unbalance files.

use crate::cli::common::plot::Plot;
use std::path::Path;

use anyhow::bail;

use super::{check, Common};
use crate::cli::common::progress;
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use rtid::estimation::spectrum::Peak;
use rtid::experiments::fluctuation::{self, Evaluation, FluctuationTest};
use rtid::io::experiment_file::{Experiment, Kind};
use rtid::model::{LoopMode, Params};
use rtid::report;

pub const LONG_ABOUT: &str = "\
Rotational fluctuation (paper §4.4, Figs. 11 and 12): the servo, in the parameter set's \
loop (controller.loop; semi-closed in the presets) unless --loop overrides it, turns the table at a constant 180°/min through one revolution counter-clockwise \
(up) and one clockwise (down), with 10° of run-in at both ends of each pass so the speed \
is steady. Both encoders are recorded (every 4 ms, quantised to their resolutions).

Outputs, in --out DIR: fluctuation.json/.csv (time_s, motor_angle_deg, table_angle_deg), \
fluctuation.svg (the deviation θt − θm·Rg·Rw over table angle, one curve per direction: \
Fig. 11; the gap between the curves is the lost motion, i.e. the backlash) and \
fluctuation-spectrum.svg (its power spectrum over cycles per revolution: Fig. 12). \
Printed: per direction the mean and peak-to-peak deviation (arc-sec) and the dominant \
orders (cycles/rev with their amplitude in arc-sec). A worm wheel of 72 teeth shows its \
fluctuation at order 72; a roller gear cam shows none.

Example:
  rtid experiment fluctuation --preset worm-gear --out runs/worm
  rtid experiment fluctuation --preset roller-gear-cam --json --out runs/roller";

/// Arguments of `rtid experiment fluctuation`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub run: RunArgs,
    /// Table speed, degrees per minute.
    #[arg(long, value_name = "DEG_PER_MIN", default_value_t = 180.0)]
    pub speed_deg_per_min: f64,
}

/// The run settings fluctuation and unbalance share.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Feedback loop [default: the parameter set's controller.loop].
    #[arg(long = "loop", value_name = "semi_closed|full_closed")]
    pub loop_mode: Option<LoopMode>,
    /// Whole revolutions measured in each direction.
    #[arg(long, default_value_t = 1)]
    pub revolutions: u32,
    /// Extra travel at both ends of each pass, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 10.0)]
    pub run_in_deg: f64,
    /// Recording interval, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 4e-3)]
    pub sample_period_s: f64,
    /// Measurement noise on the table angle reading: Gaussian, this standard
    /// deviation in arc-seconds (the motor angle, which enters the deviation divided
    /// by the ratio, stays as the encoder read it).
    #[arg(long, value_name = "ARCSEC", default_value_t = 0.0)]
    pub noise_arcsec: f64,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

impl RunArgs {
    /// The test at `speed_deg_per_min`.
    pub fn test(&self, speed_deg_per_min: f64) -> anyhow::Result<FluctuationTest> {
        if self.revolutions == 0 {
            bail!("--revolutions 0: at least one revolution is needed");
        }
        check::non_negative(self.run_in_deg, "--run-in-deg")?;
        check::non_negative(self.noise_arcsec, "--noise-arcsec")?;
        Ok(FluctuationTest {
            speed: check::positive(speed_deg_per_min, "--speed-deg-per-min")?.to_radians() / 60.0,
            revolutions: self.revolutions,
            run_in: self.run_in_deg.to_radians(),
            sample_period: check::positive(self.sample_period_s, "--sample-period-s")?,
            loop_mode: self.loop_mode,
            ..Default::default()
        })
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let test = a.run.test(a.speed_deg_per_min)?;
    a.common.create_out()?;
    run_test(&a.common, &p, &test, &a.run)
}

/// Runs `test`, writes its experiment file (with the measurement noise of `run`) and
/// reports it (fluctuation and unbalance).
pub fn run_test(
    common: &Common,
    p: &Params,
    test: &FluctuationTest,
    run: &RunArgs,
) -> anyhow::Result<()> {
    check::work(
        test.duration(),
        check::MAX_SIMULATED_S,
        "simulated seconds",
        "--speed-deg-per-min, --revolutions, --run-in-deg",
    )?;
    let name = test.kind().name();
    if p.axis == rtid::model::Axis::Linear {
        anyhow::bail!(
            "{}: a linear axis — the {name} test turns a table through whole revolutions and reports per revolution: rotary axes only (a linear axis's positioning: `rtid experiment positioning`)",
            p.name
        );
    }
    let note = super::loop_override(run.loop_mode, p, common.quiet);
    let bar = progress::bar(test.duration().ceil() as u64, name, common.quiet);
    let mut record = fluctuation::run(p, test, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    let sigma = run.noise_arcsec / rtid::experiments::positioning::iso230::ARCSEC_PER_RAD;
    rtid::experiments::measurement_noise::perturb_absolute(
        &mut record.table_angle,
        sigma,
        run.seed,
    );
    let mut manifest = fluctuation::manifest(p, test);
    if run.noise_arcsec > 0.0 {
        manifest.notes = Some(format!(
            "{}; Gaussian noise of {}″ (standard deviation) on the table angle (seed {})",
            manifest.notes.unwrap_or_default(),
            run.noise_arcsec,
            run.seed
        ));
    }
    super::add_note(&mut manifest, note);
    common.write_and_report(
        name,
        manifest,
        &fluctuation::to_data(&record, test.kind()),
        report,
    )
}

/// Evaluates a fluctuation or unbalance experiment: printed (table or JSON), the
/// deviation plot written to `plot` and the spectrum beside it (`…-spectrum.svg`).
pub fn report(exp: &Experiment, plot: &Plot, json: bool) -> anyhow::Result<()> {
    let kind = exp.manifest.kind;
    let e = fluctuation::evaluate_experiment(exp).map_err(|e| match e {
        fluctuation::FluctuationError::NoRatio { .. } => anyhow::anyhow!("{e}"),
        other => anyhow::anyhow!("{}: {other}", exp.path.display()),
    })?;
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("table");
    let what = if kind == Kind::Unbalance {
        "influence of unbalance mass"
    } else {
        "rotational fluctuation"
    };
    plot.write(
        &report::fluctuation::deviation(&e, &format!("{mechanism}: {what}")),
        "",
    )?;
    plot.write(
        &report::fluctuation::spectrum(
            &e,
            &format!("{mechanism}: power spectrum of the {what}"),
            200.0,
        ),
        "-spectrum",
    )?;
    print(&e, kind, json, &exp.path)
}

fn print(e: &Evaluation, kind: Kind, json: bool, source: &Path) -> anyhow::Result<()> {
    if json {
        let source = source.display().to_string();
        let value = rtid::report::evaluation::fluctuation(e, kind, &source)?;
        println!("{}", rtid::io::json::pretty(&value)?);
    } else {
        println!("{}: {kind} evaluation, arc-seconds", source.display());
        println!("{}", table(e, kind));
    }
    Ok(())
}

/// A readable summary in arc-seconds.
fn table(e: &Evaluation, kind: Kind) -> String {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "direction",
        "revolutions",
        "mean ″",
        "peak-to-peak ″",
        "dominant orders (cycles/rev: amplitude ″)",
        "largest step ″ at °",
    ]);
    for p in &e.passes {
        t.add_row([
            p.direction.to_string(),
            p.revolutions.to_string(),
            format!("{:.2}", p.mean_arcsec),
            format!("{:.2}", p.pp_arcsec),
            orders(&p.dominant),
            format!("{:.2} at {:.1}", p.step.size_arcsec, p.step.angle_deg),
        ]);
    }
    let mut s = format!(
        "{t}\nratio {:.6e}; peak-to-peak {:.2}″",
        e.ratio, e.pp_arcsec
    );
    if let Some(g) = e.gap_arcsec {
        s += &format!("; gap between the directions (lost motion) {g:.2}″");
    }
    s += &format!("\ndominant orders (mean spectrum): {}", orders(&e.dominant));
    if kind == Kind::Unbalance {
        s += &format!(
            "\nstep: {:.2}″ at table angle {:.1}°",
            e.step.size_arcsec, e.step.angle_deg
        );
        for p in &e.passes {
            let list: Vec<String> = p
                .steps
                .iter()
                .map(|st| format!("{:.2}″ at {:.3}°", st.size_arcsec, st.angle_deg))
                .collect();
            s += &format!("\nsteps {} (located): {}", p.direction, list.join(", "));
        }
    }
    s
}

fn orders(peaks: &[Peak]) -> String {
    peaks
        .iter()
        .map(|p| format!("{:.0}: {:.2}", p.order, p.amplitude))
        .collect::<Vec<_>>()
        .join(", ")
}
