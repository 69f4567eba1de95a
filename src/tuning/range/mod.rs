//! The machine as it may be (docs/tuning.md, "Tuning over a range"): parameters
//! varied by ratios of their values (`--vary Jt=0.5..2`) and control periods of delay
//! the loop may have beyond the model's (`--delay-periods N`, added to the encoder's
//! dead time), and the points of that range at which a setting must keep its
//! targets.
//!
//! **The points.** The nominal machine first; then a grid over the range: along each
//! varied quantity its two ends and, with one or two quantities, the points between
//! (log-spaced ratios, whole periods of delay) — five per quantity alone, three per
//! quantity with two to four, the corners alone with more (up to [`MAX_QUANTITIES`]).
//! The grid holds the range's corners, and with one quantity its geometric middle.
//! A setting's worst case over the range is its smallest margins at these points.

pub mod default;

use serde::Serialize;

use super::sampled::{Closure, DiscretePlant, SampledLoop};
use super::stability::{analyse_on, LoopMargins};
use crate::controller::MAX_DELAY_PERIODS;
use crate::model::params::ControllerParams;
use crate::model::{ParamError, Params};

/// The most quantities a range varies (its corners: 2^8 machines).
pub const MAX_QUANTITIES: usize = 8;
/// The settings the range may not vary: what the tuning chooses, and the period it
/// runs at.
const TUNED: [&str; 5] = ["Kpp", "Kpi", "Kvp", "Kvi", "Tc"];

/// One parameter varied: its value times a ratio from `low` to `high`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Vary {
    /// The parameter's registry name (`Jt`, `Kw`, …).
    pub name: String,
    pub low: f64,
    pub high: f64,
}

/// The range of machines the settings must hold on.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Range {
    pub vary: Vec<Vary>,
    /// Control periods of delay beyond the model's, from 0 to this (whole periods).
    pub delay_periods: u32,
    /// Where a default range's quantities come from, and those it left at their
    /// values ([`default::default_range`]; empty for `--vary`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub origins: Vec<default::Origin>,
}

/// One machine of the range: each varied parameter's ratio, the added delay.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Point {
    pub ratios: Vec<f64>,
    pub delay_periods: u32,
}

/// Why a range cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RangeError {
    #[error("--vary {name}={low}..{high}: ratios must be finite and positive with LOW ≤ HIGH")]
    Ratios { name: String, low: f64, high: f64 },
    #[error("--vary {name}: {why}")]
    Name { name: String, why: String },
    #[error("--vary {name}: {source}")]
    Param {
        name: String,
        #[source]
        source: ParamError,
    },
    #[error("--vary names {name} twice")]
    Twice { name: String },
    #[error("the range varies {count} quantities (--vary and --delay-periods): at most {MAX_QUANTITIES}")]
    TooMany { count: usize },
    #[error("--delay-periods {periods}: the encoder's dead time would reach {total:.1} control periods, beyond the controller's delay line of {MAX_DELAY_PERIODS}")]
    Delay { periods: u32, total: f64 },
}

impl Range {
    /// The nominal machine alone.
    pub fn nominal() -> Range {
        Range::default()
    }

    /// Whether the range is the nominal machine alone.
    pub fn is_nominal(&self) -> bool {
        self.vary.iter().all(|v| v.low == 1.0 && v.high == 1.0) && self.delay_periods == 0
    }

    /// The quantities varied.
    fn quantities(&self) -> usize {
        self.vary.len() + usize::from(self.delay_periods > 0)
    }

    /// Refuses ratios that are not finite and positive, a name twice, a name the
    /// tuning sets or that does not apply to `p` or is zero in it, too many
    /// quantities, and more delay than the controller holds.
    pub fn check(&self, p: &Params) -> Result<(), RangeError> {
        if self.quantities() > MAX_QUANTITIES {
            return Err(RangeError::TooMany {
                count: self.quantities(),
            });
        }
        for (i, v) in self.vary.iter().enumerate() {
            let ok = |x: f64| x.is_finite() && x > 0.0;
            if !(ok(v.low) && ok(v.high) && v.low <= v.high) {
                return Err(RangeError::Ratios {
                    name: v.name.clone(),
                    low: v.low,
                    high: v.high,
                });
            }
            if self.vary[..i].iter().any(|w| w.name == v.name) {
                return Err(RangeError::Twice {
                    name: v.name.clone(),
                });
            }
            self.check_name(p, &v.name)?;
        }
        let total = p.encoder_delay / p.controller.tc + f64::from(self.delay_periods);
        if total > MAX_DELAY_PERIODS as f64 {
            return Err(RangeError::Delay {
                periods: self.delay_periods,
                total,
            });
        }
        Ok(())
    }

    fn check_name(&self, p: &Params, name: &str) -> Result<(), RangeError> {
        let bad = |why: String| RangeError::Name {
            name: name.to_string(),
            why,
        };
        if TUNED.contains(&name) {
            return Err(bad(
                "the tuning sets it; vary the machine, not its settings".into(),
            ));
        }
        let value = p.get(name).map_err(|source| RangeError::Param {
            name: name.to_string(),
            source,
        })?;
        match value {
            None => Err(bad(format!("does not apply to the {} drive", p.name))),
            Some(0.0) => Err(bad(
                "is 0 in the model: a ratio of it changes nothing".into()
            )),
            Some(_) => Ok(()),
        }
    }

    /// The points of the range, the nominal machine first (the module's doc).
    pub fn points(&self) -> Vec<Point> {
        let nominal = Point {
            ratios: vec![1.0; self.vary.len()],
            delay_periods: 0,
        };
        if self.is_nominal() {
            return vec![nominal];
        }
        let per = match self.quantities() {
            1 => 5,
            2..=4 => 3,
            _ => 2,
        };
        let ratio_values: Vec<Vec<f64>> = self
            .vary
            .iter()
            .map(|v| log_spaced(v.low, v.high, per))
            .collect();
        let delays: Vec<u32> = if self.delay_periods > 0 {
            whole_spaced(self.delay_periods, per)
        } else {
            vec![0]
        };
        let mut out = vec![nominal];
        for delay_periods in delays {
            for ratios in product(&ratio_values) {
                let point = Point {
                    ratios,
                    delay_periods,
                };
                if !out.iter().any(|o| o.same(&point)) {
                    out.push(point);
                }
            }
        }
        out
    }

    /// The range's corners (each quantity at one of its ends), for the nonlinear
    /// screening; none for the nominal range.
    pub fn corners(&self) -> Vec<Point> {
        if self.is_nominal() {
            return Vec::new();
        }
        let ends: Vec<Vec<f64>> = self
            .vary
            .iter()
            .map(|v| log_spaced(v.low, v.high, 2))
            .collect();
        let delays: Vec<u32> = if self.delay_periods > 0 {
            vec![0, self.delay_periods]
        } else {
            vec![0]
        };
        let mut out: Vec<Point> = Vec::new();
        for delay_periods in delays {
            for ratios in product(&ends) {
                let point = Point {
                    ratios,
                    delay_periods,
                };
                if !out.iter().any(|o| o.same(&point)) && !point.is_nominal() {
                    out.push(point);
                }
            }
        }
        out
    }

    /// `p` at `point`: each varied parameter times its ratio, the encoder's dead time
    /// longer by the added periods.
    pub fn apply(&self, p: &Params, point: &Point) -> Result<Params, RangeError> {
        let mut q = p.clone();
        for (v, &ratio) in self.vary.iter().zip(&point.ratios) {
            let param = |source| RangeError::Param {
                name: v.name.clone(),
                source,
            };
            let value = p.get(&v.name).map_err(param)?.unwrap_or(0.0);
            q.set(&v.name, value * ratio).map_err(param)?;
        }
        q.encoder_delay += f64::from(point.delay_periods) * p.controller.tc;
        q.validate().map_err(|source| RangeError::Param {
            name: self.describe(point),
            source,
        })?;
        Ok(q)
    }

    /// The range as a table names it: `Jt ×0.5…2, +0…1 periods of delay`, or
    /// `nominal`.
    pub fn summary(&self) -> String {
        let mut parts: Vec<String> = self
            .vary
            .iter()
            .map(|v| {
                use crate::names::Num;
                format!("{} ×{}…{}", v.name, Num(v.low), Num(v.high))
            })
            .collect();
        if self.delay_periods > 0 {
            parts.push(format!("+0…{} periods of delay", self.delay_periods));
        }
        if parts.is_empty() {
            "nominal".into()
        } else {
            parts.join(", ")
        }
    }

    /// `point` as the table names it: `Jt ×2, +1 period`, or `nominal`.
    pub fn describe(&self, point: &Point) -> String {
        let mut parts: Vec<String> = self
            .vary
            .iter()
            .zip(&point.ratios)
            .filter(|(_, &r)| (r - 1.0).abs() >= 1e-12)
            .map(|(v, r)| format!("{} ×{}", v.name, crate::names::Num(round4(*r))))
            .collect();
        if point.delay_periods > 0 {
            let s = if point.delay_periods == 1 { "" } else { "s" };
            parts.push(format!("+{} period{s} of delay", point.delay_periods));
        }
        if parts.is_empty() {
            "nominal".into()
        } else {
            parts.join(", ")
        }
    }
}

impl Point {
    /// Whether this is the nominal machine (its ratios 1 within 1e-12).
    pub fn is_nominal(&self) -> bool {
        self.ratios.iter().all(|&r| (r - 1.0).abs() < 1e-12) && self.delay_periods == 0
    }

    /// Whether `other` is the same machine (ratios within 1e-12 relative).
    fn same(&self, other: &Point) -> bool {
        self.delay_periods == other.delay_periods
            && self
                .ratios
                .iter()
                .zip(&other.ratios)
                .all(|(a, b)| (a / b - 1.0).abs() < 1e-12)
    }
}

/// `x` to four significant digits (a ratio as the table names it).
pub fn round4(x: f64) -> f64 {
    let k = 10f64.powi(3 - x.abs().log10().floor() as i32);
    (x * k).round() / k
}

/// `n` ratios from `low` to `high`, evenly spaced in log (`low` alone if equal).
fn log_spaced(low: f64, high: f64, n: usize) -> Vec<f64> {
    if low == high {
        return vec![low];
    }
    let (a, b) = (low.ln(), high.ln());
    (0..n)
        .map(|i| match i {
            0 => low,
            _ if i == n - 1 => high,
            _ => (a + (b - a) * i as f64 / (n - 1) as f64).exp(),
        })
        .collect()
}

/// Up to `n` whole numbers from 0 to `top`, evenly spaced, both ends included.
fn whole_spaced(top: u32, n: usize) -> Vec<u32> {
    let mut out: Vec<u32> = (0..n)
        .map(|i| (f64::from(top) * i as f64 / (n - 1) as f64).round() as u32)
        .collect();
    out.dedup();
    out
}

/// Every combination of one value from each list.
fn product(lists: &[Vec<f64>]) -> Vec<Vec<f64>> {
    lists.iter().fold(vec![Vec::new()], |acc, values| {
        acc.iter()
            .flat_map(|prefix| {
                values.iter().map(move |&v| {
                    let mut next = prefix.clone();
                    next.push(v);
                    next
                })
            })
            .collect()
    })
}

pub use default::default_range;

/// The machines of `range` on `p`, each with its drive held over a control period.
pub struct Machines {
    pub range: Range,
    pub points: Vec<Point>,
    /// `p` at each point.
    pub params: Vec<Params>,
    pub plants: Vec<DiscretePlant>,
}

impl Machines {
    /// `range`'s points on `p`, their drives discretised.
    pub fn new(p: &Params, range: &Range) -> Result<Machines, RangeError> {
        let points = range.points();
        let params = points
            .iter()
            .map(|point| range.apply(p, point))
            .collect::<Result<Vec<_>, _>>()?;
        let plants = params
            .iter()
            .zip(&points)
            .map(|(q, point)| {
                DiscretePlant::new(q).map_err(|source| RangeError::Param {
                    name: range.describe(point),
                    source,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Machines {
            range: range.clone(),
            points,
            params,
            plants,
        })
    }

    /// The worst case of `margins` (one per point).
    pub fn worst(&self, margins: &[LoopMargins]) -> OverRange {
        OverRange::of(&self.range, &self.points, margins)
    }

    /// The cascade of `c` at every point on a grid of `grid` frequencies.
    pub fn margins(&self, c: &ControllerParams, grid: usize) -> Vec<LoopMargins> {
        self.plants
            .iter()
            .map(|plant| analyse_on(&SampledLoop::new(plant, c, Closure::Cascade), grid))
            .collect()
    }
}

/// A setting's margins over the range: at each point, and the worst of each.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OverRange {
    /// The smallest phase margin and the point it is at (`None`: no crossover, or
    /// unstable).
    pub phase_margin_deg: Option<(f64, String)>,
    /// The smallest gain margin up and down, and where.
    pub gain_margin_db: Option<(f64, String)>,
    pub gain_reduction_margin_db: Option<(f64, String)>,
    /// Points at which the cascade is unstable or conditionally stable.
    pub unstable_at: Vec<String>,
    pub conditional_at: Vec<String>,
    /// Points checked.
    pub points: usize,
}

impl OverRange {
    /// The worst case of `margins` (one per point of `range`).
    pub fn of(range: &Range, points: &[Point], margins: &[LoopMargins]) -> OverRange {
        let named = |i: usize| range.describe(&points[i]);
        let least = |get: &dyn Fn(&LoopMargins) -> Option<f64>| {
            margins
                .iter()
                .enumerate()
                .filter_map(|(i, m)| get(m).map(|v| (v, i)))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(v, i)| (v, named(i)))
        };
        let where_ = |pred: &dyn Fn(&LoopMargins) -> bool| {
            margins
                .iter()
                .enumerate()
                .filter(|(_, m)| pred(m))
                .map(|(i, _)| named(i))
                .collect()
        };
        OverRange {
            phase_margin_deg: least(&|m| m.margins.phase_margin_deg),
            gain_margin_db: least(&|m| m.margins.gain_margin_db),
            gain_reduction_margin_db: least(&|m| m.stability.gain_reduction_margin_db),
            unstable_at: where_(&|m| !m.stability.stable),
            conditional_at: where_(&|m| m.stability.conditional_window_db.is_some()),
            points: margins.len(),
        }
    }
}

/// Whether every point's margins keep the targets.
pub fn meets_everywhere(margins: &[LoopMargins], phase_deg: f64, gain_db: f64) -> bool {
    margins.iter().all(|m| m.meets(phase_deg, gain_db))
}

/// A setting's worst phase margin over the range (−∞ where unstable or without a
/// crossover somewhere): how close it comes to the targets.
pub fn worst_phase_margin(margins: &[LoopMargins]) -> f64 {
    margins
        .iter()
        .map(|m| match (m.stability.stable, m.margins.phase_margin_deg) {
            (true, Some(pm)) => pm,
            _ => f64::NEG_INFINITY,
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn jt(low: f64, high: f64) -> Range {
        Range {
            vary: vec![Vary {
                name: "Jt".into(),
                low,
                high,
            }],
            ..Range::default()
        }
    }

    #[test]
    fn one_quantity_gives_its_ends_its_middle_and_the_quarters() {
        let r = jt(0.5, 2.0);
        let ratios: Vec<f64> = r.points().iter().map(|p| p.ratios[0]).collect();
        let want = [1.0, 0.5, 0.5f64.sqrt(), 2f64.sqrt(), 2.0];
        assert_eq!(ratios.len(), want.len(), "{ratios:?}");
        for (g, w) in ratios.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{ratios:?}");
        }
        assert_eq!(r.corners().len(), 2);
        let three: Vec<f64> = jt(1.0, 3.0).points().iter().map(|p| p.ratios[0]).collect();
        assert_eq!(three.len(), 5, "{three:?}");
        assert!(
            three.iter().any(|m| (m - 3f64.sqrt()).abs() < 1e-12),
            "{three:?}"
        );
    }

    #[test]
    fn two_quantities_and_a_delay_give_their_grid_and_corners() {
        let r = Range {
            vary: vec![
                Vary {
                    name: "Jt".into(),
                    low: 1.0,
                    high: 2.0,
                },
                Vary {
                    name: "Kw".into(),
                    low: 0.7,
                    high: 1.0,
                },
            ],
            delay_periods: 2,
            ..Range::default()
        };
        let p = presets::load("two-mass").unwrap();
        r.check(&p).unwrap();
        // 3 × 3 × 3 with the nominal among them.
        assert_eq!(r.points().len(), 27);
        // 2 × 2 × 2 less the nominal corner (Jt ×1, Kw ×1, no delay).
        assert_eq!(r.corners().len(), 7);
        let q = r.apply(&p, &r.corners()[6]).unwrap();
        assert_eq!(q.jt, 2.0 * p.jt);
        assert!((q.encoder_delay - 2.0 * p.controller.tc).abs() < 1e-18);
        assert_eq!(r.describe(&r.corners()[6]), "Jt ×2, +2 periods of delay");
    }

    #[test]
    fn bad_ranges_are_refused_naming_the_option() {
        let p = presets::load("two-mass").unwrap();
        for (r, says) in [
            (jt(2.0, 0.5), "ratios"),
            (jt(0.0, 2.0), "ratios"),
            (jt(1.0, f64::NAN), "ratios"),
        ] {
            let e = r.check(&p).unwrap_err().to_string();
            assert!(e.contains("--vary Jt") && e.contains(says), "{e}");
        }
        let mut r = jt(0.5, 2.0);
        r.vary[0].name = "Kvp".into();
        assert!(r.check(&p).unwrap_err().to_string().contains("tuning sets"));
        r.vary[0].name = "Kg".into();
        assert!(r.check(&p).unwrap_err().to_string().contains("--vary Kg"));
        r.vary[0].name = "theta_bw".into();
        assert!(r.check(&p).unwrap_err().to_string().contains("is 0"));
        let delayed = Range {
            delay_periods: 100,
            ..Range::default()
        };
        assert!(delayed
            .check(&p)
            .unwrap_err()
            .to_string()
            .contains("--delay-periods"));
    }
}
