//! Normal distribution functions, one model per file.

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
