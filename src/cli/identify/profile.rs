//! `rtid identify --profile`: the profiles computed after the fit, their table and
//! their plots.

use std::path::{Path, PathBuf};

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use rtid::identify::intervals::profile;
use rtid::identify::result::warning::Coded;
use rtid::identify::{IdentifyResult, Monitor};
use rtid::model::Params;

use crate::cli::common::progress;

/// The profiles of `names` (comma-separated; empty: every fitted parameter), added
/// to `result` with their warnings. A progress bar counts the fitted points.
pub fn add_profiles(
    names: &str,
    result: &mut IdentifyResult,
    params: &Params,
    fit: (
        &dyn rtid::objectives::Objective,
        rtid::identify::Settings,
        rtid::objectives::Smoothness,
    ),
    monitor: &Monitor,
    quiet: bool,
) -> anyhow::Result<()> {
    let names: Vec<String> = if names.trim().is_empty() {
        result.parameters.keys().cloned().collect()
    } else {
        names.split(',').map(|n| n.trim().to_string()).collect()
    };
    let bar = progress::bar((names.len() * 2 * 6) as u64, "profiling (fits)", quiet);
    let request = profile::Request {
        result,
        params,
        objective: fit.0,
        settings: fit.1,
        smoothness: fit.2,
        names,
        stop: &|| monitor.stopped(),
        on_point: &|| {
            bar.inc(1);
            if bar.length().is_some_and(|n| bar.position() >= n) {
                bar.inc_length(2);
            }
        },
    };
    let (profiles, warnings) = profile::profiles(&request)?;
    bar.finish_and_clear();
    result.warnings.extend(warnings.into_iter().map(Coded));
    profile::attach(result, profiles);
    Ok(())
}

/// One plot per profile beside `out`: the likelihood-ratio statistic against the
/// held value, with the 95 % threshold.
pub fn write_profile_plots(out: &Path, result: &IdentifyResult) -> anyhow::Result<()> {
    let stem = out.with_extension("");
    for (name, p) in result.profiles.iter().flatten() {
        let path = PathBuf::from(format!("{}-profile-{name}.svg", stem.display()));
        rtid::report::identify::profile(name, p).write(&path)?;
    }
    Ok(())
}

/// Each profiled parameter's likelihood-ratio interval beside the one the standard
/// error implies (±1.96 se): where they differ, the cost is not the quadratic bowl
/// the standard error assumes.
pub fn profile_table(r: &IdentifyResult) -> Option<Table> {
    let profiles = r.profiles.as_ref().filter(|p| !p.is_empty())?;
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "parameter",
        "identified",
        "95 % profile interval",
        "relative",
        "±1.96 standard errors",
        "profile points",
    ]);
    for (name, p) in profiles {
        let v = r.parameters[name];
        let end = |e: Option<f64>| e.map_or("open".to_string(), |x| format!("{x:.4e}"));
        let rel = |e: Option<f64>| {
            e.map_or("—".to_string(), |x| {
                format!("{:+.2} %", 100.0 * (x - v) / v.abs())
            })
        };
        let se = r.standard_error(name);
        t.add_row([
            name.clone(),
            format!("{v:.5e}"),
            format!("{} … {}", end(p.lower), end(p.upper)),
            format!("{} / {}", rel(p.lower), rel(p.upper)),
            se.map_or("—".into(), |s| {
                format!("{:.4e} … {:.4e}", v - 1.96 * s, v + 1.96 * s)
            }),
            p.points.len().to_string(),
        ]);
    }
    Some(t)
}

/// For each profile read off a bowl fitted to a rough cost, one line: where the
/// bowl's minimum is, and what the interval is made of.
pub fn surface_notes(r: &IdentifyResult) -> Vec<String> {
    let profiles = r.profiles.iter().flatten();
    profiles
        .filter_map(|(name, p)| {
            let s = p.surface.as_ref()?;
            Some(format!(
                "{name}: the cost is rough; its profile is a bowl fitted to {} evaluations \
                 around the fit (their scatter about it {:.2e}), minimum at {:.5e}; \
                 half-width {:.2e} from the residuals ({:.0} effective of {}) and \
                 {:.2e} from where the roughness leaves the minimum",
                p.points.len(),
                s.roughness,
                s.minimum,
                s.statistic_half_width,
                s.effective_residuals,
                r.residuals.iter().map(|e| e.residuals.len()).sum::<usize>(),
                1.96 * s.minimum_spread,
            ))
        })
        .collect()
}
