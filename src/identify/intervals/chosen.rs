//! Which interval an identification gives by default, chosen by its cost
//! (docs/identification.md), and the held parameters' ranges it carries.
//!
//! - Where the cost is smooth (a frequency response on the linear model, or
//!   corrected by the nonlinear test until the corrections converged), the
//!   Jacobian's standard errors hold as far as the misfit is the noise's: they are
//!   printed, and the held parameters' ranges widen them by refits at each end
//!   ([`super::held`]).
//! - Where it is rough — a closed-loop replay (torque curve, unbalance test, servo
//!   trace) whose quantised encoders make the search stop in local minima — or the
//!   nonlinear corrections did not converge, the standard errors are lower bounds
//!   (on six worm gears that are not the preset they held θbw, fm and fw 1 time in
//!   18). There the residual block bootstrap runs without being asked, each
//!   replicate drawing the held parameters within their ranges and refitted by the
//!   fit's search from the fit's start ([`super::resample`]).
//!
//! The held ranges are those of the parameter set (a preset's `ranges`: the values
//! its notes mark uncertain or assumed, each with a percentage and its reason) for
//! every parameter the fit holds, overridden by `--uncertain NAME=X%`
//! (`NAME=0%`: exact).

use crate::identify::result::warning::Warning;
use crate::identify::result::IdentifyResult;
use crate::model::Params;
use crate::objectives::Smoothness;

/// What was asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Choice {
    /// By the cost: the standard errors where it is smooth, the bootstrap where not.
    #[default]
    Auto,
    /// The Jacobian's standard errors only (lower bounds on a rough cost).
    StandardErrors,
    /// The bootstrap, whatever the cost.
    Bootstrap,
}

/// The interval an identification is given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chosen {
    /// The standard errors, widened by the held ranges' refits where there are any.
    StandardErrors,
    /// The residual block bootstrap with this many replicates.
    Bootstrap(usize),
}

/// Replicates of the bootstrap when none are asked for: measured on the coverage
/// harness (docs/validation.md).
pub const REPLICATES: usize = 12;

/// The interval for `result` (its cost `smoothness`) under `choice`, with `replicates`
/// asked for (`None`: [`REPLICATES`]).
pub fn decide(
    result: &IdentifyResult,
    smoothness: Smoothness,
    choice: Choice,
    replicates: Option<usize>,
) -> Chosen {
    let n = replicates.unwrap_or(REPLICATES);
    match choice {
        Choice::Bootstrap => Chosen::Bootstrap(n),
        Choice::StandardErrors => Chosen::StandardErrors,
        Choice::Auto if replicates.is_some() || rough(result, smoothness) => Chosen::Bootstrap(n),
        Choice::Auto => Chosen::StandardErrors,
    }
}

/// Whether the standard errors of `result` are known lower bounds: its cost is rough,
/// or its corrections by the nonlinear test did not converge.
pub fn rough(result: &IdentifyResult, smoothness: Smoothness) -> bool {
    smoothness != Smoothness::Smooth
        || result
            .warnings
            .iter()
            .any(|w| matches!(w.0, Warning::CorrectionsNotConverged { .. }))
}

/// Why a held range cannot be taken.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RangeError {
    #[error("--uncertain {name}: {name} is fitted; its uncertainty is the fit's")]
    Fitted { name: String },
    #[error("--uncertain {name}: {name} is zero or not a parameter of this model: a relative range needs a value")]
    NoValue { name: String },
    #[error("--uncertain {name}={percent}%: the range must lie from 0 (exact) to below 100 % of the value")]
    Percent { name: String, percent: f64 },
}

/// The held parameters' ranges (name, value, relative half-width) of a fit of
/// `fitted` on `params`: the parameter set's own ranges of the parameters it holds,
/// then `overrides` (name, per cent; 0: held exactly) in their place or beside them.
pub fn held_ranges(
    params: &Params,
    fitted: &[String],
    overrides: &[(String, f64)],
) -> Result<Vec<(String, f64, f64)>, RangeError> {
    let value = |name: &str| {
        crate::model::spec(name)
            .ok()
            .and_then(|s| s.get(params))
            .filter(|v| *v != 0.0)
    };
    let mut out: Vec<(String, f64, f64)> = Vec::new();
    for (name, r) in &params.ranges {
        if fitted.contains(name) || overrides.iter().any(|o| &o.0 == name) {
            continue;
        }
        if let Some(v) = value(name) {
            out.push((name.clone(), v, r.percent / 100.0));
        }
    }
    for (name, percent) in overrides {
        if fitted.contains(name) {
            return Err(RangeError::Fitted { name: name.clone() });
        }
        if !(*percent >= 0.0 && *percent < 100.0) {
            return Err(RangeError::Percent {
                name: name.clone(),
                percent: *percent,
            });
        }
        let v = value(name).ok_or_else(|| RangeError::NoValue { name: name.clone() })?;
        if *percent > 0.0 {
            out.push((name.clone(), v, percent / 100.0));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_preset_s_ranges_are_carried_where_held_and_overridden_by_name() {
        let p = crate::model::presets::load("worm-gear").unwrap();
        let fitted = vec!["theta_bw".to_string(), "fm".into(), "fw".into()];
        let held = held_ranges(&p, &fitted, &[]).unwrap();
        let names: Vec<&str> = held.iter().map(|h| h.0.as_str()).collect();
        assert!(names.contains(&"Jt") && names.contains(&"Kw"), "{names:?}");
        assert!(!names.contains(&"theta_bw"), "a fitted one is not held");
        let jt = held.iter().find(|h| h.0 == "Jt").unwrap();
        assert_eq!((jt.1, jt.2), (0.108, 0.25));
        let overridden = held_ranges(
            &p,
            &fitted,
            &[("Jt".into(), 10.0), ("Kw".into(), 0.0), ("Kg".into(), 5.0)],
        )
        .unwrap();
        let get = |n: &str| overridden.iter().find(|h| h.0 == n).map(|h| h.2);
        assert_eq!(get("Jt"), Some(0.1));
        assert_eq!(get("Kw"), None, "0 % holds it exactly");
        assert_eq!(
            get("Kg"),
            Some(0.05),
            "a parameter without a range gets one"
        );
        assert_eq!(
            held_ranges(&p, &fitted, &[("fm".into(), 10.0)]),
            Err(RangeError::Fitted { name: "fm".into() })
        );
    }
}
