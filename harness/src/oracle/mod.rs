//! Oracles: independent sources of truth the checks compare models with (DESIGN.md, "Checks and
//! records"). An oracle owes nothing to the code it checks.

pub mod chi2;
pub mod cubature;
pub mod domain;
