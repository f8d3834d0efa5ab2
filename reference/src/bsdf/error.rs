//! Why a reference BSDF spec cannot be built: the field and the limit. Its own file so that
//! the BSDFs, which report it, and the spec, which builds them, do not import each other.

use thiserror::Error;

use crate::error::ParamError;

/// A reference BSDF spec that cannot be built, naming the field and the limit.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BsdfError {
    /// A number outside its domain (`eta`, `n`, `k`).
    #[error("{field} must be {requirement} (got {value})")]
    OutOfRange {
        /// The field's name.
        field: &'static str,
        /// What it must satisfy, with the limit.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// The NDF's own parameters are invalid.
    #[error("ndf: {0}")]
    Ndf(#[from] ParamError),
    /// The NDF has no Smith Λ (so no G1, G2).
    #[error("ndf: {family} has no Smith Λ: {reason} (a microfacet BSDF needs G1 and G2)")]
    NoSmith {
        /// The NDF's family.
        family: String,
        /// Why (the family's Smith limit, or no Smith capability).
        reason: String,
    },
    /// The sampling asked for is not available for the NDF.
    #[error("sampling: {sampling} is not available for {family}: it needs {needs}")]
    NoSampler {
        /// The sampling asked for (`normals`, `visible_normals`, `pseudo_vnis`).
        sampling: &'static str,
        /// The NDF's family.
        family: String,
        /// What the sampling needs.
        needs: &'static str,
    },
}

impl BsdfError {
    /// The spec field the error is about (`eta`, `n`, `k`, `ndf`, `sampling`).
    pub fn field(&self) -> &'static str {
        match self {
            BsdfError::OutOfRange { field, .. } => field,
            BsdfError::Ndf(_) | BsdfError::NoSmith { .. } => "ndf",
            BsdfError::NoSampler { .. } => "sampling",
        }
    }
}
