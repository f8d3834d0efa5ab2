//! Oracles: independent sources of truth the checks compare models with (ARCHITECTURE.md, "Checks and
//! records"). An oracle owes nothing to the code it checks.
//!
//! **What an oracle imports from the reference crate.** The capability traits it evaluates a
//! model through (`Ndf`, `NormalSampler`, `SlopeDistribution`, …); the shared vocabulary —
//! `Vec3` and the direction conventions of `geometry`, the sine, cosine and atan2 kernels of
//! `trig` (tested within 1–2 ulps of glibc, and no closed form under test: the quadratures
//! batch their trigonometry through them so that a value does not depend on how its nodes were
//! batched), and `bsdf::Directions` (a container of sampled directions); and, in two places, a
//! model's *parameters*, never its closed forms: `precise.rs` reads α and γ out of a `ModelSpec`
//! (the spec types of Beckmann, GGX and STD) to set up its own double-double integrals, and
//! `visible_moments.rs` takes a `GaussianSlopes` for its mean and covariance only. No oracle
//! calls a closed form, route or quadrature of the reference crate: `cubature.rs` writes its own
//! G7/K15 rather than import `special::gauss_kronrod`, and `quadrature.rs` uses another rule
//! family than the models' numerical routes. Nothing here imports `check/`.
//!
//! **Where each mechanism is described.** The chi-square test of a normal sampler: `chi2/`
//! (`mod.rs` the procedure; `cells.rs` the cells at the density's marginal quantiles,
//! `binning.rs`, `expected.rs` the cell masses by cubature, `judge.rs` sanity, pooling and the
//! p-value, `components.rs` the statistic's smooth and remaining parts). A BSDF's chi-square
//! over the whole sphere: `chi2/sphere.rs`, its masses by the globally adaptive cubature of
//! `cubature/global.rs` (for densities with steps), its cells found by `chi2/sphere_finder.rs`. The
//! cell grids: `hemisphere_grid.rs` (its cell finder runs under the batch samplers' SIMD dispatch), with
//! the branch-free edge search of `edge_table.rs`. The KS test: `ks/`. Where a density's lobe
//! is, from the density alone: `lobe.rs`; the chi-square and KS oracles also cut their
//! integrals at the polar kinks a reference family states (`FamilySpec::theta_kinks`, passed
//! through the subject). The nested hemisphere integrals: `quadrature.rs`, which computes the
//! sines and cosines of a step's polar nodes a block at a time and hands a direction integrand
//! its directions already built.

pub mod chi2;
pub mod cubature;
pub mod double_exponential;
mod edge_table;
pub mod gtr;
pub mod hemisphere_grid;
pub mod ks;
pub mod lobe;
pub mod lobe_centres;
pub mod lobe_climb;
pub mod monte_carlo;
pub mod precise;
pub mod quadrature;
pub mod smith_lambda;
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
