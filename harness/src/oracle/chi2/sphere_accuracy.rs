//! How accurate a BSDF chi-square's expected masses must be (`chi2/sphere.rs`, step 2): errors
//! δᵢ in the masses pᵢ act on Pearson's statistic as a noncentrality λ = N Σ δᵢ²/pᵢ over the
//! pooled bins; the cubature refines until λ cannot move the statistic, within a budget of
//! evaluations, and weighs its rounds by each piece's share of λ.

use crate::oracle::chi2::Expected;
use crate::tolerance::MIN_EXPECTED;

/// The summed error bound the expected masses of one hemisphere aim at for `samples` samples:
/// 1/N, so that all the expected counts of a hemisphere together are off by at most one sample
/// (a chi-square of N samples cannot see that), with a floor of 1e-9.
pub fn mass_target(samples: u64) -> f64 {
    (1.0 / samples.max(1) as f64).max(1e-9)
}

/// The evaluation budget of the expected masses of one hemisphere: 2·10⁷ pdf evaluations
/// (about 2 s of a reference BSDF); past it the masses keep the bound they reached, which the
/// record reports.
pub const MASS_BUDGET: u64 = 20_000_000;

/// The largest noncentrality the expected masses' errors may add to the statistic of a
/// whole-sphere chi-square (step 2): its mean moves by at most λ and its spread by 2√λ, < 0.8
/// together at λ = 0.1, against the statistic's own standard deviation √(2·dof) (≥ 20 for the
/// hundreds of bins of the BSDF grid).
pub const MASS_NONCENTRALITY: f64 = 0.1;

/// A bound on the noncentrality that the cells' error bounds δᵢ of one hemisphere's masses pᵢ
/// (summed mass P̂, summed bound D) can add to the statistic of `samples` = n samples:
/// 2n F [Σ_large δᵢ²/(pᵢ − δᵢ) + S²/max(P − S, m)], F = ((P̂ − D)/(P̂ − 2D))².
///
/// Derivation. The true masses are qᵢ = pᵢ − εᵢ, |εᵢ| ≤ δᵢ, Q = Σqᵢ, E = Σεᵢ; the chi-square
/// expects the N_b ≈ nQ binned samples in proportion to pᵢ/P̂ (failed samples are not binned),
/// so the proportions are off by eᵢ = (Q εᵢ − qᵢ E)/(Q (Q + E)) and the noncentrality is
/// N_b Σ eᵢ² Q/qᵢ = N_b [Q Σ εᵢ²/qᵢ − E²]/(Q + E)² ≤ n Σ εᵢ²/qᵢ · (Q/(Q − |E|))²: the
/// renormalization by the estimated total only takes away (the −E²), and Q/(Q − |E|) ≤ √F
/// for Q ≥ P̂ − D. Per bin, Σ εᵢ²/qᵢ is at most Σ δᵢ²/(pᵢ − δᵢ) (qᵢ ≥ pᵢ − δᵢ) over the cells
/// kept apart; the cells whose mass may expect fewer than [`MIN_EXPECTED`] samples
/// (pᵢ − δᵢ < m = MIN_EXPECTED/n) are pooled, their summed mass P and bound S giving
/// S²/max(P − S, m) (a pooled bin that expects fewer is added to one that does). The factor 2
/// covers (a + b)² ≤ 2(a² + b²) for that addition; bins that span both hemispheres are
/// covered by (a + b)²/(A + B) ≤ a²/A + b²/B, so the hemispheres' bounds add. F is infinite
/// (no bound) while D ≥ P̂/2. (The bound before 2026-12-05, 3n[… + D²], counted the
/// renormalization as adding D²; asking D ≤ 1.3·10⁻⁴ at n = 10⁶ cost a transmitting
/// BSDF's chi-square most of its evaluations.)
pub fn mass_noncentrality(e: &Expected, samples: u64) -> f64 {
    noncentrality_of(&[noncentrality_parts(e, samples)], samples)
}

/// [`mass_noncentrality`] of both hemispheres together: their brackets add, and F is the
/// whole sphere's (the renormalization is by the summed mass of both).
pub fn sphere_noncentrality(upper: &Expected, lower: &Expected, samples: u64) -> f64 {
    noncentrality_of(
        &[
            noncentrality_parts(upper, samples),
            noncentrality_parts(lower, samples),
        ],
        samples,
    )
}

/// (The bracket of [`mass_noncentrality`], the summed mass P̂, the summed bound D) of one
/// hemisphere.
fn noncentrality_parts(e: &Expected, samples: u64) -> (f64, f64, f64) {
    let least = MIN_EXPECTED / samples.max(1) as f64;
    let (pooled_mass, pooled_bound) = pooled(e, least);
    let large: f64 = e
        .mass
        .iter()
        .zip(&e.cell_bound)
        .filter(|&(&p, &d)| p - d >= least)
        .map(|(&p, &d)| d * d / (p - d))
        .sum();
    let pooled = pooled_bound * pooled_bound / (pooled_mass - pooled_bound).max(least);
    (
        large + pooled,
        e.mass.iter().sum(),
        e.cell_bound.iter().sum(),
    )
}

/// The summed mass and bound of the cells that are pooled: those whose mass may expect fewer
/// than `least` (pᵢ − δᵢ < least).
fn pooled(e: &Expected, least: f64) -> (f64, f64) {
    e.mass
        .iter()
        .zip(&e.cell_bound)
        .filter(|&(&p, &d)| p - d < least)
        .fold((0.0, 0.0), |(m, b), (&p, &d)| (m + p, b + d))
}

/// 2n F Σ brackets, F from the summed masses and bounds of the parts.
fn noncentrality_of(parts: &[(f64, f64, f64)], samples: u64) -> f64 {
    let (bracket, summed, bound) = parts
        .iter()
        .fold((0.0, 0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1, a.2 + p.2));
    if bracket == 0.0 {
        return 0.0;
    }
    if !(summed > 2.0 * bound) {
        return f64::INFINITY;
    }
    let f = ((summed - bound) / (summed - 2.0 * bound)).powi(2);
    2.0 * samples.max(1) as f64 * f * bracket
}

/// What a unit of error bound in each cell adds to [`mass_noncentrality`] (its derivative in
/// that cell's bound δᵢ, without the common factor 2nF): δᵢ(2pᵢ − δᵢ)/(pᵢ − δᵢ)² for a cell
/// kept apart, 2S/max(P − S, m) for a pooled one. The cubature bisects first where error
/// costs the statistic most: a cell of small mass, or one whose bound is large against its
/// mass, before a large smooth one (step 2).
pub fn noncentrality_weights(e: &Expected, samples: u64) -> Vec<f64> {
    let n = samples.max(1) as f64;
    let least = MIN_EXPECTED / n;
    let (pooled_mass, pooled_bound) = pooled(e, least);
    let pooled = 2.0 * pooled_bound / (pooled_mass - pooled_bound).max(least);
    e.mass
        .iter()
        .zip(&e.cell_bound)
        .map(|(&p, &d)| {
            if p - d >= least {
                d * (2.0 * p - d) / ((p - d) * (p - d))
            } else {
                pooled
            }
        })
        .collect()
}
