//! `rtid tune`: the velocity and position loop gains and notch filters for a target
//! phase margin, from the model's linear response (docs/tuning.md).

use std::path::{Path, PathBuf};

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::common::inputs::refuse_overwrite;
use crate::cli::common::plot::Plot;
use crate::cli::ModelArgs;
use rtid::io::params_file;
use rtid::tuning::{self, bode, verify, Setting, Targets, Tuned};

pub const LONG_ABOUT: &str = "\
Tune the cascade from the model (docs/tuning.md): notch filters (−20 dB) at the resonances \
of the motor's compliance below 0.8·Nyquist, then the velocity PI (its corner Kvi/Kvp at a \
quarter of the crossover) with the highest velocity-loop crossover that keeps the target \
phase margin and the gain-margin floor, then the position gain Kpp = ω_c/4 (critically \
damped on a velocity loop read as a first-order lag).

The margins are those of the velocity loop's open-loop response on the sampled loop: the \
controller's discrete PI and filters, the drive's exact linear compliance (no backlash, \
no friction), the zero-order hold, the backward-difference speed, the encoder dead time \
and the output delay; aliasing neglected. The table shows them for the current settings \
and the tuned ones. With -o the tuned parameter file is written (atomically, never over \
the --params input). With --plot the velocity loop's open loop before and after tuning is \
drawn as a Bode plot (SVG: gain in dB over phase in degrees on a log frequency axis from \
0.1 Hz to 0.99·Nyquist), each phase margin and gain margin marked where it is read and \
named with its value in the legend.

Then both settings run on the nonlinear model (backlash, friction, quantised encoders, \
the torque limit, which the margins leave out): a 1° step (1 mm on a linear axis) — \
overshoot, time to settle within 20″ (20 µm), peak torque — and a move 5° out and back \
at 10°/s — the following error at constant speed and the reversal spike beyond it.

Examples:
  rtid tune --preset worm-gear
  rtid tune fit.json --preset worm-gear -o worm-tuned.json     (the identified model)
  rtid tune --preset two-mass --phase-margin-deg 60 --gain-margin-db 10 -o two-mass-tuned.json
  rtid tune --params fit-params.json --set encoder_delay=1e-4 --json
  rtid tune --preset two-mass --plot two-mass-loop.svg
  rtid simulate --params two-mass-tuned.json --input move:target_deg=1 --duration-s 1 --out step.csv

The tuned file's setpoint filters are the notches only: filters of the input (a \
low-pass, say) are in the \"before\" column and not carried over.";

/// Arguments of `rtid tune`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// An identification result (`rtid identify --out`): its values set in the model
    /// (--preset or --params, the base the fit started from).
    #[arg(value_name = "FIT.json")]
    pub fit: Option<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    /// Target phase margin of the velocity loop, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 50.0)]
    pub phase_margin_deg: f64,
    /// Smallest gain margin of the velocity loop, dB.
    #[arg(long, value_name = "DB", default_value_t = 6.0)]
    pub gain_margin_db: f64,
    /// Print JSON (targets, resonances, before, after) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write the tuned parameter file.
    #[arg(short = 'o', long = "out", value_name = "tuned.json")]
    pub out: Option<PathBuf>,
    /// Write the velocity loop's open-loop Bode plot, before and after tuning, with
    /// the margins marked (SVG; never over an input or the -o file).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// No notes on stderr (accepted like every command's `--quiet`).
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let read: Vec<&Path> = a
        .model
        .params
        .iter()
        .chain(&a.fit)
        .map(PathBuf::as_path)
        .collect();
    if let Some(out) = &a.out {
        refuse_overwrite("-o", out, &read)?;
    }
    let plot = match &a.plot {
        Some(path) => {
            let mut inputs = read.clone();
            inputs.extend(a.out.as_deref());
            Plot::at(path.clone(), &inputs)?
        }
        None => Plot::none(),
    };
    let p = crate::cli::common::model_args::fitted(&a.model, a.fit.as_deref(), None)?;
    let targets = Targets {
        phase_margin_deg: a.phase_margin_deg,
        gain_margin_db: a.gain_margin_db,
    };
    let t = tuning::tune(&p, targets)?;
    if let Some(out) = &a.out {
        params_file::write(out, &t.params)?;
    }
    if a.plot.is_some() {
        let title = format!(
            "{}: velocity loop, open loop L(jω) on the sampled loop",
            p.name
        );
        let figure = rtid::report::tuning::open_loop(
            &bode::bode(&p, &t.before)?,
            &bode::bode(&t.params, &t.after)?,
            &title,
        );
        plot.write(&figure, "")?;
    }
    let checked = [verify::responses(&p)?, verify::responses(&t.params)?];
    if a.json {
        let mut v = rtid::io::json::value(&t)?;
        v["verification"] = serde_json::json!({
            "before": rtid::io::json::value(&checked[0])?,
            "after": rtid::io::json::value(&checked[1])?,
        });
        println!("{}", rtid::io::json::pretty(&v)?);
    } else {
        print_table(&p.name, &t);
        print_verification(&checked);
    }
    Ok(())
}

/// The step and the out-and-back move on the nonlinear model, before and after.
fn print_verification(r: &[verify::Responses; 2]) {
    let u = r[0].unit;
    println!(
        "on the nonlinear model (backlash, friction, quantised encoders, torque limit), the motor encoder × the ratio: {}",
        if u == "″" {
            "a 1° step; 5° out and back at 10°/s"
        } else {
            "a 1 mm step; 5 mm out and back at 10 mm/s"
        }
    );
    let mut table = Table::new();
    table.load_preset(UTF8_FULL_CONDENSED);
    table.set_header(vec!["", "before", "after"]);
    let row =
        |label: String, f: &dyn Fn(&verify::Responses) -> String| vec![label, f(&r[0]), f(&r[1])];
    table.add_row(row("step overshoot".into(), &|x| {
        format!("{:.1} %", x.step_overshoot_percent)
    }));
    let gap = if u == "″" { "" } else { " " };
    table.add_row(row(
        format!("step settled within {}{gap}{u}", verify::SETTLED),
        &|x| {
            x.step_settling_s
                .map_or("not within 1 s".into(), |t| format!("{:.0} ms", t * 1e3))
        },
    ));
    table.add_row(row(format!("following error, {u}"), &|x| {
        format!("{:.1}", x.following_error)
    }));
    table.add_row(row(format!("reversal spike, {u}"), &|x| {
        format!("{:.1}", x.reversal_spike)
    }));
    let effort = if u == "″" {
        "peak torque, N·m"
    } else {
        "peak force, N"
    };
    table.add_row(row(effort.into(), &|x| format!("{:.2}", x.peak_effort)));
    println!("{table}");
}

fn print_table(name: &str, t: &Tuned) {
    println!(
        "{name}: velocity-loop margins on the sampled loop; targets: phase margin ≥ {}°, gain margin ≥ {} dB",
        t.targets.phase_margin_deg, t.targets.gain_margin_db
    );
    let mut table = Table::new();
    table.load_preset(UTF8_FULL_CONDENSED);
    table.set_header(vec!["", "before", "after"]);
    let (b, a) = (&t.before, &t.after);
    let row = |label: &str, f: &dyn Fn(&Setting) -> String| vec![label.to_string(), f(b), f(a)];
    table.add_row(row("Kvp", &|s| format!("{:.4e}", s.kvp)));
    table.add_row(row("Kvi", &|s| format!("{:.4e}", s.kvi)));
    table.add_row(row("Kvi/Kvp (1/s)", &|s| format!("{:.1}", s.kvi / s.kvp)));
    table.add_row(row("Kpp (1/s)", &|s| format!("{:.1}", s.kpp)));
    table.add_row(row("setpoint filters", &|s| filters(s)));
    table.add_row(row("crossover", &|s| {
        s.velocity_loop
            .crossover_hz
            .map_or("none".into(), |f| format!("{f:.1} Hz"))
    }));
    table.add_row(row("phase margin", &|s| {
        let m = &s.velocity_loop;
        at(m.phase_margin_deg.zip(m.phase_margin_hz), "°")
    }));
    table.add_row(row("gain margin", &|s| {
        let m = &s.velocity_loop;
        at(m.gain_margin_db.zip(m.gain_margin_hz), " dB")
    }));
    table.add_row(row("position loop: peak", &|s| {
        format!("{:.2} dB", s.position_peak_db)
    }));
    println!("{table}");
}

/// `62.0° at 119.4 Hz`, or `none`.
fn at(margin: Option<(f64, f64)>, unit: &str) -> String {
    margin.map_or("none".into(), |(v, hz)| {
        format!("{v:.1}{unit} at {hz:.1} Hz")
    })
}

fn filters(s: &Setting) -> String {
    if s.filters.is_empty() {
        return "none".into();
    }
    s.filters
        .iter()
        .map(|f| match *f {
            rtid::model::SetpointFilter::Notch {
                centre_hz,
                width_hz,
                depth_db,
            } => format!(
                "notch {centre_hz:.1} Hz, width {width_hz:.1} Hz, {}",
                depth_db.map_or("full".into(), |d| format!("{d} dB"))
            ),
            rtid::model::SetpointFilter::LowPass {
                frequency_hz,
                damping,
            } => format!("low-pass {frequency_hz:.1} Hz, D {damping}"),
        })
        .collect::<Vec<_>>()
        .join("\n")
}
