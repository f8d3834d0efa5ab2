//! Chi-square goodness-of-fit test of a normal sampler against its pdf over the (φ, cos θ)
//! grid of the upper hemisphere (ARCHITECTURE.md, "Data flows one way"): the test entry points
//! and their result types here; the binning in `binning.rs`, the expected masses in
//! `expected.rs`, the verdict in `judge.rs`; the numeric tolerances in `tolerance/chi2.rs`.
//!
//! Procedure:
//!
//! 1. **Observed counts.** `samples` normals are drawn with `u` from the counter-based stream
//!    ([`crate::random`]: ChaCha8 keyed by the seed, stream id = chunk index) of each fixed
//!    chunk of [`CHUNK`] sample indices, in blocks (uniforms → the model's batch sampler →
//!    cells), and binned into the [`HemisphereGrid`] of the given resolution (R z-rows × 2R
//!    φ-columns) by a [`CellFinder`] (no atan2 per sample), in parallel (rayon). Counts are
//!    integers summed per chunk, so they are identical whatever the thread count or
//!    scheduling, and the batch path counts what the scalar path counts.
//! 2. **Expected counts.** The pdf's lobe is measured from the pdf alone
//!    ([`crate::oracle::lobe`]); every cell is integrated in (φ, θ), cut where the lobe varies,
//!    by adaptive G7/K15 product cubature ([`crate::oracle::cubature`]) with a per-cell error
//!    bound ([`expected_mass_in`]); the total mass and the summed error bound are reported.
//! 3. **Sanity failures first** (no p-value): a sample outside the upper hemisphere (non-finite, non-unit,
//!    below the horizon), a total pdf mass off from 1 by more than [`MASS_TOLERANCE`], a
//!    non-finite or negative cell mass, a sample in a cell of zero expected count.
//! 4. **Pooling.** Cells with expected count < [`MIN_EXPECTED`] are pooled into one bin; if that
//!    bin's expected count is itself < [`MIN_EXPECTED`], it is merged into the regular bin of
//!    least expected count (so a remainder of, say, 0.01 expected cannot dominate the
//!    statistic). dof = bins − 1.
//! 5. **p-value.** Pearson's statistic χ² over the pooled bins (reported with dof = bins − 1)
//!    is split into two independent parts ([`components`]): the first smooth components of
//!    the cos θ marginal, where a roughness or exponent error of the sampler lives, and the
//!    rest of the table; each part's p-value is Q(dof/2, χ²/2), the upper regularized
//!    incomplete gamma function (accurate in the far tail, unlike 1 − CDF), and the test's
//!    p-value is the smaller, Šidák-corrected; the test rejects when p < α. (A table of one row
//!    takes Q(dof/2, χ²/2) of the whole.)
//!
//! [`MASS_TOLERANCE`]: crate::tolerance::MASS_TOLERANCE
//! [`MIN_EXPECTED`]: crate::tolerance::MIN_EXPECTED
//! [`CellFinder`]: crate::oracle::hemisphere_grid::CellFinder
//! [`KINKED_CELL_RELATIVE_TOLERANCE`]: crate::tolerance::KINKED_CELL_RELATIVE_TOLERANCE
//! [`CELL_RELATIVE_TOLERANCE`]: crate::tolerance::CELL_RELATIVE_TOLERANCE
//! [`CELL_ABSOLUTE_TOLERANCE`]: crate::tolerance::CELL_ABSOLUTE_TOLERANCE

mod binning;
pub mod cells;
pub mod components;
mod expected;
mod judge;
pub mod sphere;
pub mod sphere_accuracy;
pub mod sphere_finder;

pub use binning::{observe, observe_batch, observe_blocks, Observed, CHUNK};
pub use expected::{
    expected_mass, expected_mass_global, expected_mass_global_until, expected_mass_in,
    expected_mass_in_batch, expected_mass_to, Expected,
};

use crate::oracle::hemisphere_grid::{DirectionError, HemisphereGrid};
use crate::oracle::lobe::{self, Lobe};
use crate::tolerance::CELL_RELATIVE_TOLERANCE;
use binning::scalar_batch;
pub use cells::Layout;
use judge::judge;
pub(crate) use judge::{pearson_test, pooled_statistic};
use mfh_reference::geometry::Vec3;
use mfh_reference::NormalSampler;
use std::time::Instant;

/// The parameters of one chi-square test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chi2Config {
    /// R: the grid has R z-rows and 2R φ-columns.
    pub resolution: usize,
    /// The number of samples drawn.
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// The significance level: the test fails when p < `alpha`.
    pub alpha: f64,
}

/// The outcome of a test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TestOutcome {
    /// Consistent with the pdf at level α.
    Pass,
    /// A sanity failure, or p < α.
    Fail,
}

/// Samples outside the upper hemisphere (a sanity failure of the chi-square and KS tests):
/// how many, and the first of them (in the seeded sequence) with what is wrong with it.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{count} samples outside the upper hemisphere; the first, sample {index}: {error}")]
pub struct OutsideHemisphere {
    /// Index of the first offending sample (in the seeded sequence).
    pub index: u64,
    /// What is wrong with it.
    pub error: DirectionError,
    /// How many samples were outside.
    pub count: u64,
}

/// Why a test failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Failure {
    /// Samples lie outside the upper hemisphere.
    #[error(transparent)]
    OutsideHemisphere(OutsideHemisphere),
    /// The pdf does not integrate to 1 over the hemisphere.
    #[error("pdf mass {mass} (± {error_bound:.1e}) differs from 1 by more than {tolerance}")]
    MassOff {
        /// The integrated mass.
        mass: f64,
        /// Its error bound.
        error_bound: f64,
        /// The allowed difference.
        tolerance: f64,
    },
    /// The pdf integrates to a negative or non-finite mass over a cell.
    #[error("pdf mass over cell {cell} is {mass}")]
    InvalidMass {
        /// The cell (row-major, row 0 at the horizon).
        cell: usize,
        /// Its mass.
        mass: f64,
    },
    /// Samples landed in a cell where the pdf is zero.
    #[error("{observed} samples in cell {cell}, where the pdf is zero")]
    ZeroPdfCell {
        /// The first such cell.
        cell: usize,
        /// The samples in it.
        observed: u64,
    },
    /// Fewer than two bins after pooling: nothing to test.
    #[error("only {bins} bin(s) after pooling; more samples or a finer grid are needed")]
    TooFewBins {
        /// Bins after pooling.
        bins: usize,
    },
    /// The expected-mass cubature ran out of its rectangle budget
    /// ([`crate::oracle::cubature::MAX_RECTANGLES`]) with its summed error bound above the
    /// target: the masses cannot judge the samples (an `error` record, never a pass).
    #[error(
        "expected-mass cubature stopped at {rectangles} rectangles (budget \
         oracle::cubature::MAX_RECTANGLES = {budget}) with bound {bound:.1e} > target \
         {target:.1e} (a density that oscillates or steps faster than any cell)"
    )]
    CubatureBudget {
        /// The rectangles the bisection created.
        rectangles: usize,
        /// The budget.
        budget: usize,
        /// The masses' summed error bound.
        bound: f64,
        /// The summed target.
        target: f64,
    },
    /// The distribution of samples differs from the pdf.
    #[error("p-value {p_value:.3e} below α = {alpha:.3e}")]
    Rejected {
        /// The p-value.
        p_value: f64,
        /// The level.
        alpha: f64,
    },
}

/// A batch sampler: writes the normal of u\[i\] into m\[i\].
pub type BatchSampler<'a> = dyn Fn(&[[f64; 2]], &mut [Vec3]) + Sync + 'a;

/// A batch density: writes pdf(m\[i\]) into out\[i\].
pub type BatchPdf<'a> = dyn Fn(&[Vec3], &mut [f64]) + Sync + 'a;

/// The result of a chi-square test.
#[derive(Debug, Clone, PartialEq)]
pub struct Chi2Result {
    /// The grid resolution R (R z-rows × 2R φ-columns).
    pub resolution: usize,
    /// The χ² statistic (NaN after a sanity failure).
    pub statistic: f64,
    /// Degrees of freedom: bins − 1 (0 after a sanity failure).
    pub dof: usize,
    /// The test's p-value (0 after a sanity failure): the smaller p of the two parts, corrected,
    /// of [`Chi2Result::components`] where the table has them, else Q(dof/2, χ²/2).
    pub p_value: f64,
    /// The statistic in two independent parts: the cos θ marginal's first smooth components
    /// and the rest of the table ([`components`]); `None` after a sanity failure or on a
    /// table of one row.
    pub components: Option<components::Components>,
    /// The level the verdict was taken at.
    pub alpha: f64,
    /// Cells pooled because their expected count was < [`MIN_EXPECTED`](crate::tolerance::MIN_EXPECTED).
    pub pooled_cells: usize,
    /// Samples drawn.
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// Pass or fail.
    pub verdict: TestOutcome,
    /// Why it failed, if it did.
    pub reason: Option<Failure>,
    /// The integrated pdf mass over the hemisphere.
    pub expected_mass: f64,
    /// The error bound of the expected counts (mass bound × samples).
    pub expected_error_bound: f64,
    /// Wall time of sampling and binning, seconds.
    pub sampling_seconds: f64,
    /// Wall time of the expected-count integration, seconds.
    pub integration_seconds: f64,
    /// Observed counts per cell (row-major, row 0 at the horizon).
    pub observed: Vec<u64>,
    /// Expected counts per cell (mass × samples).
    pub expected: Vec<f64>,
    /// The row edges z₀ = 0 < … < z_R = 1 (cos θ) of the cells ([`cells::layout`]).
    pub z_edges: Vec<f64>,
    /// The column edges φ₀ = 0 < … < φ_2R = 2π of the cells.
    pub phi_edges: Vec<f64>,
}

impl Chi2Result {
    /// Samples per second of sampling and binning.
    pub fn samples_per_second(&self) -> f64 {
        self.samples as f64 / self.sampling_seconds
    }
}

/// Tests the sampler `sample` against the density `pdf` (with respect to solid angle).
/// `config.resolution` of 0 is treated as 1.
pub fn chi2_test<S, P>(sample: &S, pdf: &P, config: &Chi2Config) -> Chi2Result
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    chi2_test_in(sample, pdf, config, CELL_RELATIVE_TOLERANCE, None)
}

/// [`chi2_test`] with the expected counts integrated to the per-cell relative tolerance
/// `cell_relative` (e.g. [`KINKED_CELL_RELATIVE_TOLERANCE`](crate::tolerance::KINKED_CELL_RELATIVE_TOLERANCE)) about a given lobe (e.g. measured
/// once from the model's D by [`lobe::measure`]); `None` measures it from `pdf`.
pub fn chi2_test_in<S, P>(
    sample: &S,
    pdf: &P,
    config: &Chi2Config,
    cell_relative: f64,
    lobe: Option<&Lobe>,
) -> Chi2Result
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    chi2_test_batch_in(
        &|u: &[[f64; 2]], m: &mut [Vec3]| scalar_batch(sample, u, m),
        pdf,
        config,
        cell_relative,
        lobe,
        &[],
    )
}

/// [`chi2_test_in`] with a batch sampler (`sample(u, m)` sets `m[i]` to the normal of `u[i]`,
/// as [`observe_batch`] takes it): the same result as the scalar form of the sampler. The cells
/// are also cut at `theta_kinks`, the polar angles where the density has a kink for every
/// azimuth (a reference model's registry knows them, as for [`chi2_test_batches_cut`]): the
/// same masses to the same tolerance, without the cubature subdividing the kinks.
pub fn chi2_test_batch_in<S, P>(
    sample: &S,
    pdf: &P,
    config: &Chi2Config,
    cell_relative: f64,
    lobe: Option<&Lobe>,
    theta_kinks: &[f64],
) -> Chi2Result
where
    S: Fn(&[[f64; 2]], &mut [Vec3]) + Sync + ?Sized,
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    chi2_test_batch_layout(
        sample,
        pdf,
        config,
        (cell_relative, lobe, theta_kinks),
        Layout::default(),
    )
}

/// [`chi2_test_batch_in`] on the cells of `layout` (the default, [`Layout::FollowLobe`]: rows
/// and columns at the quantiles of `pdf`'s marginals; [`Layout::EqualArea`]: the equal-area
/// grid), with (cell relative tolerance, lobe, θ kinks) as there.
pub fn chi2_test_batch_layout<S, P>(
    sample: &S,
    pdf: &P,
    config: &Chi2Config,
    (cell_relative, lobe, theta_kinks): (f64, Option<&Lobe>, &[f64]),
    layout: Layout,
) -> Chi2Result
where
    S: Fn(&[[f64; 2]], &mut [Vec3]) + Sync + ?Sized,
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    let t = Instant::now();
    let measured;
    let (lobe, lobe_evaluations) = match lobe {
        Some(lobe) => (lobe, 0),
        None => {
            measured = lobe::measure_density(&|m| pdf(m));
            (&measured, measured.evaluations)
        }
    };
    let batch = |m: &[Vec3], out: &mut [f64]| {
        for (o, &m) in out.iter_mut().zip(m) {
            *o = pdf(m);
        }
    };
    let (grid, spent) = cells::layout(&batch, lobe, config.resolution, theta_kinks, layout);
    let spent = spent + lobe_evaluations;
    timed(
        config,
        (grid, spent, t.elapsed().as_secs_f64()),
        |grid| observe_batch(sample, grid.clone(), config.samples, config.seed),
        |grid| expected_mass_in(pdf, grid.clone(), cell_relative, lobe, theta_kinks),
    )
}

/// The test on `grid` (placed with `layout_evaluations` pdf evaluations in `layout_seconds`):
/// the observed counts (`observe`), then the expected masses (`expect`), each timed (the
/// layout counts as integration), judged by [`judge`].
fn timed(
    config: &Chi2Config,
    (grid, layout_evaluations, layout_seconds): (HemisphereGrid, u64, f64),
    observe: impl FnOnce(&HemisphereGrid) -> Observed,
    expect: impl FnOnce(&HemisphereGrid) -> Expected,
) -> Chi2Result {
    let t = Instant::now();
    let observed = observe(&grid);
    let sampling_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut expected = expect(&grid);
    expected.evaluations += layout_evaluations;
    let integration_seconds = t.elapsed().as_secs_f64() + layout_seconds;
    judge(
        config,
        grid,
        observed,
        expected,
        sampling_seconds,
        integration_seconds,
    )
}

/// The chi-square test with a batch sampler and a batch density (an external model: a round
/// trip per batch), the expected masses integrated to the per-cell (relative, absolute)
/// `cell_tolerance`: with ([`CELL_RELATIVE_TOLERANCE`] or the kinked one,
/// [`CELL_ABSOLUTE_TOLERANCE`](crate::tolerance::CELL_ABSOLUTE_TOLERANCE)) the same result as [`chi2_test_batch_in`] with the scalar
/// density. With no
/// `lobe`, it is measured from the density ([`lobe::measure_with_batch`]).
pub fn chi2_test_batches_in(
    sample: &BatchSampler<'_>,
    pdf: &BatchPdf<'_>,
    config: &Chi2Config,
    cell_tolerance: (f64, f64),
    lobe: Option<&Lobe>,
) -> Chi2Result {
    chi2_test_batches_cut(sample, pdf, config, cell_tolerance, lobe, &[])
}

/// [`chi2_test_batches_in`] with the cells also cut at `theta_kinks`, the polar angles where
/// the density has a kink for every azimuth (a reference model's registry knows them, e.g. a
/// piecewise-linear profile's breakpoints): the same masses to the same tolerance, at a
/// fraction of the cost (the cubature no longer subdivides the kinks).
pub fn chi2_test_batches_cut(
    sample: &BatchSampler<'_>,
    pdf: &BatchPdf<'_>,
    config: &Chi2Config,
    cell_tolerance: (f64, f64),
    lobe: Option<&Lobe>,
    theta_kinks: &[f64],
) -> Chi2Result {
    let t = Instant::now();
    let (lobe, lobe_evaluations) = match lobe {
        Some(lobe) => (lobe.clone(), 0),
        None => {
            let lobe = lobe::measure_with_batch(pdf, &lobe::Options::default());
            let spent = lobe.evaluations;
            (lobe, spent)
        }
    };
    let (grid, spent) = cells::layout(
        pdf,
        &lobe,
        config.resolution,
        theta_kinks,
        Layout::default(),
    );
    timed(
        config,
        (grid, spent + lobe_evaluations, t.elapsed().as_secs_f64()),
        |grid| {
            observe_blocks(
                sample,
                grid.clone(),
                config.samples,
                config.seed,
                CHUNK as usize,
            )
        },
        |grid| expected_mass_in_batch(pdf, grid.clone(), cell_tolerance, &lobe, theta_kinks),
    )
}

/// Tests a model's `sample_wm` against its own `pdf_wm`.
/// Draws through [`NormalSampler::sample_wm_batch`] (the scalar method for models that do not
/// override it): the same counts as through `sample_wm`.
pub fn chi2_test_sampler(sampler: &dyn NormalSampler, config: &Chi2Config) -> Chi2Result {
    chi2_test_batch_in(
        &|u: &[[f64; 2]], m: &mut [Vec3]| sampler.sample_wm_batch(u, m),
        &|m| sampler.pdf_wm(m),
        config,
        CELL_RELATIVE_TOLERANCE,
        None,
        &[],
    )
}

#[cfg(test)]
mod tests;
