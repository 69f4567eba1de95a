//! `rtid experiment friction-map` and the evaluation of friction-map files.

use crate::cli::common::plot::Plot;

use anyhow::Context;
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use rtid::estimation::friction_law::LawFit;
use rtid::experiments::friction_map::{self, MapEvaluation, MapTest};
use rtid::io::experiment_file::{Axis, Data, Experiment};
use rtid::model::Params;
use rtid::report::friction_map as figures;

use super::{check, Common};
use crate::cli::common::progress;

pub const LONG_ABOUT: &str = "\
Friction map: the servo holds the axis at a series of constant motor speeds in both \
directions, one run each, from rest; after --settle-s the motor speed and torque are \
averaged over every integration step of --average-s (lengthened to whole revolutions of the driving shaft \
when the drive has a gear fluctuation, which averages out only over whole revolutions), \
and each run's mean and scatter make a row of the map. The map shows the friction law at \
the motor: the Coulomb level, a Stribeck rise at low speed (parameters fsm, vsm, \
stribeck_shape: `rtid params`), the viscous slope and the offset a load (Tload) puts \
between the directions — every body's friction seen through the ratios. Writes \
friction_map.json/.csv (speed_rad_s or speed_m_s, torque_nm or force_n, their standard \
deviations, samples), friction_map.svg (torque over speed with the fitted laws) and \
friction_map-residuals.svg, and prints the evaluation (`rtid evaluate` of the file): the \
runs, the laws fitted by least squares with standard errors — coulomb (Fc, Fv, Fo), \
stribeck (Fc, Fs, vs, delta, Fv, Fo), and per direction coulomb_asymmetric and \
stribeck_asymmetric — ranked by AICc, and the law the data support.

Example:
  rtid experiment friction-map --preset worm-gear --out runs/worm
  rtid experiment friction-map --preset direct-drive --set fst=0.5 --set vst=0.2 \\
      --speeds-rpm 1,2,5,10,20,50,100 --noise-percent 1 --scatter-percent 1 --out runs/dd
  rtid experiment friction-map --params fixtures/real/emps/axis.json --speeds-mm-s 2,5,10,20,50,100 --out runs/emps";

/// Arguments of `rtid experiment friction-map`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// Rotary axis: motor speeds, rpm, comma-separated; each is run in both directions
    /// (a negative value only in its own) [default: ±0.2 … ±50 % of the speed limit,
    /// eight per direction].
    #[arg(
        long,
        value_name = "RPM,…",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub speeds_rpm: Vec<f64>,
    /// Linear axis: speeds, mm/s, as --speeds-rpm.
    #[arg(
        long,
        value_name = "MM_S,…",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub speeds_mm_s: Vec<f64>,
    /// Time from each run's start to its averaging window, s.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.5,
        allow_negative_numbers = true
    )]
    pub settle_s: f64,
    /// Averaging window of each run, s.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub average_s: f64,
    /// Measurement noise on the torque samples: Gaussian, this percentage of each run's
    /// RMS torque, added to every sample before the run is averaged (as a recorder's
    /// noise is).
    #[arg(
        long,
        value_name = "PERCENT",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub noise_percent: f64,
    /// Scatter from run to run (what a real map shows beyond the recorder's noise:
    /// temperature, lubrication, position along the axis): each run's mean torque
    /// multiplied by (1 + ε), ε Gaussian with this standard deviation in per cent.
    #[arg(
        long,
        value_name = "PERCENT",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub scatter_percent: f64,
    /// Seed of the noise and the scatter.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let test = test(&a, &p)?;
    check::work(
        test.duration(&p),
        check::MAX_SIMULATED_S,
        "simulated seconds",
        "--speeds-rpm (--speeds-mm-s), --settle-s, --average-s",
    )?;
    a.common.create_out()?;
    let bar = progress::bar(test.speeds.len() as u64, "friction map", a.common.quiet);
    let progress = |done, _| bar.set_position(done as u64);
    let (manifest, map) = friction_map::run::record(&p, &test, a.scatter_percent, progress)?;
    bar.finish_and_clear();
    a.common
        .write_and_report("friction_map", manifest, &Data::FrictionMap(map), report)
}

/// The test the flags describe, or why they do not describe one.
fn test(a: &Args, p: &Params) -> anyhow::Result<MapTest> {
    check::percent(a.noise_percent, "--noise-percent")?;
    check::percent(a.scatter_percent, "--scatter-percent")?;
    let (given, option, si) = match (p.axis, a.speeds_rpm.is_empty(), a.speeds_mm_s.is_empty()) {
        (Axis::Rotary, _, true) => (&a.speeds_rpm, "--speeds-rpm", std::f64::consts::TAU / 60.0),
        (Axis::Linear, true, _) => (&a.speeds_mm_s, "--speeds-mm-s", 1e-3),
        (Axis::Rotary, _, false) => {
            anyhow::bail!("--speeds-mm-s is for a linear axis; this axis is rotary (--speeds-rpm)")
        }
        (Axis::Linear, false, _) => {
            anyhow::bail!("--speeds-rpm is for a rotary axis; this axis is linear (--speeds-mm-s)")
        }
    };
    let speeds = if given.is_empty() {
        MapTest::default_speeds(p)
    } else {
        speeds(given, option, si)?
    };
    let test = MapTest {
        speeds,
        settle: check::positive(a.settle_s, "--settle-s")?,
        average: check::positive(a.average_s, "--average-s")?,
        sample: 0.0,
        noise_percent: a.noise_percent,
        seed: a.seed,
    };
    for &v in &test.speeds {
        let window = test.window(p, v);
        if window > friction_map::run::MAX_WINDOW_S {
            anyhow::bail!(
                "{option}: at {} the averaging window would be {window:.0} s (whole revolutions of the driving shaft, whose gear fluctuation averages out only over them), beyond {} s: give faster speeds",
                v / si,
                friction_map::run::MAX_WINDOW_S
            );
        }
    }
    Ok(test)
}

/// The speeds given, in SI: each positive one in both directions, a negative one in
/// its own; zero, non-finite and repeated speeds refused naming the option.
fn speeds(given: &[f64], option: &str, si: f64) -> anyhow::Result<Vec<f64>> {
    let mut out: Vec<f64> = Vec::new();
    for &v in given {
        if !v.is_finite() || v == 0.0 {
            anyhow::bail!("{option}: {v} is not a speed of a run (finite, not 0)");
        }
        let both: &[f64] = if v > 0.0 { &[-1.0, 1.0] } else { &[1.0] };
        for s in both {
            let speed = s * v * si;
            if out.contains(&speed) {
                anyhow::bail!("{option}: {v} is given twice");
            }
            out.push(speed);
        }
    }
    out.sort_by(f64::total_cmp);
    Ok(out)
}

/// Evaluates a friction-map experiment: runs and laws printed (table or JSON), the map
/// with its laws written to `plot` and the residuals beside it (`STEM-residuals.svg`).
pub fn report(exp: &Experiment, plot: &Plot, json: bool) -> anyhow::Result<()> {
    let Data::FrictionMap(map) = &exp.data else {
        anyhow::bail!("{}: not a friction map", exp.path.display());
    };
    let e =
        friction_map::evaluate(map).map_err(|m| anyhow::anyhow!("{}: {m}", exp.path.display()))?;
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("axis");
    plot.write(&figures::map(&e, &format!("{mechanism}: friction map")), "")?;
    plot.write(
        &figures::residuals(&e, &format!("{mechanism}: friction map, residuals")),
        "-residuals",
    )?;
    if json {
        let source = exp.path.display().to_string();
        let value = rtid::report::evaluation::friction_map(&e, &source)
            .context("the evaluation as JSON")?;
        println!("{}", rtid::io::json::pretty(&value)?);
    } else {
        println!("{}: friction map, {} runs", exp.path.display(), map.len());
        println!("{}", runs_table(&e));
        println!("{}", laws_table(&e));
        println!("{}", verdict(&e));
    }
    Ok(())
}

/// The runs: speed (rpm or mm/s), mean effort, its scatter, samples, and the selected
/// law's residual.
fn runs_table(e: &MapEvaluation) -> Table {
    let (to_unit, speed, effort) = match e.axis {
        Axis::Rotary => (60.0 / std::f64::consts::TAU, "speed, rpm", "N·m"),
        Axis::Linear => (1e3, "speed, mm/s", "N"),
    };
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        speed.to_string(),
        format!("mean, {effort}"),
        format!("std, {effort}"),
        "samples".into(),
        "glitches dropped".into(),
        format!("residual, {effort}"),
    ]);
    let opt = |v: Option<f64>, f: &dyn Fn(f64) -> String| v.map_or("–".into(), f);
    for r in &e.runs {
        t.add_row([
            format!("{:.4}", r.speed * to_unit),
            format!("{:.5e}", r.effort),
            opt(r.effort_std, &|v| format!("{v:.2e}")),
            opt(r.samples, &|v| format!("{v:.0}")),
            opt(r.dropped, &|v| format!("{v:.0}")),
            format!("{:+.2e}", r.residual),
        ]);
    }
    t
}

/// The laws: parameters with standard errors, RMS residual, AICc and weight.
fn laws_table(e: &MapEvaluation) -> Table {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "law",
        "parameters (SI) ± standard error",
        "RMS residual",
        "ΔAICc",
        "weight",
    ]);
    let parameters = |fit: &LawFit| -> String {
        let all: Vec<String> = fit
            .parameters
            .iter()
            .map(|p| match p.std_error {
                Some(se) => format!("{} = {:.4e} ± {:.1e}", p.name, p.value, se),
                None => format!("{} = {:.4e} (not determined)", p.name, p.value),
            })
            .collect();
        all.join("\n")
    };
    for c in &e.laws.selection.candidates {
        let Some(fit) = e.laws.fits.iter().find(|f| f.law.name() == c.label) else {
            continue;
        };
        t.add_row([
            fit.law.name().to_string(),
            parameters(fit),
            format!("{:.2e}", fit.residual_rms()),
            format!("{:.1}", c.delta),
            format!("{:.2}", c.weight),
        ]);
    }
    // Laws the data do not determine, ranked apart (their notes say why).
    for fit in e.laws.fits.iter().filter(|f| !f.determined) {
        t.add_row([
            format!("{} (not determined)", fit.law.name()),
            parameters(fit),
            format!("{:.2e}", fit.residual_rms()),
            "not ranked".into(),
            "".into(),
        ]);
    }
    for r in &e.laws.refused {
        t.add_row([
            r.law.name().to_string(),
            format!("not fitted: {}", r.reason),
            "".into(),
            "".into(),
            "".into(),
        ]);
    }
    t
}

/// Which law the data support, and the notes on it.
fn verdict(e: &MapEvaluation) -> String {
    let selected = e.selected();
    let mut out = format!(
        "the data support the {} law (lowest {}).",
        selected.law.name(),
        e.laws.selection.criterion
    );
    if let Some(m) = e.misfit.as_ref().filter(|m| m.is_far()) {
        out += &format!(
            "\nnote ({}): its residuals (RMS {:.2e}) are {:.0} times the runs' own scatter \
             (RMS standard error of their means {:.2e}): the map holds more than the law \
             describes (a shape none of the laws has, or runs that differ by more than \
             their scatter says)",
            selected.law.name(),
            m.residual_rms,
            m.ratio,
            m.mean_std_error
        );
    }
    for fit in &e.laws.fits {
        for note in &fit.notes {
            out += &format!("\nnote ({}): {note}", fit.law.name());
        }
        if !fit.determined {
            out += &format!(
                "\nnote ({}): not determined by the data (see the notes above), ranked apart",
                fit.law.name()
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_run_both_ways_and_bad_ones_are_refused_naming_the_option() {
        let rpm = std::f64::consts::TAU / 60.0;
        let s = speeds(&[10.0, -5.0], "--speeds-rpm", rpm).unwrap();
        assert_eq!(s, vec![-10.0 * rpm, -5.0 * rpm, 10.0 * rpm]);
        for bad in [&[0.0][..], &[f64::NAN], &[5.0, -5.0]] {
            let e = speeds(bad, "--speeds-rpm", rpm).unwrap_err().to_string();
            assert!(e.starts_with("--speeds-rpm"), "{e}");
        }
    }
}
