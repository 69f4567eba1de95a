//! The integration tests, in one binary: a module per file of `tests/`, as ripgrep
//! does. A binary per file (37 of them) compiled the generic library code each file
//! uses once per file and linked the library and its dependencies 37 times: after a
//! change to the library they took 113–117 s of CPU to build, one binary takes 75–86 s
//! (docs/performance.md, CI). `Cargo.toml` sets `autotests = false`, so a file of
//! `tests/` is compiled only as a module named here; `.ci/run` checks that each one is.
//!
//! The tests of all modules share one process, in parallel threads: none sets an
//! environment variable or changes the working directory (a child's `Command::env`
//! and `current_dir` are its own), and the binary's one global allocator
//! (`alloc_watch`) keeps its counts per thread for both modules that watch allocations.

// Shared by the modules (`support` also by the benches).
mod alloc_watch;
mod cli_support;
mod support;

mod axes;
mod cli;
mod compare;
mod compensate;
mod controller;
mod conventions;
mod corpus;
mod design;
mod drive_functions;
mod fixtures;
mod fluctuation;
mod format_properties;
mod frequency_response;
mod frequency_response_modes;
mod frequency_response_time;
mod frf_complex;
mod frf_formats;
mod friction_map;
mod friction_map_epos;
mod friction_map_runs;
mod identify;
mod import;
mod import_matrices;
mod import_sinumerik;
mod import_uff_none_labels;
mod inverse_dynamics;
mod lanes;
mod multisine_synthetic;
mod multisine_two_mass;
mod no_alloc;
mod peaks;
mod physics;
mod positioning;
mod predict;
mod profile;
mod properties;
mod real_data;
mod report;
mod resample;
mod servo_trace;
mod slurm;
mod speed_loop;
mod stribeck;
mod sweep;
mod torque_curve;
mod tuning;
