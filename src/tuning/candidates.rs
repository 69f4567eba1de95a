//! The settings the search weighs (docs/tuning.md, "The search"): velocity loops
//! below the highest crossover whose velocity loop alone keeps the targets
//! ([`search::velocity`]), each with position gains from a quarter of its crossover
//! down, kept where the cascade as it runs — exact on the sampled loop, in the
//! configured loop type ([`sampled`], [`stability`]) — keeps the targets: the phase
//! margin, the gain margin both ways, and no conditional window.

use std::f64::consts::TAU;

use rayon::prelude::*;
use serde::Serialize;

use super::margins::Margins;
use super::open_loop::{VelocityLoop, VelocityPi};
use super::sampled::{Closure, DiscretePlant, SampledLoop};
use super::search::{self, Grid};
use super::stability::{analyse_on, LoopMargins};
use super::{Targets, TuneError};
use crate::model::params::ControllerParams;
use crate::model::{Params, SetpointFilter};

/// The velocity crossovers tried, as fractions of the highest that keeps the targets.
pub const CROSSOVER_SCALES: [f64; 9] = [1.0, 0.75, 0.56, 0.42, 0.32, 0.24, 0.18, 0.13, 0.1];
/// The position gains tried, as fractions of the velocity crossover ω_c (from the
/// rule's ω_c/4 down by factors of √2).
pub const KPP_OVER_CROSSOVER: [f64; 7] = [0.25, 0.177, 0.125, 0.088, 0.0625, 0.044, 0.031];
/// Grid points of the cascade's margins in the search (the final settings are
/// analysed on the full grid).
const SEARCH_GRID: usize = 1000;

/// What the engineer allows.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Limits {
    /// The highest position gain, 1/s.
    pub max_kpp: Option<f64>,
    /// The highest velocity-loop crossover, Hz.
    pub max_bandwidth_hz: Option<f64>,
    /// The notches' depth, dB (negative).
    pub notch_depth_db: f64,
    /// The narrowest notch, as a fraction of its centre.
    pub notch_min_width: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_kpp: None,
            max_bandwidth_hz: None,
            notch_depth_db: super::notches::DEPTH_DB,
            notch_min_width: super::notches::MIN_RELATIVE_WIDTH,
        }
    }
}

/// A setting of the cascade that keeps the targets.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Candidate {
    pub pi: (f64, f64),
    #[serde(rename = "Kpp")]
    pub kpp: f64,
    /// The velocity loop's crossover the PI was set for, Hz.
    pub crossover_hz: f64,
    #[serde(skip)]
    pub cascade: LoopMargins,
}

impl Candidate {
    /// `base` with this candidate's gains and `filters`.
    pub fn controller(
        &self,
        base: &ControllerParams,
        filters: &[SetpointFilter],
    ) -> ControllerParams {
        ControllerParams {
            kvp: self.pi.0,
            kvi: self.pi.1,
            kpp: self.kpp,
            filters: filters.to_vec(),
            ..base.clone()
        }
    }
}

/// The candidates on `p` with the setpoint filters `filters`, and the cascade margins
/// of the one closest to the targets when none keeps them; with the number tried.
pub fn generate(
    p: &Params,
    filters: &[SetpointFilter],
    targets: Targets,
    limits: &Limits,
) -> Result<(Vec<Candidate>, usize), TuneError> {
    let lp = VelocityLoop::new(p, filters)?;
    let grid = Grid::new(&lp);
    let highest = search::velocity(&grid, targets)?
        .margins
        .crossover_hz
        .unwrap_or(search::LOWEST_CROSSOVER_HZ);
    let highest = limits
        .max_bandwidth_hz
        .map_or(highest, |cap| highest.min(cap));
    let plant = DiscretePlant::new(p)?;
    let tried: Vec<Candidate> = pairs(&grid, highest, limits)
        .into_par_iter()
        .map(|(pi, kpp, crossover_hz)| {
            let c = ControllerParams {
                kvp: pi.kvp,
                kvi: pi.kvi,
                kpp,
                filters: filters.to_vec(),
                ..p.controller.clone()
            };
            let l = SampledLoop::new(&plant, &c, Closure::Cascade);
            Candidate {
                pi: (pi.kvp, pi.kvi),
                kpp,
                crossover_hz,
                cascade: analyse_on(&l, SEARCH_GRID),
            }
        })
        .collect();
    let (pm, gm) = (targets.phase_margin_deg, targets.gain_margin_db);
    let count = tried.len();
    if tried.iter().any(|c| c.cascade.meets(pm, gm)) {
        let within = tried
            .into_iter()
            .filter(|c| c.cascade.meets(pm, gm))
            .collect();
        return Ok((within, count));
    }
    Err(unreachable(targets, &tried))
}

/// The (PI, Kpp, crossover) pairs of the scales, capped.
fn pairs(grid: &Grid, highest: f64, limits: &Limits) -> Vec<(VelocityPi, f64, f64)> {
    let mut out = Vec::new();
    for scale in CROSSOVER_SCALES {
        let hz = scale * highest;
        if hz < search::LOWEST_CROSSOVER_HZ {
            continue;
        }
        let Some(pi) = grid.gains_at(hz) else {
            continue;
        };
        let mut last = f64::NAN;
        for q in KPP_OVER_CROSSOVER {
            let kpp = limits
                .max_kpp
                .map_or(q * TAU * hz, |cap| (q * TAU * hz).min(cap));
            if kpp != last {
                out.push((pi, kpp, hz));
                last = kpp;
            }
        }
    }
    out
}

/// The error naming the tried cascade closest to the targets: stable, with the
/// largest phase margin.
fn unreachable(targets: Targets, tried: &[Candidate]) -> TuneError {
    let best = tried
        .iter()
        .filter(|c| c.cascade.stability.stable)
        .max_by(|a, b| {
            let pm = |c: &Candidate| c.cascade.margins.phase_margin_deg.unwrap_or(f64::MIN);
            pm(a).total_cmp(&pm(b))
        });
    let m: Margins = best.map(|c| c.cascade.margins).unwrap_or_default();
    TuneError::CascadeUnreachable {
        phase_margin_deg: targets.phase_margin_deg,
        gain_margin_db: targets.gain_margin_db,
        tried: tried.len(),
        best: best.map(|c| BestTried {
            kvp: c.pi.0,
            kvi: c.pi.1,
            kpp: c.kpp,
            phase_margin_deg: m.phase_margin_deg,
            gain_margin_db: m.gain_margin_db,
            gain_reduction_margin_db: c.cascade.stability.gain_reduction_margin_db,
            conditional: c.cascade.stability.conditional_window_db.is_some(),
        }),
    }
}

/// The cascade closest to the targets, for the error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BestTried {
    pub kvp: f64,
    pub kvi: f64,
    pub kpp: f64,
    pub phase_margin_deg: Option<f64>,
    pub gain_margin_db: Option<f64>,
    pub gain_reduction_margin_db: Option<f64>,
    pub conditional: bool,
}

impl std::fmt::Display for BestTried {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let db = |g: Option<f64>| g.map_or("unbounded".to_string(), |g| format!("{g:.1} dB"));
        write!(
            f,
            "Kvp {:.4e}, Kvi {:.4e}, Kpp {:.1} 1/s: phase margin {}, gain margin {}, gain-reduction margin {}{}",
            self.kvp,
            self.kvi,
            self.kpp,
            self.phase_margin_deg
                .map_or("none".to_string(), |p| format!("{p:.1}°")),
            db(self.gain_margin_db),
            db(self.gain_reduction_margin_db),
            if self.conditional {
                ", conditionally stable"
            } else {
                ""
            }
        )
    }
}
