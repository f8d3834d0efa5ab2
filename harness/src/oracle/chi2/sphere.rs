//! Chi-square goodness-of-fit test of a BSDF's sampled directions against its pdf over the
//! **whole sphere** (reflection and transmission hemispheres), at one incidence.
//!
//! Procedure:
//!
//! 1. **Observed counts.** `samples` directions are drawn with u ∈ [0, 1)³ from the
//!    counter-based stream of each fixed chunk of [`CHUNK`] sample indices (three consecutive
//!    uniforms a sample, drawn in bulk by [`crate::random::Stream::fill_pairs`]), handed to the
//!    sampler a block at a time ([`mfh_reference::bsdf::Bsdf::sample_wo_batch`]: the directions alone), and
//!    binned: a direction with z ≥ 0 into the upper hemisphere's [`HemisphereGrid`] (R
//!    z-rows × 2R φ-columns), one with z < 0 into the lower hemisphere's, mirrored through the
//!    surface (cell of (x, y, −z)). Each hemisphere's cells follow its lobe, as the NDF
//!    chi-square's do ([`cells::layout`]): rows at the quantiles of the pdf's cos θ marginal
//!    over that hemisphere, columns at its φ quantiles for the off-axis lobes a BSDF has (the
//!    mirror and refracted directions), so that every cell expects about the same count.
//!    A sample the sampler declares failed (`None`) is counted apart. Counts are integers
//!    summed per chunk: identical whatever the thread count.
//! 2. **Expected masses.** In each hemisphere the pdf's lobe is measured from the pdf alone
//!    ([`crate::oracle::lobe`]: a reflection lobe about the mirror direction and a
//!    transmission lobe about the refracted one are off-axis modes it finds), and every cell is
//!    integrated by globally adaptive product cubature with an error bound
//!    ([`expected_mass_global_until`]) within [`MASS_BUDGET`] evaluations: a BSDF's pdf has
//!    kinks and steps where a side condition switches a lobe off (a half vector crossing the
//!    horizon, total internal reflection), which no cut can place for a model known only
//!    through its pdf, and which a locally adaptive rule bisects to its depth limit. The
//!    refinement stops as soon as the cells' error bounds cannot move the statistic
//!    ([`mass_noncentrality`] ≤ [`MASS_NONCENTRALITY`] / 2 per hemisphere), and at the latest
//!    at a summed bound of 1/N ([`mass_target`]: all expected counts together off by at most
//!    one sample). Errors δᵢ in the expected masses pᵢ act on Pearson's statistic like a
//!    noncentrality λ = N Σ δᵢ²/pᵢ over the pooled bins (its mean grows by λ, its spread by
//!    at most 2√λ), so λ ≤ 0.1 moves it by < 0.8 against a standard deviation √(2·dof) ≥ 20
//!    for the grid's hundreds of bins; a summed 1/N asks 10–100× more of a kinked pdf where
//!    it does not matter (measured: the reference GGX dielectric's five ci chi-squares
//!    3.55e7 → 6.2e6 pdf evaluations on the equal-area grid). The renormalization by the
//!    estimated total only lowers λ (derivation at [`mass_noncentrality`]), and the rounds
//!    bisect first the pieces whose error costs λ most ([`noncentrality_weights`]); the
//!    lobe-following cells are placed from one G7 × G7 rule per strip (measured 2026-12-05:
//!    the same five chi-squares on lobe-following cells 2.79e7 → 1.20e7 evaluations, the ci
//!    audit of that BSDF 3.2e7 → 1.57e7). Masses that end above the bound (the budget spent
//!    first) make `bsdf.chi2` an error record, never a verdict.
//! 3. **Sanity failures first** (no p-value): a sampled direction that is non-finite or not of
//!    unit length, a non-finite or negative cell mass, a total mass above 1 by more than
//!    [`MASS_TOLERANCE`] (a pdf of a sampler that cannot fail integrates to at most 1), samples
//!    in a cell whose expected mass is 0. No successful sample is judged by its probability
//!    under the pdf's mass, (1 − m)^N (`no_success`).
//! 4. **The test is conditional on success.** The successful samples are compared with the
//!    masses normalized by the total mass (the sampler's distribution given that it returned a
//!    direction). Whether the *rate* of failures equals 1 − ∫ pdf is a separate test
//!    (`bsdf.sample_consistency` in the checks): folding it in here would let the cubature's
//!    error in the total mass (up to 1e-4 relative, × 10⁶ samples = 100 counts) decide the test.
//! 5. **Pooling and p-value** as the NDF chi-square ([`crate::oracle::chi2`]): cells expecting
//!    fewer than [`crate::tolerance::MIN_EXPECTED`] samples are pooled, dof = bins − 1; the
//!    p-value combines the statistic's two parts ([`crate::oracle::chi2::components`]) on the
//!    table of both hemispheres' rows ordered by cos θ from 1 to −1.

use crate::oracle::chi2::cells::{self, Layout};
use crate::oracle::chi2::components::Components;
pub use crate::oracle::chi2::sphere_accuracy::{
    mass_noncentrality, mass_target, noncentrality_weights, sphere_noncentrality, MASS_BUDGET,
    MASS_NONCENTRALITY,
};
use crate::oracle::chi2::sphere_finder::SphereFinder;
use crate::oracle::chi2::{
    expected_mass_global_until, pearson_test, Chi2Config, Expected, TestOutcome,
};
use crate::oracle::hemisphere_grid::HemisphereGrid;
use crate::oracle::lobe;
use crate::random::stream;
use crate::tolerance::MASS_TOLERANCE;
use mfh_reference::bsdf::Directions;
use mfh_reference::geometry::Vec3;
use rayon::prelude::*;
use std::time::Instant;

/// Samples per random stream (the unit of work and of seeding).
pub const CHUNK: u64 = 1 << 16;
/// Samples handed to the sampler at once, within a chunk (the counts do not depend on it):
/// large enough that an external BSDF answers one request per 16 384 samples.
const BLOCK: usize = 1 << 14;

/// A batch BSDF sampler at one incidence: writes the direction of `u[k]` (or a failed sample)
/// into element k of `out` (as long as `u`).
pub type SphereSampler<'a> = dyn Fn(&[[f64; 3]], &mut Directions) + Sync + 'a;
/// A batch density over the sphere at one incidence: writes pdf(wo\[k\]) into `out[k]`.
pub type SpherePdf<'a> = dyn Fn(&[Vec3], &mut [f64]) + Sync + 'a;

/// The observed counts over the sphere.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SphereObserved {
    /// Counts per cell of the upper hemisphere (row-major, row 0 at the horizon).
    pub upper: Vec<u64>,
    /// Counts per cell of the lower hemisphere, mirrored (row 0 at the horizon).
    pub lower: Vec<u64>,
    /// Samples the sampler declared failed.
    pub failed: u64,
    /// Returned directions that are non-finite or not of unit length.
    pub invalid: u64,
    /// The first of those (lowest index) and the direction.
    pub first_invalid: Option<(u64, Vec3)>,
}

impl SphereObserved {
    /// Successful samples (binned).
    pub fn binned(&self) -> u64 {
        self.upper.iter().chain(&self.lower).sum()
    }
}

/// The result of a whole-sphere chi-square test.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereChi2Result {
    /// R: each hemisphere has R z-rows × 2R φ-columns.
    pub resolution: usize,
    /// The upper hemisphere's cells.
    pub upper_grid: HemisphereGrid,
    /// The lower hemisphere's cells (mirrored: row 0 at the horizon).
    pub lower_grid: HemisphereGrid,
    /// The χ² statistic (NaN after a sanity failure).
    pub statistic: f64,
    /// Degrees of freedom (0 after a sanity failure).
    pub dof: usize,
    /// The test's p-value (0 after a sanity failure): the combination of the two parts of
    /// `components`, the rows ordered by cos θ over the whole sphere (upper rows from the
    /// pole down, then the lower ones), as for the hemisphere's test
    /// ([`crate::oracle::chi2::components`]).
    pub p_value: f64,
    /// The statistic's two parts: the cos θ marginal's first smooth components and the rest.
    pub components: Option<Components>,
    /// The level the verdict was taken at.
    pub alpha: f64,
    /// Pass or fail.
    pub verdict: TestOutcome,
    /// Why it failed (a sanity failure or the rejection), if it did.
    pub reason: Option<String>,
    /// Whether the failure is a sanity failure (no p-value).
    pub sanity_failure: bool,
    /// Samples drawn.
    pub samples: u64,
    /// The seed of the random streams.
    pub seed: u64,
    /// The counts.
    pub observed: SphereObserved,
    /// The masses of the upper and lower hemispheres' cells.
    pub expected_upper: Expected,
    /// See `expected_upper`.
    pub expected_lower: Expected,
    /// Wall time of sampling and binning, seconds.
    pub sampling_seconds: f64,
    /// Wall time of the expected masses, seconds.
    pub integration_seconds: f64,
}

impl SphereChi2Result {
    /// The pdf's integral over the sphere.
    pub fn mass(&self) -> f64 {
        self.expected_upper.total + self.expected_lower.total
    }

    /// The error bound of [`SphereChi2Result::mass`].
    pub fn mass_error_bound(&self) -> f64 {
        self.expected_upper.error_bound + self.expected_lower.error_bound
    }

    /// The noncentrality the masses' error bounds can add to the statistic (both hemispheres'
    /// [`mass_noncentrality`] summed).
    pub fn mass_noncentrality(&self) -> f64 {
        sphere_noncentrality(&self.expected_upper, &self.expected_lower, self.samples)
    }

    /// Pdf evaluations spent on the expected masses.
    pub fn evaluations(&self) -> u64 {
        self.expected_upper.evaluations + self.expected_lower.evaluations
    }

    /// The expected counts of the successful samples (upper cells, then lower cells): the masses
    /// normalized by the total, times the binned samples.
    pub fn expected_counts(&self) -> Vec<f64> {
        let n = self.observed.binned() as f64;
        let total = self.mass();
        self.expected_upper
            .mass
            .iter()
            .chain(&self.expected_lower.mass)
            .map(|m| if total > 0.0 { m / total * n } else { 0.0 })
            .collect()
    }
}

/// Draws `samples` directions through `sample` and bins them over the sphere (step 1): each
/// block's directions binned by [`SphereFinder::cells_of`] (both hemispheres in one vectorized
/// pass, the failed samples into a cell of their own); a block with a direction outside the
/// domain is binned again one by one for the errors (the same counts either way).
pub fn observe_sphere(
    sample: &SphereSampler<'_>,
    (upper_grid, lower_grid): (HemisphereGrid, HemisphereGrid),
    samples: u64,
    seed: u64,
) -> SphereObserved {
    let finder = SphereFinder::new(upper_grid, lower_grid);
    let failed_cell = finder.failed_cell();
    let zero = || Tally {
        counts: vec![0; failed_cell + 1],
        ..Tally::default()
    };
    let tally = draw_chunks(
        samples,
        seed,
        zero,
        Buffers::default,
        |tally, buf, index, u| {
            let n = u.len();
            // Failed samples until written (a sampler that skips an element fails it).
            buf.out.resize(n);
            buf.out.fail_all();
            sample(u, &mut buf.out);
            buf.cells.resize(n, 0);
            if finder.cells_of(&buf.out, &mut buf.cells) {
                for &c in &buf.cells {
                    tally.counts[c] += 1;
                }
                return;
            }
            // A direction outside the domain: the block one by one, for the errors.
            for (k, w) in buf.out.iter().enumerate() {
                match w.map_or(Ok(failed_cell), |w| finder.cell_of(w)) {
                    Ok(c) => tally.counts[c] += 1,
                    Err(_) => {
                        tally.invalid += 1;
                        if tally.first_invalid.is_none() {
                            tally.first_invalid = w.map(|w| (index + k as u64, w));
                        }
                    }
                }
            }
        },
    )
    .into_iter()
    .fold(zero(), Tally::merge);
    let upper_cells = finder.upper().grid().cells();
    SphereObserved {
        upper: tally.counts[..upper_cells].to_vec(),
        lower: tally.counts[upper_cells..failed_cell].to_vec(),
        failed: tally.counts[failed_cell],
        invalid: tally.invalid,
        first_invalid: tally.first_invalid,
    }
}

/// A chunk's counts: per cell of the [`SphereFinder`] (the failed samples' last), and the
/// directions outside the domain.
#[derive(Default)]
struct Tally {
    counts: Vec<u64>,
    invalid: u64,
    first_invalid: Option<(u64, Vec3)>,
}

impl Tally {
    fn merge(mut self, other: Self) -> Self {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.invalid += other.invalid;
        self.first_invalid = match (self.first_invalid, other.first_invalid) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
            (a, b) => a.or(b),
        };
        self
    }
}

/// A chunk's buffers, reused block to block: the sampled directions and their cells.
#[derive(Default)]
struct Buffers {
    out: Directions,
    cells: Vec<usize>,
}

/// The u ∈ [0, 1)³ of `samples` samples from the streams of `seed` (three uniforms a sample,
/// one stream per chunk of [`CHUNK`] samples), handed to `block(acc, scratch, first index, u)` a block
/// of at most [`BLOCK`] (16 384) at a time, the chunks in parallel, each folded into its own accumulator;
/// the accumulators in chunk order (so a result folded from them does not depend on the
/// thread count). The one sampling loop of the BSDF's chi-square and of the BSDF checks.
///
/// `scratch()` is a value handed to `block` beside the chunk's accumulator, one per rayon job,
/// reused chunk to chunk (buffers allocated per block or chunk are pages the kernel maps and
/// zeroes every time: 39 % of a BSDF chi-square's time before); it must not carry results,
/// since the chunks it sees depend on the scheduling.
pub fn draw_chunks<A: Send, B>(
    samples: u64,
    seed: u64,
    init: impl Fn() -> A + Sync,
    scratch: impl Fn() -> B + Sync,
    block: impl Fn(&mut A, &mut B, u64, &[[f64; 3]]) + Sync,
) -> Vec<A> {
    let deadline = crate::deadline::current();
    (0..samples.div_ceil(CHUNK))
        .into_par_iter()
        .map_init(
            || (vec![[0.0; 2]; (3 * BLOCK).div_ceil(2)], scratch()),
            |(pairs, scratch), chunk| {
                crate::deadline::check(deadline);
                let mut rng = stream(seed, chunk);
                let mut acc = init();
                let (start, end) = (chunk * CHUNK, ((chunk + 1) * CHUNK).min(samples));
                // The block's uniforms in bulk: pairs are consecutive uniforms of the stream,
                // so 3n/2 pairs read as n triples are the triples of 3n `uniform` calls (for
                // an odd 3n the last block of a chunk draws one uniform more, which nothing
                // reads); the triples are the pairs' memory, cast (no copy).
                let mut index = start;
                while index < end {
                    let n = BLOCK.min((end - index) as usize);
                    let pairs = &mut pairs[..(3 * n).div_ceil(2)];
                    rng.fill_pairs(pairs);
                    let flat: &[f64] = bytemuck::cast_slice(pairs);
                    let u: &[[f64; 3]] = bytemuck::cast_slice(&flat[..3 * n]);
                    block(&mut acc, scratch, index, u);
                    index += n as u64;
                }
                acc
            },
        )
        .collect()
}

/// The masses of the cells of one hemisphere (`lower`: mirrored) of the density `pdf` (step 2),
/// by globally adaptive cubature to the summed error `target` within [`MASS_BUDGET`]
/// evaluations ([`expected_mass_global_until`]), or until `enough` holds of the masses; the
/// cells are `cells`'s (a given grid, or R rows and 2R columns placed at the quantiles of the
/// hemisphere's marginals by [`cells::layout`]), returned with the masses.
#[allow(clippy::too_many_arguments)]
fn expected_hemisphere_until(
    pdf: &SpherePdf<'_>,
    cells: Cells,
    lower: bool,
    target: f64,
    enough: &dyn Fn(&Expected) -> bool,
    weights: &dyn Fn(&Expected) -> Option<Vec<f64>>,
    centres: &[Vec3],
) -> (HemisphereGrid, Expected) {
    let mirrored = |w: &[Vec3], out: &mut [f64]| {
        if lower {
            let m: Vec<Vec3> = w.iter().map(|v| [v[0], v[1], -v[2]]).collect();
            pdf(&m, out);
        } else {
            pdf(w, out);
        }
    };
    // The lobe centres on this side, in its (mirrored) frame: where the mode search starts.
    let seeds: Vec<Vec3> = centres
        .iter()
        .filter(|c| (c[2] < 0.0) == lower)
        .map(|c| [c[0], c[1], c[2].abs()])
        .collect();
    let options = lobe::Options {
        hint: None,
        start_points: &seeds,
    };
    let lobe = lobe::measure_with_batch(&mirrored, &options);
    // The centres' polar angles are cut exactly: the directions refracted through horizontal
    // microfacets all lie at |wo_z| = |wi_z|·η_i/η_o, the edge of the transmission lobe (no
    // upward microfacet refracts closer to the horizon), where a density whose D is not 0 at
    // the microfacets' horizon (GGX) steps to 0 for every azimuth. A step inside a piece, near
    // its edge, is missed by both of its rules: measured before, GGX α 0.3 at cos θi 0.05, the
    // transmitted ∫ eval 7.9e-5 (η 1.005) and 1.4e-4 (η 1.05) short of an integral over the
    // microfacet normals, its bound 1.4e-6, while Beckmann (D → 0 there) agreed to 1e-7.
    let kinks: Vec<f64> = seeds.iter().map(|c| c[2].clamp(-1.0, 1.0).acos()).collect();
    let (grid, placed) = match cells {
        Cells::Given(grid) => (grid, 0),
        Cells::FollowLobe(resolution) => cells::layout(
            &mirrored,
            &lobe,
            resolution,
            &kinks,
            Layout::FollowSteppedLobe,
        ),
    };
    let (mut e, _converged) = expected_mass_global_until(
        &mirrored,
        grid.clone(),
        &lobe,
        (target, MASS_BUDGET),
        &kinks,
        enough,
        weights,
    );
    e.evaluations += lobe.evaluations + placed;
    (grid, e)
}

/// Where one hemisphere's cells are.
#[derive(Debug, Clone)]
pub enum Cells {
    /// On this grid.
    Given(HemisphereGrid),
    /// R rows at the quantiles of the hemisphere's cos θ marginal and 2R columns (at its φ
    /// quantiles for an off-axis or anisotropic lobe), as the hemisphere's chi-square places
    /// them ([`cells::layout`], its marginals by a fixed rule: [`Layout::FollowSteppedLobe`]);
    /// the equal-area grid of R where the hemisphere has no mass.
    FollowLobe(usize),
}

/// The masses of the cells of one hemisphere (`lower`: mirrored) of the density `pdf` on
/// `grid`, to the summed error `target` (within [`MASS_BUDGET`] evaluations).
pub fn expected_hemisphere(
    pdf: &SpherePdf<'_>,
    grid: HemisphereGrid,
    lower: bool,
    target: f64,
) -> Expected {
    expected_hemisphere_about(pdf, grid, lower, target, &[])
}

/// [`expected_hemisphere`] with the lobe measurement started at `centres` (directions over
/// the whole sphere, e.g. [`crate::oracle::lobe_centres::lobe_centres`]; those on the other
/// side are ignored). `target` is absolute for an integral up to 1 and relative beyond it:
/// the refinement also stops once the bound is `target` × |integral| (an eval integrated from
/// the denser side may exceed 1; one that answers 1e308 was refined towards an absolute 1e-5
/// until the record's budget, 120 s an incidence through the protocol, to no use).
pub fn expected_hemisphere_about(
    pdf: &SpherePdf<'_>,
    grid: HemisphereGrid,
    lower: bool,
    target: f64,
    centres: &[Vec3],
) -> Expected {
    expected_hemisphere_until(
        pdf,
        Cells::Given(grid),
        lower,
        target,
        &|e| e.error_bound <= target * e.total.abs(),
        &|_| None,
        centres,
    )
    .1
}

/// The expected masses of both hemispheres (upper, lower) of `pdf` on `grid`, each to the
/// summed error `target`.
pub fn expected_sphere(
    pdf: &SpherePdf<'_>,
    grid: HemisphereGrid,
    target: f64,
) -> (Expected, Expected) {
    expected_sphere_about(pdf, grid, target, &[])
}

/// [`expected_sphere`] with each hemisphere's lobe measurement started at `centres`.
pub fn expected_sphere_about(
    pdf: &SpherePdf<'_>,
    grid: HemisphereGrid,
    target: f64,
    centres: &[Vec3],
) -> (Expected, Expected) {
    (
        expected_hemisphere_about(pdf, grid.clone(), false, target, centres),
        expected_hemisphere_about(pdf, grid, true, target, centres),
    )
}

/// The equal-area resolution of the second cubature of an integral over the sphere
/// ([`cross_check_sphere`]): 13 rows × 26 columns, whose edges meet those of the checks'
/// 16 × 32 grid only at the horizon, the pole and the azimuths 0 and π.
pub const CROSS_CHECK_RESOLUTION: usize = 13;

/// A second estimate of [`expected_sphere_about`]'s integrals (upper, lower), on the
/// equal-area grid of [`CROSS_CHECK_RESOLUTION`] rather than the checks' 16: the same lobe
/// measurement and cuts, other cell edges. What [`cross_checked_allowance`] compares with.
pub fn cross_check_sphere(
    pdf: &SpherePdf<'_>,
    target: f64,
    centres: &[Vec3],
) -> (Expected, Expected) {
    let grid = HemisphereGrid::new(CROSS_CHECK_RESOLUTION).expect("R ≥ 1");
    expected_sphere_about(pdf, grid, target, centres)
}

/// The error allowed an integral `a` = (value A, error bound b_A) of the density over some
/// cells, cross-checked by a second cubature `b` = (B, b_B) of the same integral on cells whose
/// edges differ ([`cross_check_sphere`]): max(b_A, |A − B| + b_B); infinite where a value or
/// bound is not a number.
///
/// Why. Each bound is the summed G7/K15 difference of its pieces, which bounds the error of a
/// density smooth on each piece but under-states it where a lobe far narrower than a cell meets
/// the cell's edges (the pieces' rules then both miss the same part of it). The two layouts
/// share no interior edge but the azimuths 0 and π, so a lobe that one layout cuts badly the
/// other meets inside a cell: the premise is that at most one of the two bounds fails at once.
/// If A's holds, |A − truth| ≤ b_A; if B's holds, |A − truth| ≤ |A − B| + |B − truth| ≤
/// |A − B| + b_B. Either way the maximum bounds A's error, and it grows with their
/// disagreement: the oracle declines (an `error` record) where it is more than a check can
/// judge by. The premise fails where both layouts share the pieces that carry the error (a
/// near-delta lobe's cuts about its mode: Beckmann α 1e-7 at η 0.999, θi 0.9, both 4.3e-7
/// off against a bound of 1.3e-7), so `bsdf.albedo` also keeps 2 × its target as the
/// resolution it judges at; both are validated against Monte Carlo over the reference BSDFs'
/// accepted domain by the property test in `sphere_mass_tests.rs`.
pub fn cross_checked_allowance(a: (f64, f64), b: (f64, f64)) -> f64 {
    let ((va, ba), (vb, bb)) = (a, b);
    let allowance = ba.max((va - vb).abs() + bb);
    if [va, ba, vb, bb].iter().all(|x| x.is_finite()) {
        allowance
    } else {
        f64::INFINITY
    }
}

/// The cells of both hemispheres of a whole-sphere chi-square and their expected masses.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereMasses {
    /// The upper hemisphere's cells.
    pub upper_grid: HemisphereGrid,
    /// Their masses.
    pub upper: Expected,
    /// The lower hemisphere's cells (mirrored: row 0 at the horizon).
    pub lower_grid: HemisphereGrid,
    /// Their masses.
    pub lower: Expected,
}

/// The cells of both hemispheres of `pdf` at `resolution` (each following its hemisphere's
/// lobe, [`Cells::FollowLobe`]) and their expected masses for a chi-square of `samples`
/// samples (step 2): each refined until its [`mass_noncentrality`] is at most half of
/// [`MASS_NONCENTRALITY`], or to the summed error [`mass_target`].
///
/// Without lobe centres a lobe narrower than the survey's spacing is missed: for a BSDF pass
/// the incidence's [`crate::oracle::lobe_centres::lobe_centres`] to [`chi2_masses_about`]
/// (the GGX α 1e-6 × 1e-4 dielectric of η 1.5 at cos θi 0.01 from inside: reflected mass
/// 1.3e-6 here for 0.999996 with them, and the chi-square rejects at p 0).
pub fn chi2_masses(pdf: &SpherePdf<'_>, resolution: usize, samples: u64) -> SphereMasses {
    chi2_masses_about(pdf, resolution, samples, &[])
}

/// [`chi2_masses`] with each hemisphere's lobe measurement started at `centres` (the mirror
/// and refracted directions of the incidence: [`crate::oracle::lobe_centres::lobe_centres`]),
/// so that a lobe too narrow for the survey is found and cut about.
pub fn chi2_masses_about(
    pdf: &SpherePdf<'_>,
    resolution: usize,
    samples: u64,
    centres: &[Vec3],
) -> SphereMasses {
    chi2_masses_on_about(pdf, Cells::FollowLobe(resolution.max(1)), samples, centres)
}

/// [`chi2_masses`] with both hemispheres' cells given by `cells` (e.g. the equal-area grid).
pub fn chi2_masses_on(pdf: &SpherePdf<'_>, cells: Cells, samples: u64) -> SphereMasses {
    chi2_masses_on_about(pdf, cells, samples, &[])
}

/// [`chi2_masses_on`] with the lobe measurement started at `centres`.
pub fn chi2_masses_on_about(
    pdf: &SpherePdf<'_>,
    cells: Cells,
    samples: u64,
    centres: &[Vec3],
) -> SphereMasses {
    let target = mass_target(samples);
    let enough = |e: &Expected| mass_noncentrality(e, samples) <= 0.5 * MASS_NONCENTRALITY;
    let weights = |e: &Expected| Some(noncentrality_weights(e, samples));
    let (upper_grid, upper) = expected_hemisphere_until(
        pdf,
        cells.clone(),
        false,
        target,
        &enough,
        &weights,
        centres,
    );
    let (lower_grid, lower) =
        expected_hemisphere_until(pdf, cells, true, target, &enough, &weights, centres);
    SphereMasses {
        upper_grid,
        upper,
        lower_grid,
        lower,
    }
}

/// Tests `sample` against `pdf` over the sphere, on cells that follow each hemisphere's
/// lobe.
pub fn sphere_chi2(
    sample: &SphereSampler<'_>,
    pdf: &SpherePdf<'_>,
    config: &Chi2Config,
) -> SphereChi2Result {
    sphere_chi2_about(sample, pdf, config, &[])
}

/// [`sphere_chi2`] with the lobe measurement started at `centres` ([`chi2_masses_about`]).
pub fn sphere_chi2_about(
    sample: &SphereSampler<'_>,
    pdf: &SpherePdf<'_>,
    config: &Chi2Config,
    centres: &[Vec3],
) -> SphereChi2Result {
    let t = Instant::now();
    let masses = chi2_masses_about(pdf, config.resolution, config.samples, centres);
    let integration_seconds = t.elapsed().as_secs_f64();
    let mut r = sphere_chi2_against(sample, masses, config);
    r.integration_seconds = integration_seconds;
    r
}

/// [`sphere_chi2`] against cells and expected masses already integrated (by
/// [`chi2_masses`]); `integration_seconds` of the result is 0.
pub fn sphere_chi2_against(
    sample: &SphereSampler<'_>,
    masses: SphereMasses,
    config: &Chi2Config,
) -> SphereChi2Result {
    let SphereMasses {
        upper_grid,
        upper: expected_upper,
        lower_grid,
        lower: expected_lower,
    } = masses;
    let t = Instant::now();
    let observed = observe_sphere(
        sample,
        (upper_grid.clone(), lower_grid.clone()),
        config.samples,
        config.seed,
    );
    let sampling_seconds = t.elapsed().as_secs_f64();
    let integration_seconds = 0.0;
    let columns = upper_grid.columns();
    let mut result = SphereChi2Result {
        resolution: upper_grid.rows(),
        upper_grid,
        lower_grid,
        statistic: f64::NAN,
        dof: 0,
        p_value: 0.0,
        components: None,
        alpha: config.alpha,
        verdict: TestOutcome::Fail,
        reason: None,
        sanity_failure: true,
        samples: config.samples,
        seed: config.seed,
        observed,
        expected_upper,
        expected_lower,
        sampling_seconds,
        integration_seconds,
    };
    if let Some(reason) = sanity(&result) {
        result.reason = Some(reason);
        return result;
    }
    if result.observed.binned() == 0 {
        no_success(&mut result);
        return result;
    }
    let observed: Vec<u64> = result
        .observed
        .upper
        .iter()
        .chain(&result.observed.lower)
        .copied()
        .collect();
    let (table, expected) = along_cos_theta(&result, columns);
    let Ok(test) = pearson_test(
        (&observed, &result.expected_counts()),
        (&table, &expected),
        columns,
        config.alpha,
    ) else {
        // Too few successful samples for two bins (a BSDF whose pdf holds 10⁻⁶–10⁻⁴ of mass
        // at this incidence, every other sample failing): conditional on success the one bin
        // holds them all whatever the sampler, so the statistic is 0 and p is 1. Samples
        // where the pdf is 0 failed above; their number is `bsdf.failure_rate`'s to judge.
        result.sanity_failure = false;
        result.statistic = 0.0;
        result.dof = 0;
        result.p_value = 1.0;
        result.verdict = TestOutcome::Pass;
        return result;
    };
    result.sanity_failure = false;
    result.statistic = test.statistic;
    result.dof = test.dof;
    result.components = test.components;
    result.p_value = test.p_value;
    result.verdict = test.verdict;
    if test.verdict == TestOutcome::Fail {
        result.reason = Some(format!(
            "p-value {:.3e} below α = {:.3e}",
            result.p_value, config.alpha
        ));
    }
    result
}

/// The observed and expected counts as one table of 2R rows ordered by cos θ from 1 to −1:
/// the upper hemisphere's rows from the pole to the horizon, then the lower (mirrored)
/// hemisphere's from the horizon to its pole.
fn along_cos_theta(r: &SphereChi2Result, columns: usize) -> (Vec<u64>, Vec<f64>) {
    let expected = r.expected_counts();
    let (upper_e, lower_e) = expected.split_at(r.observed.upper.len());
    let (mut table, mut counts) = (Vec::new(), Vec::new());
    for (o, e) in r
        .observed
        .upper
        .chunks(columns)
        .zip(upper_e.chunks(columns))
        .rev()
        .chain(
            r.observed
                .lower
                .chunks(columns)
                .zip(lower_e.chunks(columns)),
        )
    {
        table.extend_from_slice(o);
        counts.extend_from_slice(e);
    }
    (table, counts)
}

/// The test when no sample succeeded (step 3): the chance of that under the pdf's mass m is
/// (1 − m)^N, the p-value (m at the low end of its bound: the doubt goes to the sampler). A
/// BSDF whose pdf has almost no mass at this incidence (GGX α 1e4 at normal incidence: mass
/// 1.8e-9, every reflected direction below the horizon) fails every sample and passes; one
/// whose pdf holds 10⁻⁵ or more of mass fails at 10⁶ samples (p ≤ e⁻¹⁰).
fn no_success(r: &mut SphereChi2Result) {
    let m = (r.mass() - r.mass_error_bound()).clamp(0.0, 1.0);
    let p = (r.samples as f64 * (-m).ln_1p()).exp();
    r.sanity_failure = false;
    r.statistic = 0.0;
    r.dof = 0;
    r.p_value = p;
    if p >= r.alpha {
        r.verdict = TestOutcome::Pass;
    } else {
        r.reason = Some(format!(
            "every one of {} samples failed against a pdf mass of {:.3e} (± {:.1e}): p {p:.3e} \
             below α = {:.3e}",
            r.samples,
            r.mass(),
            r.mass_error_bound(),
            r.alpha
        ));
    }
}

/// The sanity failures of step 3, in order.
fn sanity(r: &SphereChi2Result) -> Option<String> {
    let o = &r.observed;
    if let Some((index, w)) = o.first_invalid {
        return Some(format!(
            "{} sampled directions are non-finite or not of unit length (within {}); the \
             first, sample {index}: {w:?}",
            o.invalid,
            crate::oracle::hemisphere_grid::UNIT_TOLERANCE
        ));
    }
    let masses = r.expected_upper.mass.iter().chain(&r.expected_lower.mass);
    if let Some((cell, m)) = masses
        .enumerate()
        .find(|(_, m)| !(m.is_finite() && **m >= 0.0))
    {
        return Some(format!("pdf mass over cell {cell} is {m}"));
    }
    let mass = r.mass();
    if !(mass <= 1.0 + MASS_TOLERANCE + r.mass_error_bound()) {
        return Some(format!(
            "the pdf integrates to {mass} (± {:.1e}) over the sphere: more than 1 + {MASS_TOLERANCE}",
            r.mass_error_bound()
        ));
    }
    let cells = r.expected_upper.mass.len();
    let observed = o.upper.iter().chain(&o.lower);
    let expected = r.expected_upper.mass.iter().chain(&r.expected_lower.mass);
    observed
        .zip(expected)
        .enumerate()
        .find(|(_, (&n, &m))| m == 0.0 && n > 0)
        .map(|(c, (&n, _))| {
            let (side, cell) = if c < cells {
                ("upper", c)
            } else {
                ("lower", c - cells)
            };
            format!("{n} samples in cell {cell} of the {side} hemisphere, where the pdf is zero")
        })
}

#[cfg(test)]
#[path = "sphere_mass_tests.rs"]
mod sphere_mass_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::bsdf::pdf_at;
    use crate::oracle::hemisphere_grid::CellFinder;
    use crate::tolerance::MIN_EXPECTED;

    /// The reference GGX dielectric at grazing incidence (cos θi = 0.05), whose pdf steps where
    /// half vectors cross the horizon: the masses for a chi-square of 10⁶ samples meet the
    /// noncentrality criterion with several times fewer evaluations than the summed 1/N, and
    /// agree with those tighter masses within their own bounds.
    #[test]
    fn the_chi2_masses_stop_when_their_errors_cannot_move_the_statistic() {
        let spec: mfh_reference::bsdf::BsdfSpec = serde_json::from_str(
            r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#,
        )
        .unwrap();
        let bsdf = spec.build().unwrap();
        let s = (1.0f64 - 0.05 * 0.05).sqrt();
        let wi = [s, 0.0, 0.05];
        let pdf = pdf_at(bsdf.as_ref(), wi);
        let grid = HemisphereGrid::new(16).unwrap();
        let samples = 1_000_000;
        let SphereMasses {
            upper: u, lower: l, ..
        } = chi2_masses_on(&pdf, Cells::Given(grid.clone()), samples);
        let (tu, tl) = expected_sphere(&pdf, grid, mass_target(samples));
        let lambda = sphere_noncentrality(&u, &l, samples);
        assert!(lambda <= MASS_NONCENTRALITY, "λ = {lambda}");
        let (fast, tight) = (
            u.evaluations + l.evaluations,
            tu.evaluations + tl.evaluations,
        );
        eprintln!("evaluations: {fast} (λ ≤ {lambda:.3}) against {tight} (summed 1/N)");
        assert!(3 * fast < tight, "{fast} vs {tight}");
        for (a, b) in [(&u, &tu), (&l, &tl)] {
            for (i, (m, t)) in a.mass.iter().zip(&b.mass).enumerate() {
                let bound = a.cell_bound[i] + b.cell_bound[i];
                assert!(
                    (m - t).abs() <= bound + 1e-15,
                    "cell {i}: {m} vs {t} ± {bound}"
                );
            }
        }
    }

    /// The vectorized binning of `observe_sphere` counts what each hemisphere's
    /// `CellFinder::cell_of` finds one by one, on directions at the hard places (poles, φ = 0
    /// and the column edges, the horizon from both sides, row edges of a quantile grid) mixed
    /// with failed, non-finite and non-unit ones, whatever the thread count.
    #[test]
    fn sphere_binning_counts_what_cell_of_finds() {
        let grid = HemisphereGrid::with_edges(
            vec![0.0, 0.1, 0.35, 0.5, 0.8, 0.97, 1.0],
            Some(
                (0..=12)
                    .map(|j| j as f64 * std::f64::consts::TAU / 12.0)
                    .collect(),
            ),
        )
        .unwrap();
        let z_edges = grid.z_edges();
        // u[0] picks a kind of direction, u[1..] place it.
        let direction = |u: [f64; 3]| -> Option<Vec3> {
            let (phi, z) = (u[1] * std::f64::consts::TAU, 2.0 * u[2] - 1.0);
            let edge_phi = (u[1] * 12.0).floor() * std::f64::consts::TAU / 12.0;
            let edge_z = z_edges[(u[2] * 7.0) as usize % 7];
            let at = |phi: f64, z: f64| {
                let s = (1.0 - z * z).max(0.0).sqrt();
                [s * phi.cos(), s * phi.sin(), z]
            };
            match (u[0] * 10.0) as u32 {
                0 => None,
                1 => Some([0.0, 0.0, if u[2] < 0.5 { 1.0 } else { -1.0 }]),
                2 => Some(at(edge_phi, z)),
                3 => Some(at(phi, if u[2] < 0.5 { edge_z } else { -edge_z })),
                4 => Some(at(phi, if u[2] < 0.5 { 0.0 } else { -0.0 })),
                5 if u[1] < 0.01 => Some([f64::NAN, 0.0, 1.0]),
                6 if u[1] < 0.01 => Some([0.7, 0.7, 0.7]),
                _ => Some(at(phi, z)),
            }
        };
        let sampler = |u: &[[f64; 3]], out: &mut Directions| {
            for (k, &u) in u.iter().enumerate() {
                out.set(k, direction(u));
            }
        };
        let samples = 200_000;
        // The lower hemisphere equal-area: the finder puts both grids' edges on one line.
        let lower_grid = HemisphereGrid::new(6).unwrap();
        let grids = (grid.clone(), lower_grid.clone());
        let observed = observe_sphere(&sampler, grids.clone(), samples, 5);
        // One by one, over the same uniforms, by each hemisphere's own finder.
        let (upper_finder, lower_finder) = (
            CellFinder::new(grid.clone()),
            CellFinder::new(lower_grid.clone()),
        );
        let mut want = SphereObserved {
            upper: vec![0; grid.cells()],
            lower: vec![0; lower_grid.cells()],
            ..SphereObserved::default()
        };
        let blocks = draw_chunks(
            samples,
            5,
            Vec::new,
            || (),
            |acc, _, index, u| {
                acc.extend(
                    u.iter()
                        .enumerate()
                        .map(|(k, &u)| (index + k as u64, direction(u))),
                );
            },
        );
        for (index, w) in blocks.into_iter().flatten() {
            let Some(w) = w else {
                want.failed += 1;
                continue;
            };
            let (cells, finder, m) = if w[2] >= 0.0 {
                (&mut want.upper, &upper_finder, w)
            } else {
                (&mut want.lower, &lower_finder, [w[0], w[1], -w[2]])
            };
            match finder.cell_of(m) {
                Ok(c) => cells[c] += 1,
                Err(_) => {
                    want.invalid += 1;
                    want.first_invalid = want.first_invalid.or(Some((index, w)));
                }
            }
        }
        assert_eq!(observed.upper, want.upper);
        assert_eq!(observed.lower, want.lower);
        assert_eq!(
            (observed.failed, observed.invalid),
            (want.failed, want.invalid)
        );
        assert!(want.invalid > 100 && want.failed > 10_000, "{want:?}");
        assert_eq!(
            observed.first_invalid.map(|f| f.0),
            want.first_invalid.map(|f| f.0)
        );
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let again = pool.install(|| observe_sphere(&sampler, grids.clone(), samples, 5));
            // Field by field: the first invalid direction may hold a NaN (≠ itself).
            let key = |o: &SphereObserved| {
                let first = o.first_invalid.map(|(i, w)| (i, w.map(f64::to_bits)));
                (o.upper.clone(), o.lower.clone(), o.failed, o.invalid, first)
            };
            assert_eq!(key(&again), key(&observed), "{threads} threads");
        }
    }

    /// The cross-checked allowance is A's bound while the two cubatures agree within B's, their
    /// disagreement plus B's bound otherwise, and infinite (no verdict) for a value that is not
    /// a number.
    #[test]
    fn the_cross_checked_allowance_grows_with_the_disagreement() {
        assert_eq!(cross_checked_allowance((0.5, 1e-6), (0.5, 1e-7)), 1e-6);
        let got = cross_checked_allowance((0.5, 1e-7), (0.5 + 1.5e-6, 1e-7));
        assert!((got - 1.6e-6).abs() < 1e-15, "{got}");
        assert_eq!(
            cross_checked_allowance((f64::NAN, 1e-7), (0.5, 1e-7)),
            f64::INFINITY
        );
        assert_eq!(
            cross_checked_allowance((0.5, 1e-7), (0.5, f64::INFINITY)),
            f64::INFINITY
        );
        // The second grid's edges meet the first's only at the horizon, the pole and the
        // azimuths 0 and π.
        let (a, b) = (
            HemisphereGrid::new(16).unwrap(),
            HemisphereGrid::new(CROSS_CHECK_RESOLUTION).unwrap(),
        );
        let shared = |x: &[f64], y: &[f64]| {
            x.iter()
                .filter(|u| y.iter().any(|v| (*u - v).abs() < 1e-12))
                .count()
        };
        assert_eq!(shared(&a.z_edges(), &b.z_edges()), 2);
        assert_eq!(shared(&a.phi_edges(), &b.phi_edges()), 3);
    }

    #[test]
    fn the_noncentrality_bound_pools_small_cells_and_renormalizes() {
        let e = |mass: Vec<f64>, bound: Vec<f64>| Expected {
            total: mass.iter().sum(),
            error_bound: bound.iter().sum(),
            mass,
            cell_bound: bound,
            evaluations: 0,
            budget_hit: None,
        };
        // Exact masses: no noncentrality.
        assert_eq!(
            mass_noncentrality(&e(vec![0.5, 0.5], vec![0.0, 0.0]), 1000),
            0.0
        );
        // One large cell: 2N F δ²/(p − δ), F = ((P̂ − D)/(P̂ − 2D))².
        let got = mass_noncentrality(&e(vec![0.5, 0.5], vec![1e-3, 0.0]), 1000);
        let f = (0.999f64 / 0.998).powi(2);
        let want = 2000.0 * f * 1e-6 / 0.499;
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
        // No bound while the summed bound is half the mass or more.
        let got = mass_noncentrality(&e(vec![0.5, 0.5], vec![0.3, 0.2]), 1000);
        assert_eq!(got, f64::INFINITY);
        // Cells below MIN_EXPECTED/N pool; their pooled mass is floored at MIN_EXPECTED/N.
        let n = 1000;
        let tiny = 0.1 * MIN_EXPECTED / n as f64;
        let got = mass_noncentrality(&e(vec![1.0, tiny, tiny], vec![0.0, 1e-4, 1e-4]), n);
        let least = MIN_EXPECTED / n as f64;
        let f = ((1.0 + 2.0 * tiny - 2e-4) / (1.0 + 2.0 * tiny - 4e-4)).powi(2);
        let want = 2000.0 * f * 4e-8 / least;
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    }
}
