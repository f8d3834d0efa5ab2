//! The chi-square's cell layout: rows at the quantiles of the density's own cos θ marginal and,
//! for an anisotropic or off-axis lobe, columns at the quantiles of its φ marginal, so that every
//! cell expects about the same count. On the equal-area grid a peaked lobe (GGX α =
//! 0.3) puts nearly every sample into the top one or two of 16 rows, and the test spreads its
//! degrees of freedom over cells that expect almost nothing.
//!
//! The marginals come from the density alone (never from the sampler under test): the
//! hemisphere is cut into thin strips — [`SUBSTRIPS`] per interval between the lobe's polar cuts
//! (log-spaced about every θ scale, [`Lobe::polar_cuts_with`]) for θ, per interval between its
//! azimuthal cuts for φ — whose masses are integrated by the same adaptive product cubature as
//! the expected counts, to [`LAYOUT_RELATIVE_TOLERANCE`] with [`LAYOUT_ABSOLUTE_TOLERANCE`]
//! shared among the strips (each mass with an error bound). The cumulative masses at the strip
//! edges are interpolated linearly in the angle and inverted at k/R (rows) and j/2R (columns).
//! The edges need not be exact quantiles: the expected count of every cell is then integrated
//! over the cell as placed, with its own error bound (`expected.rs`), so a rough layout costs
//! only balance, never validity. A layout that does not rise strictly (a density of no mass,
//! or a lobe so narrow that its quantiles round to z = 1) falls back to the equal-area rows or
//! columns; columns wider than π (a lobe concentrated in azimuth) fall back to equal columns.

use super::expected::in_angles;
use super::BatchPdf;
use crate::oracle::cubature::{
    gauss7_products, integrate_rectangles_batch, AccuracyGoal, BatchFn2,
};
use crate::oracle::hemisphere_grid::HemisphereGrid;
use crate::oracle::lobe::Lobe;
use crate::tolerance::{LAYOUT_ABSOLUTE_TOLERANCE, LAYOUT_RELATIVE_TOLERANCE};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Strips per interval between consecutive lobe cuts.
pub const SUBSTRIPS: usize = 8;

/// Lobes at least this anisotropic (widest / narrowest width, [`Lobe::anisotropy`]) get columns
/// at φ-quantiles; below it the φ marginal is within a few % of uniform and equal columns
/// (the finder's fast path) balance the cells as well.
pub const ANISOTROPIC: f64 = 1.5;

/// How the chi-square's cells are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// The equal-area grid: rows of equal cos θ, columns of equal φ (the layout before the lobe-quantile cells).
    EqualArea,
    /// Rows at the density's cos θ-marginal quantiles, columns at its φ-marginal quantiles for
    /// an anisotropic or off-axis lobe.
    #[default]
    FollowLobe,
    /// As [`Layout::FollowLobe`], the strips' masses by one G7 × G7 product rule each (49
    /// nodes, no error estimate: [`gauss7_products`]), without bisection: for densities with steps (a BSDF's pdf switches a lobe off where a half
    /// vector crosses the horizon or total internal reflection begins), where the adaptive
    /// rule bisects every strip a step crosses to its depth limit (measured: 7.5e7 pdf
    /// evaluations for the transmission hemisphere of a GGX 0.3 dielectric at θi = 1 rad,
    /// against 2.3e6 for its masses on the equal-area grid). The edges are rougher quantiles;
    /// the masses over them are integrated to their bound all the same.
    FollowSteppedLobe,
}

/// The grid of `resolution` rows (2 × `resolution` columns) for `layout`, with the pdf
/// evaluations spent placing it: for [`Layout::FollowLobe`], rows at the quantiles of `pdf`'s
/// cos θ marginal (strips cut at `lobe`'s polar cuts and at `theta_kinks`), columns at its φ
/// quantiles where the lobe is anisotropic or off-axis.
pub fn layout(
    pdf: &BatchPdf<'_>,
    lobe: &Lobe,
    resolution: usize,
    theta_kinks: &[f64],
    layout: Layout,
) -> (HemisphereGrid, u64) {
    let resolution = resolution.max(1);
    let equal = HemisphereGrid::new(resolution).expect("resolution ≥ 1");
    if layout == Layout::EqualArea || resolution == 1 {
        return (equal, 0);
    }
    let polar = lobe.polar_cuts_with(FRAC_PI_2, theta_kinks);
    let azimuth = lobe.azimuth_cuts();
    let f = in_angles(pdf);
    let mut evaluations = 0;
    // Rows: strips in θ, each over every azimuthal piece.
    let thetas = refine(&polar);
    let bisect = layout == Layout::FollowLobe;
    let (masses, spent) = strip_masses(&f, &thetas, &azimuth, false, bisect);
    evaluations += spent;
    // θ_k with mass (R − k)/R above it (θ < θ_k), k = 1 … R − 1; z_k = cos θ_k rises with k.
    let z = quantiles(&thetas, &masses, resolution).map(|theta| {
        let mut z = vec![0.0];
        z.extend(theta.iter().rev().map(|t| t.cos()));
        z.push(1.0);
        z
    });
    let phi = if lobe.anisotropy() >= ANISOTROPIC || lobe.mode.is_some() {
        let phis = refine(&azimuth);
        let (masses, spent) = strip_masses(&f, &phis, &polar, true, bisect);
        evaluations += spent;
        quantiles(&phis, &masses, 2 * resolution).map(|inner| {
            let mut phi = vec![0.0];
            phi.extend(inner);
            phi.push(TAU);
            phi
        })
    } else {
        None
    };
    // Each axis's quantiles where they make valid edges, else that axis's equal ones.
    let z = z.filter(|z| HemisphereGrid::with_edges(z.clone(), None).is_ok());
    let phi = phi.filter(|p| HemisphereGrid::with_edges(equal.z_edges(), Some(p.clone())).is_ok());
    let grid = match (z, phi) {
        (None, None) => equal,
        (z, phi) => HemisphereGrid::with_edges(z.unwrap_or_else(|| equal.z_edges()), phi)
            .expect("edges checked on each axis"),
    };
    (grid, evaluations)
}

/// The cuts with [`SUBSTRIPS`] − 1 equally spaced points added inside every interval.
fn refine(cuts: &[f64]) -> Vec<f64> {
    let mut out = vec![cuts[0]];
    for w in cuts.windows(2) {
        for k in 1..=SUBSTRIPS {
            let t = if k == SUBSTRIPS {
                w[1]
            } else {
                w[0] + (w[1] - w[0]) * k as f64 / SUBSTRIPS as f64
            };
            out.push(t);
        }
    }
    out.dedup();
    out
}

/// The masses of the strips between consecutive `edges` (θ edges over every φ piece between
/// `across`; with `azimuthal`, φ edges over every θ piece), with the evaluations spent; each
/// piece bisected to the layout tolerances with `bisect`, else one G7 × G7 product rule.
fn strip_masses(
    f: &BatchFn2<'_>,
    edges: &[f64],
    across: &[f64],
    azimuthal: bool,
    bisect: bool,
) -> (Vec<f64>, u64) {
    let pieces = (edges.len() - 1) * (across.len() - 1);
    let per_strip = across.len() - 1;
    if !bisect {
        let mut rectangles = Vec::with_capacity(pieces);
        for e in edges.windows(2) {
            for a in across.windows(2) {
                rectangles.push(if azimuthal {
                    ([e[0], e[1]], [a[0], a[1]])
                } else {
                    ([a[0], a[1]], [e[0], e[1]])
                });
            }
        }
        let masses = gauss7_products(f, &rectangles)
            .chunks(per_strip)
            .map(|c| c.iter().sum::<f64>().max(0.0))
            .collect();
        return (masses, 49 * pieces as u64);
    }
    let tolerance = AccuracyGoal {
        absolute: LAYOUT_ABSOLUTE_TOLERANCE / pieces as f64,
        relative: LAYOUT_RELATIVE_TOLERANCE,
    };
    let mut rectangles = Vec::with_capacity(pieces);
    for e in edges.windows(2) {
        for a in across.windows(2) {
            let (phi, theta) = if azimuthal {
                ([e[0], e[1]], [a[0], a[1]])
            } else {
                ([a[0], a[1]], [e[0], e[1]])
            };
            rectangles.push((phi, theta, tolerance));
        }
    }
    let estimates = integrate_rectangles_batch(f, &rectangles);
    let masses = estimates
        .chunks(per_strip)
        .map(|c| c.iter().map(|e| e.value).sum::<f64>().max(0.0))
        .collect();
    (masses, estimates.iter().map(|e| e.evaluations).sum())
}

/// The interior quantiles x_j (j = 1 … `parts` − 1, rising) at which the cumulative mass of the
/// strips between `edges` reaches j/`parts` of the total (linear within a strip), or `None`
/// if they do not rise strictly inside (edges[0], edges[last]) or the total is not positive.
fn quantiles(edges: &[f64], masses: &[f64], parts: usize) -> Option<Vec<f64>> {
    let total: f64 = masses.iter().sum();
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    let mut out = Vec::with_capacity(parts - 1);
    let (mut strip, mut below) = (0, 0.0);
    for j in 1..parts {
        let target = total * j as f64 / parts as f64;
        while strip + 1 < masses.len() && below + masses[strip] < target {
            below += masses[strip];
            strip += 1;
        }
        let m = masses[strip];
        let fraction = if m > 0.0 {
            ((target - below) / m).clamp(0.0, 1.0)
        } else {
            0.5
        };
        out.push(edges[strip] + fraction * (edges[strip + 1] - edges[strip]));
    }
    let (first, last) = (edges[0], edges[edges.len() - 1]);
    let rising = out.windows(2).all(|w| w[0] < w[1]);
    let inside = out.iter().all(|&x| x > first && x < last);
    (rising && inside).then_some(out)
}
