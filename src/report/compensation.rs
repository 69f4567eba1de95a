//! A compensation as JSON, in the report's units (arc-seconds or µm, degrees or mm):
//! what `rtid compensate --json` prints and `rtid.compensate` returns, and a record's
//! ISO 230-2 values with and without a compensation (`rtid evaluate --compensation
//! --json`, `rtid.evaluate(…, compensation=…)`). Every number passes the finite check
//! (`json!` would write a NaN as null).

use serde_json::{json, Value};

use crate::controller::FrictionCompensation;
use crate::experiments::positioning::compensate::{BeforeAfter, Computed};
use crate::experiments::positioning::iso230::ReportUnits;
use crate::io::json::{value, JsonError};

/// The compensation `c` built from `source`: the table per target, the backlash, the
/// friction law, the ISO 230-2 values of the runs it was built from and of those that
/// check it, the warnings; `sinumerik` the SINUMERIK program's reference and shift
/// where one was made.
pub fn compensation(
    source: &str,
    c: &Computed,
    sinumerik: Option<Value>,
) -> Result<Value, JsonError> {
    let u = ReportUnits::of(c.axis);
    let k = u.deviation_per_si;
    let num = |x: f64| value(&x);
    let targets: Vec<_> = c
        .targets
        .iter()
        .map(|t| {
            Ok(json!({
                format!("target_{}", u.target_key): num(t.target * u.target_per_si)?,
                "mean_up": num(t.mean_up * k)?, "mean_down": num(t.mean_down * k)?,
                "reversal": num(t.reversal * k)?, "table": num(t.table * k)?,
            }))
        })
        .collect::<Result<_, JsonError>>()?;
    let warnings: Vec<_> = c
        .warnings
        .iter()
        .map(|w| {
            let mut v = value(w)?;
            v["message"] = w.message(k, u.deviation).into();
            Ok(v)
        })
        .collect::<Result<_, JsonError>>()?;
    Ok(json!({
        "kind": "compensation",
        "source": source,
        "unit": u.deviation_key,
        "build_runs": c.build_runs,
        "check_runs": c.check_runs,
        "backlash": num(c.compensation.backlash.unwrap_or(0.0) * k)?,
        "friction": c.compensation.friction.as_ref().map(friction).transpose()?,
        "targets": targets,
        "build": before_after(&c.build, k)?,
        "check": c.check.as_ref().map(|b| before_after(b, k)).transpose()?,
        "warnings": warnings,
        "sinumerik": sinumerik,
    }))
}

/// The axis values before, with the backlash alone, and after, scaled by `k`.
pub fn before_after(b: &BeforeAfter, k: f64) -> Result<Value, JsonError> {
    Ok(json!({
        "before": value(&b.before.scaled(k))?,
        "backlash_only": value(&b.backlash_only.scaled(k))?,
        "after": value(&b.after.scaled(k))?,
    }))
}

/// A friction compensation, SI at the motor.
pub fn friction(f: &FrictionCompensation) -> Result<Value, JsonError> {
    let num = |x: f64| value(&x);
    let stribeck = match f.law.rise {
        Some(r) => Some(json!({
            "rise": num(r.rise)?, "speed": num(r.speed)?, "shape": num(r.shape)?,
        })),
        None => None,
    };
    Ok(json!({
        "coulomb": num(f.law.coulomb)?,
        "viscous": num(f.law.viscous)?,
        "stribeck": stribeck,
        "offset": num(f.offset)?,
    }))
}

/// A positioning record's runs `runs` (of `source`) as the axis compensated by the
/// file `compensation` would show them: uncompensated, backlash only, compensated.
pub fn compensated(
    source: &str,
    compensation: &str,
    runs: &[u32],
    b: &BeforeAfter,
    u: ReportUnits,
) -> Result<Value, JsonError> {
    let k = u.deviation_per_si;
    Ok(json!({
        "kind": "positioning",
        "source": source,
        "compensation": compensation,
        "runs": runs,
        "unit": u.deviation_key,
        "uncompensated": value(&b.before.scaled(k))?,
        "backlash_only": value(&b.backlash_only.scaled(k))?,
        "compensated": value(&b.after.scaled(k))?,
    }))
}
