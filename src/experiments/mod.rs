//! The tests (docs/experiments.md), one folder each: its description, its virtual
//! experiment (run on the model), its record as experiment-file data, and the
//! evaluation of a measured or virtual record. The estimators they share — spectra,
//! frequency-response estimation, peak and mode fitting, inverse dynamics — are in
//! [`crate::estimation`], which calls nothing of this layer.
//!
//! - [`frequency_response`]: the paper's frequency-response test (§4.1), its raw time
//!   records (stepped sine, noise, chirp, periodic multisine) and their evaluation;
//! - [`torque_curve`]: the friction-torque test (§4.2);
//! - [`positioning`]: the positioning test (§4.3) and its ISO 230-2 evaluation;
//! - [`fluctuation`]: the rotational-fluctuation test (§4.4) and the unbalance-mass
//!   test (§4.5) — one procedure, the second with a mass on the table, sharing run,
//!   record and evaluation;
//! - [`servo_trace`]: recorded closed-loop runs of any axis, their replay and virtual
//!   traces;
//! - [`compare`]: the paper's Table 3 over folders of experiment files;
//!   [`measurement_noise`]: the noise virtual experiments add.

pub mod compare;
pub mod fluctuation;
pub mod frequency_response;
pub mod friction_map;
pub mod measurement_noise;
pub mod positioning;
pub mod servo_trace;
pub mod torque_curve;
