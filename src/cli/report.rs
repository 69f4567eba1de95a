//! `rtid report`: one self-contained HTML page of identification results, ISO 230-2
//! positioning tests and sweeps, for the archive or the acceptance record.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

use rtid::identify::IdentifyResult;
use rtid::report::html::{self, Options, Tolerances};

pub const LONG_ABOUT: &str = "\
Writes one HTML page with a section per input file and a table of contents. The page is \
self-contained (inline CSS and SVG charts, nothing fetched from the network), so it can \
be mailed, archived or printed to A4 from a browser (each section starts a new page).

Each FILE is recognised by its content:
  identification result (`rtid identify --out fit.json`)   the command line and rtid \
version that ran the fit, mechanism, method, cost, evaluations, wall time and how the \
search ended; each input file with the SHA-256 recorded when it was fitted and whether \
the file now is the same, CHANGED, or \"not found\" (neither beside the result nor in \
the current folder); every \
fitted parameter's start, identified value, standard error (absolute and %), bounds, and \
the profile (--profile) and bootstrap (--resample) intervals when the fit has them; the \
correlation matrix as a heat map (red positive, blue negative; near ±1 the data cannot \
tell two parameters apart); each experiment's data against the model at the start and \
identified values (gain over frequency, torque over time, a servo trace's effort and \
following error replayed); its scaled residuals against their index (a \
pattern instead of noise: the model misses something); the profiles' charts; the \
warnings in words.
  positioning experiment (a manifest with \"kind\": \"positioning\")   the ISO 230-2 \
evaluation that `rtid evaluate` prints: per target and direction x̄↑, x̄↓, s↑, s↓, Bi, x̄i, \
R↑i, R↓i, Ri; for the axis B, B̄, R↑, R↓, R, E↑, E↓, E, M, A↑, A↓, A (arc-seconds on a \
rotary axis, µm on a linear one); the deviation chart (the paper's Fig. 10); and the \
acceptance verdict: PASS when the bidirectional accuracy A is within the tolerance, FAIL \
above it. Give --tolerance-arcsec for rotary axes, --tolerance-um for linear ones; \
without one the page says \"no tolerance given\".
  sweep file (`rtid sweep --out s.csv`)   the design (method, settings, factors and \
ranges), the indices table (local sensitivities, Morris μ*/μ/σ or Sobol S1/ST with 95 % \
intervals) and the tornado charts (grid plots for a grid), as `rtid sweep` computes them.

With two or more identification results, a last section compares them as `rtid select` \
does: AIC, AICc, BIC, Akaike weights and the F-tests of nested fits (or says why fits of \
other data are not compared).

A file of any other kind, unreadable or malformed stops the report with an error naming \
it. --out is written atomically and may not be one of the inputs.

Examples:
  rtid report fit.json --out report.html
  rtid report fit.json runs/worm/positioning.json s.csv --tolerance-arcsec 20 --out report.html
  rtid report runs/linear/positioning.json --tolerance-um 8 --title \"Axis X acceptance\" --out x.html";

/// Arguments of `rtid report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Identification results, positioning manifests and sweep files, in page order.
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,
    /// The HTML page to write.
    #[arg(long, value_name = "FILE.html")]
    pub out: PathBuf,
    /// The page's title (default: "rtid report").
    #[arg(long, value_name = "TEXT")]
    pub title: Option<String>,
    /// Acceptance tolerance of A on rotary axes, arc-seconds.
    #[arg(long, value_name = "X")]
    pub tolerance_arcsec: Option<f64>,
    /// Acceptance tolerance of A on linear axes, µm.
    #[arg(long, value_name = "X")]
    pub tolerance_um: Option<f64>,
    /// Print nothing on success.
    #[arg(long)]
    pub quiet: bool,
    /// Print {"out", "sections": [{"file", "kind"}]} as JSON.
    #[arg(long)]
    pub json: bool,
}

impl Args {
    /// Validates the options into the sections' options.
    fn options(&self) -> anyhow::Result<Options> {
        for (option, value) in [
            ("--tolerance-arcsec", self.tolerance_arcsec),
            ("--tolerance-um", self.tolerance_um),
        ] {
            if let Some(v) = value {
                if !(v.is_finite() && v > 0.0) {
                    bail!("{option} {v}: must be a positive number");
                }
            }
        }
        Ok(Options {
            tolerances: Tolerances {
                arcsec: self.tolerance_arcsec,
                um: self.tolerance_um,
            },
        })
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let options = a.options()?;
    let inputs: Vec<&Path> = a.files.iter().map(PathBuf::as_path).collect();
    crate::cli::common::inputs::refuse_overwrite("--out", &a.out, &inputs)?;
    let loaded = a
        .files
        .iter()
        .map(|f| html::load(f, &options))
        .collect::<Result<Vec<_>, _>>()?;
    let fits: Vec<(String, IdentifyResult)> = (a.files.iter().zip(&loaded))
        .filter_map(|(f, l)| Some((f.display().to_string(), l.fit.clone()?)))
        .collect();
    let predictions: Vec<(String, rtid::prediction::Prediction)> = (a.files.iter().zip(&loaded))
        .filter_map(|(f, l)| Some((html::prediction::file_name(f), l.prediction.clone()?)))
        .collect();
    let records: Vec<html::prediction::Measured> =
        loaded.iter().filter_map(|l| l.measured.clone()).collect();
    let mut sections: Vec<html::Section> = loaded.into_iter().map(|l| l.section).collect();
    sections.extend(html::selection::section(&fits));
    sections.extend(html::prediction::comparison(&predictions, &records));
    let title = a.title.as_deref().unwrap_or("rtid report");
    let page = html::page(title, &sections);
    rtid::io::atomic::write(&a.out, page.as_bytes())
        .with_context(|| format!("writing {}", a.out.display()))?;
    if a.json {
        let v = serde_json::json!({
            "out": a.out,
            "sections": sections.iter().map(|s| serde_json::json!({
                "file": s.file,
                "kind": s.kind.name(),
            })).collect::<Vec<_>>(),
        });
        println!("{}", rtid::io::json::pretty(&v)?);
    } else if !a.quiet {
        println!("wrote {}", a.out.display());
    }
    Ok(())
}
