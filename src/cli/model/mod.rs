//! The commands on the model itself: its parameters ([`params`]), its modes
//! ([`modes`]) and a time simulation ([`simulate`]).

pub mod modes;
pub mod params;
pub mod simulate;
