//! `rtid sweep` and `rtid sweep merge`: sensitivity sweeps from the command line.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::{common::progress, ModelArgs};
use rtid::report::sweep as figures;
use rtid::sweep::{self, analysis::Indices, Method, Output, RunOptions, Shard, Sweep, TestLength};

pub const LONG_ABOUT: &str = "\
What-if studies: how the resonances, the reversal value, the fluctuation or the torque \
change when parameters change, and which parameter matters most.

Parameters: --vary NAME=LOW..HIGH[:log][:LEVELS], repeatable, SI units, names as in \
`rtid params` (Kw, Kg, Kb, Jt, theta_bw, ft, Ciw, …). `log` samples the range \
geometrically (needs LOW > 0); LEVELS (default 5) is the number of grid levels. For \
--method local a bare NAME is enough.

Methods (--method):
  grid    every combination of every parameter's levels (first --vary slowest); plots: \
a line per output for one parameter, a heat map for two.
  local   one at a time at the base point: normalised sensitivity ∂ln y/∂ln p (0.5: y ∝ √p) \
by central differences p·e^(±step); 1 + 2k points.
  morris  elementary effects on --trajectories paths over a --levels grid: μ* (importance, \
output units per full range), μ (sign), σ (interaction, non-linearity); r·(k+1) points.
  sobol   first-order S1 and total ST Sobol indices (Saltelli 2010 sampling on a scrambled \
Sobol sequence, Jansen's ST estimator) with 95 % bootstrap intervals; --samples·(k+2) points.

Outputs (--outputs, comma-separated; columns carry units):
  resonances      resonance_1_hz … : peaks of the exact linear frequency response (fast, < 1 ms)
  peak_gain       peak_gain_db: the highest of those peaks (fast, linear)
  modes           mode_1_hz … : undamped natural frequencies, motor held (fast, linear)
  reversal        reversal_arcsec: ISO 230-2 mean reversal value B̄    } one nonlinear
  repeatability   repeatability_arcsec: ISO 230-2 R                    } positioning
  accuracy        accuracy_arcsec: ISO 230-2 A                         } simulation
  fluctuation_pp  fluctuation_pp_arcsec: peak-to-peak of θt − θm·Rg·Rw at 180°/min
  torque_rms      torque_rms_nm: RMS motor torque under 30°·sin(2πt/3 s), full-closed loop
The nonlinear tests run shortened with --tests short (default): positioning at 5 targets \
0°–40° × 3 runs, 0.5 s dwell (≈ 23 s simulated); fluctuation over 18° of travel each \
way, peak-to-peak over the middle 10° (two worm revolutions; ≈ 13.5 s); torque over one \
period after one of run-in (6 s). Each costs about a second of CPU per point. --tests full \
runs the paper's tests as `rtid experiment` does (minutes per point).

Files: --out FILE.csv gets one row per point (index, the parameters, the outputs, error), \
appended and flushed as each finishes; at the end it is rewritten sorted by index. \
Interrupted (Ctrl-C, a killed job)? Run the same command with --resume: only missing rows \
are computed and the final file is the same as a straight run's. Beside it: \
FILE-indices.csv (local/morris/sobol) and FILE-COLUMN.svg plots (tornado charts or \
grid plots).

Clusters: --shard I/N (1 ≤ I ≤ N, counted from 1) computes design points I−1, I−1+N, … into its own \
--out; run N of them as a job array (Slurm: --shard $SLURM_ARRAY_TASK_ID/N, N the array's size), \
then `rtid sweep merge SHARD-FILES… --out FILE.csv` joins them and computes the indices. \
docs/sweeps.md has a Slurm script.

Examples:
  rtid sweep --preset worm-gear --vary Kw=1e5..1e6:log:20 --outputs resonances,peak_gain --out kw.csv
  rtid sweep --preset worm-gear --method local --vary Kw --vary Kg --vary Jt --vary Kb \\
      --outputs resonances --out local.csv
  rtid sweep --preset worm-gear --method sobol --samples 256 --vary Kw=1e5..1e6:log \\
      --vary Kb=1e7..1e8:log --vary Jt=0.08..0.14 --outputs resonances,peak_gain --out sobol.csv
  rtid sweep --preset worm-gear --method morris --vary theta_bw=1e-5..2e-4 --vary ft=0.1..0.5 \\
      --vary fm=0.05..0.3 --outputs reversal,repeatability,accuracy --out iso.csv";

/// Which design.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    Grid,
    Local,
    Morris,
    Sobol,
}

/// Arguments of `rtid sweep`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    #[command(flatten)]
    pub run: RunArgs,
}

/// `rtid sweep merge`.
#[derive(Debug, clap::Subcommand)]
pub enum SweepCommand {
    /// Join the shard files of one sweep, write the final file and compute the indices.
    Merge(MergeArgs),
}

/// Arguments of `rtid sweep merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The shard files (every shard of the sweep, any order).
    #[arg(required = true, value_name = "SHARD.csv")]
    pub shards: Vec<PathBuf>,
    /// The merged file (indices and plots are written beside it).
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
    /// Print the indices as JSON.
    #[arg(long)]
    pub json: bool,
    /// No "wrote FILE" lines.
    #[arg(long)]
    pub quiet: bool,
}

/// Arguments of a sweep run.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// A parameter to vary: NAME=LOW..HIGH[:log][:LEVELS]; repeatable.
    #[arg(long, value_name = "SPEC")]
    pub vary: Vec<String>,
    /// What to compute at each point, comma-separated (see above).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub outputs: Vec<String>,
    /// Design: grid, local, morris or sobol.
    #[arg(long, value_enum, default_value = "grid")]
    pub method: MethodArg,
    /// Sobol: base sample N (the sweep evaluates N·(k+2) points).
    #[arg(long, default_value_t = 256)]
    pub samples: usize,
    /// Sobol: bootstrap resamples for the 95 % intervals.
    #[arg(long, default_value_t = 500)]
    pub bootstrap: usize,
    /// Morris: number of trajectories r.
    #[arg(long, default_value_t = 20)]
    pub trajectories: usize,
    /// Morris: grid levels (even).
    #[arg(long, default_value_t = 4)]
    pub levels: usize,
    /// Local: relative step h of p·e^(±h).
    #[arg(long, default_value_t = 0.01)]
    pub step: f64,
    /// Seed of the Morris trajectories, the Sobol scrambling and the bootstrap.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Length of the nonlinear tests: short or full (see above).
    #[arg(long, value_name = "short|full", default_value = "short")]
    pub tests: TestLength,
    /// The sweep file (CSV).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    /// Continue an interrupted sweep in --out, computing only the missing rows.
    #[arg(long, conflicts_with = "overwrite")]
    pub resume: bool,
    /// Replace an existing --out instead of refusing.
    #[arg(long)]
    pub overwrite: bool,
    /// Compute only shard I of N (1 ≤ I ≤ N) of the design, for a job array.
    #[arg(long, value_name = "I/N", allow_hyphen_values = true)]
    pub shard: Option<Shard>,
    /// Worker threads (default: one per core).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Print the run and the indices as JSON.
    #[arg(long)]
    pub json: bool,
}

impl RunArgs {
    /// Validates the arguments into a sweep.
    pub fn sweep(&self) -> anyhow::Result<Sweep> {
        let params = self.model.load()?;
        if self.vary.is_empty() {
            bail!(
                "no parameter to vary: give --vary NAME=LOW..HIGH, e.g. --vary Kw=1e5..1e6:log:20"
            );
        }
        let factors = sweep::spec::parse_all(&self.vary, &params)?;
        if self.outputs.is_empty() {
            bail!(
                "no output: give --outputs, e.g. --outputs resonances,peak_gain (all: {})",
                sweep::outputs::ALL.map(Output::name).join(",")
            );
        }
        let mut outputs = Vec::new();
        for o in &self.outputs {
            let o: Output = o.parse().context("--outputs")?;
            if !outputs.contains(&o) {
                outputs.push(o);
            }
        }
        let method = match self.method {
            MethodArg::Grid => Method::Grid,
            MethodArg::Local => Method::Local { step: self.step },
            MethodArg::Morris => Method::Morris {
                trajectories: self.trajectories,
                levels: self.levels,
            },
            MethodArg::Sobol => Method::Sobol {
                samples: self.samples,
                bootstrap: self.bootstrap,
            },
        };
        Ok(Sweep::new(
            params, factors, method, outputs, self.tests, self.seed,
        )?)
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        Some(SweepCommand::Merge(m)) => merge(m),
        None => run_sweep(a.run),
    }
}

fn run_sweep(a: RunArgs) -> anyhow::Result<()> {
    let sweep = a.sweep()?;
    let Some(out) = a.out.clone() else {
        bail!("no --out FILE.csv given: the sweep streams its rows there");
    };
    let design_len = sweep.design()?.len();
    let mine = match a.shard {
        Some(s) => (design_len + s.count - 1 - s.index) / s.count,
        None => design_len,
    };
    let bar = progress::bar(mine as u64, "sweep", a.quiet);
    let on_row = || bar.inc(1);
    let opts = RunOptions {
        resume: a.resume,
        overwrite: a.overwrite,
        shard: a.shard,
        limit: None,
        on_row: &on_row,
    };
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = a.threads {
        if n == 0 {
            bail!("--threads 0: at least one thread is needed");
        }
        builder = builder.num_threads(n);
    }
    let pool = builder.build().context("starting the worker threads")?;
    if a.resume && out.exists() {
        // The bar counts what is left; rows already in the file are not recomputed.
        if let Ok((file, _)) = sweep::stream::read(&out) {
            bar.set_position(file.rows.len() as u64);
        }
    }
    let report = pool.install(|| sweep::run(&sweep, &out, &opts))?;
    bar.finish_and_clear();
    if !report.complete {
        bail!(
            "{}: {} of {} rows; rerun with --resume to finish",
            out.display(),
            report.resumed + report.computed,
            report.total
        );
    }
    if let Some(shard) = a.shard {
        if a.json {
            let v = serde_json::json!({"file": out, "shard": shard.to_string(), "run": rtid::io::json::value(&report)?});
            println!("{}", rtid::io::json::pretty(&v)?);
        } else {
            println!(
                "{}: shard {shard}, {} rows ({} computed now, {} failed); join the shards with `rtid sweep merge`",
                out.display(),
                report.total,
                report.computed,
                report.failed
            );
        }
        return Ok(());
    }
    let (_, rows) = sweep::load_complete(std::slice::from_ref(&out))?;
    let (indices, files) = write_report(&sweep, &rows, &out)?;
    print(
        &sweep,
        &out,
        Some(report),
        &indices,
        &files,
        (a.json, a.quiet),
    )
}

fn merge(m: MergeArgs) -> anyhow::Result<()> {
    let (sweep, rows) = sweep::load_complete(&m.shards)?;
    sweep::write_final(&sweep, &rows, &m.out)?;
    let (indices, files) = write_report(&sweep, &rows, &m.out)?;
    print(&sweep, &m.out, None, &indices, &files, (m.json, m.quiet))
}

/// The indices file (not for a grid) and the plots beside `out`: tornado charts, or
/// for a grid of one or two factors line plots or heat maps. Returns the indices and
/// the files written.
fn write_report(
    sweep: &Sweep,
    rows: &std::collections::BTreeMap<usize, Vec<String>>,
    out: &Path,
) -> anyhow::Result<(Indices, Vec<PathBuf>)> {
    let (indices, file) = sweep::write_indices(sweep, rows, out)?;
    let charts = if sweep.method == Method::Grid {
        let design = sweep.design()?;
        let y = sweep::output_matrix(sweep, rows);
        figures::grid_plots(
            &sweep.factors,
            design.values.view(),
            &sweep.output_columns(),
            y.view(),
        )?
    } else {
        figures::tornadoes(&indices)?
    };
    let mut files: Vec<PathBuf> = file.into_iter().collect();
    for (name, svg) in charts {
        let path = beside(out, &name);
        rtid::io::atomic::write(&path, svg.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        files.push(path);
    }
    Ok((indices, files))
}

/// `dir/stem.csv` → `dir/stem-NAME.svg`.
fn beside(out: &Path, name: &str) -> PathBuf {
    let stem = out
        .file_stem()
        .map_or("sweep".into(), |s| s.to_string_lossy());
    out.with_file_name(format!("{stem}-{name}.svg"))
}

fn print(
    sweep: &Sweep,
    out: &std::path::Path,
    report: Option<sweep::RunReport>,
    indices: &Indices,
    files: &[PathBuf],
    (json, quiet): (bool, bool),
) -> anyhow::Result<()> {
    if json {
        let v = serde_json::json!({
            "file": out,
            "method": sweep.method.name(),
            "run": rtid::io::json::value(&report)?,
            "indices": rtid::io::json::value(&indices)?,
            "files": files,
        });
        println!("{}", rtid::io::json::pretty(&v)?);
        return Ok(());
    }
    match report {
        Some(r) => println!(
            "{}: {} rows ({} computed now, {} resumed, {} failed)",
            out.display(),
            r.total,
            r.computed,
            r.resumed,
            r.failed
        ),
        None => println!("{}: merged", out.display()),
    }
    if !indices.rows.is_empty() {
        let mut t = Table::new();
        t.load_preset(UTF8_FULL_CONDENSED);
        let mut header = vec!["output", "parameter"];
        header.extend(indices.columns.iter().copied());
        t.set_header(header);
        for r in &indices.rows {
            let mut row = vec![r.output.clone(), r.parameter.clone()];
            row.extend(
                r.values
                    .iter()
                    .map(|v| v.map_or("–".to_string(), |v| format!("{v:.4}"))),
            );
            t.add_row(row);
        }
        println!("{t}");
    }
    for n in &indices.notes {
        println!("note: {n}");
    }
    for f in files.iter().filter(|_| !quiet) {
        println!("wrote {}", f.display());
    }
    Ok(())
}
