//! mfh-harness: the verification harness for microfacet BSDF mathematics. Oracles that owe
//! nothing to the code they check (adaptive quadrature and cubature with error bounds,
//! double-double references, Monte Carlo, chi-square and Kolmogorov–Smirnov tests), the checks
//! that compare a model with them, each giving a record with a verdict, and the sinks that
//! report them (terminal, `report.json`, `junit.xml`, `report.html`).
//!
//! A renderer's own tests gate its NDF with [`audit!`] (or [`Audit::of`]) and its BSDF with
//! [`Audit::of_bsdf`]; the model implements the traits of [`model`] and [`bsdf`], re-exported
//! here so that one dependency suffices. The binary `mfh` (feature `cli`) is a thin layer over
//! `cli::run`: audits of scenes, `mfh eval`, `mfh chi2`, `mfh cost`, `mfh selftest`, and
//! `mfh audit-external` for a model in any language behind the external protocol.

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
mod deadline;
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
pub mod record_text;
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
/// The BSDF trait a renderer implements for [`Audit::of_bsdf`] (`Bsdf`, `BsdfSample`,
/// `Transport`) and the reference BSDFs, so that one dependency on this crate gives a gate all
/// it needs.
pub use mfh_reference::bsdf;
pub use mfh_reference::model;
pub use precision::Precision;
pub use scene::Sampling;
pub use subject::Hints;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;
