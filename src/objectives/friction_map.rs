//! Friction-map residual: the model's steady-state motor torque (force) at each run's
//! mean speed (`experiments::friction_map::steady`) against the run's mean, run by run.
//! Scale: 1 % of the map's RMS effort per run (it sets the weight beside other
//! objectives; the standard errors come from the residuals' own scatter).
//!
//! What a map at the motor can separate: every body's friction reaches the motor
//! through the ratios, so a map determines one Coulomb level, one viscous slope, one
//! offset (the load `Tload`) and one Stribeck curve, all at the motor. Fit the motor's
//! (or, on a direct drive, the table's) and keep the rest fixed, or expect the
//! identifiability warning. The search starts at the direct fit of the law to the map
//! (estimation/friction_law), carried onto the model: the first estimate.

use super::definition::{Definition, Estimated, SetupError, Source};
use super::{Fidelity, Objective, ObjectiveError, Properties, Smoothness};
use crate::estimation::friction_law::{check_map, LawFit};
use crate::experiments::friction_map::{evaluate, model_effort};
use crate::io::experiment_file::{Data, FrictionMap, Kind};
use crate::model::friction::{Body, SteadyFriction};
use crate::model::{Drive, Params, Topology};

/// The friction-map objective: the model's steady state, smooth and quick.
pub static DEFINITION: Definition = Definition {
    name: "friction_map",
    summary: "error of the steady-state motor torque (force) at each run's speed of a friction map",
    reads: &[Kind::FrictionMap],
    needs: "a friction_map experiment",
    properties: Properties {
        smoothness: Smoothness::Smooth,
        frequency_response: false,
    },
    determines: |_, p| determines(p),
    default_weight: |exp, _| (exp.manifest.kind == Kind::FrictionMap).then_some(1.0),
    build,
    first_estimate: Some(direct_fit_start),
    describe: |_| None,
};

/// The body whose friction a map at the motor names: the motor's, or the one body of
/// a direct drive.
fn determines(p: &Params) -> Vec<&'static str> {
    match p.topology {
        Topology::DirectDrive => vec!["ft", "Ct", "Tload"],
        _ => vec!["fm", "Cm", "Tload"],
    }
}

fn map_of<'a>(source: &Source<'a>) -> Result<&'a FrictionMap, SetupError> {
    match &source.experiment.data {
        Data::FrictionMap(m) => Ok(m),
        _ => Err(SetupError::Unsupported {
            file: source.file.into(),
            kind: source.kind().name(),
        }),
    }
}

fn build(source: &Source<'_>, _: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let map = map_of(source)?;
    // A map no law can be fitted to is refused here, naming the file (the checks
    // alone: the laws are fitted once, by the first estimate).
    check_map(&map.speed, &map.effort).map_err(|e| SetupError::Data {
        file: source.file.into(),
        reason: e.to_string(),
    })?;
    Ok(Box::new(MapResidual::new(map)))
}

/// The direct fit of the map's law (the symmetric one of the selected family) carried
/// onto the model: the motor's (a direct drive's table's) Coulomb level, viscous
/// damping, Stribeck rise and speed, the shape, and `Tload` from the offset — each the
/// value that makes the model's map the fitted law with the other bodies as given.
fn direct_fit_start(source: &Source<'_>, base: &Params) -> Result<Option<Estimated>, SetupError> {
    let map = map_of(source)?;
    let Ok(evaluation) = evaluate(map) else {
        return Ok(None);
    };
    let Some(fit) = evaluation.symmetric() else {
        return Ok(None);
    };
    Ok(Some(Estimated {
        values: carried(fit, base)?,
        method: format!(
            "the {} law fitted directly to the map's {} runs",
            fit.law.name(),
            fit.n
        ),
    }))
}

/// The model's parameters that reproduce `fit`, with every other body of `base` as
/// it is (their Coulomb levels and dampings through the ratios; their own Stribeck
/// rises, if any, are left out of the carry): the body's own law is the map's law
/// less the others' odd part at the motor, the offset the load.
fn carried(fit: &LawFit, base: &Params) -> Result<Vec<(String, f64)>, SetupError> {
    let Some((at_motor, offset)) = fit.steady() else {
        return Ok(Vec::new());
    };
    let body = if base.topology == Topology::DirectDrive {
        Body::Table
    } else {
        Body::Motor
    };
    // The other bodies alone: the own body's friction, damping and rise and the load
    // set to 0. Their odd part at the motor is L·sgn(ω) + S·ω.
    let mut others = base.clone();
    others.set_steady(body, &SteadyFriction::NONE);
    others.tload = 0.0;
    let d = Drive::new(&others)?;
    let odd = |w: f64| 0.5 * (model_effort(&d, w) - model_effort(&d, -w));
    let slope = odd(2.0) - odd(1.0);
    let others_level = odd(1.0) - slope;
    let own = SteadyFriction {
        coulomb: at_motor.coulomb - others_level,
        viscous: at_motor.viscous - slope,
        ..at_motor
    };
    let mut out: Vec<(String, f64)> = own
        .named(body)
        .into_iter()
        .map(|(name, value)| (name.to_string(), value))
        .collect();
    // The offset at the motor is −Rg·Rw·Tload.
    out.insert(2, ("Tload".to_string(), -offset / d.ratio()));
    Ok(out)
}

/// One scaled residual is this fraction of the map's RMS effort.
pub const SCALE_OF_RMS: f64 = 0.01;

/// A measured friction map.
#[derive(Clone, Debug)]
pub struct MapResidual {
    speed: Vec<f64>,
    effort: Vec<f64>,
    /// N·m (N) per unit of scaled residual.
    scale: f64,
    unit: &'static str,
}

impl MapResidual {
    pub fn new(map: &FrictionMap) -> Self {
        let n = map.effort.len().max(1) as f64;
        let rms = (map.effort.iter().map(|t| t * t).sum::<f64>() / n).sqrt();
        MapResidual {
            speed: map.speed.clone(),
            effort: map.effort.clone(),
            scale: (SCALE_OF_RMS * rms).max(f64::MIN_POSITIVE),
            unit: map.axis.effort_unit(),
        }
    }
}

impl Objective for MapResidual {
    fn name(&self) -> &'static str {
        "friction_map"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let d = Drive::new(p)?;
        Ok(self
            .speed
            .iter()
            .zip(&self.effort)
            .map(|(&v, &t)| (model_effort(&d, v) - t) / self.scale)
            .collect())
    }

    fn len(&self) -> usize {
        self.speed.len()
    }

    fn scale(&self) -> String {
        format!(
            "{:.3e} {} at the motor per run (1 % of the map's RMS)",
            self.scale, self.unit
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::friction_map::model_map;
    use crate::model::presets;

    /// The worm with a Stribeck rise on its motor and a load, its model map at ±0.5 …
    /// ±100 rad/s.
    fn worm_map() -> (Params, FrictionMap) {
        let mut p = presets::load("worm-gear").unwrap();
        (p.fsm, p.vsm, p.stribeck_shape, p.tload) = (0.06, 3.0, 1.0, 2.0);
        let ups = [0.5, 1.0, 2.0, 4.0, 8.0, 15.0, 30.0, 60.0, 100.0];
        let speeds: Vec<f64> = ups.iter().map(|v| -v).chain(ups).collect();
        let effort = model_map(&p, &speeds).unwrap();
        (p.clone(), FrictionMap::new(p.axis, speeds, effort))
    }

    #[test]
    fn the_direct_fit_carried_onto_the_model_gives_its_motor_friction_back() {
        let (truth, map) = worm_map();
        let evaluation = evaluate(&map).unwrap();
        let fit = evaluation.symmetric().unwrap();
        let mut start = presets::load("worm-gear").unwrap();
        (start.fm, start.cm) = (0.05, 0.02);
        let values = carried(fit, &start).unwrap();
        for (name, v) in &values {
            let expected = truth.get(name).unwrap().unwrap();
            assert!(
                (v - expected).abs() <= 1e-6 * expected.abs().max(1e-3),
                "{name}: {v} against {expected}"
            );
        }
        assert_eq!(values.len(), 6, "{values:?}");
    }

    #[test]
    fn the_residual_is_zero_at_the_truth() {
        let (truth, map) = worm_map();
        let r = MapResidual::new(&map).residuals(&truth).unwrap();
        assert!(r.iter().all(|x| x.abs() < 1e-9), "{r:?}");
    }
}
