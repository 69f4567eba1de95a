//! `rtid identify`: parameters from experiment files; beside it the commands on
//! identifications: [`select`] (model selection between results) and [`design`]
//! (candidate tests ranked by the uncertainty they would give).

pub mod design;
mod held;
mod profile;
mod resample;
pub mod select;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::common::uncertain;
use crate::cli::identify::held::{add_held, held_table};
use crate::cli::identify::profile::{
    add_profiles, profile_table, surface_notes, write_profile_plots,
};
use crate::cli::identify::resample::{add_resampling, resample_table};
use crate::cli::ModelArgs;
use rtid::identify::intervals::chosen::{self, held_ranges, Chosen};
use rtid::identify::pipeline::comparison;
use rtid::identify::result::comparison::Comparison;
use rtid::identify::{
    identify, Bound, Config, ExperimentSpec, FidelityChoice, Identified, IdentifyResult, Method,
    Monitor, SearchOptions, Staging, StartChoice, Warning,
};
use rtid::io::experiment_file::{self, Kind};
use rtid::io::params_file;
use rtid::io::provenance::Provenance;
use rtid::model::Params;
use rtid::objectives::{Detail, ObjectiveKind};

pub const LONG_ABOUT: &str = "\
Identifies physical parameters of the drive — torsional stiffnesses Kw, Kg, Kb, internal \
damping Ciw, Cig, Coulomb friction fm, fw, ft, viscous damping Cm, Cw, Ct, inertias… any \
subset by name — from one or more experiment files (docs/experiment-files.md), measured on a \
rig or written by `rtid experiment`. The other parameters stay at the --preset / --params \
values.

What each experiment feeds (--objective to choose):
  frequency_response  with phase (or a compliance): gain-curve, the whole complex response — \
ln|H| and phase errors, each over its noise (the file's gain_sigma_db / coherence, else 0.1 dB \
and 0.66°), phase compared modulo 360°, a delay_s in the manifest taken out or fitted \
(\"unknown\") — and --fit defaults to the stiffnesses and the meshes' dampings (Kw, Kg, Ciw, \
Cig; a direct drive's compliance: Jt, Ct). Gain only: resonance, the measured resonance \
frequencies (peaks of the gain curve) against the model's; also peak-amplitude (peak heights, \
dB: for Ciw, Cig), gain-curve (the whole gain curve, dB) and gain-near-peaks (the gain within \
±3 % of each resonance).
  resonance           resonance (and peak-amplitude when the manifest has peak_gain_db).
  torque_curve        torque-curve: the motor torque of the closed-loop torque test, sample by \
sample. A torque curve determines one Coulomb and one viscous sum (fm + fw·Rg + ft·Rg·Rw, and \
the viscous alike): fit one of each.
  servo_trace         servo-trace: the recorded trace replayed through the servo (the \
recorded reference into the controller, closed loop, over the whole record), force and \
position against the recorded ones, sample by sample. On a direct-drive axis it determines \
Jt, Ct, ft and Tload, and the search starts at their inverse-dynamics least-squares estimate \
(IDIM-LS, instant: --start given to start at the --params values instead); on a geared axis \
fm and Cm.
  unbalance           unbalance-step: the table angles where the deviation θt − θm·Rg·Rw steps \
across the backlash (where the unbalance moment overcomes the table friction), model against \
measured, 0.05° per unit. It determines ft (the manifest must give mass_kg and radius_m).
Default --fit: Kw, Kg, Ciw, Cig from a response with phase; Kw (and Kg with a spur stage) \
from resonances; fm and Cm from a torque curve \
(the table's friction reaches the motor divided by the ratio — 1/90 for the worm — and \
hardly shows in its torque); ft from an unbalance test; Jt, Ct, ft, Tload from a servo trace \
of a direct-drive axis. fm and ft together: give both files \
and --fit fm,ft.

The model's frequency response (--model): `linear` is the exact linear response with damping \
(no backlash, no friction; microseconds); `nonlinear` searches on the linear one, then \
corrects that fit by the virtual test at the experiment's conditions (amplitude, preload; a \
time simulation per frequency) until the gain near the measured peaks matches — a few \
evaluations of the test, about a second for the worm fixture; `auto` (default) searches on the linear \
one and then checks the result on the nonlinear test, warning when backlash or friction move \
the resonances by more than 1 %. By default a gain curve feeds the resonance frequencies and, \
at weight 0.01, the peak heights: the worm's two resonances alone admit two (Kw, Kg) pairs, \
the heights tell them apart. Resonances are peaks of the damped response, never undamped eigenvalues (that \
biases Kw by ~6 %).

Search: positive parameters in log space inside --bound (default 0.1×..10× the start); \
--starts N starts (the preset's values, then a Latin hypercube in the bounds) in parallel \
(default 4; 1 with a torque curve or an unbalance test, whose every evaluation is a closed-loop \
simulation); \
--method lsq (Gauss–Newton with line search; default), lm (Levenberg–Marquardt; default with a \
direct-drive servo trace, rough only below a few per cent), nelder-mead (default with a torque \
curve, an unbalance test or a geared axis's servo trace, whose quantised encoders and backlash \
make finite differences rough) or pso. Ctrl-C ends the \
search and still writes the best result; with --checkpoint FILE, --resume continues.

Output: a table of parameter, start, identified ± standard error; warnings when the data \
cannot separate parameters (|correlation| > 0.95 or a singular JᵀJ), when a parameter ends \
on a bound, or when the fit misses the measured resonances; --out result.json with \
everything (parameters, initial, bounds, cost, residuals per experiment, evaluations, \
wall_time_s, termination, uncertainty, the fit against the data, and the command line, rtid \
version and inputs' SHA-256 for `rtid report`); an SVG per chart of the fit against the \
data (FILE-1.svg, …; a servo trace has two: effort and following error); \
--save-params FILE for `--params FILE` everywhere. --profile adds each fitted \
parameter's profile likelihood: its 95 % likelihood-ratio interval (open where the data do \
not bound it, naming the parameters that move with it), beside ±1.96 standard errors, and \
a plot each; on a rough cost (torque curve, unbalance test, servo trace) it is read off a bowl fitted to \
the cost at a few dozen points around the fit, evaluated in parallel (about a second for \
the worm's torque curve, where a walk of re-fits took a minute). --resample N repeats the whole fit on N replicates of the data (the fitted \
response plus the residuals resampled in blocks): its 95 % interval holds where the cost is \
rough (torque curve, servo trace) and the standard errors are lower bounds.

Examples:
  rtid identify fixtures/worm-gear/frequency_response.json --preset worm-gear --out fit.json
  rtid identify fixtures/worm-gear/frequency_response.json fixtures/worm-gear/torque_curve.json \\
      --preset worm-gear --fit Kw,Kg,fm,Cm --out fit.json --save-params worm-fit.json
  rtid identify fixtures/worm-gear/torque_curve.json fixtures/worm-gear/unbalance.json \\
      --preset worm-gear --fit fm,ft --out friction.json
  rtid identify fixtures/paper/worm-gear.json --preset worm-gear --fit Kw,Kg,Jt --model linear \\
      --profile
  rtid identify fixtures/worm-gear-noisy/torque_curve.json --preset worm-gear \\
      --set fm=0.2 --set Cm=0.01 --resample --out friction.json
  rtid identify fixtures/real/emps/emps_estimation.json --params fixtures/real/emps/axis.json \\
      --out emps-fit.json --save-params emps-fit-params.json
  rtid modes --params worm-fit.json";

/// Arguments of `rtid identify`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Experiment manifests (JSON).
    #[arg(value_name = "EXP.json", required = true)]
    pub experiments: Vec<PathBuf>,
    #[command(flatten)]
    pub model: ModelArgs,
    /// Parameters to fit, comma-separated names (`rtid params` lists them).
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub fit: Vec<String>,
    /// Bounds of a fitted parameter, SI units; repeatable: --bound Kw=1e5..1e7.
    #[arg(long = "bound", value_name = "NAME=LO..HI")]
    pub bounds: Vec<String>,
    /// The band of the resonances, Hz: only the measured peaks (and gain-curve points)
    /// inside it count, and the model's peaks are sought there — a noise ripple or a
    /// mode outside it is not matched. Sets `conditions.band_hz` of every
    /// frequency-response and resonance experiment.
    #[arg(long, value_name = "LO..HI")]
    pub band: Option<String>,
    /// Objectives to use (default: by experiment kind, see above); each experiment
    /// feeds those of them it can.
    #[arg(long, value_delimiter = ',', value_parser = objective_names())]
    pub objective: Option<Vec<String>>,
    /// Weight of each experiment in the joint cost, in the order given (default 1 each;
    /// relative, within 1e-6..1e6).
    #[arg(long = "weight", value_delimiter = ',', allow_negative_numbers = true)]
    pub weights: Vec<f64>,
    /// Solver [default: lsq; lm for a direct-drive servo trace; nelder-mead when a
    /// torque curve, an unbalance test or a geared axis's servo trace is fitted].
    #[arg(long, value_enum)]
    pub method: Option<MethodArg>,
    /// Frequency-response model of the objectives.
    #[arg(long = "model", value_enum, default_value = "auto")]
    pub fidelity: FidelityArg,
    /// Number of starts [default: 4; 1 when a torque curve or an unbalance test is
    /// fitted: each of its evaluations is seconds of closed-loop simulation].
    #[arg(long)]
    pub starts: Option<usize>,
    /// Seed of the Latin hypercube and of the particle swarm.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Iteration limit of each local search.
    #[arg(long, default_value_t = 50)]
    pub max_iters: u64,
    /// Result file (JSON).
    #[arg(long, value_name = "FILE.json")]
    pub out: Option<PathBuf>,
    /// Write the complete identified parameter set (for --params).
    #[arg(long, value_name = "FILE.json")]
    pub save_params: Option<PathBuf>,
    /// Checkpoint file, written after each finished start.
    #[arg(long, value_name = "FILE.json")]
    pub checkpoint: Option<PathBuf>,
    /// Continue from --checkpoint.
    #[arg(long, requires = "checkpoint")]
    pub resume: bool,
    /// Where the search starts: `estimate` — at an experiment's direct estimate where
    /// it offers one (a servo trace of a direct-drive axis: IDIM-LS for Jt, Ct, ft,
    /// Tload), else the --preset/--params values; `given` — at those values always.
    #[arg(long, value_enum, default_value = "estimate")]
    pub start: StartArg,
    /// With several experiments, fit every parameter on all of them at once. By
    /// default the fit goes by plan: each parameter first from the record that
    /// carries the most information about it (the others held; closed-loop
    /// simulations first, then frequency responses), then those whose information
    /// the records share are refined jointly; the plan is printed and in the result
    /// as `plan`.
    #[arg(long)]
    pub joint: bool,
    /// Profile likelihood of these fitted parameters (comma-separated; `--profile`
    /// alone: every fitted one): each is held at values walking out from the fit both
    /// ways while the others are re-fitted, giving its 95 % likelihood-ratio interval
    /// (open on a side where the profile stays flat up to the bound). On a rough cost
    /// (torque curve, unbalance test, servo trace) the profile is a quadratic bowl's,
    /// fitted to the cost at points around the fit, its statistic counting the
    /// residuals' correlation. In the result as `profiles`, plotted as
    /// FILE-profile-NAME.svg beside --out.
    #[arg(long, value_name = "NAMES", num_args = 0..=1, default_missing_value = "")]
    pub profile: Option<String>,
    /// Which interval: `auto` — by the cost: where it is smooth (a frequency
    /// response), the standard errors, widened by the held parameters' ranges;
    /// where it is rough (a torque curve, an unbalance test, a servo trace: the
    /// search stops in the quantised encoders' local minima) or the nonlinear
    /// corrections did not converge, the residual block bootstrap, whose intervals
    /// hold there (docs/validation.md); `standard-errors` — the Jacobian's only
    /// (lower bounds on a rough cost: fast); `bootstrap` — whatever the cost.
    #[arg(long, value_enum, default_value = "auto")]
    pub intervals: IntervalsArg,
    /// The bootstrap's replicates (`--resample` alone: 20; the bootstrap `--intervals
    /// auto` chooses on a rough cost: 12), and the bootstrap whatever the cost: each
    /// replicate is the fitted model's response plus the fit's residuals resampled
    /// in blocks (an unbalance test's few steps: normal errors), each held parameter
    /// drawn within its range, fitted again from the fit's start by the fit's own
    /// search (a fit by plan: its stages replayed), side by side in the kernel's
    /// lanes. Its 95 %
    /// interval (the fit less the replicates' bias, ± 1.96 of their spread; with
    /// held ranges the fit ± (|bias| + 1.96 sd), which holds the interval about
    /// the replicates' mean as well) holds where the standard errors do
    /// not and replaces the warning that they are lower bounds. In the result as
    /// `resampling`.
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "20",
          value_parser = clap::value_parser!(u64).range(5..=10_000))]
    pub resample: Option<u64>,
    /// A parameter the fit holds at an assumed value, with its uncertainty as a
    /// relative half-range (e.g. --uncertain Kw=10% for a stiffness from a
    /// catalogue, --uncertain theta_bg=50% for a backlash nobody measured; 0% holds
    /// it exactly); repeatable. By default every held parameter with a range in the
    /// parameter set (a preset's uncertain or assumed values: `rtid params`) is
    /// carried; this replaces or adds one. On a smooth cost the fit is repeated with
    /// each held parameter at each end of its range (from the fit's values, the same
    /// search): how the fitted parameters follow it is printed, with each one's
    /// interval widened by it, and written in the result as `held`; `rtid predict`
    /// then draws the held parameter within its range and moves the fitted ones with
    /// it. With the bootstrap (a rough cost) each replicate draws the held
    /// parameters within their ranges.
    #[arg(long, value_name = "NAME=X%")]
    pub uncertain: Vec<String>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

/// The objective names `--objective` accepts (the registry's, kebab-case).
fn objective_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        ObjectiveKind::all().map(|k| clap::builder::PossibleValue::new(k.name().replace('_', "-"))),
    )
}

/// The solver (`--method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Gauss–Newton with line search, finite-difference Jacobian in parallel.
    Lsq,
    /// Levenberg–Marquardt, Jacobian and trial steps in parallel.
    Lm,
    /// Nelder–Mead simplex.
    NelderMead,
    /// Particle swarm in the bounds.
    Pso,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Lsq => Method::Lsq,
            MethodArg::Lm => Method::Lm,
            MethodArg::NelderMead => Method::NelderMead,
            MethodArg::Pso => Method::Pso,
        }
    }
}

/// Which interval (`--intervals`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum IntervalsArg {
    /// By the cost: standard errors where smooth, the bootstrap where rough.
    Auto,
    /// The Jacobian's standard errors only.
    StandardErrors,
    /// The residual block bootstrap.
    Bootstrap,
}

impl From<IntervalsArg> for chosen::Choice {
    fn from(i: IntervalsArg) -> chosen::Choice {
        match i {
            IntervalsArg::Auto => chosen::Choice::Auto,
            IntervalsArg::StandardErrors => chosen::Choice::StandardErrors,
            IntervalsArg::Bootstrap => chosen::Choice::Bootstrap,
        }
    }
}

/// Where the search starts (`--start`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StartArg {
    /// At an experiment's direct estimate where there is one.
    Estimate,
    /// At the --preset/--params values.
    Given,
}

impl From<StartArg> for StartChoice {
    fn from(s: StartArg) -> StartChoice {
        match s {
            StartArg::Estimate => StartChoice::Estimate,
            StartArg::Given => StartChoice::Given,
        }
    }
}

/// The frequency-response model (`--model`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FidelityArg {
    /// The linear response for the search, then the nonlinear virtual test at the
    /// result as a check of the linearisation (a warning if it moves the peaks).
    Auto,
    /// The linear response only.
    Linear,
    /// The linear response for every start, then corrections of that fit by the
    /// nonlinear virtual test.
    Nonlinear,
}

impl From<FidelityArg> for FidelityChoice {
    fn from(f: FidelityArg) -> FidelityChoice {
        match f {
            FidelityArg::Auto => FidelityChoice::Auto,
            FidelityArg::Linear => FidelityChoice::Linear,
            FidelityArg::Nonlinear => FidelityChoice::Nonlinear,
        }
    }
}

/// Parses `NAME=LO..HI`.
/// The first name that occurs twice, if any.
fn repeated<'a>(names: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let mut seen = std::collections::BTreeSet::new();
    names.into_iter().find(|n| !seen.insert(*n))
}

pub(super) fn parse_bound(s: &str) -> anyhow::Result<(String, Bound)> {
    let (name, range) = s
        .split_once('=')
        .with_context(|| format!("--bound {s}: expected NAME=LO..HI, e.g. Kw=1e5..1e7"))?;
    let (lo, hi) = range
        .split_once("..")
        .with_context(|| format!("--bound {s}: expected LO..HI after `=`, e.g. 1e5..1e7"))?;
    let num = |t: &str| -> anyhow::Result<f64> {
        match t.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(anyhow::anyhow!("--bound {s}: `{t}` is not a finite number")),
        }
    };
    Ok((
        name.trim().to_string(),
        Bound {
            lo: num(lo)?,
            hi: num(hi)?,
        },
    ))
}

impl Args {
    /// The validated configuration: experiments read, bounds parsed, the chosen
    /// objectives and weights given to each experiment, before any work starts.
    fn config(&self) -> anyhow::Result<Config> {
        let base = self.model.load()?;
        let experiments = self.experiment_specs()?;
        self.refuse_overwrites(&experiments)?;
        let bounds: Vec<(String, Bound)> = self
            .bounds
            .iter()
            .map(|b| parse_bound(b))
            .collect::<anyhow::Result<_>>()?;
        if let Some(name) = repeated(bounds.iter().map(|(n, _)| n.as_str())) {
            anyhow::bail!("--bound: {name} is given twice; give each parameter one range");
        }
        anyhow::ensure!(
            self.fit.iter().all(|n| !n.trim().is_empty()),
            "--fit `{}`: an empty name in the list; write the names comma-separated, e.g. --fit Kw,Kg",
            self.fit.join(",")
        );
        anyhow::ensure!(
            self.starts != Some(0),
            "--starts 0: at least one start is needed"
        );
        anyhow::ensure!(
            self.max_iters > 0,
            "--max-iters 0: each local search needs at least one iteration"
        );
        Ok(Config {
            experiments,
            base,
            fit: self.fit.iter().map(|s| s.trim().to_string()).collect(),
            bounds,
            fidelity: self.fidelity.into(),
            search: SearchOptions {
                method: self.method.map(Method::from),
                starts: self.starts,
                seed: self.seed,
                max_iters: self.max_iters,
                max_evaluations: None,
            },
            checkpoint: self.checkpoint.clone(),
            resume: self.resume,
            start: self.start.into(),
            staging: if self.joint {
                Staging::Joint
            } else {
                Staging::ByRecord
            },
        })
    }

    /// The input files: each manifest, its data file, the parameter file.
    fn inputs<'a>(&'a self, experiments: &'a [ExperimentSpec]) -> Vec<&'a Path> {
        let mut inputs: Vec<&Path> = Vec::new();
        for (path, spec) in self.experiments.iter().zip(experiments) {
            inputs.push(path);
            inputs.extend(spec.experiment.data_path.as_deref());
        }
        inputs.extend(self.model.params.as_deref());
        inputs
    }

    /// No output (--out, --save-params, --checkpoint) over an input — a manifest, its
    /// data file or the parameter file — or in a folder that does not exist.
    fn refuse_overwrites(&self, experiments: &[ExperimentSpec]) -> anyhow::Result<()> {
        let inputs = self.inputs(experiments);
        let outputs = [
            ("--out", &self.out),
            ("--save-params", &self.save_params),
            ("--checkpoint", &self.checkpoint),
        ];
        for (option, path) in outputs {
            if let Some(path) = path {
                crate::cli::common::inputs::refuse_overwrite(option, path, &inputs)?;
                crate::cli::common::inputs::require_folder(option, path)?;
            }
        }
        Ok(())
    }

    /// Each experiment with its weight and the chosen objectives it can feed.
    fn experiment_specs(&self) -> anyhow::Result<Vec<ExperimentSpec>> {
        if !self.weights.is_empty() && self.weights.len() != self.experiments.len() {
            bail!(
                "--weight: {} weights for {} experiments: give one per experiment, in order",
                self.weights.len(),
                self.experiments.len()
            );
        }
        let chosen: Option<Vec<ObjectiveKind>> = self
            .objective
            .as_ref()
            .map(|v| v.iter().map(|o| ObjectiveKind::named(o)).collect())
            .transpose()?;
        let band = self.band.as_deref().map(parse_band).transpose()?;
        let mut specs = Vec::new();
        for (i, path) in self.experiments.iter().enumerate() {
            let mut spec =
                ExperimentSpec::new(path.display().to_string(), experiment_file::read(path)?);
            let kind = spec.experiment.manifest.kind;
            if band.is_some() && matches!(kind, Kind::FrequencyResponse | Kind::Resonance) {
                spec.experiment.manifest.conditions.band_hz = band;
            }
            if let Some(&w) = self.weights.get(i) {
                anyhow::ensure!(
                    rtid::identify::config::WEIGHTS.contains(&w),
                    "--weight {}: a weight is relative (default 1): give one within 1e-6..1e6",
                    rtid::names::Num(w)
                );
                spec.weight = w;
            }
            if let Some(all) = &chosen {
                spec.objectives = Some(usable(all, &spec)?);
            }
            specs.push(spec);
        }
        if band.is_some()
            && !specs
                .iter()
                .any(|s| s.experiment.manifest.conditions.band_hz.is_some())
        {
            bail!("--band: no frequency_response or resonance experiment to apply it to");
        }
        Ok(specs)
    }
}

/// Parses `LO..HI` (Hz) for --band.
fn parse_band(s: &str) -> anyhow::Result<[f64; 2]> {
    let (lo, hi) = s
        .split_once("..")
        .with_context(|| format!("--band {s}: expected LO..HI in Hz, e.g. 100..300"))?;
    let num = |t: &str| -> anyhow::Result<f64> {
        t.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .with_context(|| format!("--band {s}: `{t}` is not a finite number"))
    };
    let (lo, hi) = (num(lo)?, num(hi)?);
    anyhow::ensure!(
        lo >= 0.0 && lo < hi,
        "--band {s}: the band must be LO..HI Hz with 0 ≤ LO < HI"
    );
    Ok([lo, hi])
}

/// The objectives of `all` that `spec`'s experiment can feed; an error naming the
/// file when there is none.
fn usable(all: &[ObjectiveKind], spec: &ExperimentSpec) -> anyhow::Result<Vec<ObjectiveKind>> {
    let kind = spec.experiment.manifest.kind;
    let mine: Vec<ObjectiveKind> = all.iter().copied().filter(|o| o.reads(kind)).collect();
    if mine.is_empty() {
        bail!(
            "--objective {}: {} is a {kind} experiment, which none of them reads ({} needs {})",
            all.iter()
                .map(|o| o.name().replace('_', "-"))
                .collect::<Vec<_>>()
                .join(","),
            spec.source,
            all[0].name().replace('_', "-"),
            all[0].definition().needs
        );
    }
    Ok(mine)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let config = a.config()?;
    let fitted = rtid::identify::plan::Plan::new(&config)?.fit;
    let held = held_ranges(&config.base, &fitted, &uncertain::parse(&a.uncertain)?)?;
    let provenance = Provenance::of_this_run(&a.inputs(&config.experiments))
        .context("hashing the input files")?;
    let monitor = Arc::new(Monitor::default());
    stop_on_ctrl_c(&monitor);
    let bar = live_bar(&monitor, a.quiet);
    let outcome = identify(&config, &monitor);
    if let Some((bar, done, handle)) = bar {
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        let _ = handle.join();
        bar.finish_and_clear();
    }
    let Identified {
        mut result,
        params,
        objective,
        settings,
        smoothness,
        replay,
        ..
    } = outcome?;
    if let Some(names) = &a.profile {
        let fit = (objective.as_ref(), settings, smoothness);
        add_profiles(names, &mut result, &params, fit, &monitor, a.quiet)?;
    }
    let replicates = a.resample.map(|n| n as usize);
    match chosen::decide(&result, smoothness, a.intervals.into(), replicates) {
        _ if result.interrupted => {}
        Chosen::Bootstrap(n) => {
            let fit = (objective.as_ref(), settings, replay.as_ref());
            add_resampling(n, &held, &mut result, &params, fit, &monitor, a.quiet)?;
        }
        Chosen::StandardErrors if !held.is_empty() && !chosen::rough(&result, smoothness) => {
            add_held(&held, &mut result, &params, (objective.as_ref(), settings))?;
        }
        Chosen::StandardErrors => {}
    }
    result.provenance = Some(provenance);
    if a.out.is_some() || a.json {
        result.comparisons = comparisons(&config, &result, &params, a.quiet);
    }
    if let Some(path) = &a.out {
        result
            .write(path)
            .with_context(|| format!("writing {}", path.display()))?;
        write_plots(path, &result.comparisons)?;
        write_profile_plots(path, &result)?;
    }
    if let Some(path) = &a.save_params {
        save_params(path, &result, params)?;
    }
    if a.json {
        println!("{}", rtid::io::json::pretty(&result)?);
    } else {
        print_summary(&result);
    }
    Ok(())
}

/// Ctrl-C stops the search (the best point is still written); a second one quits.
fn stop_on_ctrl_c(monitor: &Arc<Monitor>) {
    let m = Arc::clone(monitor);
    crate::cli::common::interrupt::on_interrupt(move || {
        if m.stopped() {
            return false;
        }
        m.stop();
        eprintln!("\nstopping: finishing the current evaluations, then writing the best result (Ctrl-C again to quit)");
        true
    });
}

/// The complete identified parameter set, each fitted value noted with its source.
fn save_params(path: &Path, result: &IdentifyResult, mut p: Params) -> anyhow::Result<()> {
    for name in result.parameters.keys() {
        p.notes.insert(
            name.clone(),
            format!(
                "identified by rtid from {} ({} model)",
                result.experiments.join(", "),
                result.fidelity
            ),
        );
    }
    params_file::write(path, &p).with_context(|| format!("writing {}", path.display()))
}

type LiveBar = (
    indicatif::ProgressBar,
    Arc<std::sync::atomic::AtomicBool>,
    std::thread::JoinHandle<()>,
);

/// Steps of the bar: the fraction of the iteration budget, in thousandths.
const BAR_STEPS: u64 = 1000;

/// A live bar: the searches' iterations done of their budget (starts × --max-iters),
/// with the time left that implies — an upper bound, since a start that converges
/// early gives back the rest of its budget — and the evaluations and best cost so far.
fn live_bar(monitor: &Arc<Monitor>, quiet: bool) -> Option<LiveBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(BAR_STEPS);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed:>4} identifying [{bar:16}] {percent:>3}% of budget, ≤{eta} left, {msg}",
        )
        .expect("a valid template")
        .progress_chars("=> "),
    );
    let done = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let (b, d, m) = (bar.clone(), Arc::clone(&done), Arc::clone(monitor));
    let handle = std::thread::spawn(move || {
        while !d.load(std::sync::atomic::Ordering::Relaxed) {
            let best = m.best().map_or("—".into(), |b| format!("{:.3e}", b.cost));
            b.set_message(format!("{} evals, best {best}", m.evaluations()));
            let fraction = m.progress().fraction().unwrap_or(0.0);
            b.set_position((fraction * BAR_STEPS as f64) as u64);
            std::thread::sleep(Duration::from_millis(150));
        }
    });
    Some((bar, done, handle))
}

fn print_summary(r: &IdentifyResult) {
    for e in &r.start_estimates {
        let names: Vec<&str> = e.values.keys().map(String::as_str).collect();
        println!("start of {}: {}", names.join(", "), e.method);
    }
    if let Some(p) = &r.plan {
        print_plan(p);
    }
    println!("{}", parameter_table(r));
    if let Some(t) = profile_table(r) {
        println!("{t}");
        for line in surface_notes(r) {
            println!("{line}");
        }
    }
    if let Some(t) = resample_table(r) {
        println!("{t}");
        if let Some(s) = &r.resampling {
            println!("bootstrap: {}", s.method);
        }
    }
    if let Some(t) = held_table(r) {
        println!("{t}");
    }
    for res in &r.residuals {
        println!(
            "{} [{}]: RMS scaled residual {:.3} (unit: {}){}",
            res.source,
            res.objective,
            res.rms,
            res.scale,
            res.detail
                .as_ref()
                .map_or(String::new(), |d| detail(&res.objective, d))
        );
    }
    println!(
        "cost {:.4e}, {} evaluations, {:.2} s, {} ({}, {} model)",
        r.cost, r.evaluations, r.wall_time_s, r.termination.0, r.method, r.fidelity
    );
    if let Some(u) = r.uncertainty.as_ref().filter(|u| u.names.len() > 1) {
        println!("{}", correlation_table(u));
    }
    for w in &r.warnings {
        println!("warning: {}{}", w.0, hint(&w.0));
    }
}

/// The plan by record: each stage's record and parameters, each parameter's share of
/// information by record, what was refined jointly and what is not determined.
fn print_plan(p: &rtid::identify::result::record_plan::RecordPlan) {
    println!("plan: each parameter from the record that carries the most information about it, the others held; then refined jointly where the records share it");
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let records: Vec<String> = p
        .shares
        .first()
        .map(|(_, s)| s.iter().map(|(r, _)| r.clone()).collect())
        .unwrap_or_default();
    let mut header = vec!["parameter".to_string(), "determined by".into()];
    header.extend(
        records
            .iter()
            .map(|r| format!("information share: {}", short(r))),
    );
    t.set_header(header);
    for (name, shares) in &p.shares {
        let by = p
            .stages
            .iter()
            .position(|s| s.parameters.contains(name))
            .map_or_else(String::new, |k| {
                format!("stage {} ({})", k + 1, short(&p.stages[k].record))
            });
        let by = match (p.undetermined.contains(name), p.refined.contains(name)) {
            (true, _) => "not determined".to_string(),
            (false, true) if by.is_empty() => "the joint refinement".into(),
            (false, true) => format!("{by}, refined jointly"),
            (false, false) => by,
        };
        let mut row = vec![name.clone(), by];
        row.extend(shares.iter().map(|(_, s)| format!("{:.1} %", 100.0 * s)));
        t.add_row(row);
    }
    println!("{t}");
    for (k, s) in p.stages.iter().enumerate() {
        println!(
            "stage {}: {} — {} ({} evaluations, {:.1} s, {})",
            k + 1,
            s.record,
            s.parameters.join(", "),
            s.evaluations,
            s.wall_time_s,
            s.termination
        );
    }
    if let Some(r) = &p.refinement {
        println!("refined jointly: {} ({r})", p.refined.join(", "));
    }
}

/// A record's file name without its folder.
fn short(path: &str) -> String {
    Path::new(path)
        .file_name()
        .map_or(path.to_string(), |f| f.to_string_lossy().into_owned())
}

/// Parameter, start, identified, the 95 % interval that holds and what it is
/// made of, the standard error (marked where it is a lower bound), bounds.
fn parameter_table(r: &IdentifyResult) -> Table {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "parameter",
        "start",
        "identified",
        "95 % interval",
        "from",
        "standard error",
        "bounds",
    ]);
    let lower_bounds = r.uncertainty.as_ref().is_some_and(|u| u.lower_bounds);
    for (name, v) in &r.parameters {
        let b = r.bounds[name];
        let (interval, from) = interval_of(r, name, *v);
        t.add_row([
            name.clone(),
            format!("{:.5e}", r.initial[name]),
            format!("{v:.5e}"),
            interval,
            from,
            r.standard_error(name).map_or("—".into(), |s| {
                let note = if lower_bounds { ", a lower bound" } else { "" };
                format!("{s:.2e} ({:.2} %{note})", 100.0 * s / v.abs())
            }),
            format!("{:.3e}..{:.3e}", b[0], b[1]),
        ]);
    }
    t
}

/// The 95 % interval of `name` (identified `v`) that holds, and what it comes from
/// ([`IdentifyResult::interval`]).
fn interval_of(r: &IdentifyResult, name: &str, v: f64) -> (String, String) {
    use rtid::identify::result::interval::FitInterval;
    let cell = |lo: f64, hi: f64| {
        let rel = |x: f64| 100.0 * (x - v) / v.abs();
        format!("{lo:.4e} … {hi:.4e} ({:+.2} / {:+.2} %)", rel(lo), rel(hi))
    };
    match r.interval(name) {
        Some(FitInterval::Bounds { lower, upper, from }) => (cell(lower, upper), from),
        Some(FitInterval::NotDetermined(why)) => ("not determined".into(), why.into()),
        Some(FitInterval::LowerBound) => (
            "—".into(),
            "the standard error is a lower bound here: --intervals bootstrap".into(),
        ),
        None => ("—".into(), "not fitted".into()),
    }
}

/// The correlation matrix.
fn correlation_table(u: &rtid::identify::result::uncertainty::Uncertainty) -> Table {
    let mut c = Table::new();
    c.load_preset(UTF8_FULL_CONDENSED);
    let mut header = vec!["correlation".to_string()];
    header.extend(u.names.iter().cloned());
    c.set_header(header);
    for (name, row) in u.names.iter().zip(&u.correlation) {
        let mut cells = vec![name.clone()];
        cells.extend(row.iter().map(|x| format!("{x:+.3}")));
        c.add_row(cells);
    }
    c
}

/// A residual detail in the measurement's units, as its objective describes it.
fn detail(objective: &str, d: &Detail) -> String {
    ObjectiveKind::named(objective)
        .ok()
        .and_then(|k| k.describe(d))
        .unwrap_or_default()
}

/// What to change on the command line, for the warnings that have an option.
fn hint(w: &Warning) -> String {
    match w {
        Warning::AtBound { name, .. } => format!(" (--bound {name}=LO..HI)"),
        Warning::Interrupted { .. } => " (--resume with the same --checkpoint)".into(),
        Warning::Escalated { .. } => " (--model linear for the linear fit alone)".into(),
        _ => String::new(),
    }
}

/// Most points per curve of a comparison kept in the result file.
const MAX_RECORDED_POINTS: usize = 2000;

/// Each experiment's data against the model at the start and the result, thinned
/// for the file. A model that cannot be run there (a replay diverging at the start
/// values) costs the charts, said in a note, never the result.
fn comparisons(
    config: &Config,
    result: &IdentifyResult,
    fitted: &Params,
    quiet: bool,
) -> Vec<Comparison> {
    let all = start_params(&config.base, result).and_then(|start| {
        Ok(comparison::compare_all(
            &config.experiments,
            &start,
            fitted,
        )?)
    });
    match all {
        Ok(all) => all
            .into_iter()
            .map(|c| c.thinned(MAX_RECORDED_POINTS))
            .collect(),
        Err(e) => {
            if !quiet {
                eprintln!("note: no charts of the fit against the data: {e:#}");
            }
            Vec::new()
        }
    }
}

/// The parameters the search started from: the base set with the recorded start
/// values (a direct estimate may have replaced the base's).
fn start_params(base: &Params, result: &IdentifyResult) -> anyhow::Result<Params> {
    let mut p = base.clone();
    for (name, &v) in &result.initial {
        p.set(name, v)?;
    }
    Ok(p)
}

/// One SVG per comparison beside the result: FILE-1.svg, FILE-2.svg, … in order.
fn write_plots(out: &Path, comparisons: &[Comparison]) -> anyhow::Result<()> {
    let stem = out.with_extension("");
    for (k, c) in comparisons.iter().enumerate() {
        let path = PathBuf::from(format!("{}-{}.svg", stem.display(), k + 1));
        rtid::report::identify::comparison(c).write(&path)?;
    }
    Ok(())
}
