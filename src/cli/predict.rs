//! `rtid predict`: the effect of a compensation and a tuning on the identified model,
//! with the fit's uncertainty carried through (docs/compensation.md).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::Context;
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::common::inputs::refuse_overwrite;
use crate::cli::common::{self, interrupt, model_args, progress};
use crate::cli::ModelArgs;
use rtid::experiments::positioning::ensemble;
use rtid::identify::result::IdentifyResult;
use rtid::io::compensation_file;
use rtid::model::Params;
use rtid::names::Num;
use rtid::prediction::request::{self, Request, RequestError};
use rtid::prediction::{self, draws, Case, DrawSource, Prediction, Setup};

pub const LONG_ABOUT: &str = "\
The effect of settings predicted on the identified model, with the fit's uncertainty: \
parameter sets are drawn from the fit (FIT.json of `rtid identify --out`) — normal draws \
from its standard errors and correlations (in log space for a parameter with positive \
bounds), or its bootstrap replicates (`identify --resample`) — and the virtual test runs \
on each, before (the model's own controller, no compensation) and after (with \
--compensation and --tune). Each output is given at the fit's values with the central \
interval of the draws: \"A after 3.6 [3.4 … 3.9]″\".

The model is the base the fit started from (--preset or --params, as given to identify) \
with the fit's values set. The interval carries the fitted parameters' uncertainty and \
that of the held parameters: the parameter set's held ranges (`rtid params` shows a \
preset's) — those `identify` carried drawn with the fitted parameters moving as the \
fit said, or as the replicates drew them; the others, and those given here with \
--uncertain NAME=X%, uniformly within value·(1 ± X %); 0 % holds one exactly. The \
draws' interval is joined with its reflection about the value at the fit (the basic \
bootstrap interval): the draws' offset from the fit may be the fit's offset from the \
machine, the other way, and the interval always holds the value at the fit. Every other \
parameter keeps its value, and the output names them. On fifteen worm gears that are \
not the preset, the default chain (identify → compensate --fit → predict, no interval \
option) held 179 of 180 values (docs/validation.md). A fitted parameter \
the data did not determine (no standard error) cannot be drawn: the command refuses \
until it is held at its value (--hold NAME), and then says so.

Tests (--tests, comma-separated): positioning (ISO 230-2: B̄, B, E, M, R, A in \
arc-seconds or µm; --runs per direction) and servo (the check of `rtid tune`: a 1° step's \
overshoot in %, the following error at 10°/s and the reversal spike in arc-seconds or \
µm, the peak torque or force). The draws run in parallel; Ctrl-C stops them and the prediction is made \
from those done.

Examples:
  rtid identify fixtures/worm-gear/torque_curve.json fixtures/worm-gear/unbalance.json \\
      --preset worm-gear --fit theta_bw,fm,fw --out fit.json --save-params fit-params.json
  rtid compensate --fit fit.json --preset worm-gear -o compensation.json
  rtid predict fit.json --preset worm-gear --compensation compensation.json --draws 40
  rtid predict fit.json --params fit-params.json --tune tuned.json --json -o prediction.json";

/// Arguments of `rtid predict`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The identification result (`rtid identify --out`).
    #[arg(value_name = "FIT.json")]
    pub fit: PathBuf,
    #[command(flatten)]
    pub model: ModelArgs,
    /// The compensation to predict (compensation.json of `rtid compensate`).
    #[arg(long, value_name = "FILE")]
    pub compensation: Option<PathBuf>,
    /// A tuned parameter file (`rtid tune -o`): its controller settings are used.
    #[arg(long, value_name = "FILE")]
    pub tune: Option<PathBuf>,
    /// The virtual tests, comma-separated.
    #[arg(long, value_name = "LIST", default_value = "positioning")]
    pub tests: String,
    /// Parameter sets drawn (normal draws; the replicates' number is the bootstrap's).
    #[arg(long, value_name = "N", default_value_t = 50)]
    pub draws: usize,
    /// Where the draws come from [default: bootstrap where the fit has replicates].
    #[arg(long, value_enum, value_name = "SOURCE")]
    pub from: Option<FromArg>,
    /// Hold a fitted parameter at its value instead of drawing it; repeatable.
    #[arg(long, value_name = "NAME")]
    pub hold: Vec<String>,
    /// A held parameter's relative half-range in place of the parameter set's own
    /// (or beside it, for one without): drawn uniformly within value·(1 ± X %)
    /// beside the fit's draws (e.g. --uncertain Kw=10% for a stiffness taken from a
    /// catalogue); 0% holds it exactly; repeatable. For one `identify` carried, this
    /// width replaces its own (the fitted parameters still move with it).
    #[arg(long, value_name = "NAME=X%")]
    pub uncertain: Vec<String>,
    /// Positioning test: runs per direction.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub runs: u32,
    /// Runs of the positioning test at the fit under perturbations that do not change
    /// the machine (where the axis comes to rest in stick, sub-count offsets of the
    /// compensation, the noise's seed); their range (largest less least) is added on
    /// each side of each interval. 0: the draws' interval alone.
    #[arg(long, value_name = "N", default_value_t = ensemble::DEFAULT_MEMBERS)]
    pub ensemble: usize,
    /// Probability of the central interval.
    #[arg(long, value_name = "P", default_value_t = 0.95)]
    pub level: f64,
    /// Seed of the normal draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Write the prediction (JSON).
    #[arg(short = 'o', long = "out", value_name = "prediction.json")]
    pub out: Option<PathBuf>,
    /// No progress bar or notes on stderr.
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum FromArg {
    Covariance,
    Bootstrap,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    refuse_outputs(&a)?;
    let fit = model_args::read_fit(&a.fit)?;
    let mut params = a.model.load()?;
    model_args::apply_fit(&mut params, &fit, &a.fit)?;
    let (source, draws, cases) = prepare(&a, &fit, &params)?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    interrupt::on_interrupt(move || !flag.swap(true, Ordering::SeqCst));
    let bar = progress::bar(draws.sets.len() as u64, "draws", a.quiet);
    let setup = Setup {
        params: &params,
        draws: &draws,
        source,
        held: a.hold.clone(),
        level: a.level,
        cases: &cases,
        ensemble: match a.ensemble {
            0 => None,
            n => Some(
                ensemble::Ensemble::new(n).map_err(|e| anyhow::anyhow!("--ensemble {n}: {e}"))?,
            ),
        },
    };
    let p = prediction::predict(&setup, &|| bar.inc(1), &stop)?;
    bar.finish_and_clear();
    if let Some(out) = &a.out {
        let text = rtid::io::json::pretty(&p)?;
        rtid::io::atomic::write(out, format!("{text}\n").as_bytes())
            .with_context(|| format!("writing {}", out.display()))?;
    }
    if a.json {
        println!("{}", rtid::io::json::pretty(&p)?);
    } else {
        print(&a, &p, &params);
    }
    Ok(())
}

fn refuse_outputs(a: &Args) -> anyhow::Result<()> {
    let Some(out) = &a.out else { return Ok(()) };
    let mut inputs: Vec<&Path> = vec![&a.fit];
    inputs.extend(a.model.params.as_deref());
    inputs.extend(a.compensation.as_deref());
    inputs.extend(a.tune.as_deref());
    refuse_overwrite("-o", out, &inputs)
}

/// The draws, their source and the cases the options ask for
/// (`rtid::prediction::request`), each refusal naming its option.
fn prepare(
    a: &Args,
    fit: &IdentifyResult,
    params: &Params,
) -> anyhow::Result<(DrawSource, draws::Draws, Vec<Case>)> {
    let uncertain = common::uncertain::parse(&a.uncertain)?;
    let compensation = match &a.compensation {
        Some(path) => {
            let file = compensation_file::read(path)?;
            file.check_axis(path, params.axis)?;
            Some(file.compensation)
        }
        None => None,
    };
    let request = Request {
        fit,
        params,
        compensation,
        controller: a
            .tune
            .as_deref()
            .map(|t| model_args::tuned_controller(t, params))
            .transpose()?,
        tests: a.tests.split(',').map(str::to_string).collect(),
        draws: a.draws,
        from: a.from.map(|f| match f {
            FromArg::Covariance => DrawSource::Covariance,
            FromArg::Bootstrap => DrawSource::Bootstrap,
        }),
        hold: a.hold.clone(),
        uncertain,
        runs: a.runs,
        seed: a.seed,
    };
    request::prepare(&request).map_err(|e| match e {
        RequestError::Draw(e) => anyhow::Error::new(e).context(a.fit.display().to_string()),
        RequestError::Range(e) => anyhow::anyhow!("{e}"),
        other => anyhow::anyhow!("--{other}"),
    })
}

fn print(a: &Args, p: &Prediction, params: &Params) {
    let source = match p.source {
        DrawSource::Covariance => "normal draws from the fit's standard errors and correlations",
        DrawSource::Bootstrap => "the fit's bootstrap replicates",
    };
    println!(
        "{}: {} of {} parameter sets ({source}; {} drawn: {}), {} % central intervals",
        a.fit.display(),
        p.completed,
        p.asked,
        p.drawn.len(),
        p.drawn.join(", "),
        Num(p.level * 100.0)
    );
    if p.ensemble > 0 {
        println!(
            "each interval widened on each side by the range of the positioning test's own runs at the fit: {} runs under perturbations that do not change the machine (--ensemble)",
            p.ensemble
        );
    }
    print_tables(p);
    if !a.quiet {
        notes(p, params);
    }
}

fn print_tables(p: &Prediction) {
    for (test, cases) in p.by_test() {
        let mut t = Table::new();
        t.load_preset(UTF8_FULL_CONDENSED);
        let mut header = vec![format!("{test}, {}", cases[0].unit)];
        header.extend(cases.iter().map(|c| c.case.clone()));
        t.set_header(header);
        for (k, v) in cases[0].values.iter().enumerate() {
            let mut row = vec![v.name.replace("B_mean", "B̄")];
            row.extend(cases.iter().map(|c| cell(&c.values[k])));
            t.add_row(row);
        }
        println!("{t}");
    }
}

fn cell(v: &prediction::Predicted) -> String {
    match (v.lower, v.upper) {
        (Some(lo), Some(hi)) => format!("{:.2} [{:.2} … {:.2}]", v.nominal, lo, hi),
        _ => format!("{:.2} (no interval)", v.nominal),
    }
}

fn notes(p: &Prediction, params: &Params) {
    if !p.held.is_empty() {
        eprintln!(
            "note: held at the fit's values, not drawn: {}",
            p.held.join(", ")
        );
    }
    let fixed = p.conditional_on(params);
    eprintln!(
        "note: the intervals carry the uncertainty of {} only; the model's other {} parameters keep their values, which these intervals take as exact",
        p.drawn.join(", "),
        fixed.len()
    );
    if p.rejected > 0 {
        eprintln!(
            "note: {} normal draws fell outside the fit's bounds and were drawn again",
            p.rejected
        );
    }
    for n in &p.notes {
        eprintln!("note: {n}");
    }
}
