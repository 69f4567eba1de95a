//! `rtid design`: which test to run next, ranked by the standard errors it would
//! give the fitted parameters.

use std::collections::BTreeMap;

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use rtid::experiments::fluctuation::FluctuationTest;
use rtid::experiments::frequency_response::FrequencyTest;
use rtid::experiments::torque_curve::TorqueTest;
use rtid::identify::design::{self, Assessed, Candidate, Criterion, Test};

use crate::cli::experiment::check;
use crate::cli::{common::progress, ModelArgs};

pub const LONG_ABOUT: &str = "\
Which experiment should I run next? For a parameter set, the parameters to fit and candidate \
tests, rtid runs each candidate on the model (the nonlinear virtual test: backlash and \
friction included), takes the Jacobian of the scaled residuals that `rtid identify` would fit \
to it by default, and predicts from the Fisher information JᵀJ/σ² the standard errors and \
correlations that fit would have. σ (--noise) is the measurement error in units of each \
objective's scale: 0.1 % of a resonance, 0.1 dB of gain, 1 % of the torque's RMS, 0.05° of an \
unbalance step. Candidates rank by --criterion d (det(cov)^(1/2k): the geometric mean of the \
relative standard errors along the principal axes; small when every combination is pinned) or \
a (the RMS relative standard error). A candidate that cannot determine the fitted set (JᵀJ \
singular) ranks last without a score. Candidates run in parallel (docs/identification.md).

Candidates (--candidate, repeatable), KIND:key=value,… (defaults in brackets):
  frequency-response  amplitude_nm [5], preload_nm [0], from_hz [10], to_hz [600], step_hz \
[10], refine_step_hz [1]
  torque-curve        amplitude_deg [30], period_s [3], periods [2]
  unbalance           mass_kg [10], radius_m [0.1], speed_deg_per_min [360]

Examples:
  rtid design --preset worm-gear --fit Kw,Kg \\
      --candidate frequency-response:amplitude_nm=5,from_hz=150,to_hz=260,step_hz=2 \\
      --candidate frequency-response:amplitude_nm=20,preload_nm=2000,from_hz=150,to_hz=260,step_hz=2
  rtid design --preset worm-gear --fit ft --candidate torque-curve \\
      --candidate unbalance:mass_kg=10,radius_m=0.1 --json";

/// Arguments of `rtid design`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The parameters the experiment is to determine, comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    pub fit: Vec<String>,
    /// A candidate test, KIND:key=value,… (see above); two or more.
    #[arg(long = "candidate", value_name = "KIND:SETTINGS", required = true)]
    pub candidates: Vec<String>,
    /// Measurement error in units of the objectives' scales.
    #[arg(long, default_value_t = 1.0)]
    pub noise: f64,
    /// Ranking: d (D-optimal) or a (A-optimal).
    #[arg(long, value_enum, default_value = "d")]
    pub criterion: CriterionArg,
    /// Print the ranking as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// `--criterion`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CriterionArg {
    D,
    A,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let params = a.model.load()?;
    check::positive(a.noise, "--noise")?;
    let candidates = a
        .candidates
        .iter()
        .map(|c| candidate(c))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let criterion = match a.criterion {
        CriterionArg::D => Criterion::D,
        CriterionArg::A => Criterion::A,
    };
    let bar = progress::bar(candidates.len() as u64, "candidates", a.quiet);
    let request = design::Request {
        params: &params,
        fit: &a.fit,
        noise: a.noise,
        criterion,
        on_done: &|| bar.inc(1),
    };
    let ranked = design::rank(&request, &candidates)?;
    bar.finish_and_clear();
    if a.json {
        let out = serde_json::json!({
            "criterion": criterion,
            "noise": a.noise,
            "fit": a.fit,
            "candidates": rtid::io::json::value(&ranked)?,
        });
        println!("{}", rtid::io::json::pretty(&out)?);
    } else {
        println!("{}", table(&ranked, &a.fit));
    }
    Ok(())
}

/// The settings of a candidate: its keys, each a finite number, checked against
/// `allowed` (name, default).
fn settings(
    text: &str,
    rest: &str,
    allowed: &[(&str, f64)],
) -> anyhow::Result<BTreeMap<String, f64>> {
    let mut out: BTreeMap<String, f64> = allowed.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    for pair in rest.split(',').filter(|p| !p.trim().is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .with_context(|| format!("--candidate {text}: `{pair}` is not key=value"))?;
        let key = key.trim();
        if !out.contains_key(key) {
            let keys: Vec<&str> = allowed.iter().map(|(k, _)| *k).collect();
            bail!(
                "--candidate {text}: unknown setting `{key}` (expected {})",
                keys.join(", ")
            );
        }
        let v = match value.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            _ => bail!("--candidate {text}: {key}=`{value}` is not a finite number"),
        };
        out.insert(key.to_string(), v);
    }
    Ok(out)
}

/// Parses one `--candidate`.
fn candidate(text: &str) -> anyhow::Result<Candidate> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    let option = |key: &str| format!("--candidate {text}: {key}");
    let test = match kind.trim() {
        "frequency-response" => {
            let s = settings(
                text,
                rest,
                &[
                    ("amplitude_nm", 5.0),
                    ("preload_nm", 0.0),
                    ("from_hz", 10.0),
                    ("to_hz", 600.0),
                    ("step_hz", 10.0),
                    ("refine_step_hz", 1.0),
                ],
            )?;
            let from = check::positive(s["from_hz"], &option("from_hz"))?;
            let step = check::positive(s["step_hz"], &option("step_hz"))?;
            (
                s.clone(),
                Test::FrequencyResponse(FrequencyTest {
                    frequencies_hz: check::frequency_grid(from, s["to_hz"], step)?,
                    amplitude_nm: check::positive(s["amplitude_nm"], &option("amplitude_nm"))?,
                    preload_nm: s["preload_nm"],
                    refine_step_hz: check::non_negative(
                        s["refine_step_hz"],
                        &option("refine_step_hz"),
                    )?,
                    ..FrequencyTest::default()
                }),
            )
        }
        "torque-curve" => {
            let s = settings(
                text,
                rest,
                &[("amplitude_deg", 30.0), ("period_s", 3.0), ("periods", 2.0)],
            )?;
            let test = TorqueTest {
                amplitude: check::positive(s["amplitude_deg"], &option("amplitude_deg"))?
                    .to_radians(),
                period: check::positive(s["period_s"], &option("period_s"))?,
                periods: check::positive(s["periods"], &option("periods"))?,
                ..TorqueTest::default()
            };
            let simulated = (test.periods + test.run_in_periods) * test.period;
            check::work(simulated, check::MAX_SIMULATED_S, "simulated seconds", &option("period_s, periods"))?;
            (s, Test::TorqueCurve(test))
        }
        "unbalance" => {
            let s = settings(
                text,
                rest,
                &[("mass_kg", 10.0), ("radius_m", 0.1), ("speed_deg_per_min", 360.0)],
            )?;
            let test = FluctuationTest {
                speed: check::positive(s["speed_deg_per_min"], &option("speed_deg_per_min"))?
                    .to_radians()
                    / 60.0,
                unbalance: Some((
                    check::positive(s["mass_kg"], &option("mass_kg"))?,
                    check::positive(s["radius_m"], &option("radius_m"))?,
                )),
                ..FluctuationTest::default()
            };
            check::work(test.duration(), check::MAX_SIMULATED_S, "simulated seconds", &option("speed_deg_per_min"))?;
            (s, Test::Unbalance(test))
        }
        other => bail!(
            "--candidate {text}: unknown test `{other}` (expected frequency-response, torque-curve or unbalance)"
        ),
    };
    Ok(Candidate {
        label: text.to_string(),
        settings: test.0,
        test: test.1,
    })
}

/// The ranking: each candidate's predicted relative standard errors, the largest
/// correlation and the score.
fn table(ranked: &[Assessed], fit: &[String]) -> Table {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let mut header = vec!["rank".to_string(), "candidate".to_string()];
    header.extend(fit.iter().map(|n| format!("se {n}")));
    header.extend(["max |correlation|".to_string(), "score".to_string()]);
    t.set_header(header);
    for (i, a) in ranked.iter().enumerate() {
        let mut row = vec![(i + 1).to_string(), a.label.clone()];
        row.extend(fit.iter().map(|n| {
            a.predicted_se
                .get(n)
                .copied()
                .flatten()
                .map_or("not determined".into(), |s| format!("{:.3} %", 100.0 * s))
        }));
        let max_corr = a
            .correlations
            .iter()
            .enumerate()
            .flat_map(|(i, row)| {
                row.iter()
                    .enumerate()
                    .filter(move |(j, _)| *j != i)
                    .map(|(_, r)| r.abs())
            })
            .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.max(r))));
        row.push(max_corr.map_or("—".into(), |r| format!("{r:.3}")));
        row.push(
            a.score
                .map_or("—".into(), |s| format!("{:.3} %", 100.0 * s)),
        );
        t.add_row(row);
    }
    t
}
