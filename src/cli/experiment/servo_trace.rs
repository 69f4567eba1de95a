//! `rtid experiment servo-trace` (a virtual trace of the model) and `rtid evaluate` of
//! a servo trace: the friction law by inverse dynamics (IDIM-LS) and, with a model,
//! the trace replayed and the benchmark's simulation error.

use crate::cli::common::plot::Plot;

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use rtid::estimation::inverse_dynamics::{IdimOverrideError, IdimOverrides, IdimSettings};
use rtid::experiments::servo_trace::{
    evaluate, virtual_trace, MoveTo, ServoTrace, TrapezoidalMoves,
};
use rtid::io::experiment_file::{Axis, Data, Experiment};
use rtid::model::Params;
use rtid::report::evaluation::TraceReport;
use rtid::report::servo_trace as figures;

use super::{check, Common};

/// How IDIM-LS treats a servo trace in `rtid evaluate` (defaults: the EMPS
/// benchmark's design carried to the record's sampling rate).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct IdimArgs {
    /// Servo traces (IDIM-LS): cut-off of the zero-phase Butterworth low-pass on the
    /// position before it is differentiated, Hz. Default: a tenth of the sampling rate
    /// (100 Hz at 1 kHz).
    #[arg(long, value_name = "HZ", help_heading = "Servo traces (IDIM-LS)")]
    pub cutoff_hz: Option<f64>,
    /// Servo traces: keep every K-th row after the decimation filter (1: every row, no
    /// decimation filter). Default 10.
    #[arg(long, value_name = "K", help_heading = "Servo traces (IDIM-LS)")]
    pub decimation: Option<usize>,
    /// Servo traces: seconds dropped at each end of the record (the filters' start and
    /// end transients). Default: 200 samples (0.2 s at 1 kHz, 0.8 s at 250 Hz).
    #[arg(long, value_name = "SECONDS", help_heading = "Servo traces (IDIM-LS)")]
    pub trim_s: Option<f64>,
    /// Servo traces: rows whose filtered speed is below this are left out (their
    /// friction's sign is in doubt), rad/s on a rotary axis, m/s on a linear one.
    /// Default 0.001.
    #[arg(long, value_name = "SPEED", help_heading = "Servo traces (IDIM-LS)")]
    pub min_speed: Option<f64>,
}

impl IdimArgs {
    /// The settings for a record sampled every `period_s`: the defaults
    /// ([`IdimSettings::for_sample_period`]) with what was given.
    pub fn settings(&self, period_s: f64) -> anyhow::Result<IdimSettings> {
        let overrides = IdimOverrides {
            cutoff_hz: self.cutoff_hz,
            decimation: self.decimation,
            trim_s: self.trim_s,
            min_speed: self.min_speed,
        };
        overrides.settings(period_s).map_err(|e| match e {
            IdimOverrideError::Negative { name, value } => anyhow::anyhow!(
                "--{} {value}: must be a finite number ≥ 0",
                name.replace('_', "-")
            ),
            IdimOverrideError::Decimation => {
                anyhow::anyhow!("--decimation 0: must be at least 1 (1: no decimation)")
            }
        })
    }
}
use crate::cli::common::progress;

pub const LONG_ABOUT: &str = "\
A servo trace of the model (docs/experiment-files.md, servo_trace): the axis's own sampled \
servo drives it from rest at 0 along point-to-point moves with trapezoidal velocity, and \
the run is recorded at the control period as a drive's oscilloscope would record it — time, \
the position reference, the loop encoder (quantised), the table encoder, the drive's torque \
or force and the controller output. Units follow the axis: degrees and N·m on a rotary one, \
metres and N on a linear one; --moves, --acceleration in rad or m (SI).

The default moves go to +0.1 at 0.2 per s, to −0.1 at 0.1 per s and back to 0 at 0.05 per s, \
accelerating at 2 per s², with 0.2 s dwells (5.5 s): three speeds in both directions, so \
that a friction fit separates viscous from Coulomb friction. Such a trace is unlike the \
torque test's sine: `rtid identify servo_trace.json` fits the axis to it (fm, Cm on a \
geared table; Jt, Ct, ft, Tload on a direct drive, from their IDIM-LS estimate).

Outputs, in --out DIR: servo_trace.json/.csv and the evaluation of `rtid evaluate`: the \
friction law by inverse dynamics and plots of the following error and the force.

Examples:
  rtid experiment servo-trace --preset worm-gear --out runs/worm-trace
  rtid experiment servo-trace --preset direct-drive --moves 0.5@1,-0.5@0.5,0@0.25 --out runs/dd";

/// Arguments of `rtid experiment servo-trace`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// The moves in turn from 0, TARGET@SPEED each (rad and rad/s, or m and m/s):
    /// 0.1@0.2,-0.1@0.1,0@0.05 by default.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "TARGET@SPEED",
        allow_hyphen_values = true
    )]
    pub moves: Vec<String>,
    /// Acceleration and deceleration of every move, rad/s² or m/s².
    #[arg(long, value_name = "PER_S2", default_value_t = 2.0)]
    pub acceleration: f64,
    /// Rest before the first move and after each, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.2)]
    pub dwell_s: f64,
}

/// Parses `TARGET@SPEED`.
fn parse_move(s: &str) -> anyhow::Result<MoveTo> {
    let (target, speed) = s
        .split_once('@')
        .with_context(|| format!("--moves {s}: expected TARGET@SPEED, e.g. 0.1@0.2"))?;
    let num = |t: &str| -> anyhow::Result<f64> {
        match t.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(anyhow::anyhow!("--moves {s}: `{t}` is not a finite number")),
        }
    };
    Ok(MoveTo {
        target: num(target)?,
        speed: num(speed)?,
    })
}

/// The moves the flags describe, checked before anything runs.
fn moves(a: &Args) -> anyhow::Result<TrapezoidalMoves> {
    let mut m = TrapezoidalMoves {
        acceleration: check::positive(a.acceleration, "--acceleration")?,
        dwell_s: check::non_negative(a.dwell_s, "--dwell-s")?,
        ..Default::default()
    };
    if !a.moves.is_empty() {
        m.moves = a
            .moves
            .iter()
            .map(|s| parse_move(s))
            .collect::<anyhow::Result<_>>()?;
    }
    m.check()
        .map_err(|e| anyhow::anyhow!("--moves/--acceleration/--dwell-s: {e}"))?;
    Ok(m)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let m = moves(&a)?;
    check::work(
        m.duration(),
        check::MAX_SIMULATED_S,
        "simulated seconds",
        "--moves, --acceleration, --dwell-s",
    )?;
    a.common.create_out()?;
    let bar = progress::bar(1, "servo trace", a.common.quiet);
    let trace = virtual_trace(&p, &m, None)?;
    bar.finish_and_clear();
    let (manifest, data) = rtid::experiments::servo_trace::to_file(&p, &m, &trace);
    a.common
        .write_and_report("servo_trace", manifest, &data, |exp, plot, json| {
            report(exp, plot, json, None, &IdimArgs::default())
        })
}

/// Evaluates the trace `exp`; replays it on `model` when one is given.
pub fn report(
    exp: &Experiment,
    plot: &Plot,
    json: bool,
    model: Option<Params>,
    idim: &IdimArgs,
) -> anyhow::Result<()> {
    let (Data::ServoTrace(file), Some(trace)) = (&exp.data, ServoTrace::from_experiment(exp))
    else {
        bail!("{}: not a servo trace", exp.path.display());
    };
    let source = exp.path.display().to_string();
    let sample_period_s = trace.check().with_context(|| source.clone())?;
    let settings = idim.settings(sample_period_s)?;
    let e = evaluate(exp, (&trace, file.axis), &settings, model.as_ref())
        .with_context(|| source.clone())?;
    let run = e.replay.as_ref().map(|(run, _)| run);
    plot.write(&figures::following_error(&trace, run, file.axis), "")?;
    plot.write(&figures::effort(&trace, run, file.axis), "-effort")?;
    let report = TraceReport::new(source, file.axis, (trace.len(), sample_period_s), e);
    if json {
        println!("{}", rtid::io::json::pretty(&report)?);
    } else {
        print_report(&report);
    }
    Ok(())
}

fn print_report(r: &TraceReport) {
    let (force, position) = (r.axis.effort_unit(), r.axis.position_unit());
    println!(
        "{}: servo trace, {} axis, {} samples every {:.6} s",
        r.source, r.axis, r.samples, r.sample_period_s
    );
    let f = &r.inverse_dynamics;
    let inertia = match r.axis {
        Axis::Linear => "M (mass), kg",
        Axis::Rotary => "J (inertia), kg·m²",
    };
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let frame = match r.ratio {
        Some(ratio) => format!(
            "at the motor (positions ÷ ratio, 1:{})",
            (1e6 / ratio).round() / 1e6
        ),
        None => "as recorded".to_string(),
    };
    t.set_header([
        format!("F = M·a + Fv·v + Fc·sign(v) + OF (IDIM-LS), {frame}"),
        "value".to_string(),
        "± std. error".to_string(),
    ]);
    for (name, e) in [
        (inertia.to_string(), f.inertia),
        (format!("Fv (viscous), {force}·s/{position}"), f.viscous),
        (format!("Fc (Coulomb), {force}"), f.coulomb),
        (format!("OF (offset = −Tload), {force}"), f.offset),
    ] {
        t.add_row([
            name,
            format!("{:.5}", e.value),
            format!("{:.3}", e.std_error),
        ]);
    }
    println!("{t}");
    if r.ratio.is_none() && r.axis == Axis::Rotary {
        println!(
            "(as recorded: the effort over the loop encoder's position, in the table's frame; \
             on a geared axis these are in neither frame — give conditions.ratio, --preset or \
             --params to have them at the motor)"
        );
    }
    let s = &f.settings;
    println!(
        "IDIM-LS: position low-passed at {:.4} Hz (--cutoff-hz; order {}, zero phase), decimated by {} (--decimation), {} samples ({:.3} s, --trim-s) dropped at each end, {} rows below {} {position}/s left out (--min-speed), {} rows; residual {:.4} {force} RMS; standard errors assume a white residual (lower bounds)",
        s.cutoff_hz,
        s.filter_order,
        s.decimation,
        s.trim,
        s.trim as f64 * f.sample_period_s,
        f.slow_rows,
        rtid::names::Num(s.min_speed),
        f.rows,
        f.residual_rms
    );
    match &r.simulation_error {
        Some(m) => {
            let (scale, unit) = figures::position_unit(r.axis);
            let effort = match r.axis {
                Axis::Linear => "force",
                Axis::Rotary => "torque",
            };
            println!(
                "replayed on the model: position error {:.3} {unit} RMS, {:.3} {unit} max; {effort} error {:.4} {force} RMS",
                m.position_rms * scale,
                m.position_max * scale,
                m.force_rms
            );
        }
        None => println!("(give --params or --preset to replay the trace on a model)"),
    }
}
