//! `rtid import`: records as labs export them — what is in a file (`--list`), and an
//! rtid experiment file made of its channels (`--kind … --map … --out DIR`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use serde_json::{json, Map, Value};

use rtid::io::experiment_file::{self, Conditions};
use rtid::io::formats::detect::{self, Format};
use rtid::io::import::kinds::ImportKind;
use rtid::io::import::{self, mapping, Source};

mod drive;
mod list;

pub const LONG_ABOUT: &str = "\
Reads the files labs export — MATLAB MAT-files (v5/v7), Beckhoff TwinCAT Scope View CSV, \
Maxon EPOS Studio data-recorder CSV, UFF datasets 58/58b, SINUMERIK/SINAMICS \
measuring-function XML, delimited text with a header — \
as they are, and writes rtid experiment files (manifest + CSV in SI units) from them \
(docs/import.md).

First see what a file holds, without choosing anything:
  rtid import DATA_EMPS.mat --list
lists each channel's name as the file spells it, its unit, number of samples, sample \
period (or abscissa), first, last and mean value — after the scale factors and offsets \
the file itself declares; a MAT-file's matrix once, with its shape and how its signals \
are spelled (rec.q(i,:), i = 1…6). --filter TEXT lists only the names containing TEXT. \
--json prints the same as {\"channels\": [...], \"format\", \
\"notes\"} (an array of them for several files).

Then map channels onto the roles of an experiment kind:
  rtid import FILE --kind KIND --map ROLE=CHANNEL[*SCALE][:UNIT] ... --out DIR
Each role is taken from the named channel (exactly as --list spells it), multiplied by \
SCALE (a number; *-1 flips a sign), in UNIT — the unit of CHANNEL×SCALE; without UNIT the \
channel's own unit label, else the unit its name ends in (_deg, _nm = N·m, _deg_per_s …, \
with a note). With no map for it, a frequency response's frf (a torque curve's effort) \
takes the one channel that fits. rtid converts to its SI columns. A computed role is a scaled \
channel: the force of a drive is its controller output (V) times the drive gain (N/V): \
effort=vir*35.15:N.

Units: s, ms, µs (us); rad, deg, arcsec, rev; m, mm, µm (um), nm; rad/s, deg/s, rpm, \
m/s, mm/s, mm/min; N·m (Nm), mN·m (mNm), N; A, mA; V; Hz; dB; 1 (a ratio). Per cent of a \
nominal value: %(9.84 mN·m). Encoder increments with their resolution: inc(4096/rev), \
inc(1000/mm).

Kinds and their roles (time or frequency defaults to the channels' own abscissa):
  servo-trace              time, reference_position, position, table_position, effort, \
controller_output, controller_added
  torque-curve             time, effort, position
  frequency-response       frequency, frf (a complex channel) or gain (dB or ratio) and \
phase
  frequency-response-time  time, motor_torque or motor_current, motor_angle, table_angle
  positioning              target, deviation, direction (> 0 up, < 0 down), run (from 1)
  friction-map             speed (rad/s, rpm, m/s …), effort, time: one constant-speed run \
per file, the maps applied to each file alike; one file whose speed steps through several \
plateaus gives one run per plateau
--condition NAME=VALUE sets a manifest condition (docs/experiment-files.md), e.g. \
drive_gain=35.15, loop_period_s=0.001.

A drive's own measurement (SINUMERIK/SINAMICS measuring-function XML) says what it \
measured: `rtid import freq_trace.XML --out DIR` writes the closed speed loop's response \
(actual over setpoint speed, response \"speed_loop\") from the drive's stored spectra as \
DIR/speed_loop.json and, as a check, recomputed from its time series with rtid's periodic \
estimator as DIR/speed_loop_time_series.json (--name NAME for another stem); no --kind, \
no --map.

Nothing is smoothed silently: a sample more than 10 robust deviations from its \
neighbours is reported with file, line and value (and kept), a gap in the time base \
names its line. A friction map's run is reduced to its mean speed and effort: its \
glitches are dropped (each said with its line), the samples before the speed settles \
within max(5 %, 2 quanta) of its median are left out as the transient, and a run that \
has not settled (fewer than 10 samples left, more than 10 % outside that band, or halves \
whose mean speeds differ by more than it) is refused, naming the file. The manifest records the source files with their SHA-256, their format, \
the maps and conditions as given, and rtid's version.

Examples:
  rtid import fixtures/formats/matlab/DATA_EMPS.mat --list
  rtid import fixtures/formats/matlab/DATA_EMPS.mat --kind servo-trace \\
      --map time=t:s --map position=qm:m --map reference_position=qg:m \\
      --map controller_output=vir:V --map effort=vir*35.15065188248547:N \\
      --condition drive_gain=35.15065188248547 --condition loop_period_s=0.001 --out emps
  rtid import run.csv --kind torque-curve --map time=t:ms \\
      --map 'effort=Torque actual value*-1:%(9.84 mN·m)' --out runs/torque
  rtid import steady/10.csv steady/n10.csv steady/50.csv steady/n50.csv --kind friction-map \\
      --map 'speed=Velocity actual value averaged*-1:rpm' \\
      --map 'effort=Torque actual value averaged*-1:%(9.84 mN·m)' --out runs/map";

/// Arguments of `rtid import`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The files to read (one experiment: several files are read together, their
    /// channels named as in each; for friction-map each file is one run, mapped alike).
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,
    /// List each file's channels (name, unit, samples, sample period, first, last,
    /// mean) and write nothing.
    #[arg(long, conflicts_with_all = ["kind", "map", "out"])]
    pub list: bool,
    /// With --list: only the channels (and matrices) whose names contain TEXT,
    /// ignoring case; a matrix's signals are then listed one by one.
    #[arg(long, value_name = "TEXT", conflicts_with_all = ["kind", "map", "out"])]
    pub filter: Option<String>,
    /// The reader to use (default: recognised from the file's first bytes).
    #[arg(long, value_name = "FORMAT", value_parser = parse_format)]
    pub format: Option<Format>,
    /// The experiment to write: servo-trace, torque-curve, frequency-response,
    /// frequency-response-time, positioning, friction-map.
    #[arg(long, value_name = "KIND", value_parser = parse_kind, requires = "out")]
    pub kind: Option<ImportKind>,
    /// ROLE=CHANNEL[*SCALE][:UNIT]; repeatable, one per role.
    #[arg(
        long,
        value_name = "ROLE=CHANNEL[*SCALE][:UNIT]",
        allow_hyphen_values = true
    )]
    pub map: Vec<String>,
    /// NAME=VALUE, a manifest condition; repeatable.
    #[arg(long, value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub condition: Vec<String>,
    /// The manifest's `mechanism` (free text).
    #[arg(long, value_name = "TEXT")]
    pub mechanism: Option<String>,
    /// The manifest's file name in DIR, without `.json` (default: the kind's name,
    /// e.g. servo_trace).
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// The folder to write the manifest and its CSV into (without --kind: a drive's
    /// own measurement, which says what it measured).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No notes on stderr.
    #[arg(long)]
    pub quiet: bool,
}

fn parse_format(s: &str) -> Result<Format, String> {
    Format::parse(s).ok_or_else(|| {
        let names: Vec<&str> = Format::all().map(|f| f.name()).collect();
        format!("unknown format `{s}`: expected {}", names.join(", "))
    })
}

fn parse_kind(s: &str) -> Result<ImportKind, String> {
    ImportKind::parse(s).ok_or_else(|| {
        let names: Vec<&str> = ImportKind::ALL.iter().map(|k| k.name()).collect();
        format!(
            "`{s}` is not a kind import writes: expected {}",
            names.join(", ")
        )
    })
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let sources = read_all(&a.files, a.format)?;
    if a.list || (a.kind.is_none() && a.out.is_none()) {
        return list::list(&sources, a.filter.as_deref(), a.json);
    }
    if a.kind.is_none() {
        return drive_measurement(&a, &sources);
    }
    let request = request(&a)?;
    let imported = import::build(&sources, &request)?;
    let out = a
        .out
        .as_deref()
        .context("--out DIR is needed with --kind")?;
    let name = a
        .name
        .clone()
        .unwrap_or_else(|| request.kind.kind().to_string());
    let manifest_path = out.join(format!("{name}.json"));
    refuse_overwriting_inputs(&manifest_path, &a.files)?;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    experiment_file::write(&manifest_path, &imported.manifest, &imported.data)?;
    report(&manifest_path, &imported, a.json, a.quiet)
}

/// `--out` without `--kind`: the one file a drive's own measurement.
fn drive_measurement(a: &Args, sources: &[Source]) -> anyhow::Result<()> {
    let [source] = sources else {
        bail!("--out without --kind writes one drive measurement at a time: give one file");
    };
    if !import::drive_measurement::is_drive_measurement(source) {
        bail!(
            "{} is a {} recording, whose channels must be mapped: give --kind and --map \
             (rtid import FILE --list shows them); only a drive's own measurement \
             (sinumerik-trace) says what it measured",
            source.path.display(),
            source.recording.format
        );
    }
    if !a.map.is_empty() {
        bail!("--map needs --kind: a drive's own measurement is imported without maps");
    }
    let out = a.out.as_deref().context("--out DIR")?;
    drive::write(
        source,
        out,
        a.name.as_deref(),
        (
            &conditions(&a.condition)?,
            &a.condition,
            a.mechanism.clone(),
        ),
        (a.json, a.quiet),
    )
}

/// Every file read.
fn read_all(files: &[PathBuf], format: Option<Format>) -> anyhow::Result<Vec<Source>> {
    files
        .iter()
        .map(|path| {
            Ok(Source {
                path: path.clone(),
                recording: detect::read(path, format)?,
            })
        })
        .collect()
}

fn request(a: &Args) -> anyhow::Result<import::Request> {
    let kind = a.kind.context("--kind is needed to write an experiment")?;
    let maps = a
        .map
        .iter()
        .map(|m| mapping::parse(m).map_err(|e| anyhow::anyhow!("--map {e}")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(import::Request {
        kind,
        maps,
        conditions: conditions(&a.condition)?,
        conditions_given: a.condition.clone(),
        mechanism: a.mechanism.clone(),
    })
}

/// `--condition NAME=VALUE`s as the manifest's conditions: VALUE read as JSON (a
/// number, `true`, `[1, 2]`), else as text.
fn conditions(given: &[String]) -> anyhow::Result<Conditions> {
    let mut map = Map::new();
    for c in given {
        let (name, value) = c
            .split_once('=')
            .with_context(|| format!("--condition {c}: write NAME=VALUE"))?;
        let name = name.trim();
        if map.contains_key(name) {
            bail!("--condition {c}: `{name}` is given twice");
        }
        let value =
            serde_json::from_str::<Value>(value.trim()).unwrap_or_else(|_| json!(value.trim()));
        if let Some(v) = value.as_f64().filter(|v| !v.is_finite()) {
            bail!("--condition {c}: {v} is not a finite number");
        }
        map.insert(name.to_string(), value);
    }
    serde_json::from_value(Value::Object(map)).context("--condition: a value of the wrong type")
}

pub(super) fn refuse_overwriting_inputs(manifest: &Path, inputs: &[PathBuf]) -> anyhow::Result<()> {
    let csv = manifest.with_extension("csv");
    for input in inputs {
        let same = |p: &Path| match (p.canonicalize(), input.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if same(manifest) || same(&csv) {
            bail!(
                "--out: {} would be written over the input {}",
                manifest.display(),
                input.display()
            );
        }
    }
    Ok(())
}

fn report(path: &Path, imported: &import::Imported, json: bool, quiet: bool) -> anyhow::Result<()> {
    if json {
        let out = json!({
            "manifest": path.display().to_string(),
            "kind": imported.manifest.kind.to_string(),
            "rows": imported.data.len(),
            "findings": imported.findings,
        });
        println!("{}", rtid::io::json::pretty(&out)?);
        return Ok(());
    }
    println!(
        "wrote {} ({}, {} rows)",
        path.display(),
        imported.manifest.kind,
        imported.data.len()
    );
    if !quiet {
        for f in &imported.findings {
            eprintln!("note: {f}");
        }
    }
    Ok(())
}
