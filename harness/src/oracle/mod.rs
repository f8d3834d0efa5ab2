//! Oracles: independent sources of truth the checks compare models with (ARCHITECTURE.md, "Checks and
//! records"). An oracle owes nothing to the code it checks.

pub mod chi2;
pub mod cubature;
pub mod domain;
pub mod double_exponential;
mod edge_table;
pub mod gtr;
pub mod ks;
pub mod lobe;
pub mod lobe_centres;
pub mod monte_carlo;
pub mod precise;
pub mod quadrature;
pub mod smith_lambda;
pub mod sphere_chi2;
pub mod sphere_finder;
pub mod student_t;
pub mod visible_moments;

/// An integral (or other numerical) estimate with a bound on its error.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// A bound on |value − truth| (for quadrature: the summed local error estimates, which
    /// bound the error for integrands smooth on each piece).
    pub error_bound: f64,
    /// Integrand evaluations spent.
    pub evaluations: u64,
}

#[cfg(test)]
mod sweep_tests;
