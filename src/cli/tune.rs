//! `rtid tune`: the velocity and position loop gains and notch filters for a target
//! phase margin, from the model's linear response (docs/tuning.md).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::common::inputs::refuse_overwrite;
use crate::cli::common::plot::Plot;
use crate::cli::ModelArgs;
use rtid::io::params_file;
use rtid::model::params::LoopMode;
use rtid::model::Axis;
use rtid::names::Num;
use rtid::tuning::{
    self, bode, objective, verify, Criterion, Limits, LoopMargins, Objective, Options, Setting,
    Targets, TuneWarning, Tuned,
};

pub const LONG_ABOUT: &str = "\
Tune the cascade on the nonlinear model, in the loop it runs (docs/tuning.md): notch filters \
at the resonances of the motor's compliance below 0.8·Nyquist; then velocity PIs (corner \
Kvi/Kvp at a quarter of the crossover) at crossovers from the highest whose velocity loop \
keeps the targets down to a tenth of it, each with position gains Kpp from ω_c/4 down to \
ω_c/32; of these, the settings whose cascade as it runs keeps the targets — phase margin, \
gain margins both ways, no conditional window, exact on the sampled loop: the drive held \
over a control period, the controller sample by sample, the position loop closed on the \
motor encoder (semi-closed) or the table encoder (full-closed) — are weighed on the \
nonlinear model (backlash, friction with stick, quantised encoders, the torque limit) \
against today's settings:

  the ISO 230-2 cycle at the table, A and R after the compensation built for the setting;
  a 1° (1 mm) step: overshoot and settling within 20″ (20 µm) at the table;
  the table's motion at rest after it (a limit cycle refuses the setting);
  the following error at 10°/s (10 mm/s) and the reversal spike;
  the peak torque of the move (--torque-reserve of the limit kept free).

The weighting is --objective's (positioning, the default: A, then R, then the settling; \
following: the following error and the reversal spike; settling: the step at the table). \
The settings are screened on a short cycle (every 90°, two runs), candidates side by side in \
the kernel's lanes; the best are checked on the standard cycle with their compensation run \
in the controller. Today's settings are a candidate: if none beats them, tune says so and \
proposes nothing new; a proposed setting that makes any criterion worse than today's \
carries a warning naming it and by how much.

The table shows each setting's gains with their units (Tn = Kvp/Kvi; Kv in 1/s and in the \
CNC's (rev/min)/rev or (m/min)/mm), the margins of the velocity loop alone and of the \
cascade as it runs, and the check before and after. With -o the tuned parameter file is \
written (atomically, never over an input). With --plot the open loops before and after — \
the velocity loop alone and the cascade as it runs — are drawn as a Bode plot with their \
margins marked.

Examples:
  rtid tune --preset worm-gear
  rtid tune --preset worm-gear --loop full_closed -o worm-full-closed.json
  rtid tune fit.json --preset worm-gear -o worm-tuned.json     (the identified model)
  rtid tune --preset two-mass --objective following --max-kpp 60 --json
  rtid tune --preset two-mass --phase-margin-deg 60 --gain-margin-db 10 --plot loop.svg

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
    /// Target phase margin of the cascade as it runs, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 50.0)]
    pub phase_margin_deg: f64,
    /// Smallest gain margin of the cascade, up and down, dB.
    #[arg(long, value_name = "DB", default_value_t = 6.0)]
    pub gain_margin_db: f64,
    /// What the settings are weighed by: positioning (ISO 230-2 A and R after
    /// compensation, then settling), following (following error, reversal spike) or
    /// settling (the step at the table).
    #[arg(long, value_name = "KIND", default_value = "positioning")]
    pub objective: Objective,
    /// The loop to tune (semi_closed or full_closed); default the parameter file's
    /// `controller.loop`. Overriding it is said on stderr.
    #[arg(long = "loop", value_name = "LOOP")]
    pub loop_mode: Option<LoopMode>,
    /// The highest position gain Kpp (Kv) allowed, 1/s.
    #[arg(long, value_name = "1/s")]
    pub max_kpp: Option<f64>,
    /// The highest velocity-loop crossover allowed, Hz.
    #[arg(long, value_name = "HZ")]
    pub max_bandwidth_hz: Option<f64>,
    /// The notches' depth at their centre, dB (−60 to −1).
    #[arg(long, value_name = "DB", default_value_t = -20.0, allow_negative_numbers = true)]
    pub notch_depth_db: f64,
    /// The narrowest notch, as a fraction of its centre frequency (0.01 to 1).
    #[arg(long, value_name = "FRACTION", default_value_t = 0.2)]
    pub notch_min_width: f64,
    /// The fraction of the torque limit the move at speed must leave free (0 to 0.9).
    #[arg(long, value_name = "FRACTION", default_value_t = 0.2)]
    pub torque_reserve: f64,
    /// Print JSON (targets, resonances, before, after, search, check, warnings)
    /// instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Write the tuned parameter file.
    #[arg(short = 'o', long = "out", value_name = "tuned.json")]
    pub out: Option<PathBuf>,
    /// Write the open loops' Bode plot — the velocity loop alone and the cascade as
    /// it runs, before and after tuning — with the margins marked (SVG; never over an
    /// input or the -o file).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// A drive's measured closed speed loop (`rtid import` of its measuring function, a
    /// frequency response with response "speed_loop"): overlaid on the model's with
    /// today's and the proposed settings (FILE-speed-loop.svg beside --plot, and
    /// `measured_speed_loop` in --json), with a warning first where the model does not
    /// explain it.
    #[arg(long, value_name = "SPEED_LOOP.json")]
    pub measured: Option<PathBuf>,
    /// Write the tuned settings as a commented SINAMICS parameter list: p1460
    /// (speed controller gain, N·m·s/rad), p1462 (integral time, ms), the current
    /// setpoint filters p1656-p1676 (docs/drive-settings.md).
    #[arg(long, value_name = "FILE")]
    pub sinamics: Option<PathBuf>,
    /// Write the tuned settings as SINUMERIK machine data: MD32200 Kv in
    /// (m/min)/mm, the gear MD31050/MD31060, the speed feed-forward MD32620/32610/32810
    /// (needs --axis-number; docs/drive-settings.md).
    #[arg(long, value_name = "FILE", requires = "axis_number")]
    pub sinumerik: Option<PathBuf>,
    /// The machine axis of the SINUMERIK data: AX<N>.
    #[arg(long, value_name = "N")]
    pub axis_number: Option<u32>,
    /// The gear as the CNC counts it, MOTOR:LOAD revolutions (e.g. 90:1), where rtid's
    /// Rg·Rw is not a ratio of whole numbers up to 100000.
    #[arg(long, value_name = "MOTOR:LOAD", value_parser = gear_ratio)]
    pub gear_ratio: Option<(u64, u64)>,
    /// No progress bar or notes on stderr.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let plot = outputs(&a)?;
    let mut p = crate::cli::common::model_args::fitted(&a.model, a.fit.as_deref(), None)?;
    if let Some(mode) = a.loop_mode {
        if mode != p.controller.loop_mode && !a.quiet {
            eprintln!(
                "note: --loop {mode} overrides the parameter set's controller.loop ({})",
                p.controller.loop_mode
            );
        }
        p.controller.loop_mode = mode;
    }
    let options = options(&a)?;
    let measured = match &a.measured {
        Some(path) => {
            let m = crate::cli::tune_measured::read(path)?;
            if let Some(w) = crate::cli::tune_measured::check(path, &m, &p)? {
                eprintln!("warning: {w}");
            }
            Some((path, m))
        }
        None => None,
    };
    let bar = crate::cli::common::progress::bar(0, "weighing", a.quiet || a.json);
    let t = tuning::tune(&p, &options, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    let forms = drive_forms(&a, &t.params)?;
    if let Some(out) = &a.out {
        params_file::write(out, &t.params)?;
    }
    for (path, text) in forms {
        rtid::io::atomic::write(&path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if a.plot.is_some() {
        write_plot(&plot, &p, &t)?;
    }
    let overlay = match &measured {
        Some((path, m)) => Some(crate::cli::tune_measured::overlay(
            path, m, &p, &t.params, &plot,
        )?),
        None => None,
    };
    if a.json {
        let mut v = rtid::io::json::value(&t)?;
        if let (Some(o), serde_json::Value::Object(map)) = (&overlay, &mut v) {
            map.insert("measured_speed_loop".into(), rtid::io::json::value(o)?);
        }
        println!("{}", rtid::io::json::pretty(&v)?);
    } else {
        print_table(&p, &t);
        print_check(&p, &t);
        print_warnings(&p, &t);
        if let Some(o) = &overlay {
            crate::cli::tune_measured::print(o);
        }
    }
    Ok(())
}

/// The written files checked against the inputs and each other (none over another),
/// and where the plot goes.
fn outputs(a: &Args) -> anyhow::Result<Plot> {
    let read: Vec<&Path> = a
        .model
        .params
        .iter()
        .chain(&a.fit)
        .map(PathBuf::as_path)
        .collect();
    let mut written: Vec<&Path> = Vec::new();
    for (option, path) in [
        ("-o", &a.out),
        ("--sinamics", &a.sinamics),
        ("--sinumerik", &a.sinumerik),
    ] {
        if let Some(path) = path {
            let mut others = read.clone();
            others.extend(written.iter().copied());
            refuse_overwrite(option, path, &others)?;
            written.push(path);
        }
    }
    match &a.plot {
        Some(path) => {
            let mut inputs = read.clone();
            inputs.extend(a.out.as_deref());
            Plot::at(path.clone(), &inputs)
        }
        None => Ok(Plot::none()),
    }
}

/// The search's targets, objective and limits, the margins checked.
fn options(a: &Args) -> anyhow::Result<Options> {
    if !(a.phase_margin_deg > 0.0 && a.phase_margin_deg < 180.0) {
        bail!(
            "--phase-margin-deg {}: a phase margin lies between 0° and 180°",
            Num(a.phase_margin_deg)
        );
    }
    if !(0.0..=60.0).contains(&a.gain_margin_db) {
        bail!(
            "--gain-margin-db {}: a gain margin target lies in 0..60 dB",
            Num(a.gain_margin_db)
        );
    }
    Ok(Options {
        targets: Targets {
            phase_margin_deg: a.phase_margin_deg,
            gain_margin_db: a.gain_margin_db,
        },
        objective: a.objective,
        limits: Limits {
            max_kpp: a.max_kpp,
            max_bandwidth_hz: a.max_bandwidth_hz,
            notch_depth_db: a.notch_depth_db,
            notch_min_width: a.notch_min_width,
        },
        torque_reserve: a.torque_reserve,
    })
}

/// The open loops before and after: the velocity loop alone and the cascade.
fn write_plot(plot: &Plot, p: &rtid::Params, t: &Tuned) -> anyhow::Result<()> {
    let title = format!(
        "{}: open loops on the sampled loop, opened at the torque setpoint ({} loop)",
        p.name, t.loop_mode
    );
    let curves = [
        ("velocity loop alone, before", bode::bode(p, &t.before)?),
        (
            "velocity loop alone, after",
            bode::bode(&t.params, &t.after)?,
        ),
        ("cascade as it runs, before", bode::cascade(p, &t.before)?),
        (
            "cascade as it runs, after",
            bode::cascade(&t.params, &t.after)?,
        ),
    ];
    let named: Vec<(&str, &bode::Bode)> = curves.iter().map(|(n, b)| (*n, b)).collect();
    let figure = rtid::report::tuning::open_loop(&named, &title);
    plot.write(&figure, "")?;
    Ok(())
}

/// `MOTOR:LOAD` as two whole numbers of revolutions.
fn gear_ratio(s: &str) -> Result<(u64, u64), String> {
    let parse = |x: &str| x.trim().parse::<u64>().ok().filter(|&n| n > 0);
    match s.split_once(':').map(|(m, l)| (parse(m), parse(l))) {
        Some((Some(m), Some(l))) => Ok((m, l)),
        _ => Err(format!(
            "{s:?}: give MOTOR:LOAD revolutions as whole numbers, e.g. 90:1"
        )),
    }
}

/// The drive forms asked for, as (path, text), made before anything is written so
/// that a missing quantity writes nothing.
fn drive_forms(a: &Args, p: &rtid::Params) -> anyhow::Result<Vec<(PathBuf, String)>> {
    use rtid::io::drive_settings::{sinamics, sinumerik, ServoSettings};
    let s = ServoSettings::from_params(p);
    let mut out = Vec::new();
    if let Some(path) = &a.sinamics {
        let text = sinamics::program(&s, &sinamics::SinamicsContext::default())
            .with_context(|| format!("--sinamics {}", path.display()))?;
        out.push((path.clone(), text));
    }
    if let Some(path) = &a.sinumerik {
        let ctx = sinumerik::SinumerikContext {
            axis_number: a.axis_number,
            gear: a.gear_ratio,
            ..Default::default()
        };
        let text = sinumerik::program(&s, &ctx)
            .with_context(|| format!("--sinumerik {}", path.display()))?;
        out.push((path.clone(), text));
    }
    Ok(out)
}

/// The unit of a setting's gains: the output's per rad/s and per rad (N·m for a
/// torque command, N on a linear axis, the drive's unit with a drive gain).
fn gain_units(p: &rtid::Params) -> (&'static str, &'static str) {
    match (p.controller.drive_gain == 1.0, p.axis) {
        (true, Axis::Rotary) => ("N·m·s/rad", "N·m/rad"),
        (true, Axis::Linear) => ("N·s/m", "N/m"),
        (false, Axis::Rotary) => ("output·s/rad", "output/rad"),
        (false, Axis::Linear) => ("output·s/m", "output/m"),
    }
}

fn print_table(p: &rtid::Params, t: &Tuned) {
    println!(
        "{}: {} loop; targets on the cascade as it runs: phase margin ≥ {}°, gain margins ≥ {} dB up and down, no conditional window",
        p.name, t.loop_mode, t.targets.phase_margin_deg, t.targets.gain_margin_db
    );
    let mut table = Table::new();
    table.load_preset(UTF8_FULL_CONDENSED);
    let after = if t.proposes {
        "after"
    } else {
        "after (today's kept)"
    };
    table.set_header(vec!["", "before", after]);
    let (b, a) = (&t.before, &t.after);
    let row = |label: &str, f: &dyn Fn(&Setting) -> String| vec![label.to_string(), f(b), f(a)];
    let (kvp_unit, kvi_unit) = gain_units(p);
    table.add_row(row(&format!("Kvp ({kvp_unit})"), &|s| {
        format!("{:.4e}", s.kvp)
    }));
    table.add_row(row(&format!("Kvi ({kvi_unit})"), &|s| {
        format!("{:.4e}", s.kvi)
    }));
    table.add_row(row("Tn = Kvp/Kvi (ms)", &|s| {
        if s.kvi > 0.0 {
            format!("{:.2}", 1e3 * s.kvp / s.kvi)
        } else {
            "no integral action".into()
        }
    }));
    table.add_row(row("Kpp = Kv (1/s)", &|s| format!("{:.2}", s.kpp)));
    let (kv_unit, kv_per) = match p.axis {
        Axis::Rotary => ("Kv ((rev/min)/rev)", 60.0),
        Axis::Linear => ("Kv ((m/min)/mm)", 0.06),
    };
    table.add_row(row(kv_unit, &|s| format!("{:.3}", s.kpp * kv_per)));
    table.add_row(row("setpoint filters", &|s| filters(s)));
    let velocity = |s: &Setting| s.velocity_loop;
    table.add_row(row("velocity loop alone: crossover", &|s| {
        velocity(s)
            .crossover_hz
            .map_or("none".into(), |f| format!("{f:.1} Hz"))
    }));
    table.add_row(row("  phase margin", &|s| {
        let m = velocity(s);
        at(m.phase_margin_deg.zip(m.phase_margin_hz), "°")
    }));
    table.add_row(row("  gain margin", &|s| {
        let m = velocity(s);
        at(m.gain_margin_db.zip(m.gain_margin_hz), " dB")
    }));
    table.add_row(row("cascade as it runs: stability", &|s| {
        stability(&s.cascade)
    }));
    table.add_row(row("  crossover", &|s| {
        s.cascade
            .margins
            .crossover_hz
            .map_or("none".into(), |f| format!("{f:.1} Hz"))
    }));
    table.add_row(row("  phase margin", &|s| {
        let m = &s.cascade.margins;
        at(m.phase_margin_deg.zip(m.phase_margin_hz), "°")
    }));
    table.add_row(row("  gain margin (increase)", &|s| {
        let m = &s.cascade.margins;
        at(m.gain_margin_db.zip(m.gain_margin_hz), " dB")
    }));
    table.add_row(row("  gain margin (reduction)", &|s| {
        let m = &s.cascade.stability;
        at(
            m.gain_reduction_margin_db.zip(m.gain_reduction_margin_hz),
            " dB",
        )
    }));
    table.add_row(row("position loop: peak", &|s| {
        format!("{:.2} dB", s.position_peak_db)
    }));
    println!("{table}");
    let s = &t.search;
    println!(
        "search ({}): {} settings tried on the cascade, {} within the targets; {} weighed on the nonlinear model (today's among them; {} refused: a limit cycle or the torque reserve), {} checked on the standard cycle; {:.1} s",
        t.objective, s.tried, s.within_margins, s.screened, s.refused, s.checked, s.wall_s
    );
}

/// `stable`, `UNSTABLE`, or the conditional window.
fn stability(m: &LoopMargins) -> String {
    let s = &m.stability;
    match (s.stable, s.conditional_window_db) {
        (false, _) => format!("UNSTABLE (pole at |z| = {:.4})", s.spectral_radius),
        (true, Some([from, to])) => {
            format!("conditionally stable: unstable from +{from:.1} to +{to:.1} dB")
        }
        (true, None) => "stable".into(),
    }
}

/// Both settings on the standard cycle and the servo's responses.
fn print_check(p: &rtid::Params, t: &Tuned) {
    let (before, after) = (&t.check.before, &t.check.after);
    let u = before.servo.unit;
    let effort = if p.axis == Axis::Rotary { "N·m" } else { "N" };
    println!(
        "on the nonlinear model (backlash, friction, quantised encoders, torque limit), {} loop: the ISO 230-2 cycle ({} targets, {} runs) with the compensation built for each setting run in the controller; a {} step and a move {} out and back",
        t.loop_mode,
        before.positioning.targets,
        before.positioning.runs,
        if u == "″" { "1°" } else { "1 mm" },
        if u == "″" { "5° at 10°/s" } else { "5 mm at 10 mm/s" },
    );
    let mut table = Table::new();
    table.load_preset(UTF8_FULL_CONDENSED);
    table.set_header(vec!["", "before", "after"]);
    let fmt = |x: f64| format!("{x:.2}");
    table.add_row(vec![
        format!("ISO 230-2 A uncompensated ({u})"),
        fmt(before.positioning.a_uncompensated),
        fmt(after.positioning.a_uncompensated),
    ]);
    table.add_row(vec![
        format!("ISO 230-2 B̄ uncompensated ({u})"),
        fmt(before.positioning.b_mean_uncompensated),
        fmt(after.positioning.b_mean_uncompensated),
    ]);
    table.add_row(vec![
        format!("ISO 230-2 B̄ after compensation ({u})"),
        fmt(before.positioning.b_mean),
        fmt(after.positioning.b_mean),
    ]);
    for k in objective::ALL {
        let unit = k.unit(u, effort);
        let show = |c: &tuning::Criteria| match (k, c.servo.table_settling_s) {
            (Criterion::TableSettling, None) => "not within 1 s".to_string(),
            (Criterion::TableSettling, Some(s)) => format!("{:.0} ms", s * 1e3),
            _ => fmt(k.value(c)),
        };
        let label = if k == Criterion::TableSettling {
            let gap = if u == "″" { "" } else { " " };
            format!("{} within {}{gap}{u}", k.label(), verify::SETTLED)
        } else {
            format!("{} ({unit})", k.label())
        };
        table.add_row(vec![label, show(before), show(after)]);
    }
    table.add_row(vec![
        format!("step overshoot, motor × ratio (%)"),
        fmt(before.servo.step_overshoot_percent),
        fmt(after.servo.step_overshoot_percent),
    ]);
    table.add_row(vec![
        format!("peak torque, step command ({effort})"),
        fmt(before.servo.peak_effort),
        fmt(after.servo.peak_effort),
    ]);
    println!("{table}");
}

fn print_warnings(p: &rtid::Params, t: &Tuned) {
    let u = t.check.before.servo.unit;
    let effort = if p.axis == Axis::Rotary { "N·m" } else { "N" };
    for w in &t.warnings {
        println!("warning: {}", warning_text(w, t.objective, u, effort));
    }
}

/// A warning as the table prints it.
fn warning_text(
    w: &TuneWarning,
    objective: Objective,
    u: &'static str,
    effort: &'static str,
) -> String {
    match w {
        TuneWarning::Worse(w) => {
            let unit = w.criterion.unit(u, effort);
            format!(
                "{} worse than today's: {:.2} → {:.2} {unit} (+{:.2} {unit})",
                w.criterion.label(),
                w.before,
                w.after,
                w.after - w.before
            )
        }
        TuneWarning::NothingBetter { best_check_score } => format!(
            "no setting within the targets beats today's on the {} objective{}: today's settings are kept",
            objective,
            best_check_score.map_or(String::new(), |s| format!(" (the best checked scores {s:.3} against today's 1)"))
        ),
        TuneWarning::TodayOutsideTargets => {
            "today's cascade does not keep the targets (see its margins)".into()
        }
    }
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
