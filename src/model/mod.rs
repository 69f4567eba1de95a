//! The axis-drive model: parameters (their registry and file form), presets, the
//! compiled drive, the laws of its meshes and friction, the simulation kernel, states
//! at rest and modal analysis.

pub mod backlash;
mod by_name;
pub mod drive;
pub mod friction;
pub mod kernel;
pub mod lane_drive;
pub mod lanes;
pub mod linear_response;
pub mod modes;
pub mod params;
pub mod params_json;
pub mod presets;
pub mod registry;
pub mod rest;
pub mod setpoint_filter;

pub use by_name::MAGNITUDE_RANGE;
pub use drive::{idx, Drive, NSTATE};
pub use kernel::{Kernel, States};
pub use lane_drive::{LaneDrive, LaneKey, LaneMismatch};
pub use params::{
    Axis, ControllerParams, HeldRange, LoopMode, ParamError, Params, Spread, Topology,
};
pub use registry::{spec, Applies, Constraint, ParamSpec, PARAMS};
pub use setpoint_filter::{FilterError, SetpointFilter, MAX_FILTERS};
