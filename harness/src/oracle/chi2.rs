//! Chi-square goodness-of-fit test of a normal sampler against its pdf over the (φ, cos θ)
//! grid of the upper hemisphere (ARCHITECTURE.md, "Checks and records").
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
//! 3. **Sanity failures first** (no p-value): a sample outside the domain (non-finite, non-unit,
//!    below the horizon), a total pdf mass off from 1 by more than [`MASS_TOLERANCE`], a
//!    non-finite or negative cell mass, a sample in a cell of zero expected count.
//! 4. **Pooling.** Cells with expected count < [`MIN_EXPECTED`] are pooled into one bin; if that
//!    bin's expected count is itself < [`MIN_EXPECTED`], it is merged into the regular bin of
//!    least expected count (so a remainder of, say, 0.01 expected cannot dominate the
//!    statistic). dof = bins − 1.
//! 5. **p-value** Q(dof/2, χ²/2), the upper regularized incomplete gamma function (accurate in
//!    the far tail, unlike 1 − CDF); the test rejects when p < α.

use crate::oracle::cubature::{integrate_rectangle, integrate_rectangles_batch, Tolerance};
use crate::oracle::domain::{CellFinder, DomainError, HemisphereGrid};
use crate::oracle::lobe::{self, Lobe};
use crate::oracle::Estimate;
use crate::random::stream;
use mfh_reference::geometry::Vec3;
use mfh_reference::trig::{sin_cos, sin_cos_block};
use mfh_reference::NormalSampler;
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;
use std::time::Instant;

/// Samples per random stream: the unit of work and of seeding.
pub const CHUNK: u64 = 1 << 16;
/// Samples drawn before they are binned, within a chunk (a throughput detail: the counts
/// do not depend on it).
const BATCH: usize = 256;
/// Cells with fewer expected samples than this are pooled.
pub const MIN_EXPECTED: f64 = 5.0;
/// How far the integrated pdf mass over the hemisphere may be from 1.
pub const MASS_TOLERANCE: f64 = 1e-3;
/// The default seed of the test (overridable everywhere a seed is taken).
pub const DEFAULT_SEED: u64 = 0x6d66_6800_0000_0001;
/// Per-cell relative tolerance of the expected-mass cubature.
pub const CELL_RELATIVE_TOLERANCE: f64 = 1e-9;
/// Per-cell absolute tolerance of the expected-mass cubature.
pub const CELL_ABSOLUTE_TOLERANCE: f64 = 1e-14;
/// Per-cell relative tolerance of the expected-mass cubature for densities with a kink inside
/// cells (the terminator of ⟨wi·m⟩⁺ of a visible-normal density): the expected counts need a
/// relative accuracy well below 1/√(expected count), ≥ 2.3e-3 even at the thorough profile's
/// 10⁸ samples over 512 cells, so 1e-4 keeps a margin of 23; a relative error ε of every
/// expected count moves χ² by about ε²·N, 1 at N = 10⁸ (2e-3 at the quick audit's 2·10⁵)
/// against its standard deviation √(2·dof) ≈ 32. It was 1e-6: each factor 10 costs the cubature ~√10 times the
/// pieces along the kink (the error of a piece across a kink is ∝ its size squared), 3.3 s for
/// GGX's visible normals at θi = 1.3 in the quick audit. Remote models (an external process)
/// take the same relative tolerance and only a looser absolute one
/// ([`REMOTE_CELL_ABSOLUTE_TOLERANCE`]).
pub const KINKED_CELL_RELATIVE_TOLERANCE: f64 = 1e-4;
/// [`CELL_ABSOLUTE_TOLERANCE`] for a remote model: 1e-11 of mass per cell is 1e-3 counts at
/// 10⁸ samples, far below the ≥ 5 counts a cell needs to enter the statistic unpooled.
pub const REMOTE_CELL_ABSOLUTE_TOLERANCE: f64 = 1e-11;

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

impl Default for Chi2Config {
    fn default() -> Self {
        Self {
            resolution: 32,
            samples: 1_000_000,
            seed: DEFAULT_SEED,
            alpha: 1e-4,
        }
    }
}

/// The Šidák-corrected level for each of `k` independent tests so that the family-wise level
/// is `alpha`: 1 − (1 − α)^{1/k} (computed as −expm1(ln(1 − α)/k), exact for small α).
pub fn sidak_alpha(alpha: f64, k: usize) -> f64 {
    if k <= 1 {
        return alpha;
    }
    -((-alpha).ln_1p() / k as f64).exp_m1()
}

/// The outcome of a test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Consistent with the pdf at level α.
    Pass,
    /// A sanity failure, or p < α.
    Fail,
}

/// Samples outside the upper hemisphere (a sanity failure of the chi-square and KS tests):
/// how many, and the first of them (in the seeded sequence) with what is wrong with it.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{count} samples outside the domain; the first, sample {index}: {error}")]
pub struct OutsideDomain {
    /// Index of the first offending sample (in the seeded sequence).
    pub index: u64,
    /// What is wrong with it.
    pub error: DomainError,
    /// How many samples were outside.
    pub count: u64,
}

/// Why a test failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Failure {
    /// Samples lie outside the upper hemisphere.
    #[error(transparent)]
    OutsideDomain(OutsideDomain),
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
    /// The distribution of samples differs from the pdf.
    #[error("p-value {p_value:.3e} below α = {alpha:.3e}")]
    Rejected {
        /// The p-value.
        p_value: f64,
        /// The level.
        alpha: f64,
    },
}

/// Observed counts per cell, with the samples that fell outside the domain.
#[derive(Debug, Clone, PartialEq)]
pub struct Observed {
    /// Counts per cell (row-major, row 0 at the horizon).
    pub counts: Vec<u64>,
    /// Samples outside the domain.
    pub outside: u64,
    /// The first sample outside the domain (lowest index) and why.
    pub first_outside: Option<(u64, DomainError)>,
}

impl Observed {
    fn zero(cells: usize) -> Self {
        Self {
            counts: vec![0; cells],
            outside: 0,
            first_outside: None,
        }
    }

    fn merge(mut self, other: Self) -> Self {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.outside += other.outside;
        self.first_outside = match (self.first_outside, other.first_outside) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
            (a, b) => a.or(b),
        };
        self
    }
}

/// The expected probability mass per cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Expected {
    /// Mass per cell (row-major, row 0 at the horizon).
    pub mass: Vec<f64>,
    /// The total mass (the pdf's integral over the hemisphere).
    pub total: f64,
    /// The sum of the per-cell error bounds of the cubature.
    pub error_bound: f64,
    /// Pdf evaluations spent.
    pub evaluations: u64,
}

impl Expected {
    /// The expected masses of the cells' estimates, in cell order, with their summed error
    /// bound and evaluations.
    fn of_cells(estimates: &[Estimate]) -> Self {
        Expected {
            mass: estimates.iter().map(|e| e.value).collect(),
            total: estimates.iter().map(|e| e.value).sum(),
            error_bound: estimates.iter().map(|e| e.error_bound).sum(),
            evaluations: estimates.iter().map(|e| e.evaluations).sum(),
        }
    }
}

/// Draws `samples` normals with `sample` and bins them into `grid`, in parallel, with a result
/// independent of the thread count (the scalar form of [`observe_batch`]: the same counts).
pub fn observe<S>(sample: &S, grid: HemisphereGrid, samples: u64, seed: u64) -> Observed
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
{
    observe_batch(
        &|u: &[[f64; 2]], m: &mut [Vec3]| scalar_batch(sample, u, m),
        grid,
        samples,
        seed,
    )
}

/// `m[i] = sample(u[i])`: a scalar sampler as a batch sampler.
#[inline]
fn scalar_batch<S>(sample: &S, u: &[[f64; 2]], m: &mut [Vec3])
where
    S: Fn([f64; 2]) -> Vec3 + ?Sized,
{
    for (m, &u) in m.iter_mut().zip(u) {
        *m = sample(u);
    }
}

/// Draws `samples` normals with the batch sampler `sample` (`sample(u, m)` sets `m[i]` to the
/// normal of `u[i]`, e.g. [`NormalSampler::sample_wm_batch`]) and bins them into `grid`, in
/// parallel: per chunk of [`CHUNK`] samples, its stream's uniforms in blocks of [`BATCH`]
/// pairs ([`crate::random::Stream::fill_pairs`]) → the batch sampler → the block's cells
/// ([`CellFinder::cells_of`]) → the thread's histogram; the threads' histograms are summed
/// once at the end. Integer counts: the same whatever the thread count, and the same as
/// [`observe`] with the scalar form of the sampler.
pub fn observe_batch<S>(sample: &S, grid: HemisphereGrid, samples: u64, seed: u64) -> Observed
where
    S: Fn(&[[f64; 2]], &mut [Vec3]) + Sync + ?Sized,
{
    observe_blocks(sample, grid, samples, seed, BATCH)
}

/// [`observe_batch`] with blocks of `block` samples (at most [`CHUNK`]): the same counts for
/// any block size (the streams' pairs do not depend on how they are read); a whole chunk per
/// call suits an external model (one round trip per 65 536 samples).
pub fn observe_blocks<S>(
    sample: &S,
    grid: HemisphereGrid,
    samples: u64,
    seed: u64,
    block: usize,
) -> Observed
where
    S: Fn(&[[f64; 2]], &mut [Vec3]) + Sync + ?Sized,
{
    let chunks = samples.div_ceil(CHUNK);
    let finder = CellFinder::new(grid);
    let block = block.clamp(1, CHUNK as usize);
    (0..chunks)
        .into_par_iter()
        .fold(
            || Observed::zero(grid.cells()),
            |mut acc, chunk| {
                let mut rng = stream(seed, chunk);
                let start = chunk * CHUNK;
                let end = (start + CHUNK).min(samples);
                let mut u = vec![[0.0; 2]; block];
                let mut m = vec![[0.0; 3]; block];
                let mut cells = vec![0usize; block];
                let mut first = start;
                while first < end {
                    let n = (end - first).min(block as u64) as usize;
                    rng.fill_pairs(&mut u[..n]);
                    sample(&u[..n], &mut m[..n]);
                    if finder.cells_of(&m[..n], &mut cells[..n]) {
                        for &cell in &cells[..n] {
                            acc.counts[cell] += 1;
                        }
                    } else {
                        // A direction outside the domain in this block (rare): one by one.
                        for (index, &m) in (first..).zip(&m[..n]) {
                            match finder.cell_of(m) {
                                Ok(cell) => acc.counts[cell] += 1,
                                Err(error) => {
                                    acc.outside += 1;
                                    if acc.first_outside.is_none_or(|(i, _)| index < i) {
                                        acc.first_outside = Some((index, error));
                                    }
                                }
                            }
                        }
                    }
                    first += n as u64;
                }
                acc
            },
        )
        .reduce(|| Observed::zero(grid.cells()), Observed::merge)
}

/// Integrates `pdf` (a density with respect to solid angle) over every cell of `grid`, where
/// its lobe is measured from `pdf` itself ([`lobe::measure_density`]).
pub fn expected_mass<P>(pdf: &P, grid: HemisphereGrid) -> Expected
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    expected_mass_to(pdf, grid, CELL_RELATIVE_TOLERANCE, &[])
}

/// [`expected_mass`] with the per-cell relative tolerance `relative` and the cells also cut at
/// `theta_kinks` (see [`expected_mass_in`]).
pub fn expected_mass_to<P>(
    pdf: &P,
    grid: HemisphereGrid,
    relative: f64,
    theta_kinks: &[f64],
) -> Expected
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    let lobe = lobe::measure_density(&|m| pdf(m));
    let mut e = expected_mass_in(pdf, grid, relative, &lobe, theta_kinks);
    e.evaluations += lobe.evaluations;
    e
}

/// Integrates `pdf` over every cell of `grid` to the per-cell relative tolerance `relative`,
/// with the cells cut where `lobe` says the density varies and at `theta_kinks` (polar angles
/// where the density has a kink for every azimuth, e.g. a piecewise-linear profile's
/// breakpoints: cut there, every piece is smooth and the cubature does not subdivide the kink
/// down to the tolerance).
///
/// Each cell, a rectangle in (φ, z = cos θ), is integrated in (φ, θ) (dω = sin θ dθ dφ: no
/// loss of precision near the pole, where 1 − z² cancels), cut at the lobe's polar cuts
/// ([`Lobe::polar_cuts_with`]: log-spaced about every θ scale, so that a lobe of width 1e-4
/// inside a top row 0.25 rad high is resolved, and the kinks) and azimuthal cuts ([`Lobe::azimuth_cuts`]) that fall
/// inside it. Every piece is integrated by adaptive G7/K15 product cubature to max(relative ×
/// its first estimate, [`CELL_ABSOLUTE_TOLERANCE`] / pieces); the cell's error bound is the sum
/// of its pieces' bounds, so it is at most ≈ relative × cell mass + the absolute tolerance for
/// integrands smooth on each piece (a piece at [`crate::oracle::cubature::MAX_DEPTH`] still reports its error).
pub fn expected_mass_in<P>(
    pdf: &P,
    grid: HemisphereGrid,
    relative: f64,
    lobe: &Lobe,
    theta_kinks: &[f64],
) -> Expected
where
    P: Fn(Vec3) -> f64 + Sync + ?Sized,
{
    let polar = lobe.polar_cuts_with(FRAC_PI_2, theta_kinks);
    let azimuth = lobe.azimuth_cuts();
    let estimates: Vec<_> = (0..grid.cells())
        .into_par_iter()
        .map(|i| {
            let (thetas, phis, pieces) = cell_pieces(grid, i, &polar, &azimuth);
            let tolerance = Tolerance {
                absolute: CELL_ABSOLUTE_TOLERANCE / pieces as f64,
                relative,
            };
            let f = |phi: f64, theta: f64| {
                let (s, c) = sin_cos(theta);
                let (sp, cp) = sin_cos(phi);
                pdf([s * cp, s * sp, c.max(0.0)]) * s
            };
            let mut sum = Estimate::default();
            for p in phis.windows(2) {
                for t in thetas.windows(2) {
                    let e = integrate_rectangle(&f, [p[0], p[1]], [t[0], t[1]], tolerance);
                    sum.value += e.value;
                    sum.error_bound += e.error_bound;
                    sum.evaluations += e.evaluations;
                }
            }
            sum
        })
        .collect();
    Expected::of_cells(&estimates)
}

/// A batch sampler: writes the normal of u[i] into m[i].
pub type BatchSampler<'a> = dyn Fn(&[[f64; 2]], &mut [Vec3]) + Sync + 'a;

/// A batch density: writes pdf(m[i]) into out[i].
pub type BatchPdf<'a> = dyn Fn(&[Vec3], &mut [f64]) + Sync + 'a;

/// The pieces of cell `i` between the lobe's cuts: the polar and azimuthal breakpoints inside
/// the cell (θ decreases with z: the top of the row, z₁, is the smaller θ) and their count.
fn cell_pieces(
    grid: HemisphereGrid,
    i: usize,
    polar: &[f64],
    azimuth: &[f64],
) -> (Vec<f64>, Vec<f64>, usize) {
    let cell = grid.cell(i);
    let theta = [
        cell.z[1].clamp(0.0, 1.0).acos(),
        cell.z[0].clamp(0.0, 1.0).acos(),
    ];
    let thetas = inside(polar, theta);
    let phis = inside(azimuth, cell.phi);
    let pieces = (thetas.len() - 1) * (phis.len() - 1);
    (thetas, phis, pieces)
}

/// [`expected_mass_in`] for a batch density, to the per-cell (relative, absolute) tolerances
/// (`expected_mass_in` takes [`CELL_ABSOLUTE_TOLERANCE`]): the pieces of every cell are integrated together
/// ([`integrate_rectangles_batch`], the density evaluated in parallel chunks of 16 384 points),
/// so an external model pays a round trip per chunk, not per node. The same masses bit for bit.
pub fn expected_mass_in_batch(
    pdf: &BatchPdf<'_>,
    grid: HemisphereGrid,
    (relative, absolute): (f64, f64),
    lobe: &Lobe,
    theta_kinks: &[f64],
) -> Expected {
    let polar = lobe.polar_cuts_with(FRAC_PI_2, theta_kinks);
    let azimuth = lobe.azimuth_cuts();
    let mut rectangles = Vec::new();
    let mut per_cell = Vec::with_capacity(grid.cells());
    for i in 0..grid.cells() {
        let (thetas, phis, pieces) = cell_pieces(grid, i, &polar, &azimuth);
        let tolerance = Tolerance {
            absolute: absolute / pieces as f64,
            relative,
        };
        for p in phis.windows(2) {
            for t in thetas.windows(2) {
                rectangles.push(([p[0], p[1]], [t[0], t[1]], tolerance));
            }
        }
        per_cell.push(pieces);
    }
    let f = |pt: &[[f64; 2]], out: &mut [f64]| {
        const CHUNK: usize = 16_384;
        out.par_chunks_mut(CHUNK)
            .zip(pt.par_chunks(CHUNK))
            .for_each(|(out, pt)| {
                // The sines and cosines of θ and φ a block at a time (vectorized), the bits
                // of the scalar form's `sin_cos`.
                let n = pt.len();
                let mut angles: Vec<f64> = pt.iter().map(|&[_, theta]| theta).collect();
                angles.extend(pt.iter().map(|&[phi, _]| phi));
                let (mut sines, mut cosines) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
                sin_cos_block(&angles, &mut sines, &mut cosines);
                let dirs: Vec<Vec3> = (0..n)
                    .map(|j| {
                        let (s, c) = (sines[j], cosines[j]);
                        let (sp, cp) = (sines[n + j], cosines[n + j]);
                        [s * cp, s * sp, c.max(0.0)]
                    })
                    .collect();
                pdf(&dirs, out);
                for (o, &s) in out.iter_mut().zip(&sines[..n]) {
                    *o *= s;
                }
            });
    };
    let pieces = integrate_rectangles_batch(&f, &rectangles);
    let mut at = 0;
    let estimates: Vec<Estimate> = per_cell
        .iter()
        .map(|&n| {
            let mut sum = Estimate::default();
            for e in &pieces[at..at + n] {
                sum.value += e.value;
                sum.error_bound += e.error_bound;
                sum.evaluations += e.evaluations;
            }
            at += n;
            sum
        })
        .collect();
    Expected::of_cells(&estimates)
}

/// The cut points strictly inside `range`, with its ends.
fn inside(cuts: &[f64], range: [f64; 2]) -> Vec<f64> {
    let mut out = vec![range[0]];
    out.extend(
        cuts.iter()
            .copied()
            .filter(|c| *c > range[0] && *c < range[1]),
    );
    out.push(range[1]);
    out
}

/// The result of a chi-square test.
#[derive(Debug, Clone, PartialEq)]
pub struct Chi2Result {
    /// The grid resolution R (R z-rows × 2R φ-columns).
    pub resolution: usize,
    /// The χ² statistic (NaN after a sanity failure).
    pub statistic: f64,
    /// Degrees of freedom: bins − 1 (0 after a sanity failure).
    pub dof: usize,
    /// Q(dof/2, χ²/2) (0 after a sanity failure).
    pub p_value: f64,
    /// The level the verdict was taken at.
    pub alpha: f64,
    /// Cells pooled because their expected count was < [`MIN_EXPECTED`].
    pub pooled_cells: usize,
    /// Samples drawn.
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// Pass or fail.
    pub verdict: Verdict,
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
/// `cell_relative` (e.g. [`KINKED_CELL_RELATIVE_TOLERANCE`]) about a given lobe (e.g. measured
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
    timed(
        config,
        |grid| observe_batch(sample, grid, config.samples, config.seed),
        |grid| match lobe {
            Some(lobe) => expected_mass_in(pdf, grid, cell_relative, lobe, theta_kinks),
            None => expected_mass_to(pdf, grid, cell_relative, theta_kinks),
        },
    )
}

/// The test on `config`'s grid: the observed counts (`observe`), then the expected masses
/// (`expect`), each timed, judged by [`judge`].
fn timed(
    config: &Chi2Config,
    observe: impl FnOnce(HemisphereGrid) -> Observed,
    expect: impl FnOnce(HemisphereGrid) -> Expected,
) -> Chi2Result {
    let grid = HemisphereGrid::new(config.resolution.max(1)).expect("resolution ≥ 1");
    let t = Instant::now();
    let observed = observe(grid);
    let sampling_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let expected = expect(grid);
    let integration_seconds = t.elapsed().as_secs_f64();
    judge(
        config,
        grid,
        observed,
        expected,
        sampling_seconds,
        integration_seconds,
    )
}

/// The verdict from the observed and expected counts.
fn judge(
    config: &Chi2Config,
    grid: HemisphereGrid,
    observed: Observed,
    expected: Expected,
    sampling_seconds: f64,
    integration_seconds: f64,
) -> Chi2Result {
    let n = config.samples as f64;
    let mut result = Chi2Result {
        resolution: grid.rows(),
        statistic: f64::NAN,
        dof: 0,
        p_value: 0.0,
        alpha: config.alpha,
        pooled_cells: 0,
        samples: config.samples,
        seed: config.seed,
        verdict: Verdict::Fail,
        reason: None,
        expected_mass: expected.total,
        expected_error_bound: expected.error_bound * n,
        sampling_seconds,
        integration_seconds,
        expected: expected.mass.iter().map(|m| m * n).collect(),
        observed: observed.counts,
    };
    result.reason = sanity(&result, &expected, observed.outside, observed.first_outside);
    if result.reason.is_some() {
        return result;
    }
    let (statistic, bins, pooled) = pooled_statistic(&result.observed, &result.expected);
    result.pooled_cells = pooled;
    if bins < 2 {
        result.reason = Some(Failure::TooFewBins { bins });
        return result;
    }
    result.statistic = statistic;
    result.dof = bins - 1;
    result.p_value =
        statrs::function::gamma::checked_gamma_ur(0.5 * result.dof as f64, 0.5 * statistic)
            .unwrap_or(f64::NAN);
    if result.p_value >= config.alpha {
        result.verdict = Verdict::Pass;
    } else {
        result.reason = Some(Failure::Rejected {
            p_value: result.p_value,
            alpha: config.alpha,
        });
    }
    result
}

/// The chi-square test with a batch sampler and a batch density (an external model: a round
/// trip per batch), the expected masses integrated to the per-cell (relative, absolute)
/// `cell_tolerance`: with ([`CELL_RELATIVE_TOLERANCE`] or the kinked one,
/// [`CELL_ABSOLUTE_TOLERANCE`]) the same result as [`chi2_test_batch_in`] with the scalar
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
    timed(
        config,
        |grid| observe_blocks(sample, grid, config.samples, config.seed, CHUNK as usize),
        |grid| match lobe {
            Some(lobe) => expected_mass_in_batch(pdf, grid, cell_tolerance, lobe, theta_kinks),
            None => {
                let lobe = lobe::measure_with_batch(pdf, &lobe::Options::default());
                let mut e = expected_mass_in_batch(pdf, grid, cell_tolerance, &lobe, theta_kinks);
                e.evaluations += lobe.evaluations;
                e
            }
        },
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

/// The sanity failures, in order: samples outside the domain, invalid or off mass, samples in
/// zero-pdf cells.
fn sanity(
    result: &Chi2Result,
    expected: &Expected,
    outside: u64,
    first_outside: Option<(u64, DomainError)>,
) -> Option<Failure> {
    if let Some((index, error)) = first_outside {
        return Some(Failure::OutsideDomain(OutsideDomain {
            index,
            error,
            count: outside,
        }));
    }
    if let Some((cell, &mass)) = expected
        .mass
        .iter()
        .enumerate()
        .find(|(_, m)| !(m.is_finite() && **m >= 0.0))
    {
        return Some(Failure::InvalidMass { cell, mass });
    }
    if !((expected.total - 1.0).abs() <= MASS_TOLERANCE) {
        return Some(Failure::MassOff {
            mass: expected.total,
            error_bound: expected.error_bound,
            tolerance: MASS_TOLERANCE,
        });
    }
    result
        .observed
        .iter()
        .zip(&expected.mass)
        .enumerate()
        .find(|(_, (&o, &m))| m == 0.0 && o > 0)
        .map(|(cell, (&observed, _))| Failure::ZeroPdfCell { cell, observed })
}

/// Σ (O − E)² / E over the pooled bins; returns (statistic, bins, pooled cells).
fn pooled_statistic(observed: &[u64], expected: &[f64]) -> (f64, usize, usize) {
    let mut bins: Vec<(f64, f64)> = Vec::with_capacity(expected.len());
    let (mut pool_o, mut pool_e, mut pooled) = (0.0, 0.0, 0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < MIN_EXPECTED {
            pool_o += o as f64;
            pool_e += e;
            pooled += 1;
        } else {
            bins.push((o as f64, e));
        }
    }
    if pool_e >= MIN_EXPECTED || (bins.is_empty() && pool_e > 0.0) {
        bins.push((pool_o, pool_e));
    } else if pool_e > 0.0 {
        let smallest = bins
            .iter_mut()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("bins is not empty");
        smallest.0 += pool_o;
        smallest.1 += pool_e;
    }
    let statistic = bins.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    (statistic, bins.len(), pooled)
}

#[cfg(test)]
#[path = "chi2_tests.rs"]
mod tests;
