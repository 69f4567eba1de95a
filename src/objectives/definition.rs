//! What an objective declares about itself — its [`Definition`] — and the types
//! every objective shares to say it: the experiment it reads ([`Source`]), how it is
//! built, its direct first estimate, and why a setup fails ([`SetupError`]). The
//! list of definitions is [`super::registry::REGISTRY`]; this file knows none of
//! them.

use std::fmt;

use super::{Detail, Fidelity, Objective, Properties};
use crate::io::experiment_file::{Experiment, Kind};
use crate::model::{ParamError, Params};

/// Which default set of objectives: that of a search, or that of the nonlinear
/// correction stage of `--model nonlinear`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    Search,
    Correction,
}

/// An experiment as an objective reads it: the file it came from and its content.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    pub file: &'a str,
    pub experiment: &'a Experiment,
}

impl Source<'_> {
    /// The experiment's kind.
    pub fn kind(&self) -> Kind {
        self.experiment.manifest.kind
    }
}

/// How an objective is built for one experiment at a fidelity.
pub type Build = fn(&Source<'_>, Fidelity) -> Result<Box<dyn Objective>, SetupError>;

/// A direct estimate of some parameters from one experiment, made before any
/// simulation (a servo trace's inverse-dynamics least squares): where the search
/// starts. `None` when the experiment or the parameter set does not allow one.
pub type FirstEstimate = fn(&Source<'_>, &Params) -> Result<Option<Estimated>, SetupError>;

/// What a [`FirstEstimate`] gives: values of named parameters (SI) and how they were
/// obtained, in words.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimated {
    pub values: Vec<(String, f64)>,
    pub method: String,
}

/// What an objective declares about itself.
pub struct Definition {
    /// The name in results (`peak_amplitude`); `peak-amplitude` is accepted too.
    pub name: &'static str,
    /// One line: what it compares.
    pub summary: &'static str,
    /// The experiment kinds it reads.
    pub reads: &'static [Kind],
    /// Those kinds in words, for errors ("a torque_curve experiment").
    pub needs: &'static str,
    pub properties: Properties,
    /// The parameters a user who names none wants fitted from it.
    pub determines: fn(&Experiment, &Params) -> Vec<&'static str>,
    /// Its weight (relative to the experiment's) among the objectives an experiment
    /// feeds by default at `stage`; `None`: not a default there.
    pub default_weight: fn(&Experiment, Stage) -> Option<f64>,
    /// The objective of one experiment at a fidelity.
    pub build: Build,
    /// Its direct estimate of where to start, if it has one.
    pub first_estimate: Option<FirstEstimate>,
    /// Its [`Detail`] in words, for the console (`None`: it has nothing to add to
    /// the RMS, or the detail is not its own).
    pub describe: fn(&Detail) -> Option<String>,
}

/// An objective by name: a handle on its [`Definition`] in the registry.
#[derive(Clone, Copy)]
pub struct ObjectiveKind(pub(super) &'static Definition);

impl ObjectiveKind {
    pub fn definition(self) -> &'static Definition {
        self.0
    }

    pub fn name(self) -> &'static str {
        self.0.name
    }

    pub fn properties(self) -> Properties {
        self.0.properties
    }

    /// Whether it reads experiments of `kind`.
    pub fn reads(self, kind: Kind) -> bool {
        self.0.reads.contains(&kind)
    }

    /// Its objective for one experiment at `fidelity`; a mismatch error naming both
    /// when it does not read the experiment's kind.
    pub fn build(
        self,
        source: &Source<'_>,
        fidelity: Fidelity,
    ) -> Result<Box<dyn Objective>, SetupError> {
        if !self.reads(source.kind()) {
            return Err(SetupError::Mismatch {
                file: source.file.into(),
                kind: source.kind().name(),
                objective: self.name(),
                needs: self.0.needs,
            });
        }
        (self.0.build)(source, fidelity)
    }

    /// Its detail at a result in words ([`Definition::describe`]).
    pub fn describe(self, detail: &Detail) -> Option<String> {
        (self.0.describe)(detail)
    }

    /// Its direct estimate from one experiment, when it has one and the experiment and
    /// `base` allow it.
    pub fn first_estimate(
        self,
        source: &Source<'_>,
        base: &Params,
    ) -> Result<Option<Estimated>, SetupError> {
        match self.0.first_estimate {
            Some(f) if self.reads(source.kind()) => f(source, base),
            _ => Ok(None),
        }
    }
}

impl PartialEq for ObjectiveKind {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.0, other.0)
    }
}

impl Eq for ObjectiveKind {}

impl fmt::Debug for ObjectiveKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for ObjectiveKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for ObjectiveKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Why experiments and objectives do not fit together.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum SetupError {
    #[error(
        "{file}: a {kind} experiment cannot feed the {objective} objective (it needs {needs})"
    )]
    Mismatch {
        file: String,
        kind: &'static str,
        objective: &'static str,
        needs: &'static str,
    },
    #[error("{file}: {kind} experiments are not used for identification (use frequency_response, resonance, torque_curve or unbalance)")]
    Unsupported { file: String, kind: &'static str },
    #[error("{file}: {reason}")]
    Data { file: String, reason: String },
    #[error("{file}: no resonance peak found in the gain curve")]
    NoPeaks { file: String },
    #[error(
        "{file}: weight {}: a weight is relative (default 1): give one within 1e-6..1e6",
        crate::names::Num(*weight)
    )]
    BadWeight { file: String, weight: f64 },
    #[error(transparent)]
    Param(#[from] ParamError),
}
