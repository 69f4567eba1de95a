//! `rtid evaluate` of a servo trace: the friction law by inverse dynamics (IDIM-LS)
//! and, with a model, the trace replayed and the benchmark's simulation error.

use std::path::Path;

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use serde::Serialize;

use rtid::experiments::inverse_dynamics::{IdimFit, IdimSettings};
use rtid::experiments::servo_trace::{replay, simulation_error, Misfit, ServoTrace};
use rtid::io::experiment_file::{Axis, Data, Experiment};
use rtid::model::Params;
use rtid::report::servo_trace as figures;

/// What the evaluation of a trace reports (SI units).
#[derive(Serialize)]
struct TraceReport {
    kind: &'static str,
    source: String,
    axis: Axis,
    samples: usize,
    sample_period_s: f64,
    /// M, Fv, Fc, OF of F = M·a + Fv·v + Fc·sign(v) + OF (OF = −Tload).
    inverse_dynamics: IdimFit,
    /// The trace replayed on `--preset`/`--params`: position in m or rad, force in N
    /// or N·m.
    simulation_error: Option<Misfit>,
}

/// Evaluates the trace `exp`; replays it on `model` when one is given.
pub fn report(
    exp: &Experiment,
    plot: &Path,
    json: bool,
    model: Option<Params>,
) -> anyhow::Result<()> {
    let Data::ServoTrace(file) = &exp.data else {
        bail!("{}: not a servo trace", exp.path.display());
    };
    let source = exp.path.display().to_string();
    let trace = ServoTrace::from_file(file);
    let sample_period_s = trace.check().with_context(|| source.clone())?;
    let fit = trace
        .fit_friction(&IdimSettings::for_sample_period(sample_period_s))
        .with_context(|| format!("{source}: inverse dynamics"))?;
    let run = match &model {
        Some(p) => Some(replayed(p, &trace, file.axis, &source)?),
        None => None,
    };
    let misfit = match &run {
        Some(r) => Some(simulation_error(&trace, r).with_context(|| source.clone())?),
        None => None,
    };
    figures::following_error(&trace, run.as_ref(), file.axis).write(plot)?;
    let stem = plot.file_stem().unwrap_or_default().to_string_lossy();
    figures::effort(&trace, run.as_ref(), file.axis)
        .write(&plot.with_file_name(format!("{stem}-effort.svg")))?;
    let report = TraceReport {
        kind: "servo_trace",
        source,
        axis: file.axis,
        samples: trace.len(),
        sample_period_s,
        inverse_dynamics: fit,
        simulation_error: misfit,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report);
    }
    Ok(())
}

/// The trace replayed on `p`, which must be of the trace's axis.
fn replayed(
    p: &Params,
    trace: &ServoTrace,
    axis: Axis,
    source: &str,
) -> anyhow::Result<rtid::experiments::servo_trace::Replay> {
    if p.axis != axis {
        bail!(
            "{source}: the trace is of a {axis} axis, the parameters (--preset/--params) of a {} one",
            p.axis
        );
    }
    replay(p, trace).with_context(|| format!("{source}: replay"))
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
    t.set_header([
        "F = M·a + Fv·v + Fc·sign(v) + OF (IDIM-LS)",
        "value",
        "± std. error",
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
    println!(
        "IDIM-LS: position low-passed at {} Hz (order {}, zero phase), decimated by {}, {} rows, residual {:.4} {force} RMS; standard errors assume a white residual (lower bounds)",
        f.settings.cutoff_hz, f.settings.filter_order, f.settings.decimation, f.rows, f.residual_rms
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
