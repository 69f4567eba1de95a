//! `--vary` specifications: which parameter a sweep varies, over which range, on which
//! scale and at how many grid levels.
//!
//! Syntax: `NAME=LOW..HIGH[:log|:lin][:LEVELS]`, e.g. `Kw=1e5..1e6:log:20` or
//! `theta_bw=0..2e-4:10`. `NAME` is a name of the parameter registry
//! ([`crate::model::PARAMS`]); values are SI. `log` spaces the levels (and samples
//! the range) geometrically and needs `0 < LOW`; `LEVELS` (≥ 2) counts the grid
//! levels of that parameter (default [`DEFAULT_LEVELS`]). A bare `NAME` is allowed
//! for local sensitivities, which need no range: they are taken at the base value.

use serde::{Deserialize, Serialize};

use crate::model::registry::{self, PARAMS};
use crate::model::Params;

/// Grid levels of a parameter whose specification gives none.
pub const DEFAULT_LEVELS: usize = 5;

/// How a range is sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Evenly spaced values.
    Lin,
    /// Evenly spaced logarithms (a factor of 10 counts as much anywhere in the range).
    Log,
}

/// One varied parameter: a registry name, its range (SI) and how to sample it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Factor {
    /// Parameter name (registry name; any label for a function that is not the model).
    pub name: String,
    /// Lower end of the range, SI.
    pub low: f64,
    /// Upper end of the range, SI.
    pub high: f64,
    /// Linear or logarithmic sampling.
    pub scale: Scale,
    /// Grid levels (full-grid design only).
    pub levels: usize,
}

/// A `--vary` specification that cannot be used; each names the specification.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpecError {
    #[error("--vary {spec}: {reason}")]
    Syntax { spec: String, reason: String },
    #[error("--vary {spec}: unknown parameter `{name}`; the parameters are {known}")]
    UnknownParameter {
        spec: String,
        name: String,
        known: String,
    },
    #[error("--vary {spec}: the range {low}..{high} is empty (LOW must be below HIGH)")]
    EmptyRange { spec: String, low: f64, high: f64 },
    #[error("--vary {spec}: a log range needs positive bounds, got {low}..{high}")]
    LogBounds { spec: String, low: f64, high: f64 },
    #[error("--vary {spec}: {levels} levels; a grid needs at least 2")]
    Levels { spec: String, levels: usize },
    #[error("--vary {spec}: this method needs a range NAME=LOW..HIGH")]
    NoRange { spec: String },
    #[error("parameter `{name}` is varied twice")]
    Duplicate { name: String },
    #[error("--vary {spec}: {source}")]
    Bound {
        spec: String,
        #[source]
        source: crate::model::ParamError,
    },
}

impl Factor {
    /// A factor over `low..high`, checked (finite, non-empty, log bounds positive).
    pub fn new(
        name: &str,
        low: f64,
        high: f64,
        scale: Scale,
        levels: usize,
    ) -> Result<Self, SpecError> {
        let spec = format!("{name}={low}..{high}");
        if !(low.is_finite() && high.is_finite()) {
            return Err(SpecError::Syntax {
                spec,
                reason: "the bounds must be finite numbers".into(),
            });
        }
        if low >= high {
            return Err(SpecError::EmptyRange { spec, low, high });
        }
        if scale == Scale::Log && low <= 0.0 {
            return Err(SpecError::LogBounds { spec, low, high });
        }
        if levels < 2 {
            return Err(SpecError::Levels { spec, levels });
        }
        Ok(Factor {
            name: name.to_string(),
            low,
            high,
            scale,
            levels,
        })
    }

    /// The value at the unit coordinate `u` ∈ [0, 1] of the range.
    pub fn value(&self, u: f64) -> f64 {
        match self.scale {
            Scale::Lin => self.low + u * (self.high - self.low),
            Scale::Log => (self.low.ln() + u * (self.high.ln() - self.low.ln())).exp(),
        }
    }

    /// Whether the factor is a point (a bare name for local sensitivities).
    pub fn is_point(&self) -> bool {
        self.low == self.high
    }
}

/// Parses one `--vary` specification against the registry and the base parameters
/// `base` (for the topology and, for a bare name, the base value).
pub fn parse(spec: &str, base: &Params) -> Result<Factor, SpecError> {
    let syntax = |reason: &str| syntax(spec, reason);
    let (name, rest) = match spec.split_once('=') {
        Some((n, r)) => (n.trim(), Some(r.trim())),
        None => (spec.trim(), None),
    };
    let registered = registry::spec(name).map_err(|_| SpecError::UnknownParameter {
        spec: spec.to_string(),
        name: name.to_string(),
        known: PARAMS.iter().map(|s| s.name).collect::<Vec<_>>().join(", "),
    })?;
    let Some(rest) = rest else {
        let v = registered.get(base).ok_or_else(|| SpecError::Bound {
            spec: spec.to_string(),
            source: crate::model::ParamError::NotApplicable {
                name: registered.name,
            },
        })?;
        return Ok(Factor {
            name: name.to_string(),
            low: v,
            high: v,
            scale: Scale::Lin,
            levels: DEFAULT_LEVELS,
        });
    };
    let mut parts = rest.split(':');
    let range = parts.next().unwrap_or_default();
    let (low, high) = range
        .split_once("..")
        .ok_or_else(|| syntax("expected NAME=LOW..HIGH[:log][:LEVELS], e.g. Kw=1e5..1e6:log:20"))?;
    let number = |s: &str, what: &str| -> Result<f64, SpecError> {
        s.trim()
            .parse::<f64>()
            .map_err(|_| syntax(&format!("{what} `{}` is not a number", s.trim())))
    };
    let (low, high) = (number(low, "LOW")?, number(high, "HIGH")?);
    let (scale, levels) = options(spec, parts)?;
    let factor = Factor::new(registered.name, low, high, scale, levels).map_err(|e| e.of(spec))?;
    physical(spec, registered, low, high, base)?;
    Ok(factor)
}

/// A syntax error of `spec`.
fn syntax(spec: &str, reason: &str) -> SpecError {
    SpecError::Syntax {
        spec: spec.to_string(),
        reason: reason.to_string(),
    }
}

/// The scale and the number of levels of `spec`'s options after its range (each
/// at most once; linear and [`DEFAULT_LEVELS`] where absent).
fn options<'a>(
    spec: &str,
    parts: impl Iterator<Item = &'a str>,
) -> Result<(Scale, usize), SpecError> {
    let (mut scale, mut levels) = (None, None);
    for option in parts {
        let (slot, what) = match option.trim() {
            "log" => (scale.replace(Scale::Log).is_some(), "the scale"),
            "lin" => (scale.replace(Scale::Lin).is_some(), "the scale"),
            other => {
                let n = other.parse().map_err(|_| {
                    syntax(
                        spec,
                        &format!("`{other}` is neither `log`, `lin` nor a number of levels"),
                    )
                })?;
                (levels.replace(n).is_some(), "the number of levels")
            }
        };
        if slot {
            return Err(syntax(
                spec,
                &format!(
                    "{what} is given twice: write NAME=LOW..HIGH[:log][:LEVELS] with each once"
                ),
            ));
        }
    }
    Ok((
        scale.unwrap_or(Scale::Lin),
        levels.unwrap_or(DEFAULT_LEVELS),
    ))
}

/// Whether the whole range `low..high`, not only its ends, holds physical values of
/// the parameter (a ratio from −1 to 1 passes through 0), each end on `base`'s
/// topology.
fn physical(
    spec: &str,
    registered: &registry::ParamSpec,
    low: f64,
    high: f64,
    base: &Params,
) -> Result<(), SpecError> {
    if let Some(fault) = registered
        .constraint
        .range_fault(low.min(high), low.max(high))
    {
        return Err(syntax(spec, fault));
    }
    for v in [low, high] {
        let mut p = base.clone();
        p.set(registered.name, v)
            .and_then(|_| p.validate())
            .map_err(|source| SpecError::Bound {
                spec: spec.to_string(),
                source,
            })?;
    }
    Ok(())
}

impl SpecError {
    /// The error as the specification `spec` gave it ([`Factor::new`] names the
    /// range it was given).
    fn of(self, spec: &str) -> SpecError {
        let spec = spec.to_string();
        match self {
            SpecError::EmptyRange { low, high, .. } => SpecError::EmptyRange { spec, low, high },
            SpecError::LogBounds { low, high, .. } => SpecError::LogBounds { spec, low, high },
            SpecError::Levels { levels, .. } => SpecError::Levels { spec, levels },
            SpecError::Syntax { reason, .. } => SpecError::Syntax { spec, reason },
            other => other,
        }
    }
}

/// Parses every specification; a parameter may appear once.
pub fn parse_all(specs: &[String], base: &Params) -> Result<Vec<Factor>, SpecError> {
    let mut out: Vec<Factor> = Vec::with_capacity(specs.len());
    for s in specs {
        let f = parse(s, base)?;
        if out.iter().any(|g| g.name == f.name) {
            return Err(SpecError::Duplicate { name: f.name });
        }
        out.push(f);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn worm() -> Params {
        presets::load("worm-gear").unwrap()
    }

    #[test]
    fn the_issue_examples_parse() {
        let f = parse("Kw=1e5..1e6:log:20", &worm()).unwrap();
        assert_eq!(
            (f.low, f.high, f.scale, f.levels),
            (1e5, 1e6, Scale::Log, 20)
        );
        assert!((f.value(0.5) - 1e5 * 10f64.sqrt()).abs() < 1e-6);
        let f = parse("theta_bw=0..2e-4:10", &worm()).unwrap();
        assert_eq!((f.scale, f.levels, f.value(0.5)), (Scale::Lin, 10, 1e-4));
        let f = parse("Kw", &worm()).unwrap();
        assert!(f.is_point() && f.low == 3.1e5);
    }

    #[test]
    fn bad_specifications_name_what_is_wrong() {
        let cases = [
            (
                "Kx=1..2",
                "unknown parameter `Kx`; the parameters are Jm, Jw",
            ),
            ("Kw=2e5..1e5", "range 200000..100000 is empty"),
            ("Kw=1e5..1e5", "is empty"),
            ("theta_bw=0..2e-4:log", "log range needs positive bounds"),
            ("Kw=-1e5..1e6:log", "log range needs positive bounds"),
            ("Kw=1e5..1e6:1", "1 levels"),
            ("Kw=1e5", "expected NAME=LOW..HIGH"),
            ("Kw=a..1", "LOW `a` is not a number"),
            ("Kw=1..2:cubic", "`cubic` is neither"),
            ("Kw=-1..2", "must be positive: the range may not go below 0"),
            ("Rg=-1..1", "may not pass through 0"),
            ("Kw=1e5..2e5:log:log", "the scale is given twice"),
            ("Kw=1e5..2e5:5:7", "the number of levels is given twice"),
        ];
        for (spec, want) in cases {
            let err = parse(spec, &worm()).unwrap_err().to_string();
            assert!(err.contains(want) && err.contains(spec), "{spec}: {err}");
        }
        let roller = presets::load("roller-gear-cam").unwrap();
        let err = parse("Kg=1..2", &roller).unwrap_err().to_string();
        assert!(err.contains("does not apply"), "{err}");
        let err = parse_all(&["Kw=1..2".into(), "Kw=3..4".into()], &worm()).unwrap_err();
        assert_eq!(err.to_string(), "parameter `Kw` is varied twice");
    }
}
