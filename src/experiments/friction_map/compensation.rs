//! The friction compensation a friction map determines (docs/compensation.md): the
//! symmetric law of the family the map's data support (Coulomb, or Stribeck where
//! the map shows the rise), with its offset, at the motor, fed forward on the
//! commanded speed. From a measured (or virtual) map, or from a model's steady map at
//! the standard speeds — exact where the bodies' laws lump into one.

use crate::controller::FrictionCompensation;
use crate::estimation::friction_law::{LawFit, MapProblem};
use crate::io::compensation_file::axis_name;
use crate::io::experiment_file::{Axis, Data, Experiment, FrictionMap};
use crate::model::{ParamError, Params};

use super::{evaluate, steady::model_map, MapEvaluation, MapTest};

/// Why a map gives no friction compensation.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NoCompensation {
    /// The map cannot be evaluated.
    #[error(transparent)]
    Map(#[from] MapProblem),
    /// The model's steady map cannot be computed.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// Not a friction map.
    #[error("a `{kind}` experiment, not a friction map")]
    NotAMap {
        /// The experiment's kind.
        kind: &'static str,
    },
    /// A map of the other kind of axis.
    #[error("a map of a {map} axis for a {record} axis's compensation")]
    Axis {
        /// The map's axis.
        map: &'static str,
        /// The compensation's axis.
        record: &'static str,
    },
    /// The family the data support has no determined symmetric form.
    #[error("the map determines no symmetric law (the data support {selected}, whose symmetric form is not determined): no friction compensation")]
    NotDetermined {
        /// The law the data support.
        selected: String,
    },
}

/// The compensation of the law `evaluation` selects, if determined.
pub fn of_evaluation(evaluation: &MapEvaluation) -> Result<FrictionCompensation, NoCompensation> {
    let Some((law, offset)) = evaluation.symmetric().and_then(LawFit::steady) else {
        return Err(NoCompensation::NotDetermined {
            selected: evaluation.laws.selected.to_string(),
        });
    };
    Ok(FrictionCompensation {
        law,
        offset,
        pulse: None,
    })
}

/// The compensation a friction map determines.
pub fn of_map(map: &FrictionMap) -> Result<FrictionCompensation, NoCompensation> {
    of_evaluation(&evaluate(map)?)
}

/// The compensation a friction-map experiment determines, for an axis of kind `axis`
/// (the positioning record's, or the model's).
pub fn of_experiment(exp: &Experiment, axis: Axis) -> Result<FrictionCompensation, NoCompensation> {
    let Data::FrictionMap(map) = &exp.data else {
        return Err(NoCompensation::NotAMap {
            kind: exp.manifest.kind.name(),
        });
    };
    if map.axis != axis {
        return Err(NoCompensation::Axis {
            map: axis_name(map.axis),
            record: axis_name(axis),
        });
    }
    of_map(map)
}

/// The compensation of model `p`: the law fitted to its steady map at the standard
/// friction-map speeds ([`MapTest::default_speeds`]), its family chosen as for a
/// measured map.
pub fn of_model(p: &Params) -> Result<FrictionCompensation, NoCompensation> {
    let speeds = MapTest::default_speeds(p);
    let effort = model_map(p, &speeds)?;
    of_map(&FrictionMap::new(p.axis, speeds, effort))
}
