//! mfh-harness: the verification harness for microfacet BSDF mathematics — evaluation of
//! closed forms (`mfh eval`), and, as the project grows, oracles, checks, audits and reports.
//!
//! The binary `mfh` is a thin layer over `cli::run` (feature `cli`). A renderer's own tests use [`Audit`]
//! on their models, which implement the traits of [`model`].

// Doc comments name the private constants and helpers a function's contract rests on (budgets,
// block sizes); `cargo doc --document-private-items` renders them as links, the public docs
// as plain names, which is what they are to a user.
#![allow(rustdoc::private_intra_doc_links)]

pub mod audit;
pub mod baseline;
pub mod check;
#[cfg(feature = "cli")]
pub mod cli;
pub mod cost;
pub mod estimate;
pub mod eval;
pub mod external;
pub mod merge;
pub mod messages;
#[cfg(feature = "mitsuba")]
pub mod mitsuba;
pub mod oracle;
pub mod plan;
pub mod precision;
pub mod random;
pub mod readback;
pub mod record;
pub mod record_serde;
pub mod record_trust;
pub mod report;
pub mod run;
pub mod sampler_chi2;
pub mod scene;
pub mod scene_file;
pub mod selftest;
pub mod shard;
pub mod subject;
pub mod tolerance;

pub use audit::Audit;
pub use check::Profile;
pub use mfh_reference::model;
pub use precision::Precision;
pub use scene::Sampling;
pub use subject::Hints;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;
