//! Parameter sets drawn from a fit: from its standard errors and correlations (a
//! multivariate normal, in log space for a parameter whose bounds are positive), or its
//! bootstrap replicates as they are.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::{rngs::StdRng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};

use super::PredictError;
use crate::identify::result::held::Held;
use crate::identify::result::IdentifyResult;

/// Where the parameter sets come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DrawSource {
    /// Normal draws from the fit's standard errors and correlations.
    Covariance,
    /// The fit's bootstrap replicates (`rtid identify --resample`), each one set.
    Bootstrap,
}

/// The drawn parameter sets: `sets[k][j]` is parameter `names[j]` in set `k`.
#[derive(Clone, Debug, PartialEq)]
pub struct Draws {
    pub names: Vec<String>,
    pub sets: Vec<Vec<f64>>,
    /// Normal draws thrown away because a value fell outside the fit's bounds.
    pub rejected: usize,
}

/// Draws `n` sets from the fit's covariance, the parameters in `held` kept at their
/// fitted values. Every fitted parameter not held needs a standard error: one the
/// data did not determine cannot be drawn, and is named.
pub fn from_covariance(
    fit: &IdentifyResult,
    held: &[String],
    n: usize,
    seed: u64,
) -> Result<Draws, PredictError> {
    let u = fit
        .uncertainty
        .as_ref()
        .ok_or(PredictError::NoUncertainty)?;
    let drawn: Vec<usize> = (0..u.names.len())
        .filter(|&j| !held.contains(&u.names[j]))
        .collect();
    let marginals = drawn
        .iter()
        .map(|&j| marginal(fit, &u.names[j], u.standard_errors[j].1))
        .collect::<Result<Vec<_>, _>>()?;
    let correlation = DMatrix::from_fn(drawn.len(), drawn.len(), |a, b| {
        u.correlation[drawn[a]][drawn[b]]
    });
    let root = square_root(correlation);
    let names: Vec<String> = drawn.iter().map(|&j| u.names[j].clone()).collect();
    let mut rng = StdRng::seed_from_u64(seed);
    let (mut sets, mut rejected) = (Vec::with_capacity(n), 0);
    while sets.len() < n {
        if rejected > 20 * n.max(1) {
            return Err(PredictError::OutsideBounds { rejected });
        }
        let z = DVector::from_fn(names.len(), |_, _| StandardNormal.sample(&mut rng));
        let x = &root * z;
        let set: Vec<f64> = marginals
            .iter()
            .zip(x.iter())
            .map(|(m, &x)| m.at(x))
            .collect();
        if marginals.iter().zip(&set).all(|(m, &v)| m.holds(v)) {
            sets.push(set);
        } else {
            rejected += 1;
        }
    }
    Ok(Draws {
        names,
        sets,
        rejected,
    })
}

/// The fit's bootstrap replicates, each one parameter set.
pub fn from_bootstrap(fit: &IdentifyResult) -> Result<Draws, PredictError> {
    let r = fit.resampling.as_ref().ok_or(PredictError::NoReplicates)?;
    let names: Vec<String> = r.values.keys().cloned().collect();
    let count = r.values.values().map(Vec::len).min().unwrap_or(0);
    if count < 2 {
        return Err(PredictError::NoReplicates);
    }
    let sets = (0..count)
        .map(|k| names.iter().map(|name| r.values[name][k]).collect())
        .collect();
    Ok(Draws {
        names,
        sets,
        rejected: 0,
    })
}

/// A held parameter drawn within value·(1 ± half_width) beside the fit's draws:
/// what a prediction rests on besides the fit (a preset's stiffness, an inertia from
/// a drawing). Where the fit gave its response to it (`identify --uncertain`,
/// [`Held`]), the fitted parameters move with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncertain {
    pub name: String,
    pub value: f64,
    pub half_width: f64,
    /// Each fitted parameter's value at the fit and its change with this parameter
    /// at value·(1 + half_width) (empty: drawn independently of the fit).
    pub moves: Vec<(String, f64, f64)>,
}

impl Uncertain {
    /// `name` within value·(1 ± half_width), independent of the fit.
    pub fn independent(name: &str, value: f64, half_width: f64) -> Uncertain {
        Uncertain {
            name: name.to_string(),
            value,
            half_width,
            moves: Vec::new(),
        }
    }

    /// The range the fit carries for `held` (its shifts scaled to `half_width`
    /// where given), the fitted values from `fit`.
    pub fn of_fit(held: &Held, fit: &IdentifyResult, half_width: Option<f64>) -> Uncertain {
        let half = half_width.unwrap_or(held.half_width);
        let moves = (held.shifts.iter())
            .filter_map(|(n, s)| {
                let at = fit.parameters.get(n)?;
                Some((n.clone(), *at, s * half / held.half_width))
            })
            .collect();
        Uncertain {
            name: held.name.clone(),
            value: held.value,
            half_width: half,
            moves,
        }
    }

    /// Set `set` (names `names`) at u ∈ [−1, 1] of this range: the fitted
    /// parameters moved by u of their shift (by a power of its ratio where the
    /// value is positive, so it stays so), and this parameter's value returned.
    fn apply(&self, names: &[String], set: &mut [f64], u: f64) -> f64 {
        for (name, at, shift) in &self.moves {
            let Some(j) = names.iter().position(|n| n == name) else {
                continue;
            };
            let ratio = 1.0 + shift / at;
            if *at > 0.0 && ratio > 0.0 {
                set[j] *= ratio.powf(u);
            } else {
                set[j] += u * shift;
            }
        }
        self.value * (1.0 + self.half_width * u)
    }
}

impl Draws {
    /// The sets widened by parameters the fit held at assumed values
    /// ([`Uncertain`]), each drawn uniformly within its range, independently of the
    /// others.
    pub fn with_uncertain(mut self, uncertain: &[Uncertain], seed: u64) -> Draws {
        use rand::Rng;
        let mut rng = StdRng::seed_from_u64(seed ^ 0x5eed_u64.rotate_left(32));
        for set in &mut self.sets {
            let mut values = Vec::with_capacity(uncertain.len());
            for u in uncertain {
                values.push(u.apply(&self.names, set, rng.random_range(-1.0..=1.0)));
            }
            set.extend(values);
        }
        self.names.extend(uncertain.iter().map(|u| u.name.clone()));
        self
    }
}

/// One parameter's normal marginal: in log space when its bounds are positive (a
/// stiffness, a friction level: the draw stays positive, the standard error read as
/// relative), else linear.
#[derive(Clone, Copy, Debug)]
struct Marginal {
    value: f64,
    spread: f64,
    log: bool,
    bounds: [f64; 2],
}

impl Marginal {
    fn at(&self, z: f64) -> f64 {
        if self.log {
            self.value * (self.spread * z).exp()
        } else {
            self.value + self.spread * z
        }
    }

    fn holds(&self, v: f64) -> bool {
        v.is_finite() && v >= self.bounds[0] && v <= self.bounds[1]
    }
}

fn marginal(
    fit: &IdentifyResult,
    name: &str,
    standard_error: Option<f64>,
) -> Result<Marginal, PredictError> {
    let not_determined = || PredictError::NotDetermined {
        name: name.to_string(),
    };
    let se = standard_error
        .filter(|s| s.is_finite() && *s >= 0.0)
        .ok_or_else(not_determined)?;
    let value = *fit.parameters.get(name).ok_or_else(not_determined)?;
    let bounds = fit
        .bounds
        .get(name)
        .copied()
        .unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
    let log = bounds[0] > 0.0 && value > 0.0;
    Ok(Marginal {
        value,
        spread: if log { se / value } else { se },
        log,
        bounds,
    })
}

/// A square root R of a correlation matrix (R·Rᵀ = C): its Cholesky factor, or where
/// C is only semi-definite (a parameter the others determine) the symmetric root
/// with the negative eigenvalues of rounding set to zero.
fn square_root(c: DMatrix<f64>) -> DMatrix<f64> {
    if let Some(ch) = c.clone().cholesky() {
        return ch.l();
    }
    let e = SymmetricEigen::new(c);
    let sqrt = e.eigenvalues.map(|l| l.max(0.0).sqrt());
    &e.eigenvectors * DMatrix::from_diagonal(&sqrt) * e.eigenvectors.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn correlation_of(sets: &[Vec<f64>], a: usize, b: usize) -> f64 {
        let n = sets.len() as f64;
        let mean = |j: usize| sets.iter().map(|s| s[j]).sum::<f64>() / n;
        let (ma, mb) = (mean(a), mean(b));
        let cov = |x: usize, mx: f64, y: usize, my: f64| {
            sets.iter().map(|s| (s[x] - mx) * (s[y] - my)).sum::<f64>() / n
        };
        cov(a, ma, b, mb) / (cov(a, ma, a, ma) * cov(b, mb, b, mb)).sqrt()
    }

    #[test]
    fn a_semi_definite_correlation_has_a_root() {
        let c = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let r = square_root(c.clone());
        assert!((&r * r.transpose() - c).abs().max() < 1e-12);
    }

    #[test]
    fn draws_keep_the_correlation_and_the_spread() {
        let mut fit: IdentifyResult =
            serde_json::from_str(include_str!("tests/two_parameter_fit.json")).unwrap();
        let draws = from_covariance(&fit, &[], 4000, 1).unwrap();
        assert_eq!(draws.names, ["Kw", "c"]);
        let r = correlation_of(&draws.sets, 0, 1);
        assert!((r + 0.8).abs() < 0.03, "correlation {r}");
        let c: Vec<f64> = draws.sets.iter().map(|s| s[1]).collect();
        let mean = c.iter().sum::<f64>() / c.len() as f64;
        let sd = (c.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / c.len() as f64).sqrt();
        assert!(
            (mean - 0.5).abs() < 0.01 && (sd - 0.1).abs() < 0.005,
            "{mean} {sd}"
        );
        // Kw's bounds are positive: drawn in log space, 1 % relative.
        let kw: Vec<f64> = draws.sets.iter().map(|s| s[0].ln()).collect();
        let m = kw.iter().sum::<f64>() / kw.len() as f64;
        let s = (kw.iter().map(|v| (v - m).powi(2)).sum::<f64>() / kw.len() as f64).sqrt();
        assert!((s - 0.01).abs() < 5e-4, "{s}");
        fit.uncertainty.as_mut().unwrap().standard_errors[1].1 = None;
        let err = from_covariance(&fit, &[], 10, 1).unwrap_err();
        assert!(err.to_string().contains("`c`"), "{err}");
        let held = from_covariance(&fit, &["c".to_string()], 10, 1).unwrap();
        assert_eq!(held.names, ["Kw"]);
    }

    #[test]
    fn uncertain_parameters_are_drawn_within_their_range() {
        let fit: IdentifyResult =
            serde_json::from_str(include_str!("tests/two_parameter_fit.json")).unwrap();
        let draws = from_covariance(&fit, &[], 2000, 1)
            .unwrap()
            .with_uncertain(&[Uncertain::independent("Jt", 0.1, 0.05)], 1);
        assert_eq!(draws.names, ["Kw", "c", "Jt"]);
        let jt: Vec<f64> = draws.sets.iter().map(|s| s[2]).collect();
        let (lo, hi) = jt
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(
            lo >= 0.095 && hi <= 0.105 && lo < 0.0951 && hi > 0.1049,
            "{lo} {hi}"
        );
    }

    #[test]
    fn fitted_parameters_move_with_a_held_one_as_the_fit_said() {
        let fit: IdentifyResult =
            serde_json::from_str(include_str!("tests/two_parameter_fit.json")).unwrap();
        // The fit said: Jt at 0.1·(1 + 0.1) puts Kw 4 % higher and c 0.05 lower.
        let held = Held {
            name: "Jt".into(),
            value: 0.1,
            half_width: 0.1,
            shifts: [("Kw".into(), 0.04 * 4e5), ("c".into(), -0.05)].into(),
        };
        // Asked at half the range: the moves halve.
        let u = Uncertain::of_fit(&held, &fit, Some(0.05));
        let draws = from_covariance(&fit, &["c".to_string()], 1, 1).unwrap();
        let names = draws.names.clone();
        let mut set = vec![4e5];
        let jt = u.apply(&names, &mut set, 1.0);
        assert!((jt - 0.105).abs() < 1e-15, "{jt}");
        assert!((set[0] / 4e5 - 1.02).abs() < 1e-12, "{set:?}");
        let mut set = vec![4e5];
        u.apply(&names, &mut set, -1.0);
        assert!((set[0] / 4e5 - 1.0 / 1.02).abs() < 1e-12, "{set:?}");
        // Drawn: Kw and Jt move together. Kw's own spread (1 %, log-normal) beside
        // the ±2 % uniform that Jt brings: correlation √(0.02²/3 / (0.01² + 0.02²/3))
        // = 0.756.
        let d = from_covariance(&fit, &["c".to_string()], 2000, 3)
            .unwrap()
            .with_uncertain(&[u], 3);
        assert_eq!(d.names, ["Kw", "Jt"]);
        let r = correlation_of(&d.sets, 0, 1);
        assert!((r - 0.756).abs() < 0.04, "correlation {r}");
    }

    #[test]
    fn draws_outside_the_bounds_are_redrawn_and_counted() {
        let mut fit: IdentifyResult =
            serde_json::from_str(include_str!("tests/two_parameter_fit.json")).unwrap();
        fit.bounds.insert("c".into(), [0.45, 10.0]);
        let draws = from_covariance(&fit, &[], 200, 2).unwrap();
        assert!(draws.sets.iter().all(|s| s[1] >= 0.45));
        // Positive bounds: c drawn in log space, P(c < 0.45) = Φ(ln 0.9 / 0.2) ≈ 0.30,
        // so about 200·0.30/0.70 ≈ 86 rejected.
        assert!((60..120).contains(&draws.rejected), "{}", draws.rejected);
        fit.bounds.insert("c".into(), [5.0, 10.0]);
        let err = from_covariance(&fit, &[], 20, 2).unwrap_err();
        assert!(matches!(err, PredictError::OutsideBounds { .. }), "{err}");
    }
}
