//! Reports: SVG charts.

pub mod plot;
