//! What every command shares: the mechanism's arguments ([`model_args`]), reading
//! input files ([`inputs`]), where plots go ([`plot`]), progress bars ([`progress`]), the Ctrl-C handler
//! ([`interrupt`]) and held parameters' ranges ([`uncertain`]).

pub mod inputs;
pub mod interrupt;
pub mod model_args;
pub mod plot;
pub mod progress;
pub mod uncertain;
