//! From the experiments to the joint objective: which objectives each experiment
//! feeds at a stage (its own, or its kind's defaults from the registry), with which
//! weights, and which parameters a user who names none wants fitted.

use crate::identify::config::ExperimentSpec;
use crate::model::Params;
use crate::objectives::{Fidelity, Joint, ObjectiveKind, SetupError, Smoothness, Source, Stage};

/// The objectives `spec` feeds at `stage`, each with its weight (the experiment's
/// times the objective's relative one).
pub(crate) fn selection(
    spec: &ExperimentSpec,
    stage: Stage,
) -> Result<Vec<(ObjectiveKind, f64)>, SetupError> {
    let w = spec.weight;
    if !crate::identify::config::WEIGHTS.contains(&w) {
        return Err(SetupError::BadWeight {
            file: spec.source.clone(),
            weight: w,
        });
    }
    let kind = spec.experiment.manifest.kind;
    let chosen = match &spec.objectives {
        Some(list) => {
            let mut chosen = Vec::new();
            for &o in list {
                if !o.reads(kind) {
                    return Err(SetupError::Mismatch {
                        file: spec.source.clone(),
                        kind: kind.name(),
                        objective: o.name(),
                        needs: o.definition().needs,
                    });
                }
                chosen.push((o, 1.0));
            }
            chosen
        }
        None => ObjectiveKind::defaults(&spec.experiment, stage),
    };
    if chosen.is_empty() {
        return Err(SetupError::Unsupported {
            file: spec.source.clone(),
            kind: kind.name(),
        });
    }
    Ok(chosen.into_iter().map(|(o, r)| (o, w * r)).collect())
}

/// The joint objective of `specs` at `stage` and `fidelity`.
pub fn build(
    specs: &[ExperimentSpec],
    stage: Stage,
    fidelity: Fidelity,
) -> Result<Joint, SetupError> {
    let mut joint = Joint::default();
    for spec in specs {
        let source = Source {
            file: &spec.source,
            experiment: &spec.experiment,
        };
        for (kind, weight) in selection(spec, stage)? {
            joint.push(
                spec.source.clone(),
                weight,
                kind,
                kind.build(&source, fidelity)?,
            );
        }
    }
    Ok(joint)
}

/// The parameters fitted when none are named: what the primary objectives of the
/// search (those at full relative weight, not tie-breakers) determine, in registry
/// order, each once.
pub(crate) fn default_fit(specs: &[ExperimentSpec], p: &Params) -> Result<Vec<String>, SetupError> {
    let mut primary: Vec<(ObjectiveKind, &ExperimentSpec)> = Vec::new();
    for spec in specs {
        for (kind, weight) in selection(spec, Stage::Search)? {
            if weight >= spec.weight {
                primary.push((kind, spec));
            }
        }
    }
    let mut fit: Vec<String> = Vec::new();
    for kind in ObjectiveKind::all() {
        for (_, spec) in primary.iter().filter(|(k, _)| *k == kind) {
            for name in (kind.definition().determines)(&spec.experiment, p) {
                if !fit.iter().any(|f| f == name) {
                    fit.push(name.to_string());
                }
            }
        }
    }
    Ok(fit)
}

/// What the objectives of `specs` at `stage` declare, together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Declared {
    /// Some objective is rough (a closed-loop simulation).
    pub rough: bool,
    /// Some objective is rough at the scale of any difference step
    /// ([`Smoothness::Rough`]): the search is derivative-free.
    pub derivative_free: bool,
    /// Some objective depends on the frequency-response model.
    pub frequency_response: bool,
    /// Some experiment is a measured gain curve (the nonlinear stage has flanks to fit).
    pub gain_curve: bool,
}

/// The declared properties of the objectives `specs` feed at `stage`.
pub(crate) fn declared(specs: &[ExperimentSpec], stage: Stage) -> Result<Declared, SetupError> {
    let mut d = Declared {
        rough: false,
        derivative_free: false,
        frequency_response: false,
        gain_curve: false,
    };
    for spec in specs {
        d.gain_curve |=
            spec.experiment.manifest.kind == crate::io::experiment_file::Kind::FrequencyResponse;
        for (kind, _) in selection(spec, stage)? {
            let p = kind.properties();
            d.rough |= p.smoothness != Smoothness::Smooth;
            d.derivative_free |= p.smoothness == Smoothness::Rough;
            d.frequency_response |= p.frequency_response;
        }
    }
    Ok(d)
}
