//! The expected masses of the chi-square test: the pdf integrated over every cell of the grid
//! by adaptive product cubature, cut where its lobe varies and at its polar kinks, with a
//! per-cell error bound.

use super::BatchPdf;
use crate::oracle::cubature::{
    integrate_rectangle, integrate_rectangles_batch_budgeted, AccuracyGoal, BudgetHit,
};
use crate::oracle::hemisphere_grid::HemisphereGrid;
use crate::oracle::lobe::{self, Lobe};
use crate::oracle::Estimate;
use crate::tolerance::{CELL_ABSOLUTE_TOLERANCE, CELL_RELATIVE_TOLERANCE};
use mfh_reference::geometry::Vec3;
use mfh_reference::trig::{sin_cos, sin_cos_block};
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;

/// The expected probability mass per cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Expected {
    /// Mass per cell (row-major, row 0 at the horizon).
    pub mass: Vec<f64>,
    /// The total mass (the pdf's integral over the hemisphere).
    pub total: f64,
    /// The sum of the per-cell error bounds of the cubature.
    pub error_bound: f64,
    /// The error bound of each cell (the order of `mass`).
    pub cell_bound: Vec<f64>,
    /// Pdf evaluations spent.
    pub evaluations: u64,
    /// Where the cubature's rectangle budget ([`crate::oracle::cubature::MAX_RECTANGLES`])
    /// stopped its refinement: the bound it reached against the target asked.
    pub budget_hit: Option<BudgetHit>,
}

impl Expected {
    /// The expected masses of the cells' estimates, in cell order, with their summed error
    /// bound and evaluations.
    fn of_cells(estimates: &[Estimate]) -> Self {
        Expected {
            mass: estimates.iter().map(|e| e.value).collect(),
            total: estimates.iter().map(|e| e.value).sum(),
            error_bound: estimates.iter().map(|e| e.error_bound).sum(),
            cell_bound: estimates.iter().map(|e| e.error_bound).collect(),
            evaluations: estimates.iter().map(|e| e.evaluations).sum(),
            budget_hit: None,
        }
    }
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
    let deadline = crate::deadline::current();
    let estimates: Vec<_> = (0..grid.cells())
        .into_par_iter()
        .map(|i| {
            crate::deadline::check(deadline);
            let (thetas, phis, pieces) = cell_pieces(&grid, i, &polar, &azimuth);
            let tolerance = AccuracyGoal {
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

/// The pieces of cell `i` between the lobe's cuts: the polar and azimuthal breakpoints inside
/// the cell (θ decreases with z: the top of the row, z₁, is the smaller θ) and their count.
fn cell_pieces(
    grid: &HemisphereGrid,
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
/// ([`integrate_rectangles_batch`](crate::oracle::cubature::integrate_rectangles_batch), the density evaluated in parallel chunks of 16 384 points),
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
        let (thetas, phis, pieces) = cell_pieces(&grid, i, &polar, &azimuth);
        let tolerance = AccuracyGoal {
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
    let f = in_angles(pdf);
    let (pieces, budget_hit) = integrate_rectangles_batch_budgeted(&f, &rectangles);
    let estimates = sum_per_cell(&pieces, &per_cell);
    Expected {
        budget_hit,
        ..Expected::of_cells(&estimates)
    }
}

/// A batch density over directions as a batch integrand over (φ, θ): pdf(direction) · sin θ,
/// evaluated in parallel chunks of 16 384 points.
pub(super) fn in_angles<'p>(pdf: &'p BatchPdf<'p>) -> impl Fn(&[[f64; 2]], &mut [f64]) + 'p {
    move |pt: &[[f64; 2]], out: &mut [f64]| {
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
    }
}

/// [`expected_mass_in_batch`] by globally adaptive cubature
/// ([`crate::oracle::cubature::global`]): the cells' pieces (cut as there) compete for one
/// summed error `target` within `budget` evaluations — for densities with steps (a BSDF's),
/// where the locally adaptive form bisects every piece a step crosses to its depth limit.
/// Returns the masses and whether the target was met (else the bound is what the budget bought).
pub fn expected_mass_global(
    pdf: &BatchPdf<'_>,
    grid: HemisphereGrid,
    lobe: &Lobe,
    target: f64,
    budget: u64,
) -> (Expected, bool) {
    expected_mass_global_until(pdf, grid, lobe, (target, budget), &[], &|_| false, &|_| {
        None
    })
}

/// [`expected_mass_global`] that also stops, converged, once the masses so far satisfy
/// `enough` (a caller's criterion on the cells' estimates), bisecting first where `weights`
/// (per cell: what a unit of error bound there adds to that criterion) says error costs most
/// (see [`crate::oracle::cubature::global::integrate_global_weighted`]). The polar angles
/// `kinks` are cut exactly ([`Lobe::polar_cuts_with`]): where the density may jump for every
/// azimuth, a piece edge there keeps the jump out of the pieces' rules, whose nodes stop
/// 0.4 % short of a piece's edge and would not see a step in that strip (nor its error).
pub fn expected_mass_global_until(
    pdf: &BatchPdf<'_>,
    grid: HemisphereGrid,
    lobe: &Lobe,
    (target, budget): (f64, u64),
    kinks: &[f64],
    enough: &dyn Fn(&Expected) -> bool,
    weights: &dyn Fn(&Expected) -> Option<Vec<f64>>,
) -> (Expected, bool) {
    let polar = lobe.polar_cuts_with(FRAC_PI_2, kinks);
    let azimuth = lobe.azimuth_cuts();
    let mut rectangles = Vec::new();
    let mut per_cell = Vec::with_capacity(grid.cells());
    for i in 0..grid.cells() {
        let (thetas, phis, pieces) = cell_pieces(&grid, i, &polar, &azimuth);
        for p in phis.windows(2) {
            for t in thetas.windows(2) {
                rectangles.push(([p[0], p[1]], [t[0], t[1]]));
            }
        }
        per_cell.push(pieces);
    }
    let f = in_angles(pdf);
    let cells = |pieces: &[Estimate]| sum_per_cell(pieces, &per_cell);
    let cell_of: Vec<usize> = per_cell
        .iter()
        .enumerate()
        .flat_map(|(i, &n)| std::iter::repeat_n(i, n))
        .collect();
    let result = crate::oracle::cubature::global::integrate_global_weighted(
        &f,
        &rectangles,
        target,
        budget,
        &|pieces| enough(&Expected::of_cells(&cells(pieces))),
        &|pieces| {
            let w = weights(&Expected::of_cells(&cells(pieces)))?;
            Some(
                cell_of
                    .iter()
                    .map(|&c| w.get(c).copied().unwrap_or(0.0))
                    .collect(),
            )
        },
    );
    let mut e = Expected::of_cells(&cells(&result.estimates));
    e.evaluations = result.evaluations;
    (e, result.converged)
}

/// The estimates of the cells from those of their pieces (`per_cell[i]` consecutive pieces a
/// cell, in cell order): values, bounds and evaluations summed.
fn sum_per_cell(pieces: &[Estimate], per_cell: &[usize]) -> Vec<Estimate> {
    let mut at = 0;
    per_cell
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
        .collect()
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
