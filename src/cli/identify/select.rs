//! `rtid select`: which of several identifications of the same data the data
//! support — AIC, AICc, BIC, Akaike weights, and F-tests of nested fits.

use std::path::{Path, PathBuf};

use anyhow::Context;
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use rtid::identify::selection::{self, Selection};
use rtid::identify::IdentifyResult;

pub const LONG_ABOUT: &str = "\
Compares identifications of the same data — result files of `rtid identify --out` with \
different fitted sets (does the worm need Kb fitted? does EMPS need Tload?) or models — by \
how well each fits for how many parameters it spends (docs/identification.md):

  AIC  = n·ln(SSR/n) + 2k        n residuals, k fitted parameters, SSR the cost
  AICc = AIC + 2k(k+1)/(n−k−1)   the small-sample correction (matters for n/k < 40)
  BIC  = n·ln(SSR/n) + k·ln n    a heavier price per parameter
  weight                         exp(−ΔAICc/2), normalised: each model's relative support
  F-test (nested fits)           F = ((SSR_r − SSR_f)/(k_f − k_r)) / (SSR_f/(n − k_f)) and \
its p-value: small p (< 0.05) — the added parameters lower the cost by more than noise would

Rows are ranked by AICc (by AIC when a fit has too few residuals for it); a Δ below 2 is no real preference, above 10 is decisive. The \
results must fit the same residuals: the same experiment files with the same objectives, \
weights and scales (checked; other data are refused, their costs are on other scales).

Examples:
  rtid identify fixtures/worm-gear-noisy/frequency_response.json --preset worm-gear \\
      --model linear --out kw-kg.json
  rtid identify fixtures/worm-gear-noisy/frequency_response.json --preset worm-gear \\
      --model linear --fit Kw,Kg,Kb --out kw-kg-kb.json
  rtid select kw-kg.json kw-kg-kb.json";

/// Arguments of `rtid select`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Result files of `rtid identify --out` (two or more).
    #[arg(value_name = "RESULT.json", required = true, num_args = 2..)]
    pub results: Vec<PathBuf>,
    /// Print the comparison as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress display or notes on stderr (the command is quick: it has no
    /// progress bar; accepted like every command's `--quiet`, for scripts).
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let results = a
        .results
        .iter()
        .map(|p| read(p).map(|r| (p.display().to_string(), r)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let s = selection::select(&results)?;
    if a.json {
        println!("{}", rtid::io::json::pretty(&s)?);
    } else {
        print(&s);
    }
    Ok(())
}

/// A result file.
fn read(path: &Path) -> anyhow::Result<IdentifyResult> {
    let text = rtid::io::read_input(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(rtid::io::without_bom(&text)).with_context(|| {
        format!(
            "{}: not a result file of `rtid identify --out`",
            path.display()
        )
    })
}

fn print(s: &Selection) {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "result", "fitted", "n", "k", "cost", "AIC", "AICc", "BIC", "Δ", "weight",
    ]);
    for c in &s.candidates {
        t.add_row([
            c.label.clone(),
            c.fitted.join(", "),
            c.n.to_string(),
            c.k.to_string(),
            format!("{:.4e}", c.cost),
            format!("{:.2}", c.aic),
            c.aicc.map_or("—".into(), |v| format!("{v:.2}")),
            format!("{:.2}", c.bic),
            format!("{:.2}", c.delta),
            format!("{:.3}", c.weight),
        ]);
    }
    println!("{t}");
    for n in &s.nested {
        println!(
            "F-test: {} adds {} to {}: F({}, {}) = {:.3}, p = {:.3e} — {}",
            n.full,
            n.added.join(", "),
            n.restricted,
            n.df.0,
            n.df.1,
            n.f,
            n.p_value,
            n.verdict()
        );
    }
    let name = if s.criterion == "aicc" { "AICc" } else { "AIC" };
    if s.criterion == "aic" {
        println!("ranked by AIC (Δ, weight): a fit has too few residuals for AICc (n ≤ k + 1)");
    }
    let best = &s.candidates[0];
    let second = s.candidates.get(1).map_or(f64::INFINITY, |c| c.delta);
    let strength = match second {
        d if d < 2.0 => format!("no real preference (Δ{name} < 2)"),
        d if d < 10.0 => "preferred".to_string(),
        _ => format!("decisively preferred (Δ{name} > 10)"),
    };
    println!(
        "best by {name}: {} ({}) — {strength}",
        best.label,
        best.fitted.join(", ")
    );
}
