//! How well the data determine the fitted parameters: standard errors and correlations
//! from the Jacobian ([`uncertainty`]), profile-likelihood intervals ([`profile`]) and
//! the residual block bootstrap ([`resample`]).

pub mod profile;
pub mod request;
pub mod resample;
pub mod surface;
pub mod uncertainty;
