//! Readers of the files labs export, one module per format, each turning a foreign
//! file into named channels with units that `rtid import` maps onto rtid's
//! experiment files (`crate::io::experiment_file`): MAT-files, TwinCAT Scope View
//! CSV, EPOS Studio data-recorder CSV, UFF datasets 58/58b, delimited text with a
//! header. Nothing here knows the tests; the tests know nothing of these formats.
//!
//! Empty until the readers land (docs/architecture.md, "Where each kind of change
//! goes": a new format).
