//! Which identification runs: several experiments by plan ([`by_record`]) unless
//! the configuration asks for the joint cost, one or a joint fit on its own
//! ([`identify_one`]).

use crate::identify::by_record;
use crate::identify::config::{Config, Staging};
use crate::identify::error::IdentifyError;
use crate::identify::run::{identify_one, Identified};
use crate::identify::search::problem::Monitor;

/// Runs the identification. `monitor` carries the stop flag (Ctrl-C) and the count
/// of evaluations; stopping it ends the search early with the best point so far.
///
/// The worm-gear table's drive stiffnesses from its shipped frequency response
/// (a virtual measurement of the preset), started 40 % and 60 % off, on the linear
/// model:
///
/// ```
/// use rtid::{identify, preset, read_experiment, ExperimentSpec, IdentifyConfig, Monitor};
///
/// let file = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/worm-gear/frequency_response.json");
/// let experiment = read_experiment(file.as_ref())?;
/// let mut start = preset("worm-gear")?;
/// let truth = (start.kw, start.kg.unwrap());
/// (start.kw, start.kg) = (0.6 * truth.0, Some(1.4 * truth.1));
/// let mut config = IdentifyConfig::new(vec![ExperimentSpec::new(file, experiment)], start, &["Kw", "Kg"]);
/// config.fidelity = rtid::FidelityChoice::Linear;
/// let found = identify(&config, &Monitor::default())?;
/// let kw = found.result.parameters["Kw"];
/// assert!((kw / truth.0 - 1.0).abs() < 0.05, "Kw {kw}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn identify(config: &Config, monitor: &Monitor) -> Result<Identified, IdentifyError> {
    if config.staging == Staging::ByRecord && config.experiments.len() > 1 {
        if let Some(planned) = by_record::plan(config, monitor)? {
            return by_record::run(config, planned, monitor);
        }
    }
    identify_one(config, monitor)
}
