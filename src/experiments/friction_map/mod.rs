//! The friction map (docs/experiments.md, "Friction map"): the axis run at a series of
//! constant speeds in both directions, the mean motor torque (or force) at each — the
//! experiment that shows a drive's friction law: the Coulomb level, a Stribeck rise at
//! low speed, the viscous slope and the offset a load puts between the directions.
//!
//! - [`steady`]: the model's map, the torque its steady state needs at each speed;
//! - [`run`]: the virtual experiment, the servo holding each speed in turn;
//! - [`evaluate`]: a map's fitted laws (estimation/friction_law) and which the data
//!   support;
//! - [`compensation`]: the friction compensation a map (or a model's) determines.

pub mod compensation;
pub mod evaluate;
pub mod run;
pub mod steady;

pub use evaluate::{evaluate, MapEvaluation};
pub use run::{run, MapTest};
pub use steady::{model_effort, model_map};
