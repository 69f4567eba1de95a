//! `--uncertain NAME=X%` (identify and predict): a parameter held at an assumed
//! value, with its relative half-range.

use anyhow::{bail, Context};
use rtid::model::Params;

/// Each `--uncertain NAME=X%`: a parameter of the model that `fitted` does not
/// name, its value in `params`, and X/100.
pub fn parse(
    specs: &[String],
    params: &Params,
    fitted: &dyn Fn(&str) -> bool,
) -> anyhow::Result<Vec<(String, f64, f64)>> {
    let mut out: Vec<(String, f64, f64)> = Vec::new();
    for s in specs {
        let form = || format!("--uncertain {s}: expected NAME=X%, e.g. Kw=10%");
        let (name, range) = s.split_once('=').with_context(form)?;
        let percent = range
            .trim()
            .trim_start_matches('±')
            .strip_suffix('%')
            .with_context(form)?;
        let percent: f64 = percent.trim().parse().ok().with_context(form)?;
        if !(percent > 0.0 && percent < 100.0) {
            bail!("--uncertain {s}: the range must lie between 0 and 100 % of the value");
        }
        let spec =
            rtid::model::spec(name.trim()).map_err(|e| anyhow::anyhow!("--uncertain {s}: {e}"))?;
        if fitted(spec.name) {
            bail!(
                "--uncertain {s}: {} is fitted; its uncertainty is the fit's",
                spec.name
            );
        }
        if out.iter().any(|(n, ..)| n == spec.name) {
            bail!("--uncertain: {} is given twice", spec.name);
        }
        let value = spec
            .get(params)
            .filter(|v| *v != 0.0)
            .with_context(|| format!("--uncertain {s}: {} is zero or not a parameter of this model: a relative range needs a value", spec.name))?;
        out.push((spec.name.to_string(), value, percent / 100.0));
    }
    Ok(out)
}
