//! rtid — simulation and identification of CNC axis drives (worm-gear and
//! roller-gear-cam rotary tables, direct and two-mass drives, rotary or linear), after
//! the model of IMECE2008-66108.
//!
//! Data flows one way: files (`io`) → simulation (`model`, `controller`, `sim`) →
//! results → report.
//!
//! # The front
//!
//! What a program, a script binding or another crate uses is re-exported here, flat:
//!
//! - **parameters**: [`Params`] (every parameter by its registry name, SI units:
//!   [`Params::set`], [`Params::get`], [`Params::validate`]), [`preset`] and
//!   [`preset_names`], the registry [`PARAMS`] with each parameter's unit and meaning,
//!   [`ParamError`]; the drive's natural frequencies and mode shapes, [`modes`] into
//!   [`Modes`];
//! - **simulation**: [`Simulation`] (open loop under a [`TorqueInput`] such as
//!   [`Sine`], closed loop along a [`Move`]) into a [`Recorder`], [`default_step`],
//!   [`SimError`];
//! - **experiment files** — the tests' records as rtid writes and reads them:
//!   [`read_experiment`], [`write_experiment`], [`Experiment`], [`Kind`], [`Data`];
//!   the formats labs export, [`read_recording`] into a [`Recording`];
//! - **the tests** on the model and their evaluations: [`FrequencyTest`],
//!   [`TorqueTest`], [`PositioningTest`], [`FluctuationTest`], [`MapTest`] with the
//!   modules [`frequency_response`], [`torque_curve`], [`positioning`],
//!   [`fluctuation`], [`friction_map`], [`servo_trace`] (each: `run`, the record ↔
//!   file, `evaluate`);
//! - **identification**: [`identify`] from a [`IdentifyConfig`] of
//!   [`ExperimentSpec`]s (the model by [`FidelityChoice`]), watched by a [`Monitor`], into an [`Identified`] with its
//!   [`IdentifyResult`] (values, standard errors, correlations, [`Warning`]s),
//!   [`IdentifyError`];
//! - **sweeps**: [`Sweep`], [`run_sweep`] with [`SweepOptions`] into a
//!   [`SweepReport`], [`SweepError`];
//! - [`VERSION`].
//!
//! The modules below the front (`model`, `sim`, `experiments`, `objectives`,
//! `identify`, …) are hidden from these docs: they are the command line's, the
//! tests' and the benches' way in (separate crates of this package, they see only
//! what is `pub`), and may change without notice. docs/architecture.md shows the
//! front and why the modules are not yet private.
//!
//! # Example
//!
//! The worm-gear table's first resonance, then a sine of the motor torque near it:
//!
//! ```
//! use rtid::{modes, preset, NullRecorder, Simulation, Sine};
//!
//! let p = preset("worm-gear")?;
//! let first_hz = modes(&p)?.clamped_hz[0];
//! assert!(first_hz > 50.0 && first_hz < 2000.0);
//!
//! let mut sim = Simulation::with_default_step(&p)?;
//! let mut input = Sine::new(first_hz, 5.0, 0.0);
//! sim.run_open_loop(&mut input, 0.05, &mut NullRecorder)?;
//! let table_angle = sim.state()[rtid::TABLE_ANGLE];
//! assert!(table_angle.is_finite());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use version::VERSION;

#[doc(hidden)]
pub mod angle;
#[doc(hidden)]
pub mod controller;
#[doc(hidden)]
pub mod estimation;
#[doc(hidden)]
pub mod experiments;
#[doc(hidden)]
pub mod identify;
#[doc(hidden)]
pub mod input;
#[doc(hidden)]
pub mod input_spec;
pub mod interrupt;
#[doc(hidden)]
pub mod io;
pub mod limits;
#[doc(hidden)]
pub mod model;
#[doc(hidden)]
pub mod names;
#[doc(hidden)]
pub mod objectives;
#[doc(hidden)]
pub mod prediction;
#[doc(hidden)]
pub mod recorder;
#[doc(hidden)]
pub mod report;
#[doc(hidden)]
pub mod sim;
#[doc(hidden)]
pub mod sweep;
#[doc(hidden)]
pub mod tuning;
mod version;

// Parameters and presets.
pub use model::drive::idx::THETA_T as TABLE_ANGLE;
pub use model::modes::{modes, Modes};
pub use model::presets::{load as preset, names as preset_names};
pub use model::{Axis, ParamError, ParamSpec, Params, Topology, PARAMS};

// Simulation.
pub use input::{Move, Sine, TorqueInput};
pub use recorder::{NullRecorder, Recorder};
pub use sim::{default_step, SimError, Simulation};

// Experiment files and the formats labs export.
pub use io::experiment_file::{
    read as read_experiment, write as write_experiment, Data, Experiment, ExperimentFileError, Kind,
};
pub use io::formats::detect::read as read_recording;
pub use io::formats::{FormatError, Recording};

// The tests.
pub use experiments::fluctuation::FluctuationTest;
pub use experiments::frequency_response::FrequencyTest;
pub use experiments::friction_map::MapTest;
pub use experiments::positioning::PositioningTest;
pub use experiments::torque_curve::TorqueTest;
pub use experiments::{
    fluctuation, frequency_response, friction_map, positioning, servo_trace, torque_curve,
};

// Identification.
pub use identify::{
    identify, Config as IdentifyConfig, ExperimentSpec, FidelityChoice, Identified, IdentifyError,
    IdentifyResult, Monitor, Warning,
};

// Sweeps.
pub use sweep::{
    run as run_sweep, RunOptions as SweepOptions, RunReport as SweepReport, Sweep, SweepError,
};
