//! What a tuning is asked for ([`Options`]: the targets, the objective, the limits,
//! the range of machines and the ensemble's size) and why it is refused
//! ([`TuneError`]), every value checked before any work.

use serde::Serialize;

use super::candidates::{self, Limits};
use super::range::{Range, RangeError};
use super::weigh::criteria::CriteriaError;
use super::weigh::objective::Objective;
use crate::experiments::positioning::ensemble::{Ensemble, MAX_MEMBERS};
use crate::model::{ParamError, Params};

/// What the tuned cascade must keep.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Targets {
    /// Phase margin, deg (default 50).
    pub phase_margin_deg: f64,
    /// Gain margin floor, both ways, dB (default 6).
    pub gain_margin_db: f64,
}

impl Default for Targets {
    fn default() -> Self {
        Targets {
            phase_margin_deg: 50.0,
            gain_margin_db: 6.0,
        }
    }
}

/// How to tune.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Options {
    pub targets: Targets,
    pub objective: Objective,
    pub limits: Limits,
    /// The fraction of the torque limit the move must leave free (0 to 1).
    pub torque_reserve: f64,
    /// The machines the targets must hold on (default: [`super::range::default_range`]
    /// of the parameter set, which [`Options::for_params`] fills in).
    pub range: Range,
    /// The ensemble the check weighs each setting by (docs/tuning.md, "The check").
    pub ensemble: Ensemble,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            targets: Targets::default(),
            objective: Objective::default(),
            limits: Limits::default(),
            torque_reserve: 0.2,
            range: Range::nominal(),
            ensemble: Ensemble::default(),
        }
    }
}

impl Options {
    /// The defaults with the parameter set's own range (its held ranges).
    pub fn for_params(p: &Params) -> Options {
        Options {
            range: super::range::default_range(p, &[], &[]),
            ..Options::default()
        }
    }
}

/// Why a drive could not be tuned.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TuneError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("{}", unreachable_message(*phase_margin_deg, *gain_margin_db, *best_phase_margin_deg, *best_crossover_hz, *best_gain_margin_db))]
    Unreachable {
        phase_margin_deg: f64,
        gain_margin_db: f64,
        best_phase_margin_deg: Option<f64>,
        best_crossover_hz: Option<f64>,
        best_gain_margin_db: Option<f64>,
    },
    #[error("no cascade of the {tried} tried keeps a phase margin of {phase_margin_deg}° and gain margins of {gain_margin_db} dB both ways without a conditional window{}; {}", over.as_ref().map_or(String::new(), |o| format!(" on all {o}")), best.as_ref().map_or("none of them is stable".to_string(), |b| format!("the closest: {b}")))]
    CascadeUnreachable {
        phase_margin_deg: f64,
        gain_margin_db: f64,
        tried: usize,
        /// The range's machines, when there is more than the nominal one.
        over: Option<String>,
        best: Option<Box<candidates::BestTried>>,
    },
    #[error("targets must be finite with a phase margin in (0°, 180°) and a gain margin ≥ 0 dB: got {phase_margin_deg}° and {gain_margin_db} dB")]
    Targets {
        phase_margin_deg: f64,
        gain_margin_db: f64,
    },
    #[error("{option} must be {expected}: got {value}")]
    Option {
        option: &'static str,
        expected: &'static str,
        value: f64,
    },
    #[error(transparent)]
    Range(#[from] RangeError),
    #[error("the check of today's settings on the nonlinear model failed: {0}")]
    Today(#[source] CriteriaError),
}

fn unreachable_message(
    pm: f64,
    gm: f64,
    best: Option<f64>,
    at: Option<f64>,
    best_gm: Option<f64>,
) -> String {
    let best = match (best, at) {
        (Some(b), Some(f)) => format!(
            "the best is {b:.1}° at a crossover of {f:.2} Hz (gain margin {})",
            best_gm.map_or("unbounded".into(), |g| format!("{g:.1} dB"))
        ),
        _ => "no gain tried crosses over".into(),
    };
    format!(
        "target phase margin {pm}° with a gain margin ≥ {gm} dB not reachable with the \
         PI corner at a quarter of the crossover: {best}"
    )
}

/// Refuses targets, limits, a range and an ensemble out of range, naming the option.
pub fn check(o: &Options, p: &Params) -> Result<(), TuneError> {
    let (pm, gm) = (o.targets.phase_margin_deg, o.targets.gain_margin_db);
    if !(pm.is_finite() && pm > 0.0 && pm < 180.0 && gm.is_finite() && gm >= 0.0) {
        return Err(TuneError::Targets {
            phase_margin_deg: pm,
            gain_margin_db: gm,
        });
    }
    let l = &o.limits;
    let positive = |option, v: Option<f64>| match v {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(TuneError::Option {
            option,
            expected: "finite and positive",
            value: v,
        }),
        _ => Ok(()),
    };
    positive("--max-kpp", l.max_kpp)?;
    positive("--max-bandwidth-hz", l.max_bandwidth_hz)?;
    let within = |option, v: f64, lo: f64, hi: f64, expected| {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(())
        } else {
            Err(TuneError::Option {
                option,
                expected,
                value: v,
            })
        }
    };
    within(
        "--notch-depth-db",
        l.notch_depth_db,
        -60.0,
        -1.0,
        "between -60 and -1 dB",
    )?;
    within(
        "--notch-min-width",
        l.notch_min_width,
        0.01,
        1.0,
        "between 0.01 and 1 (of the centre)",
    )?;
    within(
        "--torque-reserve",
        o.torque_reserve,
        0.0,
        0.9,
        "between 0 and 0.9",
    )?;
    within(
        "--ensemble",
        o.ensemble.members as f64,
        1.0,
        MAX_MEMBERS as f64,
        "between 1 and 256 members",
    )?;
    o.range.check(p)?;
    Ok(())
}
