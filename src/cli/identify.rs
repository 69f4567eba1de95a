//! `rtid identify`: parameters from experiment files.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use super::ModelArgs;
use rtid::identify::comparison;
use rtid::identify::setup::ObjectiveKind;
use rtid::identify::space::parse_bound;
use rtid::identify::{identify, Config, FidelityChoice, Identified, Method, Monitor, Settings};
use rtid::io::experiment_file::{self, Experiment};
use rtid::io::params_file;
use rtid::model::Params;

pub const LONG_ABOUT: &str = "\
Identifies physical parameters of the drive — torsional stiffnesses Kw, Kg, Kb, internal \
damping Ciw, Cig, Coulomb friction fm, fw, ft, viscous damping Cm, Cw, Ct, inertias… any \
subset by name — from one or more experiment files (docs/experiment-files.md), measured on a \
rig or written by `rtid experiment`. The other parameters stay at the --preset / --params \
values.

What each experiment feeds (--objective to choose):
  frequency_response  resonance: the measured resonance frequencies (peaks of the gain curve) \
against the model's; also peak-amplitude (peak heights, dB: for Ciw, Cig), gain-curve (the \
whole gain curve, dB) and gain-near-peaks (the gain within ±3 % of each resonance).
  resonance           resonance (and peak-amplitude when the manifest has peak_gain_db).
  torque_curve        torque-curve: the motor torque of the closed-loop torque test, sample by \
sample. A torque curve determines one Coulomb and one viscous sum (fm + fw·Rg + ft·Rg·Rw, and \
the viscous alike): fit one of each.
  unbalance           unbalance-step: the table angles where the deviation θt − θm·Rg·Rw steps \
across the backlash (where the unbalance moment overcomes the table friction), model against \
measured, 0.05° per unit. It determines ft (the manifest must give mass_kg and radius_m).
Default --fit: Kw (and Kg with a spur stage) from resonances; fm and Cm from a torque curve \
(the table's friction reaches the motor divided by the ratio — 1/90 for the worm — and \
hardly shows in its torque); ft from an unbalance test. fm and ft together: give both files \
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
--method lsq (Gauss–Newton with line search; default), nelder-mead (default with a torque \
curve or an unbalance test, whose quantised encoders make finite differences rough) or pso. Ctrl-C ends the \
search and still writes the best result; with --checkpoint FILE, --resume continues.

Output: a table of parameter, start, identified ± standard error; warnings when the data \
cannot separate parameters (|correlation| > 0.95 or a singular JᵀJ), when a parameter ends \
on a bound, or when the fit misses the measured resonances; --out result.json with \
everything (parameters, initial, bounds, cost, residuals per experiment, evaluations, \
wall_time_s, termination, uncertainty); an SVG per experiment of the fit against the data; \
--save-params FILE for `--params FILE` everywhere.

Examples:
  rtid identify fixtures/worm-gear/frequency_response.json --preset worm-gear --out fit.json
  rtid identify fixtures/worm-gear/frequency_response.json fixtures/worm-gear/torque_curve.json \\
      --preset worm-gear --fit Kw,Kg,fm,Cm --out fit.json --save-params worm-fit.json
  rtid identify fixtures/worm-gear/torque_curve.json fixtures/worm-gear/unbalance.json \\
      --preset worm-gear --fit fm,ft --out friction.json
  rtid identify fixtures/paper/worm-gear.json --preset worm-gear --fit Kw,Kg,Jt --model linear
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
    /// Objectives to use (default: by experiment kind, see above).
    #[arg(long, value_delimiter = ',', value_enum)]
    pub objective: Option<Vec<ObjectiveArg>>,
    /// Weight of each experiment in the joint cost, in the order given (default 1 each).
    #[arg(long = "weight", value_delimiter = ',', allow_negative_numbers = true)]
    pub weights: Vec<f64>,
    /// Solver (default: lsq; nelder-mead when a torque curve is fitted).
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
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

/// The solver (`--method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Gauss–Newton with line search, finite-difference Jacobian in parallel.
    Lsq,
    /// Nelder–Mead simplex.
    NelderMead,
    /// Particle swarm in the bounds.
    Pso,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Lsq => Method::Lsq,
            MethodArg::NelderMead => Method::NelderMead,
            MethodArg::Pso => Method::Pso,
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

/// An objective (`--objective`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ObjectiveArg {
    /// Relative error of the resonance frequencies.
    Resonance,
    /// dB error of the resonance peak heights.
    PeakAmplitude,
    /// dB error of the gain at every measured frequency.
    GainCurve,
    /// dB error of the gain within ±3 % of each resonance.
    GainNearPeaks,
    /// Error of the motor torque of the torque test.
    TorqueCurve,
    /// Error of the table angles where the unbalance test's deviation steps.
    UnbalanceStep,
}

impl From<ObjectiveArg> for ObjectiveKind {
    fn from(o: ObjectiveArg) -> ObjectiveKind {
        match o {
            ObjectiveArg::Resonance => ObjectiveKind::Resonance,
            ObjectiveArg::PeakAmplitude => ObjectiveKind::PeakAmplitude,
            ObjectiveArg::GainCurve => ObjectiveKind::GainCurve,
            ObjectiveArg::GainNearPeaks => ObjectiveKind::GainNearPeaks,
            ObjectiveArg::TorqueCurve => ObjectiveKind::TorqueCurve,
            ObjectiveArg::UnbalanceStep => ObjectiveKind::UnbalanceStep,
        }
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let base = a.model.load()?;
    let mut experiments = Vec::new();
    for path in &a.experiments {
        let exp = experiment_file::read(path)?;
        experiments.push((path.display().to_string(), exp));
    }
    let mut bounds = Vec::new();
    for b in &a.bounds {
        bounds.push(parse_bound(b).map_err(anyhow::Error::msg)?);
    }
    // Objectives on a closed-loop time simulation with quantised encoders: rough on
    // the scale of finite differences, and seconds per evaluation.
    let has_torque = experiments.iter().any(|(_, e): &(String, Experiment)| {
        use rtid::io::experiment_file::Kind;
        matches!(e.manifest.kind, Kind::TorqueCurve | Kind::Unbalance)
    });
    let starts = a.starts.unwrap_or(if has_torque { 1 } else { 4 });
    anyhow::ensure!(starts >= 1, "--starts must be at least 1");
    let config = Config {
        experiments,
        base,
        fit: a
            .fit
            .iter()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect(),
        bounds,
        objectives: a
            .objective
            .as_ref()
            .map(|v| v.iter().map(|&o| o.into()).collect()),
        weights: a.weights.clone(),
        fidelity: a.fidelity.into(),
        settings: Settings {
            method: a.method.map(Method::from).unwrap_or(if has_torque {
                Method::NelderMead
            } else {
                Method::Lsq
            }),
            starts,
            seed: a.seed,
            max_iters: a.max_iters,
            ..Settings::default()
        },
        checkpoint: a.checkpoint.clone(),
        resume: a.resume,
    };
    let monitor = Arc::new(Monitor::default());
    {
        let m = Arc::clone(&monitor);
        // A second handler cannot be installed (tests run commands in-process): then
        // Ctrl-C simply ends the process, as it would without rtid's handling.
        let _ = ctrlc::set_handler(move || {
            if m.stopped() {
                std::process::exit(130);
            }
            m.stop();
            eprintln!("\nstopping: finishing the current evaluations, then writing the best result (Ctrl-C again to quit)");
        });
    }
    let spinner = spinner(&monitor, a.quiet);
    let outcome = identify(&config, &monitor);
    if let Some((bar, done, handle)) = spinner {
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        let _ = handle.join();
        bar.finish_and_clear();
    }
    let Identified { result, params } = outcome?;
    if let Some(path) = &a.out {
        result
            .write(path)
            .with_context(|| format!("writing {}", path.display()))?;
        write_plots(path, &config.experiments, &config.base, &params)?;
    }
    if let Some(path) = &a.save_params {
        let mut p = params.clone();
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
        params_file::write(path, &p).with_context(|| format!("writing {}", path.display()))?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        print_summary(&result);
    }
    Ok(())
}

type Spinner = (
    indicatif::ProgressBar,
    Arc<std::sync::atomic::AtomicBool>,
    std::thread::JoinHandle<()>,
);

/// A live line: evaluations and the best cost so far.
fn spinner(monitor: &Arc<Monitor>, quiet: bool) -> Option<Spinner> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed} identifying: {msg}")
            .expect("a valid template"),
    );
    let done = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let (b, d, m) = (bar.clone(), Arc::clone(&done), Arc::clone(monitor));
    let handle = std::thread::spawn(move || {
        while !d.load(std::sync::atomic::Ordering::Relaxed) {
            let best = m.best().map_or("—".into(), |b| format!("{:.4e}", b.cost));
            b.set_message(format!("{} evaluations, best cost {best}", m.evaluations()));
            b.tick();
            std::thread::sleep(Duration::from_millis(150));
        }
    });
    Some((bar, done, handle))
}

fn print_summary(r: &rtid::identify::result::IdentifyResult) {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "parameter",
        "start",
        "identified",
        "± standard error",
        "bounds",
    ]);
    let se = |name: &str| {
        r.uncertainty
            .as_ref()
            .and_then(|u| u.standard_errors.iter().find(|(n, _)| n == name))
            .and_then(|(_, s)| *s)
    };
    for (name, v) in &r.parameters {
        let b = r.bounds[name];
        t.add_row([
            name.clone(),
            format!("{:.5e}", r.initial[name]),
            format!("{v:.5e}"),
            se(name).map_or("—".into(), |s| {
                format!("{s:.2e} ({:.2} %)", 100.0 * s / v.abs())
            }),
            format!("{:.3e}..{:.3e}", b[0], b[1]),
        ]);
    }
    println!("{t}");
    for res in &r.residuals {
        let extra = match &res.detail {
            Some(d) if d.get("model_hz").is_some() => format!(
                "  measured {} Hz, model {} Hz",
                list(&d["measured_hz"]),
                list(&d["model_hz"])
            ),
            Some(d) if d.get("error_db").is_some() => {
                format!("  errors {} dB", list(&d["error_db"]))
            }
            Some(d) if d.get("measured_step_deg").is_some() => {
                let model: Vec<String> = d["model_step_deg"]
                    .as_array()
                    .map(|a| {
                        a.iter()
                            .map(|x| x.as_f64().map_or("none".into(), |v| format!("{v:.3}")))
                            .collect()
                    })
                    .unwrap_or_default();
                format!(
                    "  step angles measured {} °, model {} °",
                    list3(&d["measured_step_deg"]),
                    model.join(", ")
                )
            }
            Some(d) if d.get("rms_error_nm").is_some() => {
                format!(
                    "  RMS error {:.4} N·m",
                    d["rms_error_nm"].as_f64().unwrap_or(f64::NAN)
                )
            }
            _ => String::new(),
        };
        println!(
            "{} [{}]: RMS scaled residual {:.3} (unit: {}){extra}",
            res.source, res.objective, res.rms, res.scale
        );
    }
    println!(
        "cost {:.4e}, {} evaluations, {:.2} s, {} ({}, {} model)",
        r.cost, r.evaluations, r.wall_time_s, r.termination, r.method, r.fidelity
    );
    if let Some(u) = &r.uncertainty {
        if u.names.len() > 1 {
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
            println!("{c}");
        }
    }
    for w in &r.warnings {
        println!("warning: {w}");
    }
}

fn list3(v: &serde_json::Value) -> String {
    v.as_array()
        .map(|a| {
            a.iter()
                .map(|x| format!("{:.3}", x.as_f64().unwrap_or(f64::NAN)))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default()
}

fn list(v: &serde_json::Value) -> String {
    v.as_array()
        .map(|a| {
            a.iter()
                .map(|x| format!("{:.2}", x.as_f64().unwrap_or(f64::NAN)))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default()
}

/// One SVG per experiment beside the result: the data and the identified model.
fn write_plots(
    out: &Path,
    experiments: &[(String, Experiment)],
    start: &Params,
    fitted: &Params,
) -> anyhow::Result<()> {
    let stem = out.with_extension("");
    for (k, (file, exp)) in experiments.iter().enumerate() {
        if let Some(c) = comparison::compare(file, exp, start, fitted)? {
            let path = PathBuf::from(format!("{}-{}.svg", stem.display(), k + 1));
            rtid::report::identify::comparison(&c).write(&path)?;
        }
    }
    Ok(())
}
