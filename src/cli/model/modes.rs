//! `rtid modes`: natural frequencies of the linearised drive.

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::ModelArgs;
use rtid::model::modes;

pub const LONG_ABOUT: &str = "\
Natural frequencies and mode shapes of the linearised drive: meshes without backlash, \
no Coulomb friction, no gear fluctuation.

Two boundary conditions:
  motor held (clamped)  the motor angle fixed. The table/motor amplitude ratio measured \
in the frequency-response test peaks at these modes (damped), so these are the ones to \
compare with measured resonances (the paper: 230/280 Hz worm, 270/430 Hz roller cam).
  motor free            the whole drive floating; the rigid-body mode (0 Hz) is omitted.

Example:
  rtid modes --preset worm-gear --set Kw=1e6 --json";

/// Arguments of `rtid modes`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Print JSON {\"clamped_hz\": [...], \"free_hz\": [...], ...} instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress display or notes on stderr (the command is quick: it has no
    /// progress bar; accepted like every command's `--quiet`, for scripts).
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.model.load()?;
    let m = modes::modes(&p)?;
    if a.json {
        println!("{}", rtid::io::json::pretty(&m)?);
        return Ok(());
    }
    println!(
        "{} ({} topology): natural frequencies of the linearised drive",
        p.name, p.topology
    );
    for (title, hz, shapes, dofs) in [
        (
            "motor held",
            &m.clamped_hz,
            &m.clamped_shapes,
            &m.clamped_dofs,
        ),
        ("motor free", &m.free_hz, &m.free_shapes, &m.free_dofs),
    ] {
        let mut t = Table::new();
        t.load_preset(UTF8_FULL_CONDENSED);
        let mut header = vec![format!("{title}: Hz")];
        header.extend(dofs.iter().map(|d| format!("shape {d}")));
        t.set_header(header);
        for (f, shape) in hz.iter().zip(shapes) {
            let mut row = vec![format!("{f:.1}")];
            row.extend(shape.iter().map(|v| format!("{v:+.3}")));
            t.add_row(row);
        }
        println!("{t}");
    }
    Ok(())
}
