//! Linear units, current-driven records and servo traces.
