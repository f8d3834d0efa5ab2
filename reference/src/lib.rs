//! mfh-reference: the reference closed forms of microfacet BSDF mathematics.
//!
//! Normal distribution functions, Smith Λ / G1 / G2, importance-sampling inversions and slope
//! moments, each citing the source document and equation it implements (documents 000–004, cited by id;
//! see ARCHITECTURE.md). This crate holds closed forms only: no oracles, no I/O, no randomness.
//! Every closed form is checked by the harness (`mfh-harness`) against independent oracles.

pub mod bsdf;
pub mod errata;
pub mod error;
pub mod family;
pub mod geometry;
pub mod model;
pub mod ndf;
pub mod registry;
pub mod sg;
pub mod slopes;
pub mod spec;
pub mod special;
#[cfg(test)]
mod test_support;
pub mod trig;

pub use bsdf::{Bsdf, BsdfSample, BsdfSpec, Transport};
pub use error::{ParamError, QueryError};
pub use geometry::Vec3;
pub use model::{
    Masking, Model, Ndf, NormalSampler, SlopeDistribution, Smith, VisibleNormalSampler,
};
pub use spec::ModelSpec;
