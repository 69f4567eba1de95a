//! Periodic excitation (Pintelon & Schoukens, *System Identification: A Frequency
//! Domain Approach*, 2nd ed., 2012): the [`multisine`] that excites whole numbers of
//! cycles per period, the [`record`] cut into whole periods and transformed, the
//! frequency-response [`estimate`] at the excited lines with their noise, the
//! [`nonlinear_distortion`] at the lines left out, and the line-to-line
//! [`line_scatter`] both use.

pub mod estimate;
pub mod line_scatter;
pub mod multisine;
pub mod nonlinear_distortion;
pub mod record;
