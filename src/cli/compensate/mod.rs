//! `rtid compensate`: the backlash and error table of an axis from its ISO 230-2
//! positioning record (or an identified model's virtual one: [`model`]), checked on
//! the runs it was not built from, written as compensation.json, a SINUMERIK program
//! and a CSV.

mod model;
mod sinumerik;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::common::inputs::refuse_overwrite;
use crate::cli::ModelArgs;
use rtid::controller::FrictionCompensation;
use rtid::experiments::friction_map;
use rtid::experiments::positioning::compensate::{self, BeforeAfter, Computed, Runs};
use rtid::experiments::positioning::iso230::{AxisStats, ReportUnits};
use rtid::experiments::positioning::{self};
use rtid::io::compensation_file::{self, table_csv, CompensationFile, Source};
use rtid::io::experiment_file::{self, Experiment};
use rtid::model::Axis;

pub const LONG_ABOUT: &str = "\
The compensation of an axis from its ISO 230-2 positioning record (docs/compensation.md): \
an error table of −x̄↑ at each target (the mean deviation approaching upwards, with its sign \
turned) and a backlash of the mean reversal value B̄ = mean(x̄↑ − x̄↓), each added to the \
commanded position (the backlash while moving down), which cancel the record's mean \
deviations in both directions up to the target-to-target scatter of the reversal. On a \
rotary axis whose targets lie within one turn the table is modulo 360°.

With --runs the compensation is built from those runs and checked on the others: the \
ISO 230-2 values before and after are printed for both, and a warning says so when it \
does not lower the systematic deviation E of the runs it was not built from (an axis that \
drifts between runs, warming up): a table that only fits the runs it came from is no \
compensation. Warnings also say when it makes their accuracy A or repeatability R worse. \
Without --runs every run builds it, and nothing checks it.

Outputs, each only when asked and never over an input, written atomically:
  -o compensation.json   positions and values in degrees (mm on a linear axis)
  --sinumerik FILE --axis-number N   a SINUMERIK EEC program ($AA_ENC_COMP…, values the \
axis's error: the opposite sign), resampled onto equidistant points, modulo 360° on a \
rotary table, shifted to be zero at the reference point (--reference-deg or \
--reference-mm; default the table's first point: the shift is printed); the backlash \
for MD32450 in a comment
  --csv FILE             position_deg,value_arcsec (position_mm,value_um)

Examples:
  rtid experiment positioning --preset worm-gear --noise-arcsec 0.3 --seed 1 --out runs/worm
  rtid compensate runs/worm/positioning.json --runs 1-3 -o runs/worm/compensation.json
  rtid evaluate runs/worm/positioning.json --runs 4-5 --compensation runs/worm/compensation.json
  rtid compensate runs/worm/positioning.json --sinumerik AX4_EEC.SPF --axis-number 4 --csv table.csv

With --friction-map MAP.json the file also holds a friction compensation: the symmetric \
law the map determines (Coulomb, viscous, a Stribeck rise where the map shows one, the \
offset), at the motor, fed forward on the commanded speed (docs/compensation.md):
  rtid compensate runs/worm/positioning.json --friction-map runs/worm/friction_map.json -o c.json

From an identification instead of a record: --fit FIT.json with the base it started from \
(--preset or --params) runs the identified model's own ISO 230-2 cycle (5 runs, no noise) \
and builds the compensation from it — the reversal the meshes' play, the elastic lost \
motion and the friction make together, not the play alone. --friction adds the friction \
law of the model's steady map at the motor; --tune FILE uses a tuned controller (a \
compensation holds for the servo settings it was made with). `rtid predict` then gives \
its effect with the fit's uncertainty:
  rtid compensate --fit fit.json --preset worm-gear --friction -o compensation.json
  rtid predict fit.json --preset worm-gear --compensation compensation.json";

/// Arguments of `rtid compensate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The positioning record (experiment manifest); without it, the model's own
    /// virtual positioning test (--fit with --preset or --params).
    #[arg(value_name = "POSITIONING.json", required_unless_present_any = ["fit", "preset", "params"])]
    pub file: Option<PathBuf>,
    /// An identification result (`rtid identify --out`): its values set in the model
    /// (--preset or --params, the base it started from), whose virtual positioning test
    /// gives the compensation.
    #[arg(long, value_name = "FIT.json", conflicts_with = "file")]
    pub fit: Option<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    /// With a model: the controller settings of this tuned parameter file (`rtid tune
    /// -o`) — a compensation holds for the servo settings it was made with.
    #[arg(long, value_name = "FILE", conflicts_with = "file")]
    pub tune: Option<PathBuf>,
    /// With a model: add the friction compensation its steady friction map gives (the
    /// symmetric law at the motor).
    #[arg(long, conflicts_with_all = ["file", "friction_map"])]
    pub friction: bool,
    /// Build from these runs (`1-3`, `2`); the others check it [default: all].
    #[arg(long, value_name = "FIRST-LAST")]
    pub runs: Option<Runs>,
    /// Write the compensation file.
    #[arg(short = 'o', long = "out", value_name = "compensation.json")]
    pub out: Option<PathBuf>,
    /// Write a SINUMERIK encoder/leadscrew error compensation program (needs --axis-number).
    #[arg(long, value_name = "FILE", requires = "axis_number")]
    pub sinumerik: Option<PathBuf>,
    /// The machine axis of the SINUMERIK program: AX<N>.
    #[arg(long, value_name = "N")]
    pub axis_number: Option<u32>,
    /// Rotary axis: the reference point of the SINUMERIK program, degrees; its table
    /// is shifted to be zero there [default: the table's first point].
    #[arg(
        long,
        value_name = "DEG",
        requires = "sinumerik",
        conflicts_with = "reference_mm",
        allow_negative_numbers = true
    )]
    pub reference_deg: Option<f64>,
    /// Linear axis: the reference point of the SINUMERIK program, mm; its table is
    /// shifted to be zero there [default: the table's first point].
    #[arg(
        long,
        value_name = "MM",
        requires = "sinumerik",
        allow_negative_numbers = true
    )]
    pub reference_mm: Option<f64>,
    /// Write the table as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// Add a friction compensation: the symmetric law (Coulomb, viscous, Stribeck,
    /// offset) this friction map determines, at the motor. Refused where the map does
    /// not determine one.
    #[arg(long, value_name = "MAP.json")]
    pub friction_map: Option<PathBuf>,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No notes on stderr.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let origin = origin(&a)?;
    let outputs = outputs(&a, &origin.inputs)?;
    let mut computed = compensate::compute(&origin.measurements, origin.axis, a.runs.as_ref())
        .with_context(|| origin.name.clone())?;
    if let Some(map) = &a.friction_map {
        computed.compensation.friction = Some(friction_of(map, origin.axis)?);
    }
    if let Some(p) = origin.model.as_ref().filter(|_| a.friction) {
        computed.compensation.friction = Some(model::friction(p, &origin.name)?);
    }
    let zeroed = sinumerik::table(&a, &computed)?;
    write_outputs(&a, &origin, &computed, zeroed.as_ref(), &outputs)?;
    if a.json {
        print_json(&origin, &computed, zeroed.as_ref())
    } else {
        print_tables(&origin, &computed, zeroed.as_ref());
        Ok(())
    }
}

/// Where the readings come from: a record, or the model's virtual test.
pub(crate) struct Origin {
    /// The record, or the model, in messages and the file's source.
    name: String,
    /// The files read (no output may overwrite them).
    inputs: Vec<PathBuf>,
    measurements: Vec<positioning::iso230::Measurement>,
    axis: Axis,
    /// The model, where it is the origin.
    model: Option<rtid::model::Params>,
    /// `--runs` as given.
    runs: Option<Runs>,
}

fn origin(a: &Args) -> anyhow::Result<Origin> {
    if let Some(file) = &a.file {
        if a.model.given() || !a.model.set.is_empty() {
            bail!("--preset, --params and --set describe a model: give a positioning record or a model (--fit with --preset/--params), not both");
        }
        let exp = experiment_file::read(file)?;
        let (measurements, axis) = record(&exp)?;
        let mut inputs = vec![file.clone()];
        inputs.extend(exp.data_path.clone());
        return Ok(Origin {
            name: file.display().to_string(),
            inputs,
            measurements,
            axis,
            model: None,
            runs: a.runs.clone(),
        });
    }
    let p = model::params(a)?;
    let measurements = model::record(&p, a.quiet || a.json)?;
    let inputs = a
        .fit
        .iter()
        .chain(&a.model.params)
        .chain(&a.tune)
        .cloned()
        .collect();
    Ok(Origin {
        name: model::name(a),
        inputs,
        measurements,
        axis: p.axis,
        model: Some(p),
        runs: a.runs.clone(),
    })
}

/// The friction compensation a friction map determines: the symmetric law of its
/// selected family, if determined, on the positioning record's axis.
fn friction_of(path: &Path, axis: Axis) -> anyhow::Result<FrictionCompensation> {
    let exp = experiment_file::read(path)?;
    friction_map::compensation::of_experiment(&exp, axis)
        .with_context(|| format!("--friction-map {}", path.display()))
}

/// The outputs asked for, each refused over an input or over another output.
fn outputs(a: &Args, inputs: &[PathBuf]) -> anyhow::Result<Vec<(&'static str, PathBuf)>> {
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let asked = [
        ("-o", a.out.as_ref()),
        ("--sinumerik", a.sinumerik.as_ref()),
        ("--csv", a.csv.as_ref()),
    ];
    let mut outs: Vec<(&'static str, PathBuf)> = Vec::new();
    for (option, path) in asked {
        let Some(path) = path else { continue };
        refuse_overwrite(option, path, &inputs)?;
        let before: Vec<&Path> = outs.iter().map(|o| o.1.as_path()).collect();
        refuse_overwrite(option, path, &before)?;
        outs.push((option, path.clone()));
    }
    Ok(outs)
}

/// The measurements (SI) and the axis of a positioning record.
pub fn record(exp: &Experiment) -> anyhow::Result<(Vec<positioning::iso230::Measurement>, Axis)> {
    let Some(m) = positioning::from_data(&exp.data) else {
        bail!(
            "{}: a `{}` experiment, not a positioning record",
            exp.path.display(),
            exp.manifest.kind.name()
        );
    };
    Ok((m, exp.data.axis().unwrap_or_default()))
}

fn write_outputs(
    a: &Args,
    o: &Origin,
    c: &Computed,
    zeroed: Option<&sinumerik::Zeroed>,
    outputs: &[(&'static str, PathBuf)],
) -> anyhow::Result<()> {
    for (option, path) in outputs {
        match (*option, zeroed) {
            ("-o", _) => compensation_file::write(path, &file_of(a, o, c))?,
            ("--sinumerik", z) => {
                let z = z.context("the SINUMERIK table was not computed")?;
                let text = sinumerik::program(a, o, c, z)?;
                compensation_file::sinumerik::write(path, &text)?;
            }
            _ => {
                let table = table_of(c)?;
                let text = table_csv::text(table, c.axis, c.compensation.backlash);
                table_csv::write(path, &text).with_context(|| path.display().to_string())?;
            }
        }
        if !a.quiet && !a.json {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

pub(crate) fn table_of(c: &Computed) -> anyhow::Result<&rtid::controller::ErrorTable> {
    c.compensation
        .table
        .as_ref()
        .context("the compensation has no table")
}

fn file_of(a: &Args, o: &Origin, c: &Computed) -> CompensationFile {
    CompensationFile {
        axis: c.axis,
        compensation: c.compensation.clone(),
        source: std::iter::once(Source {
            file: o.name.clone(),
            runs: o.runs.as_ref().map(Runs::to_string),
            model: o
                .model
                .as_ref()
                .map(|_| compensation_file::MODEL_SOURCE.to_string()),
        })
        .chain(a.friction_map.iter().map(|m| Source {
            file: m.display().to_string(),
            runs: None,
            model: None,
        }))
        .collect(),
    }
}

fn print_json(o: &Origin, c: &Computed, zeroed: Option<&sinumerik::Zeroed>) -> anyhow::Result<()> {
    let sinumerik = zeroed.map(|z| sinumerik::json(z, c.axis)).transpose()?;
    let value = rtid::report::compensation::compensation(&o.name, c, sinumerik)?;
    println!("{}", rtid::io::json::pretty(&value)?);
    Ok(())
}

/// The friction compensation in words.
fn friction_text(f: &FrictionCompensation, axis: Axis) -> String {
    let (effort, speed) = compensation_file::friction_units(axis);
    let rise = f.law.rise.map_or(String::new(), |r| {
        format!(
            ", Stribeck rise {:.4} {effort} at {:.4} {speed} (shape {:.2})",
            r.rise, r.speed, r.shape
        )
    });
    format!(
        "friction (at the motor, on the commanded speed) = {:.4} {effort} + {:.4e} {effort} per {speed}{rise}, offset {:.4} {effort}",
        f.law.coulomb, f.law.viscous, f.offset
    )
}

fn print_tables(o: &Origin, c: &Computed, zeroed: Option<&sinumerik::Zeroed>) {
    let u = ReportUnits::of(c.axis);
    let (k, d) = (u.deviation_per_si, u.deviation);
    println!(
        "{}: compensation from runs {} ({}), each value added to the commanded position",
        o.name,
        runs_text(&c.build_runs),
        u.deviation_name
    );
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        format!("target {}", u.target),
        format!("x̄↑ {d}"),
        format!("x̄↓ {d}"),
        format!("table {d}"),
        format!("reversal Bi {d}"),
    ]);
    for r in &c.targets {
        t.add_row([
            format!("{:.2}", r.target * u.target_per_si),
            format!("{:.2}", r.mean_up * k),
            format!("{:.2}", r.mean_down * k),
            format!("{:.2}", r.table * k),
            format!("{:.2}", r.reversal * k),
        ]);
    }
    println!("{t}");
    let b = c.compensation.backlash.unwrap_or(0.0) * k;
    println!("backlash (added while moving down) = B̄ = {b:.2}{d}");
    if let Some(f) = &c.compensation.friction {
        println!("{}", friction_text(f, c.axis));
    }
    println!(
        "{}",
        before_after_table(
            &c.build,
            &format!("runs {} (built from)", runs_text(&c.build_runs)),
            k,
            d
        )
    );
    if let Some(check) = &c.check {
        let title = format!("runs {} (check)", runs_text(&c.check_runs));
        println!("{}", before_after_table(check, &title, k, d));
    }
    if let Some(z) = zeroed {
        println!("{}", sinumerik::summary(z, c.axis));
    }
    for w in &c.warnings {
        println!("warning: {}", w.message(k, d));
    }
}

/// Runs as text: `1-3` when consecutive, else listed.
fn runs_text(runs: &[u32]) -> String {
    match (runs.first(), runs.last()) {
        (Some(&a), Some(&b)) if (b - a) as usize + 1 == runs.len() && a != b => format!("{a}-{b}"),
        _ => runs
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// One of the axis values.
type AxisValue = fn(&AxisStats) -> f64;

/// The ISO 230-2 axis values of some runs before, with the backlash alone, and after.
fn before_after_table(b: &BeforeAfter, title: &str, k: f64, d: &str) -> Table {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        format!("{title}, {d}"),
        "uncompensated".into(),
        "backlash only".into(),
        "compensated".into(),
    ]);
    let rows: [(&str, AxisValue); 5] = [
        ("mean reversal B̄", |x| x.b_mean),
        ("reversal B", |x| x.b),
        ("systematic deviation E", |x| x.e),
        ("repeatability R", |x| x.r),
        ("accuracy A", |x| x.a),
    ];
    for (name, f) in rows {
        t.add_row([
            name.to_string(),
            format!("{:.2}", f(&b.before) * k),
            format!("{:.2}", f(&b.backlash_only) * k),
            format!("{:.2}", f(&b.after) * k),
        ]);
    }
    t
}

/// `rtid evaluate POSITIONING.json --compensation FILE`: the ISO 230-2 values of runs
/// `runs` (all for `None`) without and with the compensation of `file`.
pub fn evaluate(
    exp: &Experiment,
    file: &Path,
    runs: Option<&Runs>,
    plot: &crate::cli::common::plot::Plot,
    json: bool,
) -> anyhow::Result<()> {
    let (all, axis) = record(exp)?;
    let comp = compensation_file::read(file)?;
    comp.check_axis(file, axis)?;
    let measurements = compensate::select(&all, runs);
    if measurements.is_empty() {
        bail!(
            "{}: no measurement of runs {} (its runs: {})",
            exp.path.display(),
            runs.map_or(String::new(), Runs::to_string),
            runs_text(&compensate::run_numbers(&all))
        );
    }
    let b = compensate::before_after(&measurements, &comp.compensation)
        .map_err(|e| anyhow::anyhow!("{}: {e}", exp.path.display()))?;
    let u = ReportUnits::of(axis);
    let corrected = compensate::apply(&measurements, &comp.compensation);
    let report = positioning::iso230::evaluate(&corrected)?;
    crate::cli::experiment::positioning::plot_deviations(exp, &report, u, plot, ", compensated")?;
    let runs_used = runs_text(&compensate::run_numbers(&measurements));
    let k = u.deviation_per_si;
    if json {
        let value = rtid::report::compensation::compensated(
            &exp.path.display().to_string(),
            &file.display().to_string(),
            &compensate::run_numbers(&measurements),
            &b,
            u,
        )?;
        println!("{}", rtid::io::json::pretty(&value)?);
        return Ok(());
    }
    println!(
        "{}: ISO 230-2 evaluation of runs {runs_used}, {}, as the axis compensated by {} would show them",
        exp.path.display(),
        u.deviation_name,
        file.display()
    );
    println!(
        "{}",
        before_after_table(&b, &format!("runs {runs_used}"), k, u.deviation)
    );
    Ok(())
}
