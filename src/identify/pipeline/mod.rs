//! The steps of an identification after the plan: the [`stages`] (a multi-start
//! search, the [`correction`]s by the nonlinear test when the [`escalation`] check
//! asks for them, resumable from a [`checkpoint`]), the [`assess`]ment of the best
//! point, the result [`assemble`]d, and the [`comparison`] of the fitted model with
//! each experiment's data.

pub mod assemble;
pub mod assess;
pub mod checkpoint;
pub mod comparison;
pub mod correction;
pub mod escalation;
pub mod stages;
