//! Normal distribution functions, one model per file.
//!
//! Beside the models: their Λ routes (`student_lambda.rs`, `gtr_lambda.rs`,
//! `piecewise_lambda.rs`), document 001's pseudo-VNIS (`student_vnis.rs`), and the batch samplers —
//! `batch.rs`, the one block loop the elliptic normal samplers (GGX, Beckmann, Student) share,
//! each giving only its radius kernel, compiled for AVX-512 or AVX2 + FMA by `pulp`'s safe
//! runtime dispatch where the CPU has it and bit for bit the scalar result on every path (so a
//! count never depends on the CPU); and `ggx_visible_batch.rs`, GGX's visible-normal batch on
//! the same block loop, within [`GGX_VISIBLE_BATCH_MAX_ULPS`] per component of the scalar
//! sampler and the same bits on every path. A new family is its file (with its `pub mod` line
//! below), its spec type and one entry in the list of families (`crate::spec`):
//! ARCHITECTURE.md, "A new NDF family".

pub mod angular_profile;
mod batch;
pub mod beckmann;
pub mod blend;
pub mod ggx;
mod ggx_visible;
mod ggx_visible_batch;
pub mod gtr;
pub mod gtr_lambda;
pub mod piecewise;
pub mod piecewise_lambda;
pub mod student;
pub mod student_lambda;
pub mod student_vnis;

#[cfg(test)]
mod conformance;
#[cfg(test)]
mod student_errata;

pub use angular_profile::AngularProfile;
pub use beckmann::Beckmann;
pub use blend::Blend;
pub use ggx::Ggx;
/// How many ulps per component GGX's batch visible-normal sampler may differ from
/// `Ggx::sample_wm_visible`.
pub use ggx_visible_batch::MAX_ULPS as GGX_VISIBLE_BATCH_MAX_ULPS;
pub use gtr::Gtr;
pub use piecewise::PiecewiseLinear;
pub use student::Student;
