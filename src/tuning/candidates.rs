//! The settings the search weighs (docs/tuning.md, "The search"): velocity loops
//! below the highest crossover whose velocity loop alone keeps the targets
//! ([`search::velocity`]), each with position gains from a quarter of its crossover
//! down, kept where the cascade as it runs — exact on the sampled loop, in the
//! configured loop type ([`sampled`], [`stability`]) — keeps the targets: the phase
//! margin, the gain margin both ways, and no conditional window.

use std::f64::consts::TAU;

use rayon::prelude::*;
use serde::Serialize;

use super::open_loop::{VelocityLoop, VelocityPi};
use super::range::{meets_everywhere, worst_phase_margin, Machines, OverRange};
use super::sampled::{Closure, SampledLoop};
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
/// The PI corners tried over a range of machines, as fractions of the crossover (at
/// the nominal machine alone, [`search::PI_CORNER`]).
pub const PI_CORNERS_OVER_RANGE: [f64; 3] = [0.25, 0.125, 0.0625];
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
    /// The cascade's margins on the nominal machine.
    #[serde(skip)]
    pub cascade: LoopMargins,
    /// Its margins at each point of the range (the nominal first; only the nominal
    /// where it misses the targets there).
    #[serde(skip)]
    pub over_range: Vec<LoopMargins>,
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

/// The candidates on `p` with the setpoint filters `filters` that keep the targets at
/// every machine of `machines` (the nominal first), and the cascade margins of the
/// one closest to the targets when none keeps them; with the number tried.
pub fn generate(
    p: &Params,
    filters: &[SetpointFilter],
    targets: Targets,
    limits: &Limits,
    machines: &Machines,
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
    let (pm, gm) = (targets.phase_margin_deg, targets.gain_margin_db);
    // Over a range the loop's gain moves: a PI corner lower than a quarter of the
    // crossover keeps its phase lag small where the crossover falls.
    let corners: &[f64] = if machines.points.len() > 1 {
        &PI_CORNERS_OVER_RANGE
    } else {
        &[search::PI_CORNER]
    };
    let tried: Vec<Candidate> = pairs(&grid, highest, limits, corners)
        .into_par_iter()
        .map(|(pi, kpp, crossover_hz)| {
            let c = ControllerParams {
                kvp: pi.kvp,
                kvi: pi.kvi,
                kpp,
                filters: filters.to_vec(),
                ..p.controller.clone()
            };
            let nominal = analyse_on(
                &SampledLoop::new(&machines.plants[0], &c, Closure::Cascade),
                SEARCH_GRID,
            );
            let over_range = if nominal.meets(pm, gm) && machines.plants.len() > 1 {
                let mut all = vec![nominal];
                all.extend(machines.plants[1..].iter().map(|plant| {
                    analyse_on(&SampledLoop::new(plant, &c, Closure::Cascade), SEARCH_GRID)
                }));
                all
            } else {
                vec![nominal]
            };
            Candidate {
                pi: (pi.kvp, pi.kvi),
                kpp,
                crossover_hz,
                cascade: nominal,
                over_range,
            }
        })
        .collect();
    let count = tried.len();
    let everywhere = |c: &Candidate| {
        c.over_range.len() == machines.plants.len() && meets_everywhere(&c.over_range, pm, gm)
    };
    if tried.iter().any(everywhere) {
        let mut within: Vec<Candidate> = Vec::new();
        // Of the PI corners of one crossover and position gain, the highest that
        // keeps the targets (the most integral action the range allows).
        for c in tried.into_iter().filter(everywhere) {
            if !within
                .iter()
                .any(|w| w.crossover_hz == c.crossover_hz && w.kpp == c.kpp)
            {
                within.push(c);
            }
        }
        return Ok((within, count));
    }
    Err(unreachable(targets, &tried, machines))
}

/// The (PI, Kpp, crossover) pairs of the scales, capped, with the PI's corner at
/// each of `corners` (fractions of the crossover).
fn pairs(
    grid: &Grid,
    highest: f64,
    limits: &Limits,
    corners: &[f64],
) -> Vec<(VelocityPi, f64, f64)> {
    let mut out = Vec::new();
    for &corner in corners {
        for scale in CROSSOVER_SCALES {
            let hz = scale * highest;
            if hz < search::LOWEST_CROSSOVER_HZ {
                continue;
            }
            let Some(pi) = grid.gains_with_corner(hz, corner) else {
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
    }
    out
}

/// The error naming the tried cascade closest to the targets: of those that keep
/// them on the nominal machine, the one with the largest worst phase margin over the
/// range; else the stable one with the largest phase margin.
fn unreachable(targets: Targets, tried: &[Candidate], machines: &Machines) -> TuneError {
    let (pm, gm) = (targets.phase_margin_deg, targets.gain_margin_db);
    let over_range = tried
        .iter()
        .filter(|c| c.cascade.meets(pm, gm))
        .max_by(|a, b| {
            worst_phase_margin(&a.over_range).total_cmp(&worst_phase_margin(&b.over_range))
        });
    let best = over_range.or_else(|| {
        tried
            .iter()
            .filter(|c| c.cascade.stability.stable)
            .max_by(|a, b| {
                let pm = |c: &Candidate| c.cascade.margins.phase_margin_deg.unwrap_or(f64::MIN);
                pm(a).total_cmp(&pm(b))
            })
    });
    TuneError::CascadeUnreachable {
        phase_margin_deg: pm,
        gain_margin_db: gm,
        tried: tried.len(),
        over: (machines.points.len() > 1).then(|| {
            format!(
                "{} machines of the range ({})",
                machines.points.len(),
                machines.range.summary()
            )
        }),
        best: best.map(|c| {
            let w = machines.worst(&c.over_range);
            Box::new(best_tried(c, w))
        }),
    }
}

/// `c`'s margins for the error: its worst over the range `w`, or its nominal ones.
fn best_tried(c: &Candidate, w: OverRange) -> BestTried {
    let m = &c.cascade;
    let worst = c.over_range.len() > 1;
    let nominal = |v: Option<f64>| v.map(|v| (v, "nominal".to_string()));
    let pick = |over: Option<(f64, String)>, at_nominal: Option<f64>| {
        if worst {
            over
        } else {
            nominal(at_nominal)
        }
    };
    BestTried {
        kvp: c.pi.0,
        kvi: c.pi.1,
        kpp: c.kpp,
        phase_margin_deg: pick(w.phase_margin_deg, m.margins.phase_margin_deg),
        gain_margin_db: pick(w.gain_margin_db, m.margins.gain_margin_db),
        gain_reduction_margin_db: pick(
            w.gain_reduction_margin_db,
            m.stability.gain_reduction_margin_db,
        ),
        unstable_at: w.unstable_at,
        conditional: !w.conditional_at.is_empty() || m.stability.conditional_window_db.is_some(),
    }
}

/// The cascade closest to the targets, for the error: its margins (the worst over
/// the range, with where).
#[derive(Clone, Debug, PartialEq)]
pub struct BestTried {
    pub kvp: f64,
    pub kvi: f64,
    pub kpp: f64,
    pub phase_margin_deg: Option<(f64, String)>,
    pub gain_margin_db: Option<(f64, String)>,
    pub gain_reduction_margin_db: Option<(f64, String)>,
    pub unstable_at: Vec<String>,
    pub conditional: bool,
}

impl std::fmt::Display for BestTried {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let at = |a: &str| {
            if a == "nominal" {
                String::new()
            } else {
                format!(" at {a}")
            }
        };
        let db = |g: &Option<(f64, String)>| {
            g.as_ref().map_or("unbounded".to_string(), |(g, a)| {
                format!("{g:.1} dB{}", at(a))
            })
        };
        write!(
            f,
            "Kvp {:.4e}, Kvi {:.4e}, Kpp {:.1} 1/s: phase margin {}, gain margin {}, gain-reduction margin {}{}{}",
            self.kvp,
            self.kvi,
            self.kpp,
            self.phase_margin_deg
                .as_ref()
                .map_or("none".to_string(), |(p, a)| format!("{p:.1}°{}", at(a))),
            db(&self.gain_margin_db),
            db(&self.gain_reduction_margin_db),
            if self.unstable_at.is_empty() {
                String::new()
            } else {
                format!(", unstable at {}", self.unstable_at.join("; "))
            },
            if self.conditional {
                ", conditionally stable"
            } else {
                ""
            }
        )
    }
}
