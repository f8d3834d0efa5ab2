//! Normal distribution functions, one model per file.

pub mod beckmann;
pub mod ggx;
pub mod student;
pub mod student_lambda;

#[cfg(test)]
mod conformance;
#[cfg(test)]
mod student_errata;

pub use beckmann::Beckmann;
pub use ggx::Ggx;
pub use student::Student;
