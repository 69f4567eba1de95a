//! Files in and out: parameter files, experiment files, atomic writes.

pub mod atomic;
pub mod experiment_file;
pub mod params_file;
pub mod torque_file;

/// JSON text without a leading UTF-8 byte-order mark (editors on Windows write one;
/// JSON parsers refuse it at "line 1, column 1").
pub fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}
