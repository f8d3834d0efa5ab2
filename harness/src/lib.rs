//! mfh-harness: the verification harness for microfacet BSDF mathematics. It audits an
//! implementation of the capability traits: every property a model offers is compared, case by
//! case, with an oracle that owes nothing to the code it checks (adaptive quadrature and
//! cubature with error bounds, double-double references, Monte Carlo, chi-square and
//! Kolmogorov–Smirnov tests) at a stated tolerance, each comparison giving a
//! [`record::CheckRecord`] with a verdict, and the records make an [`run::AuditReport`].
//!
//! # Entry points
//!
//! - A renderer's own tests gate its NDF with [`audit!`] (the compiler finds every capability
//!   trait the model implements) or [`Audit::of`], and its BSDF with [`Audit::of_bsdf`]; the
//!   builder takes a [`Profile`], a seed, [`Hints`], a [`Precision`], a [`Sampling`], and
//!   [`Audit::run`] returns the report, whose [`assert_pass`](run::AuditReport::assert_pass)
//!   is the CI gate. The traits are those of [`model`] and [`bsdf`], re-exported from
//!   `mfh-reference` so that one dependency suffices.
//! - A scene (what a renderer uses: [`scene::Scene`]) is audited by [`run::audit_scene`], or
//!   planned by [`plan::plan`] and run by [`run::run_plan`] with [`run::AuditOptions`];
//!   [`run::RunControl`] tells a callback of each check's start and finish, resumes an
//!   interrupted run and sets a time limit. The library prints nothing: what is shown is the
//!   caller's, from those events.
//! - A program in any language behind the external protocol is audited by [`external::audit`].
//! - The sinks of [`report`] write a report (`report.json`, `junit.xml`, the terminal summary,
//!   the artefacts, `report.html`); [`record`] and [`tolerance`] are the records' vocabulary
//!   and the tolerances they are judged by; [`oracle`] the oracles and [`check`] the checks.
//!
//! The `mfh` binary is built from the hidden module `cli` over the same library (`mfh audit`,
//! `mfh audit-external`, `mfh eval`, `mfh chi2`, `mfh cost`, `mfh selftest`, …); the modules
//! behind its other commands are public only for it, the benchmarks and the tests, and hidden
//! from these docs.
//!
//! # Features
//!
//! All three are default; a renderer's dev-dependency takes `default-features = false` and
//! keeps the audit, the terminal summary, `report.json`, `junit.xml` and the JSON artefacts.
//!
//! - `cli`: the `mfh` binary and its commands (clap, indicatif, signal-hook), with shards,
//!   their merge and the baseline comparison; implies `html` and `mitsuba`.
//! - `html`: `report.html` and its SVG plots and heat maps (plotters).
//! - `mitsuba`: scenes in Mitsuba 3 XML (roxmltree).
//!
//! The code map, the layers and their invariants: `ARCHITECTURE.md` at the repository's root.

// Doc comments name the private constants and helpers a function's contract rests on (budgets,
// block sizes); `cargo doc --document-private-items` renders them as links, the public docs
// as plain names, which is what they are to a user.
#![allow(rustdoc::private_intra_doc_links)]

pub mod audit;
// Only the CLI compares with a baseline, splits an audit into shards, merges them and reads a
// report back: without it these modules are not compiled.
#[cfg(feature = "cli")]
mod baseline;
pub mod check;
#[cfg(feature = "cli")]
#[doc(hidden)]
pub mod cli;
#[doc(hidden)]
pub mod cost;
mod deadline;
mod estimate;
#[doc(hidden)]
pub mod eval;
pub mod external;
#[cfg(feature = "cli")]
mod merge;
mod messages;
#[cfg(feature = "mitsuba")]
mod mitsuba;
pub mod oracle;
pub mod plan;
mod precision;
#[doc(hidden)]
pub mod random;
#[cfg(feature = "cli")]
mod readback;
pub mod record;
mod record_serde;
#[doc(hidden)]
pub mod record_text;
mod record_trust;
pub mod report;
pub mod run;
#[doc(hidden)]
pub mod sampler_chi2;
pub mod scene;
mod scene_file;
#[doc(hidden)]
pub mod selftest;
#[cfg(feature = "cli")]
mod shard;
mod subject;
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
