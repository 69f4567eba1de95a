//! The closed speed loops of the folders `rtid compare` reads: a drive's measurement
//! (`rtid import` of its measuring function) beside the model's with some settings
//! (`rtid experiment speed-loop [--tune FILE]`), as rows of the table, a field of the
//! JSON and one Bode plot of all of them (`--plot`).

use std::path::PathBuf;

use comfy_table::Table;

use crate::cli::common::plot::Plot;
use rtid::report::speed_loop::{bode, Curve};
use rtid::tuning::speed_loop::measured::{is_speed_loop, MeasuredSpeedLoop, Summary};

/// A folder's speed-loop response: its lines and summary.
pub struct Found {
    pub lines: MeasuredSpeedLoop,
    pub summary: Summary,
}

/// The first speed-loop response among `sources` (a folder's manifests), if any.
pub fn find(sources: &[PathBuf]) -> anyhow::Result<Option<Found>> {
    for path in sources {
        let exp = rtid::read_experiment(path)?;
        if !is_speed_loop(&exp) {
            continue;
        }
        let lines =
            MeasuredSpeedLoop::of(&exp).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let summary = lines.summary();
        return Ok(Some(Found { lines, summary }));
    }
    Ok(None)
}

/// The table's speed-loop rows, where a folder has one.
pub fn rows(t: &mut Table, found: &[Option<Found>]) {
    if found.iter().all(Option::is_none) {
        return;
    }
    type Cell = fn(&Summary) -> String;
    let rows: [(&str, Cell); 2] = [
        ("Speed loop −3 dB (phase there)", |s| {
            match (s.bandwidth_hz, s.phase_at_bandwidth_deg) {
                (Some(f), Some(p)) => format!("{f:.1} Hz ({p:.0}°)"),
                _ => "none in its lines".into(),
            }
        }),
        ("Speed loop peak below it", |s| {
            format!("{:+.2} dB at {:.1} Hz", s.peak_db, s.peak_hz)
        }),
    ];
    for (name, cell) in rows {
        let mut row = vec![name.to_string()];
        row.extend(
            found
                .iter()
                .map(|f| f.as_ref().map_or("—".into(), |f| cell(&f.summary))),
        );
        t.add_row(row);
    }
}

/// All folders' speed loops on one Bode plot, each named by its folder.
pub fn plot(plot: &Plot, found: &[(&PathBuf, Option<&Found>)]) -> anyhow::Result<()> {
    /// A folder's name, its gains and phases, and its lines.
    type Named<'a> = (String, (Vec<f64>, Vec<f64>), &'a Found);
    let bodes: Vec<Named> = found
        .iter()
        .filter_map(|&(dir, f)| Some((dir.display().to_string(), f?.lines.bode(), f?)))
        .collect();
    if bodes.is_empty() {
        return Ok(());
    }
    let curves: Vec<Curve> = bodes
        .iter()
        .map(|(name, (gain, phase), f)| Curve {
            name,
            frequency_hz: &f.lines.frequency_hz,
            gain_db: gain,
            phase_deg: phase,
            measured: f.lines.noise_stated,
        })
        .collect();
    plot.write(&bode("closed speed loops", &curves), "")?;
    Ok(())
}
