//! The fitted parameters: which, their bounds, and the optimiser's coordinates.
//!
//! Positive parameters are optimised in log space (a stiffness is as likely to be off
//! by ×2 as by ×½); a parameter whose lower bound is 0 or negative stays linear. The
//! bounds are enforced by a transform, so that every solver — with or without bound
//! support — sees an unbounded problem: the unit coordinate u ∈ [0, 1] (0 at the lower
//! bound) is u = (1 + sin x)/2 of the solver's coordinate x (MINUIT's transform), and
//! the value is lo·(hi/lo)^u (log) or lo + (hi − lo)·u (linear).

use nalgebra::DVector;
use rand::{rngs::StdRng, seq::SliceRandom, Rng, SeedableRng};

use crate::identify::result::warning::Side;
use crate::model::registry::Constraint;
use crate::model::{ParamError, Params};

/// The range a parameter may take.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bound {
    pub lo: f64,
    pub hi: f64,
}

impl Bound {
    /// Log space when the whole range is positive.
    pub fn log(&self) -> bool {
        self.lo > 0.0
    }

    /// The unit coordinate of a value (0 at `lo`, 1 at `hi`), not clamped.
    pub fn unit(&self, v: f64) -> f64 {
        if self.log() {
            (v / self.lo).ln() / (self.hi / self.lo).ln()
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    /// The value at unit coordinate `u` (inside the bounds, rounding included).
    pub fn value(&self, u: f64) -> f64 {
        let v = if self.log() {
            self.lo * (self.hi / self.lo).powf(u)
        } else {
            self.lo + (self.hi - self.lo) * u
        };
        v.clamp(self.lo, self.hi)
    }
}

/// Fitted parameters or bounds that cannot make a search space.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpaceError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error("nothing to fit")]
    Empty,
    #[error("{name} is fitted twice")]
    Twice { name: String },
    #[error("{name} does not apply to this mechanism (no spur-gear stage): it cannot be fitted")]
    NotApplicable { name: String },
    #[error("bounds of {name} (--bound {name}={lo}..{hi}): {reason}")]
    BadBound {
        name: String,
        lo: f64,
        hi: f64,
        reason: String,
    },
    #[error("{name} has bounds but is not fitted")]
    NotFitted { name: String },
    #[error("{name} starts at {value}, which has no default range (0.1×..10× the start needs a positive start, −10|v|..10|v| a signed one a non-zero start): give it bounds")]
    NoDefaultBound { name: String, value: f64 },
    #[error("{name} starts at {value}, outside its bounds {lo}..{hi}")]
    StartOutside {
        name: String,
        value: f64,
        lo: f64,
        hi: f64,
    },
}

/// The fitted subset of a parameter set.
#[derive(Clone, Debug)]
pub struct ParamSpace {
    /// The complete parameter set the fitted values are written into.
    pub base: Params,
    pub names: Vec<&'static str>,
    pub bounds: Vec<Bound>,
    /// Start values (from `base`).
    pub start: Vec<f64>,
}

/// Keeps the solver coordinate off the flat ends of the sine, where its slope is 0.
const EDGE: f64 = 1e-6;

impl ParamSpace {
    /// `names` fitted, starting from `base`; `bounds` given per name, the others
    /// 0.1×..10× their start (a signed parameter, a load: −10|v|..10|v|).
    pub fn new(
        base: Params,
        names: &[String],
        bounds: &[(String, Bound)],
    ) -> Result<Self, SpaceError> {
        if names.is_empty() {
            return Err(SpaceError::Empty);
        }
        let mut specs: Vec<&'static str> = Vec::new();
        let mut start = Vec::new();
        for n in names {
            let spec = crate::model::spec(n.trim())?;
            if specs.contains(&spec.name) {
                return Err(SpaceError::Twice {
                    name: spec.name.into(),
                });
            }
            let v = spec.get(&base).ok_or_else(|| SpaceError::NotApplicable {
                name: spec.name.into(),
            })?;
            specs.push(spec.name);
            start.push(v);
        }
        for (name, _) in bounds {
            if !specs.iter().any(|s| s == name) {
                return Err(SpaceError::NotFitted { name: name.clone() });
            }
        }
        let mut out = Vec::new();
        for (name, &v) in specs.iter().zip(&start) {
            let signed = crate::model::spec(name)?.constraint == Constraint::Finite;
            let b = match bounds.iter().find(|(n, _)| n == name) {
                Some((_, b)) => {
                    let bad = |reason: &str| SpaceError::BadBound {
                        name: name.to_string(),
                        lo: b.lo,
                        hi: b.hi,
                        reason: reason.into(),
                    };
                    if !(b.lo.is_finite() && b.hi.is_finite()) {
                        return Err(bad("bounds must be finite"));
                    }
                    if b.lo >= b.hi {
                        return Err(bad("the lower bound must be below the upper"));
                    }
                    if let Some(fault) =
                        crate::model::spec(name)?.constraint.range_fault(b.lo, b.hi)
                    {
                        return Err(bad(fault));
                    }
                    *b
                }
                None if v > 0.0 && !signed => Bound {
                    lo: 0.1 * v,
                    hi: 10.0 * v,
                },
                // A load may take either sign: a linear range as wide on both sides.
                None if v != 0.0 && signed => Bound {
                    lo: -10.0 * v.abs(),
                    hi: 10.0 * v.abs(),
                },
                None => {
                    return Err(SpaceError::NoDefaultBound {
                        name: name.to_string(),
                        value: v,
                    })
                }
            };
            if !(b.lo <= v && v <= b.hi) {
                return Err(SpaceError::StartOutside {
                    name: name.to_string(),
                    value: v,
                    lo: b.lo,
                    hi: b.hi,
                });
            }
            out.push(b);
        }
        Ok(ParamSpace {
            base,
            names: specs,
            bounds: out,
            start,
        })
    }

    pub(crate) fn dim(&self) -> usize {
        self.names.len()
    }

    /// The complete, validated parameter set with the fitted `values`.
    pub fn params(&self, values: &[f64]) -> Result<Params, ParamError> {
        let mut p = self.base.clone();
        for (name, &v) in self.names.iter().zip(values) {
            p.set(name, v)?;
        }
        p.validate()?;
        Ok(p)
    }

    /// Solver coordinates of physical values.
    pub(crate) fn to_solver(&self, values: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            self.dim(),
            self.bounds.iter().zip(values).map(|(b, &v)| {
                let u = b.unit(v).clamp(EDGE, 1.0 - EDGE);
                (2.0 * u - 1.0).asin()
            }),
        )
    }

    /// Physical values of solver coordinates (always inside the bounds).
    pub(crate) fn physical(&self, x: &DVector<f64>) -> Vec<f64> {
        self.bounds
            .iter()
            .zip(x.iter())
            .map(|(b, &x)| b.value(0.5 * (1.0 + x.sin())))
            .collect()
    }

    /// `n` starts: the given start, then a Latin hypercube in the unit cube of the
    /// bounds (log-uniform for log parameters), seeded.
    pub fn starts(&self, n: usize, seed: u64) -> Vec<Vec<f64>> {
        let mut rng = StdRng::seed_from_u64(seed);
        let extra = n.saturating_sub(1);
        let columns: Vec<Vec<f64>> = self
            .bounds
            .iter()
            .map(|b| {
                let mut strata: Vec<usize> = (0..extra).collect();
                strata.shuffle(&mut rng);
                strata
                    .into_iter()
                    .map(|k| b.value((k as f64 + rng.random::<f64>()) / extra as f64))
                    .collect()
            })
            .collect();
        let mut out = vec![self.start.clone()];
        out.extend((0..extra).map(|i| columns.iter().map(|c| c[i]).collect()));
        out.truncate(n.max(1));
        out
    }

    /// Names of parameters within 0.1 % (of the unit range) of a bound, and which.
    pub(crate) fn at_bounds(&self, values: &[f64]) -> Vec<(&'static str, Side)> {
        self.names
            .iter()
            .zip(&self.bounds)
            .zip(values)
            .filter_map(|((n, b), &v)| {
                let u = b.unit(v);
                if u < 1e-3 {
                    Some((*n, Side::Lower))
                } else if u > 1.0 - 1e-3 {
                    Some((*n, Side::Upper))
                } else {
                    None
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn space(names: &[&str], bounds: &[(&str, f64, f64)]) -> Result<ParamSpace, SpaceError> {
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        let bounds: Vec<(String, Bound)> = bounds
            .iter()
            .map(|(n, lo, hi)| (n.to_string(), Bound { lo: *lo, hi: *hi }))
            .collect();
        ParamSpace::new(presets::load("worm-gear").unwrap(), &names, &bounds)
    }

    #[test]
    fn solver_coordinates_round_trip_and_respect_bounds() {
        let s = space(&["Kw", "theta_bw"], &[("theta_bw", 0.0, 2e-4)]).unwrap();
        assert!(s.bounds[0].log() && !s.bounds[1].log());
        let v = vec![4.4e5, 1.3e-4];
        let back = s.physical(&s.to_solver(&v));
        assert!((back[0] / v[0] - 1.0).abs() < 1e-12 && (back[1] - v[1]).abs() < 1e-15);
        for x in [-1e3, -2.0, 0.0, 7.0, 1e3] {
            let v = s.physical(&DVector::from_vec(vec![x, x]));
            assert!(
                v[0] >= 3.1e4 * (1.0 - 1e-12) && v[0] <= 3.1e6 * (1.0 + 1e-12),
                "{v:?}"
            );
            assert!((0.0..=2e-4).contains(&v[1]), "{v:?}");
        }
    }

    #[test]
    fn latin_hypercube_starts_fill_every_stratum() {
        let s = space(&["Kw", "Kg"], &[]).unwrap();
        let starts = s.starts(9, 7);
        assert_eq!(starts[0], s.start);
        for j in 0..2 {
            let mut strata: Vec<usize> = starts[1..]
                .iter()
                .map(|v| (s.bounds[j].unit(v[j]) * 8.0).floor() as usize)
                .collect();
            strata.sort();
            assert_eq!(strata, (0..8).collect::<Vec<_>>());
        }
        assert_eq!(starts, s.starts(9, 7), "seeded");
    }

    #[test]
    fn bad_fits_and_bounds_are_named() {
        let cases: Vec<(Result<ParamSpace, SpaceError>, &str)> = vec![
            (space(&["Kx"], &[]), "unknown parameter `Kx`"),
            (space(&["Kw", "Kw"], &[]), "fitted twice"),
            (
                space(&["theta_bw"], &[("theta_bw", 1.0, 0.0)]),
                "lower bound must be below",
            ),
            (
                space(&["Kw"], &[("Kg", 1.0, 2.0)]),
                "Kg has bounds but is not fitted",
            ),
            (space(&["Kw"], &[("Kw", 1.0, 2.0)]), "outside its bounds"),
            (space(&["fluct_phase"], &[]), "give it bounds"),
            (
                space(&["Kw"], &[("Kw", -1.0, 1e6)]),
                "bounds of Kw (--bound Kw=-1..1000000): the parameter must be positive",
            ),
            (
                space(&["theta_bw"], &[("theta_bw", -1e-5, 1e-4)]),
                "must be ≥ 0",
            ),
        ];
        for (r, want) in cases {
            let e = r.unwrap_err().to_string();
            assert!(e.contains(want), "{e} should contain {want}");
        }
    }
}
