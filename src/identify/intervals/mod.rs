//! How well the data determine the fitted parameters: standard errors and correlations
//! from the Jacobian ([`uncertainty`]), profile-likelihood intervals ([`profile`]) and
//! the residual block bootstrap ([`resample`]), and the fit's response to the held
//! parameters' ranges ([`held`]).

pub mod chosen;
pub mod held;
pub mod profile;
pub mod request;
pub mod resample;
pub mod surface;
pub mod uncertainty;
