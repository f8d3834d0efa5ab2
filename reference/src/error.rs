//! Typed errors: invalid model parameters, and queries a model cannot answer.

use thiserror::Error;

/// A model parameter that violates the model's domain of validity.
///
/// Every constructor validates with `!(x > bound)` style comparisons, so that NaN fails too.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// A roughness parameter is not a finite number greater than zero.
    #[error("{name} must be finite and > 0 (got {value})")]
    AlphaNotPositive {
        /// The parameter's name (`alpha`, `alpha_x`, `alpha_y`).
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A roughness parameter is positive but outside the supported range (see
    /// `model::ALPHA_MIN`, `model::ALPHA_MAX`).
    #[error("{name} must be in [{min:e}, {max:e}], the supported roughness range (got {value:e})")]
    AlphaOutOfRange {
        /// The parameter's name (`alpha`, `alpha_x`, `alpha_y`).
        name: &'static str,
        /// The value given.
        value: f64,
        /// The smallest supported roughness.
        min: f64,
        /// The largest supported roughness.
        max: f64,
    },
    /// The shape parameter γ is outside the model's domain.
    #[error("gamma must be {requirement} for {family} (got {value})")]
    GammaOutOfRange {
        /// The model family.
        family: &'static str,
        /// What γ must satisfy, in words.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// A parameter other than α or γ is outside its domain.
    #[error("{name} must be {requirement} (got {value})")]
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// What it must satisfy, in words.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// The parameters were given in a combination the model does not accept.
    #[error("{0}")]
    Combination(String),
    /// A piecewise-linear profile (breakpoints and values, document 000 eq 4) is malformed.
    #[error("profile {axis}: {requirement} (at index {index}, got {value})")]
    InvalidProfile {
        /// Which profile (`x`, `y`).
        axis: &'static str,
        /// The index of the offending breakpoint or value.
        index: usize,
        /// What the profile must satisfy, in words.
        requirement: &'static str,
        /// The offending number (a length, for length errors).
        value: f64,
    },
    /// A model that must be isotropic (D depends on θ only) is not.
    #[error("the {axis} model ({family}) must be isotropic")]
    NotIsotropic {
        /// Which slot (`x`, `y`).
        axis: &'static str,
        /// The model's family.
        family: &'static str,
    },
}

/// A query that is well-formed but that the model cannot answer as asked.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum QueryError {
    /// The model has no meaning for this quantity (e.g. Λ of an NDF without a Smith form).
    #[error("{family} does not support {quantity}")]
    Unsupported {
        /// The model family.
        family: String,
        /// The quantity asked for.
        quantity: String,
    },
    /// The route is unknown for this quantity, or does not apply to these parameters.
    #[error("route {route:?} is not available: {reason}")]
    Route {
        /// The route asked for.
        route: String,
        /// Why it is not available (unknown, or its condition on γ fails).
        reason: String,
    },
    /// An argument of the query is outside its domain.
    #[error("{0}")]
    Argument(String),
}
