//! Every objective by name, with what it declares: the experiments it reads, its
//! properties, what it determines, its default weight, how it is built. Adding an
//! objective is one file with its [`Definition`] and one line in [`REGISTRY`].

use std::fmt;

use super::{Fidelity, Objective, Properties};
use crate::io::experiment_file::{Experiment, Kind};
use crate::model::{ParamError, Params};
use crate::names::UnknownName;

/// The objectives, in the order their residuals are stacked and their parameters
/// listed.
pub static REGISTRY: [&Definition; 8] = [
    &super::resonance::DEFINITION,
    &super::peak_amplitude::DEFINITION,
    &super::gain_curve::DEFINITION,
    &super::gain_curve::NEAR_PEAKS,
    &super::torque_curve::DEFINITION,
    &super::unbalance_step::DEFINITION,
    &super::servo_trace::DEFINITION,
    &super::friction_map::DEFINITION,
];

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
}

/// An objective by name: a handle on its [`Definition`] in the registry.
#[derive(Clone, Copy)]
pub struct ObjectiveKind(&'static Definition);

impl ObjectiveKind {
    /// Every objective, in registry order.
    pub fn all() -> impl Iterator<Item = ObjectiveKind> {
        REGISTRY.iter().map(|d| ObjectiveKind(d))
    }

    /// The objective named `name` (`peak_amplitude` or `peak-amplitude`).
    pub fn named(name: &str) -> Result<ObjectiveKind, UnknownName> {
        let wanted = name.trim().replace('-', "_");
        Self::all()
            .find(|k| k.name() == wanted)
            .ok_or_else(|| UnknownName {
                what: "objective",
                given: name.to_string(),
                expected: Self::all().map(|k| k.name()).collect::<Vec<_>>().join(", "),
            })
    }

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

    /// The objectives `experiment` feeds by default at `stage`, with their relative
    /// weights, in registry order.
    pub fn defaults(experiment: &Experiment, stage: Stage) -> Vec<(ObjectiveKind, f64)> {
        Self::all()
            .filter_map(|k| (k.0.default_weight)(experiment, stage).map(|w| (k, w)))
            .collect()
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

impl<'de> serde::Deserialize<'de> for ObjectiveKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        ObjectiveKind::named(&name).map_err(serde::de::Error::custom)
    }
}

impl std::str::FromStr for ObjectiveKind {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, UnknownName> {
        ObjectiveKind::named(s)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found_in_both_spellings() {
        for k in ObjectiveKind::all() {
            assert_eq!(
                ObjectiveKind::all()
                    .filter(|o| o.name() == k.name())
                    .count(),
                1
            );
            assert_eq!(
                ObjectiveKind::named(&k.name().replace('_', "-")).unwrap(),
                k
            );
        }
        let err = ObjectiveKind::named("torque").unwrap_err().to_string();
        assert!(err.contains("torque_curve"), "{err}");
    }

    /// An experiment of `kind` with `data`, for the defaults.
    fn experiment(kind: Kind, data: crate::io::experiment_file::Data) -> Experiment {
        Experiment {
            manifest: crate::io::experiment_file::Manifest::new(kind),
            data,
            path: "e.json".into(),
            data_path: None,
        }
    }

    fn gain_curve(phase: bool) -> Experiment {
        experiment(
            Kind::FrequencyResponse,
            crate::io::experiment_file::Data::FrequencyResponse {
                frequency_hz: vec![10.0, 20.0],
                gain_db: vec![0.0, 0.1],
                phase_rad: phase.then(|| vec![0.0, -0.1]),
                extra: Default::default(),
            },
        )
    }

    fn names(e: &Experiment, stage: Stage) -> Vec<(&'static str, f64)> {
        ObjectiveKind::defaults(e, stage)
            .into_iter()
            .map(|(k, w)| (k.name(), w))
            .collect()
    }

    #[test]
    fn a_gain_curve_feeds_resonances_and_heights_by_default() {
        let e = gain_curve(false);
        assert_eq!(
            names(&e, Stage::Search),
            [("resonance", 1.0), ("peak_amplitude", 0.01)]
        );
        assert_eq!(names(&e, Stage::Correction), [("gain_near_peaks", 1.0)]);
        let positioning = experiment(
            Kind::Positioning,
            crate::io::experiment_file::Data::Resonance {
                peaks_hz: vec![],
                peak_gain_db: None,
            },
        );
        assert!(ObjectiveKind::defaults(&positioning, Stage::Search).is_empty());
    }

    #[test]
    fn a_response_with_phase_feeds_its_whole_complex_curve_by_default() {
        let e = gain_curve(true);
        assert_eq!(names(&e, Stage::Search), [("gain_curve", 1.0)]);
        assert_eq!(names(&e, Stage::Correction), [("gain_near_peaks", 1.0)]);
        let p = crate::model::presets::load("worm-gear").unwrap();
        let fit = (ObjectiveKind::named("gain_curve")
            .unwrap()
            .definition()
            .determines)(&e, &p);
        assert_eq!(fit, ["Kw", "Kg", "Ciw", "Cig"]);
        let without = (ObjectiveKind::named("gain_curve")
            .unwrap()
            .definition()
            .determines)(&gain_curve(false), &p);
        assert_eq!(without, ["Kw", "Kg"]);
    }
}
