//! mfh-harness: the verification harness for microfacet BSDF mathematics — evaluation of
//! closed forms (`mfh eval`), and, as the project grows, oracles, checks, audits and reports.
//!
//! The binary `mfh` is a thin layer over [`cli::run`].

pub mod audit;
pub mod check;
pub mod chi2_command;
pub mod cli;
pub mod eval;
pub mod eval_sg;
pub mod heatmap;
pub mod oracle;
pub mod plan;
pub mod random;
pub mod record;
pub mod report;
pub mod scene;
pub mod tolerance;
