//! Files in and out: parameter files, experiment files, atomic writes.

pub mod atomic;
pub mod experiment_file;
pub mod params_file;
pub mod torque_file;
