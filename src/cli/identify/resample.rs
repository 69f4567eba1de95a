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
/// replicates' bias and spread ("not determined" where replicates ran to a bound).
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
        let (interval, relative) = match i.at_bound {
            Some(a) => (
                "not determined".into(),
                format!("{} of {} at its {} bound", a.replicates, s.fitted, a.side),
            ),
            None => (
                format!("{:.4e} … {:.4e}", i.lower, i.upper),
                format!("{} / {}", rel(i.lower), rel(i.upper)),
            ),
        };
        t.add_row([
            name.clone(),
            format!("{v:.5e}"),
            interval,
            relative,
            format!("{:.2e}", i.standard_error),
            format!("{:+.2e}", i.bias),
            se.map_or("—".into(), |s| {
                format!("{:.4e} … {:.4e}", v - 1.96 * s, v + 1.96 * s)
            }),
        ]);
    }
    Some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtid::identify::result::resampling::{AtBound, Interval, Resampling};

    #[test]
    fn a_parameter_whose_replicates_ran_to_a_bound_has_no_interval_in_the_table() {
        let text = include_str!("../../../fixtures/predict/worm-gear/fit.json");
        let mut fit: IdentifyResult = serde_json::from_str(text).unwrap();
        let interval = |lower: f64, upper: f64, at_bound| Interval {
            lower,
            upper,
            standard_error: 0.1 * (upper - lower),
            bias: 0.0,
            at_bound,
        };
        let side = rtid::identify::result::warning::Side::Lower;
        let at = AtBound {
            side,
            replicates: 4,
        };
        fit.resampling = Some(Resampling {
            method: "residual block bootstrap".into(),
            level: 0.95,
            asked: 12,
            fitted: 12,
            block_lengths: vec![],
            intervals: [
                ("fm".to_string(), interval(0.1, 0.2, None)),
                ("theta_bw".to_string(), interval(8e-6, 4.6e-5, Some(at))),
            ]
            .into(),
            values: Default::default(),
            notes: vec![],
        });
        let table = resample_table(&fit).unwrap().to_string();
        let row = |name: &str| {
            (table.lines())
                .find(|l| l.contains(name))
                .unwrap_or_else(|| panic!("no row {name} in\n{table}"))
                .to_string()
        };
        assert!(row("theta_bw").contains("not determined"), "{table}");
        assert!(
            row("theta_bw").contains("4 of 12 at its lower bound"),
            "{table}"
        );
        assert!(row("fm").contains("1.0000e-1 … 2.0000e-1"), "{table}");
    }
}
