//! Standard errors and correlations as the result file holds them
//! ([`crate::identify::intervals::uncertainty`] computes them).

/// The uncertainty of a result.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Uncertainty {
    /// Name → standard error in the parameter's unit (absent when undefined).
    pub standard_errors: Vec<(String, Option<f64>)>,
    /// Parameter names, and the correlation matrix in their order.
    pub names: Vec<String>,
    pub correlation: Vec<Vec<f64>>,
    /// σ² of the scaled residuals: ~1 when the model fits to the assumed measurement
    /// error, ≪ 1 on noise-free virtual data.
    pub residual_variance: f64,
    /// Smallest / largest singular value of the column-scaled Jacobian.
    pub conditioning: f64,
    /// Whether the standard errors are known lower bounds: the cost is rough (a
    /// closed-loop simulation, where the search stops in local minima) or the
    /// nonlinear corrections did not converge. They are then not the interval to
    /// read: the bootstrap's is (docs/identification.md).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub lower_bounds: bool,
}
