//! How a search or a stage of one ended, typed.

use std::fmt;

use serde::{Deserialize, Serialize};

/// How a local search (or the nonlinear correction stage) ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "code", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Termination {
    /// The solver's convergence test was met.
    Converged,
    /// The iteration limit was reached.
    IterationLimit,
    /// Stopped by Ctrl-C or an evaluation budget.
    Interrupted,
    /// Gauss–Newton found JᵀJ singular at this start.
    Singular,
    /// Another reason argmin gave.
    Solver { reason: String },
    /// The solver failed.
    SolverError { message: String },
    /// The corrections of the linear fit by the nonlinear test ended: converged (no
    /// parameter moved more than the tolerance) or at their limit.
    Corrections {
        corrections: usize,
        nonlinear_evaluations: usize,
        converged: bool,
        /// Largest relative move of the last correction.
        last_step: f64,
        /// Each fitted parameter's relative move in the last correction, where it
        /// did not converge (empty when it did).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        moved: Vec<(String, f64)>,
    },
    /// The corrected linear problem could not be evaluated near this point.
    CorrectionFailed { at: String },
    /// No start ran.
    NoStart,
}

impl Termination {
    /// Whether the search was stopped before its end.
    pub fn interrupted(&self) -> bool {
        *self == Termination::Interrupted
    }

    /// Whether it converged (a solver's test, or the corrections').
    pub fn converged(&self) -> bool {
        matches!(
            self,
            Termination::Converged
                | Termination::Corrections {
                    converged: true,
                    ..
                }
        )
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Termination::Converged => f.write_str("converged"),
            Termination::IterationLimit => f.write_str("iteration limit reached"),
            Termination::Interrupted => f.write_str("interrupted"),
            Termination::Singular => f.write_str(
                "stopped: JᵀJ singular at this start (the residuals do not depend on every parameter there)",
            ),
            Termination::Solver { reason } => f.write_str(reason),
            Termination::SolverError { message } => write!(f, "solver error: {message}"),
            Termination::Corrections {
                corrections,
                nonlinear_evaluations,
                converged: true,
                ..
            } => write!(
                f,
                "converged after {corrections} corrections of the linear fit ({nonlinear_evaluations} evaluations of the nonlinear test)"
            ),
            Termination::Corrections {
                corrections,
                nonlinear_evaluations,
                last_step,
                ..
            } => write!(
                f,
                "{corrections} corrections of the linear fit ({nonlinear_evaluations} evaluations of the nonlinear test); the last moved the result by {:.2} %",
                100.0 * last_step
            ),
            Termination::CorrectionFailed { at } => write!(
                f,
                "the corrected linear problem could not be evaluated near {at}"
            ),
            Termination::NoStart => f.write_str("no start ran"),
        }
    }
}
