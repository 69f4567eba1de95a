//! `rtid tune`: the velocity and position loop gains and notch filters for a target
//! phase margin, from the model's linear response (docs/tuning.md).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::common::inputs::refuse_overwrite;
use crate::cli::common::model_args;
use crate::cli::common::plot::Plot;
use crate::cli::ModelArgs;
use rtid::experiments::positioning::ensemble;
use rtid::io::params_file;
use rtid::model::params::LoopMode;
use rtid::model::Axis;
use rtid::names::Num;
use rtid::tuning::{
    self, bode, objective, verify, Compared, Criterion, Limits, LoopMargins, Objective, Options,
    Range, Setting, Targets, TuneWarning, Tuned, Vary, Verdict,
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

The settings must hold on the machine as it may be. By default that is the machine as \
the data leave it: each parameter the fit (FIT.json) determined over its interval, each \
held range it carried, and the parameter set's own held ranges (a preset's uncertain \
values, `rtid params`) — the four that move today's margins most, by 0.5° or 0.5 dB at \
least; the others (a backlash, a Coulomb friction) are listed above the table, held at \
their values, with the reason. --vary and --delay-periods give a range of one's own, \
--nominal the nominal machine alone.

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
  rtid tune --preset direct-drive --vary Jt=1..3 --delay-periods 1   (a range of one's own)

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
    /// A parameter of the machine as it may be, as ratios of its value (repeatable):
    /// the targets must hold at the range's corners and worst case, e.g. Jt=0.5..2
    /// for a table loaded from half to twice the model's inertia.
    #[arg(long = "vary", value_name = "NAME=LOW..HIGH", value_parser = vary)]
    pub vary: Vec<Vary>,
    /// Control periods of delay the loop may have beyond the model's (0 to N, added
    /// to the encoder's dead time): the targets must hold with each.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub delay_periods: u32,
    /// Tune for the nominal machine alone. Without --vary, --delay-periods or this, the
    /// range is the fit's intervals and the parameter set's held ranges (a preset's
    /// uncertain values), the four that move today's margins most.
    #[arg(long, conflicts_with_all = ["vary", "delay_periods"])]
    pub nominal: bool,
    /// Runs in each ensemble the check weighs a setting by (1 to 256): the standard
    /// ISO 230-2 cycle and the servo's step and move, perturbed by sub-count offsets
    /// that do not change the machine.
    #[arg(long, value_name = "N", default_value_t = ensemble::DEFAULT_MEMBERS)]
    pub ensemble: usize,
    /// Print JSON (targets, resonances, before, after, search, check, warnings)
    /// instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Write the tuned parameter file.
    #[arg(short = 'o', long = "out", value_name = "tuned.json")]
    pub out: Option<PathBuf>,
    /// Write the open loops' Bode plot — the velocity loop alone and the cascade as
    /// it runs, before and after tuning — with the margins marked (SVG; never over an
    /// input or the -o file), and beside it (FILE-closed.svg) the loops closed: the
    /// speed and position loops' gains and the cascade's sensitivity |S|.
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
    let mut p = a.model.load()?;
    let fit = match &a.fit {
        Some(path) => {
            let fit = model_args::read_fit(path)?;
            model_args::apply_fit(&mut p, &fit, path)?;
            Some(fit)
        }
        None => None,
    };
    if let Some(mode) = a.loop_mode {
        if mode != p.controller.loop_mode && !a.quiet {
            eprintln!(
                "note: --loop {mode} overrides the parameter set's controller.loop ({})",
                p.controller.loop_mode
            );
        }
        p.controller.loop_mode = mode;
    }
    let options = options(&a, &p, fit.as_ref())?;
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
    let forms = drive_forms(&a, &t)?;
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

/// The search's targets, objective, limits, range and ensemble (the library checks
/// the range against `p` and the ensemble's size).
fn options(
    a: &Args,
    p: &rtid::Params,
    fit: Option<&rtid::identify::IdentifyResult>,
) -> anyhow::Result<Options> {
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
        range: range(a, p, fit),
        ensemble: ensemble::Ensemble {
            members: a.ensemble,
        },
    })
}

/// The range of machines ([`tuning::range::default::asked`]).
fn range(a: &Args, p: &rtid::Params, fit: Option<&rtid::identify::IdentifyResult>) -> Range {
    let f = fit.map(|f| f.spreads()).unwrap_or_default();
    let (vary, delay) = (a.vary.clone(), a.delay_periods);
    tuning::range::default::asked(vary, delay, a.nominal, p, (&f.spreads, &f.without))
}

/// `NAME=LOW..HIGH`: a parameter's ratios.
fn vary(s: &str) -> Result<Vary, String> {
    let bad =
        || format!("{s:?}: give NAME=LOW..HIGH, ratios of the parameter's value, e.g. Jt=0.5..2");
    let (name, ratios) = s.split_once('=').ok_or_else(bad)?;
    let (low, high) = ratios.split_once("..").ok_or_else(bad)?;
    let number = |x: &str| x.trim().parse::<f64>().map_err(|_| bad());
    Ok(Vary {
        name: name.trim().to_string(),
        low: number(low)?,
        high: number(high)?,
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
    let (before, after) = (
        bode::closed(p, &t.before)?,
        bode::closed(&t.params, &t.after)?,
    );
    let title = format!("{}: the loops closed ({} loop)", p.name, t.loop_mode);
    let figure =
        rtid::report::tuning::closed_loops(&[("before", &before), ("after", &after)], &title);
    plot.write(&figure, "-closed")?;
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
fn drive_forms(a: &Args, t: &Tuned) -> anyhow::Result<Vec<(PathBuf, String)>> {
    use rtid::io::drive_settings::{sinamics, sinumerik, ServoSettings};
    let s = ServoSettings {
        equivalent_time_s: t.after.closed_loop.equivalent_time_s,
        speed_bandwidth_hz: t.after.closed_loop.speed_bandwidth_hz,
        ..ServoSettings::from_params(&t.params)
    };
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
    print_range(&t.range);
    let mut table = Table::new();
    table.load_preset(UTF8_FULL_CONDENSED);
    let after = if t.proposes {
        "after"
    } else {
        "after (today's kept)"
    };
    table.set_header(vec!["", "before", after]);
    add_gain_rows(&mut table, p, t);
    add_margin_rows(&mut table, t);
    add_closed_loop_rows(&mut table, t);
    if let (Some(_), Some(_)) = (&t.before.over_range, &t.after.over_range) {
        add_range_rows(&mut table, t);
    }
    println!("{table}");
    print_search(t);
}

/// Where a default range's quantities come from, and those left at their values.
fn print_range(r: &Range) {
    if r.origins.is_empty() {
        return;
    }
    println!("the range (the fit's intervals and the held ranges; --vary or --nominal to choose):");
    for o in &r.origins {
        let s = &o.spread;
        match &o.left_out {
            None => println!(
                "  {} ×{}…{}: {}; {}",
                s.name,
                Num(tuning::range::round4(s.low)),
                Num(tuning::range::round4(s.high)),
                s.from,
                o.effect
                    .map_or("today's loop is unstable: kept unranked".into(), |e| {
                        format!("moves today's margins by {e:.1}° / dB")
                    })
            ),
            Some(why) => println!("  {} held at its value: {why}", s.name),
        }
    }
}

/// A row of the table: `label`, then `f` of today's setting and of the proposed one.
fn row(t: &Tuned, label: &str, f: &dyn Fn(&Setting) -> String) -> Vec<String> {
    vec![label.to_string(), f(&t.before), f(&t.after)]
}

/// The gains in rtid's and the CNC's units, and the setpoint filters.
fn add_gain_rows(table: &mut Table, p: &rtid::Params, t: &Tuned) {
    let row = |label: &str, f: &dyn Fn(&Setting) -> String| row(t, label, f);
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
}

/// The velocity loop's and the cascade's margins.
fn add_margin_rows(table: &mut Table, t: &Tuned) {
    let row = |label: &str, f: &dyn Fn(&Setting) -> String| row(t, label, f);
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
}

/// The closed loops: peaks, bandwidths, MD32810's time constant, |S|max.
fn add_closed_loop_rows(table: &mut Table, t: &Tuned) {
    let row = |label: &str, f: &dyn Fn(&Setting) -> String| row(t, label, f);
    table.add_row(row("position loop: peak", &|s| {
        format!("{:.2} dB", s.position_peak_db)
    }));
    let bandwidth = |f: Option<f64>, peak: f64| {
        format!(
            "{}, peak {peak:+.2} dB",
            f.map_or("none below Nyquist".into(), |f| format!("{f:.1} Hz"))
        )
    };
    table.add_row(row("closed speed loop: −3 dB bandwidth", &|s| {
        bandwidth(
            s.closed_loop.speed_bandwidth_hz,
            s.closed_loop.speed_peak_db,
        )
    }));
    table.add_row(row("  equivalent time constant (MD32810)", &|s| {
        s.closed_loop
            .equivalent_time_s
            .map_or("none".into(), |t| format!("{:.3} ms", 1e3 * t))
    }));
    table.add_row(row("closed position loop: −3 dB bandwidth", &|s| {
        bandwidth(
            s.closed_loop.position_bandwidth_hz,
            s.closed_loop.position_peak_db,
        )
    }));
    table.add_row(row("sensitivity |S|max", &|s| {
        let c = &s.closed_loop;
        format!(
            "{:.2} dB at {:.1} Hz",
            c.sensitivity_peak_db, c.sensitivity_peak_hz
        )
    }));
}

/// What the search did, in one line.
fn print_search(t: &Tuned) {
    let s = &t.search;
    let machines = if s.machines > 1 {
        format!(" at each of {} machines of the range", s.machines)
    } else {
        String::new()
    };
    let corners = if s.corners > 0 {
        format!(", at the range's {} corners too", s.corners)
    } else {
        String::new()
    };
    println!(
        "search ({}): {} settings tried on the cascade, {} within the targets{machines}; {} weighed on the nonlinear model (today's among them{corners}; {} refused: a limit cycle or the torque reserve), {} checked with today's on the standard cycle as ensembles of {}; {:.1} s",
        t.objective, s.tried, s.within_margins, s.screened, s.refused, s.checked, s.members, s.wall_s
    );
}

/// The worst case of both settings over the range.
fn add_range_rows(table: &mut Table, t: &Tuned) {
    let worst = |s: &Setting| s.over_range.clone().expect("over a range");
    let (b, a) = (worst(&t.before), worst(&t.after));
    let at = |m: &Option<(f64, String)>, unit: &str| {
        m.as_ref()
            .map_or("none".into(), |(v, w)| format!("{v:.1}{unit} at {w}"))
    };
    let mut row = |label: String, f: &dyn Fn(&tuning::range::OverRange) -> String| {
        table.add_row(vec![label, f(&b), f(&a)]);
    };
    row(
        format!(
            "over the range ({}; {} machines): worst phase margin",
            t.range.summary(),
            b.points
        ),
        &|w| at(&w.phase_margin_deg, "°"),
    );
    row("  worst gain margin (increase)".into(), &|w| {
        at(&w.gain_margin_db, " dB")
    });
    row("  worst gain margin (reduction)".into(), &|w| {
        at(&w.gain_reduction_margin_db, " dB")
    });
    row("  unstable or conditionally stable at".into(), &|w| {
        let all: Vec<String> = w
            .unstable_at
            .iter()
            .map(|x| format!("unstable at {x}"))
            .chain(
                w.conditional_at
                    .iter()
                    .map(|x| format!("conditional at {x}")),
            )
            .collect();
        if all.is_empty() {
            "none".into()
        } else {
            all.join("\n")
        }
    });
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

/// Both settings on the standard cycle and the servo's responses, as ensembles: each
/// figure's mean ± standard deviation over the members, and the paired difference
/// with the half-width of its 95 % interval and the verdict.
fn print_check(p: &rtid::Params, t: &Tuned) {
    let (before, after) = (&t.check.before, &t.check.after);
    let (Some(b0), Some(a0)) = (before.members.first(), after.members.first()) else {
        return;
    };
    let u = b0.servo.unit;
    let effort = if p.axis == Axis::Rotary { "N·m" } else { "N" };
    println!(
        "on the nonlinear model (backlash, friction, quantised encoders, torque limit), {} loop: the ISO 230-2 cycle ({} targets, {} runs) with the compensation built for each setting (from its first cycle) run in the controller, a {} step read at the table on the axis so compensated, and a move {} out and back; each an ensemble of {} runs (sub-count offsets of the compensation and of the rest position), mean ± standard deviation, the difference paired run by run ± the half-width of its 95 % interval",
        t.loop_mode,
        b0.positioning.targets,
        b0.positioning.runs,
        if u == "″" { "1°" } else { "1 mm" },
        if u == "″" { "5° at 10°/s" } else { "5 mm at 10 mm/s" },
        t.check.ensemble.members,
    );
    let mut table = Table::new();
    table.load_preset(UTF8_FULL_CONDENSED);
    table.set_header(vec!["", "before", "after", "after − before"]);
    let fmt = |x: f64| format!("{x:.2}");
    let first = |label: String, f: &dyn Fn(&tuning::Criteria) -> f64| {
        vec![
            label,
            fmt(f(b0)),
            fmt(f(a0)),
            "(first cycle: one run)".into(),
        ]
    };
    table.add_row(first(format!("ISO 230-2 A uncompensated ({u})"), &|c| {
        c.positioning.a_uncompensated
    }));
    table.add_row(first(format!("ISO 230-2 B̄ uncompensated ({u})"), &|c| {
        c.positioning.b_mean_uncompensated
    }));
    let spread = |c: &tuning::Checked, f: &dyn Fn(&tuning::Criteria) -> f64| {
        ensemble::Spread::of(&c.members.iter().map(f).collect::<Vec<_>>())
    };
    let b_mean = |c: &tuning::Checked| spread(c, &|m| m.positioning.b_mean);
    table.add_row(vec![
        format!("ISO 230-2 B̄ after compensation ({u})"),
        with_sd(&b_mean(before)),
        with_sd(&b_mean(after)),
        String::new(),
    ]);
    for k in objective::ALL {
        let unit = k.unit(u, effort);
        let label = if k == Criterion::TableSettling {
            let gap = if u == "″" { "" } else { " " };
            format!("{} within {}{gap}{u} (s)", k.label(), verify::SETTLED)
        } else {
            format!("{} ({unit})", k.label())
        };
        let c = t.check.judgement.of(k);
        table.add_row(vec![
            label,
            with_sd(&c.before),
            with_sd(&c.after),
            difference(c),
        ]);
    }
    let score = &t.check.judgement.score;
    table.add_row(vec![
        format!("score, {} objective (today's 1)", t.objective),
        with_sd(&score.before),
        with_sd(&score.after),
        difference(score),
    ]);
    table.add_row(vec![
        "step overshoot, motor × ratio (%)".into(),
        fmt(b0.servo.step_overshoot_percent),
        fmt(a0.servo.step_overshoot_percent),
        "(unperturbed run)".into(),
    ]);
    table.add_row(vec![
        format!("peak torque, step command ({effort})"),
        fmt(b0.servo.peak_effort),
        fmt(a0.servo.peak_effort),
        "(unperturbed run)".into(),
    ]);
    println!("{table}");
}

/// `3.52 ± 0.33`.
fn with_sd(s: &ensemble::Spread) -> String {
    format!("{:.2} ± {:.2}", s.mean, s.sd)
}

/// `−0.74 ± 0.45: better`.
fn difference(c: &Compared) -> String {
    let verdict = match c.verdict {
        Verdict::Better => "better",
        Verdict::Worse => "worse",
        Verdict::NoDifferent => "no different (within the spread)",
    };
    format!("{:+.2} ± {:.2}: {verdict}", c.difference, c.half_width)
}

fn print_warnings(p: &rtid::Params, t: &Tuned) {
    let u = rtid::experiments::positioning::iso230::ReportUnits::of(p.axis).deviation;
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
        TuneWarning::NothingBetter {
            best_check_score,
            half_width,
        } => format!(
            "no setting within the targets beats today's on the {} objective beyond the spread of its ensemble{}: today's settings are kept",
            objective,
            best_check_score.zip(*half_width).map_or(String::new(), |(s, h)| format!(
                " (the best checked scores {s:.3} ± {h:.3} against today's 1)"
            ))
        ),
        TuneWarning::TodayOutsideTargets { replaced: true } => {
            "today's cascade does not keep the targets (see its margins): it is replaced by the best setting that does".into()
        }
        TuneWarning::TodayOutsideTargets { replaced: false } => {
            "today's cascade does not keep the targets (see its margins), and no setting that does could be checked".into()
        }
        TuneWarning::TorqueLimit {
            setting,
            test,
            peak,
            limit,
        } => format!(
            "{setting}: the {test} reaches the torque limit ({peak:.3} of {limit:.3} {effort}): the output saturates"
        ),
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
