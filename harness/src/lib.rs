//! mfh-harness: the verification harness for microfacet BSDF mathematics — evaluation of
//! closed forms (`mfh eval`), and, as the project grows, oracles, checks, audits and reports.
//!
//! The binary `mfh` is a thin layer over [`cli::run`].

pub mod audit;
pub mod baseline;
pub mod check;
pub mod chi2_command;
pub mod cli;
pub mod eval;
pub mod eval_sg;
pub mod heatmap;
pub mod merge;
pub mod mitsuba;
pub mod oracle;
pub mod plan;
pub mod plan_table;
pub mod readback;
pub mod record;
pub mod report;
pub mod scene;
pub mod shard;
pub mod tolerance;
