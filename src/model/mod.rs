//! The rotary-table model: parameters, presets, the compiled drive, the laws of its
//! meshes and friction, the simulation kernel and modal analysis.

pub mod backlash;
pub mod drive;
pub mod friction;
pub mod kernel;
pub mod lanes;
pub mod linear_response;
pub mod modes;
pub mod params;
pub mod presets;

pub use drive::{idx, Drive, NSTATE};
pub use kernel::{Kernel, States};
pub use params::{ControllerParams, LoopMode, ParamError, Params, Topology};
