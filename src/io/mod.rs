//! Files in and out: parameter files, atomic writes.

pub mod atomic;
pub mod params_file;
pub mod torque_file;
