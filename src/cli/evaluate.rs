//! `rtid evaluate`: the statistics of a measured (or virtual) experiment file.

use std::path::PathBuf;

use anyhow::bail;

use super::experiment::{fluctuation, positioning};
use crate::io::experiment_file::{self, Kind};

pub const LONG_ABOUT: &str = "\
Evaluates an experiment file (a JSON manifest with its CSV, docs/experiment-files.md), \
measured on a real table or written by `rtid experiment`, and writes a plot beside it.

Kinds evaluated:
  positioning   ISO 230-2 statistics in arc-seconds: per target x̄↑, x̄↓, s↑, s↓, Bi, R↑i, \
R↓i, Ri; for the axis the reversal B and mean reversal B̄, repeatability R↑, R↓, R, \
systematic deviation E↑, E↓, E, mean deviation M, accuracy A↑, A↓, A. Plot: the paper's \
Fig. 10.
  fluctuation   deviation θt − θm·ratio over table angle per direction (ratio: the \
manifest's conditions.ratio, else Rg·Rw of the preset named in `mechanism`): mean, \
peak-to-peak, the gap between the directions (lost motion), the power spectrum over \
cycles per revolution and its dominant orders with amplitudes, the largest step. Plots: \
FILE.svg (Fig. 11) and FILE-spectrum.svg (Fig. 12).
  unbalance     as fluctuation; the step (largest change of the deviation across 0.5° of \
table angle, and where) is the backlash crossed when the unbalance moment overcomes the \
friction. Plots: FILE.svg (Fig. 14) and FILE-spectrum.svg.

Example:
  rtid evaluate runs/worm/positioning.json --json
  rtid evaluate runs/worm/fluctuation.json";

/// Arguments of `rtid evaluate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The experiment manifest.
    #[arg(value_name = "FILE.json")]
    pub file: PathBuf,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Where to write the plot (default: beside the manifest, FILE.svg).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let exp = experiment_file::read(&a.file)?;
    let plot = a
        .plot
        .clone()
        .unwrap_or_else(|| a.file.with_extension("svg"));
    match exp.manifest.kind {
        Kind::Positioning => positioning::report(&exp, &plot, a.json),
        Kind::Fluctuation | Kind::Unbalance => fluctuation::report(&exp, &plot, a.json),
        other => bail!(
            "{}: evaluating `{}` experiments is not part of this version yet (positioning, fluctuation and unbalance are)",
            a.file.display(),
            other.name()
        ),
    }
}
