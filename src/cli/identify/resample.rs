//! `rtid identify --resample`: the residual block bootstrap computed after the fit,
//! and its table.

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use rtid::identify::intervals::resample;
use rtid::identify::{IdentifyResult, Monitor};
use rtid::model::Params;

use crate::cli::common::progress;

/// The bootstrap of `result` with `replicates` replicates, each drawing the `held`
/// parameters within their ranges, added to it ([`resample::attach`]).
pub fn add_resampling(
    replicates: usize,
    held: &[(String, f64, f64)],
    result: &mut IdentifyResult,
    params: &Params,
    fit: (
        &dyn rtid::objectives::Objective,
        rtid::identify::Settings,
        Option<&rtid::identify::Replay>,
    ),
    monitor: &Monitor,
    quiet: bool,
) -> anyhow::Result<()> {
    let steps = replicates * fit.2.map_or(1, |r| r.steps());
    let bar = progress::bar(steps as u64, "resampling (fits)", quiet);
    let request = resample::Request {
        result,
        params,
        objective: fit.0,
        settings: fit.1,
        replay: fit.2,
        replicates,
        held,
        stop: &|| monitor.stopped(),
        on_replicate: &|| bar.inc(1),
    };
    let resampling = resample::resample(&request)?;
    bar.finish_and_clear();
    resample::attach(result, resampling);
    Ok(())
}

/// Each parameter's bootstrap interval beside ±1.96 standard errors, with the
/// replicates' bias and spread.
pub fn resample_table(r: &IdentifyResult) -> Option<Table> {
    let s = r.resampling.as_ref().filter(|s| !s.intervals.is_empty())?;
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "parameter",
        "identified",
        "95 % bootstrap interval",
        "relative",
        "bootstrap se",
        "bias",
        "±1.96 standard errors",
    ]);
    for (name, i) in &s.intervals {
        let v = r.parameters[name];
        let rel = |x: f64| format!("{:+.2} %", 100.0 * (x - v) / v.abs());
        let se = r.standard_error(name);
        t.add_row([
            name.clone(),
            format!("{v:.5e}"),
            format!("{:.4e} … {:.4e}", i.lower, i.upper),
            format!("{} / {}", rel(i.lower), rel(i.upper)),
            format!("{:.2e}", i.standard_error),
            format!("{:+.2e}", i.bias),
            se.map_or("—".into(), |s| {
                format!("{:.4e} … {:.4e}", v - 1.96 * s, v + 1.96 * s)
            }),
        ]);
    }
    Some(t)
}
