//! rtid — simulation and identification of CNC rotary tables (worm-gear and
//! roller-gear-cam drives), after the model of IMECE2008-66108.
//!
//! Data flows one way: files (`io`) → simulation (`model`, `controller`, `sim`) →
//! results → report.
#![forbid(unsafe_code)]

/// The version and the commit built from: `0.1.0 (commit 1a2b3c4d5e6f)`.
pub const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (", env!("RTID_COMMIT"), ")");

pub mod controller;
pub mod estimation;
pub mod experiments;
pub mod identify;
pub mod input;
pub mod io;
pub mod model;
pub mod names;
pub mod objectives;
pub mod recorder;
pub mod report;
pub mod sim;
pub mod sweep;
