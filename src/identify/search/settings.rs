//! How a search runs: the solver ([`Method`]), its starts, limits and steps.

/// How one stage searches (resolved by the [`crate::identify::plan`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub method: Method,
    /// Starts: the given start, then a Latin hypercube in the bounds.
    pub starts: usize,
    pub seed: u64,
    pub max_iters: u64,
    /// Forward-difference step of the Gauss–Newton Jacobian, solver coordinates
    /// (≈ 2× as much in ln p for the default ×100 range).
    pub fd_step: f64,
    /// Stop after this many evaluations in all (None: no limit).
    pub max_evaluations: Option<usize>,
    /// Nelder–Mead's initial simplex: each vertex this far from the start along one
    /// solver coordinate (≈ 2.3× as much in ln p for the default ×100 range).
    pub simplex_step: f64,
}

/// The default simplex step: 0.4 solver units, a factor ≈ 2.5 in a positive
/// parameter — a search from values that may be guesses.
pub const SIMPLEX_STEP: f64 = 0.4;

/// The simplex step from a direct estimate: 0.02 solver units, ≈ 5 % in a positive
/// parameter — the estimate is close (IDIM-LS on EMPS: within 2.5 % of the
/// output-error result).
pub const SIMPLEX_STEP_NEAR: f64 = 0.02;

impl Default for Settings {
    fn default() -> Self {
        Settings {
            method: Method::Lsq,
            starts: 4,
            seed: 1,
            max_iters: 50,
            fd_step: 1e-5,
            max_evaluations: None,
            simplex_step: SIMPLEX_STEP,
        }
    }
}

/// The solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Gauss–Newton with line search, finite-difference Jacobian in parallel.
    Lsq,
    /// Levenberg–Marquardt, finite-difference Jacobian and trial steps in parallel,
    /// stopped on the relative cost (for a direct-drive servo trace's replay).
    Lm,
    /// Nelder–Mead simplex.
    NelderMead,
    /// Particle swarm in the bounds.
    Pso,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Lsq => "lsq",
            Method::Lm => "lm",
            Method::NelderMead => "nelder-mead",
            Method::Pso => "pso",
        }
    }
}
