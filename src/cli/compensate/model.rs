//! `rtid compensate --fit FIT.json --preset …`: the compensation of an identified
//! model, from its own virtual positioning test (the reversal the meshes' play, the
//! elastic lost motion and the friction make together) and, with `--friction`, the
//! friction law its steady map gives at the motor.

use anyhow::Context;

use super::Args;
use rtid::controller::FrictionCompensation;
use rtid::experiments::friction_map;
use rtid::experiments::positioning::{self, iso230::Measurement, PositioningTest};
use rtid::model::Params;

/// The identified model: the base set (--preset, --params) with the fit's values and
/// the tuned controller (--tune).
pub fn params(a: &Args) -> anyhow::Result<Params> {
    crate::cli::common::model_args::fitted(&a.model, a.fit.as_deref(), a.tune.as_deref())
}

/// The model's name in messages: the fit, else the parameter file or preset.
pub fn name(a: &Args) -> String {
    match (&a.fit, &a.model.params, &a.model.preset) {
        (Some(f), _, _) => f.display().to_string(),
        (None, Some(p), _) => p.display().to_string(),
        (None, None, Some(n)) => format!("preset {n}"),
        _ => "the model".into(),
    }
}

/// The standard positioning test's readings on the model (no noise).
pub fn record(p: &Params, quiet: bool) -> anyhow::Result<Vec<Measurement>> {
    let test = PositioningTest::standard(p.axis);
    let bar = crate::cli::common::progress::bar(test.readings() as u64, "positioning", quiet);
    let readings = positioning::run(p, &test, |done, _| bar.set_position(done as u64))
        .context("the virtual positioning test on the model")?;
    bar.finish_and_clear();
    Ok(readings)
}

/// The friction compensation of the model: the symmetric law fitted to its steady
/// map at the standard friction-map speeds (exact where the bodies' laws lump into
/// one; the fit's family chosen as for a measured map).
pub fn friction(p: &Params, name: &str) -> anyhow::Result<FrictionCompensation> {
    friction_map::compensation::of_model(p)
        .with_context(|| format!("--friction: the steady map of {name}"))
}
