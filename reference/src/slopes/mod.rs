//! Gaussian slope distributions (document 002, §3–6): the model, its rotation into the view frame
//! and the mean and covariance of its visible slopes D_s.

pub mod gaussian;
pub mod pseudocode;
pub(crate) mod ramp;
#[cfg(test)]
mod test_quadrature;

pub use gaussian::{visible_moments_psd, GaussianSlopes};
pub use pseudocode::Transcription;
