//! `rtid params`: list, check and save parameter sets.

use std::path::PathBuf;

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::ModelArgs;
use rtid::io::params_file;
use rtid::model::PARAMS;

pub const LONG_ABOUT: &str = "\
Lists every parameter of a mechanism with its value, SI unit and meaning, the notes on \
where uncertain values come from, and the held range of each value that is uncertain or \
assumed (value·(1 ± X %), with its reason: a parameter file's `ranges`). Where such a \
parameter is held — not fitted — `rtid identify` and `rtid predict` carry its range into \
their intervals by default (`--uncertain NAME=X%` gives another, `--uncertain NAME=0%` \
holds it exactly). With --out, writes the set (after --set overrides) as a parameter file \
that every command accepts with --params.

Examples:
  rtid params --preset worm-gear
  rtid params --preset worm-gear --set theta_bw=5e-5 --out my-table.json
  rtid params --params my-table.json --json";

/// Arguments of `rtid params`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Write the parameter set to this file (atomically).
    #[arg(long, value_name = "FILE.json")]
    pub out: Option<PathBuf>,
    /// Print the parameter set as JSON.
    #[arg(long)]
    pub json: bool,
    /// No "wrote FILE" note on stderr.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.model.load()?;
    if let Some(path) = &a.out {
        params_file::write(path, &p)?;
        if !a.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    if a.json {
        println!("{}", rtid::io::json::pretty(&p)?);
        return Ok(());
    }
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(["name", "value", "unit", "meaning", "held range", "note"]);
    for s in PARAMS {
        let Some(v) = s.get(&p) else { continue };
        let note = p.notes.get(s.name).map(String::as_str).unwrap_or("");
        let range = p.ranges.get(s.name).map_or(String::new(), |r| {
            format!("±{} %", rtid::names::Num(r.percent))
        });
        t.add_row([s.name, &format!("{v:.6e}"), s.unit, s.meaning, &range, note]);
    }
    println!(
        "{} ({} topology, {} loop)",
        p.name, p.topology, p.controller.loop_mode
    );
    println!("{t}");
    if !p.ranges.is_empty() {
        println!("held ranges (carried into identify's and predict's intervals where the parameter is held):");
        for (name, r) in &p.ranges {
            println!("  {name} ±{} %: {}", rtid::names::Num(r.percent), r.reason);
        }
    }
    Ok(())
}
