//! `--uncertain NAME=X%` (identify and predict): the relative half-range of a
//! parameter held at an assumed value, in place of its parameter set's own (`rtid
//! params` shows a preset's); `NAME=0%` holds it exactly.

use anyhow::{bail, Context};

/// Each `--uncertain NAME=X%`: the parameter's registry name and X (per cent, 0
/// allowed).
pub fn parse(specs: &[String]) -> anyhow::Result<Vec<(String, f64)>> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for s in specs {
        let form =
            || format!("--uncertain {s}: expected NAME=X%, e.g. Kw=10% (0% holds it exactly)");
        let (name, range) = s.split_once('=').with_context(form)?;
        let percent = range
            .trim()
            .trim_start_matches('±')
            .strip_suffix('%')
            .with_context(form)?;
        let percent: f64 = percent.trim().parse().ok().with_context(form)?;
        if !(0.0..100.0).contains(&percent) {
            bail!("--uncertain {s}: the range must lie from 0 % (held exactly) to below 100 % of the value");
        }
        let spec =
            rtid::model::spec(name.trim()).map_err(|e| anyhow::anyhow!("--uncertain {s}: {e}"))?;
        if out.iter().any(|(n, _)| n == spec.name) {
            bail!("--uncertain: {} is given twice", spec.name);
        }
        out.push((spec.name.to_string(), percent));
    }
    Ok(out)
}
