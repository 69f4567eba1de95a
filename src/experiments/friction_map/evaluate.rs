//! What a friction map says: its runs, the friction laws fitted to their mean efforts
//! with standard errors (estimation/friction_law), and which law the data support
//! (AICc, as `rtid select` ranks fits).

use serde::Serialize;

use crate::estimation::friction_law::{fit_all, Comparison, Law, MapProblem};
use crate::io::experiment_file::{Axis, FrictionMap};

/// A map's evaluation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MapEvaluation {
    /// `rotary` (rad/s, N·m) or `linear` (m/s, N).
    pub axis: Axis,
    /// The runs, in order of increasing speed.
    pub runs: Vec<Run>,
    /// The laws fitted and their comparison.
    pub laws: Comparison,
    /// The selected law's misfit against the runs' own scatter, when the map gives
    /// each run's effort deviation and samples ([`Misfit`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub misfit: Option<Misfit>,
}

/// How far the selected law misses the runs, against how well each run's mean is
/// known: the residuals' RMS over the RMS standard error of the runs' mean efforts
/// (σᵢ/√nᵢ). Above [`MISFIT`], the map holds more than the law describes — a shape
/// none of the laws has, or runs whose means differ by more than their scatter says
/// (a drift between runs, a position-dependent friction).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Misfit {
    /// The selected law's RMS residual, N·m or N.
    pub residual_rms: f64,
    /// The RMS standard error of the runs' mean efforts, N·m or N.
    pub mean_std_error: f64,
    /// residual_rms / mean_std_error.
    pub ratio: f64,
}

/// A law's residuals more than this many times the runs' standard errors are said.
pub const MISFIT: f64 = 3.0;

impl Misfit {
    /// Whether the law misses the runs by more than [`MISFIT`] times their scatter.
    pub fn is_far(&self) -> bool {
        self.ratio > MISFIT
    }
}

/// The misfit of residuals `residuals` against the runs' `effort_std` over `samples`.
fn misfit(residuals: &[f64], effort_std: &[f64], samples: &[f64]) -> Option<Misfit> {
    let n = residuals.len() as f64;
    let residual_rms = (residuals.iter().map(|r| r * r).sum::<f64>() / n).sqrt();
    let se2: f64 = effort_std
        .iter()
        .zip(samples)
        .map(|(s, k)| s * s / k)
        .sum::<f64>()
        / n;
    let mean_std_error = se2.sqrt();
    (mean_std_error > 0.0 && mean_std_error.is_finite()).then(|| Misfit {
        residual_rms,
        mean_std_error,
        ratio: residual_rms / mean_std_error,
    })
}

/// One run of the map, SI.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Run {
    pub speed: f64,
    pub effort: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effort_std: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub samples: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dropped: Option<f64>,
    /// The selected law's residual here: measured − law.
    pub residual: f64,
}

impl MapEvaluation {
    /// The law the data support, fitted.
    pub fn selected(&self) -> &crate::estimation::friction_law::LawFit {
        self.laws
            .fit(self.laws.selected)
            .expect("the selected law is one of the fits")
    }

    /// The model-side law closest to the selected one: the symmetric law of its family
    /// (the model's friction is the same in both directions; a load's offset is
    /// `Tload`), if fitted.
    pub fn symmetric(&self) -> Option<&crate::estimation::friction_law::LawFit> {
        let law = if self.laws.selected.is_stribeck() {
            Law::Stribeck
        } else {
            Law::Coulomb
        };
        self.laws
            .fit(law)
            .filter(|f| f.determined)
            .or_else(|| self.laws.fit(Law::Coulomb))
    }
}

/// Evaluates `map`; why no law can be fitted to it (one direction, a single speed,
/// efforts of one sign) otherwise.
pub fn evaluate(map: &FrictionMap) -> Result<MapEvaluation, MapProblem> {
    let map = map.sorted();
    let laws = fit_all(&map.speed, &map.effort)?;
    let residuals = &laws
        .fit(laws.selected)
        .expect("the selected law is fitted")
        .residuals;
    let at = |v: &Option<Vec<f64>>, i: usize| v.as_ref().map(|v| v[i]);
    let runs = (0..map.len())
        .map(|i| Run {
            speed: map.speed[i],
            effort: map.effort[i],
            effort_std: at(&map.effort_std, i),
            samples: at(&map.samples, i),
            dropped: at(&map.dropped, i),
            residual: residuals[i],
        })
        .collect();
    let misfit = match (&map.effort_std, &map.samples) {
        (Some(std), Some(samples)) => misfit(residuals, std, samples),
        _ => None,
    };
    Ok(MapEvaluation {
        axis: map.axis,
        runs,
        laws,
        misfit,
    })
}
