//! The step ladder of a finite-difference density: where the Jacobian checks' one stencil
//! (`regime::densities`, steps h, h/2, h/4) cannot judge a point, or judges it failing, the
//! point is measured again on a ladder of steps h·2ʲ, j from [`FINEST`] up to [`TOP`] in u, and
//! judged at the rung whose error bound is smallest.
//!
//! Why: the error of a central-difference density is truncation, which grows with the step,
//! plus rounding, which grows as its inverse; one fixed step is wrong for some maps. The
//! relative truncation of a sampling map depends on how fast the map bends in u, not on its
//! roughness, while its rounding grows as 1/α: at α 1e-6 × 1e-4 and cos θi 0.01 the densities
//! at h = 1e-4 are off by 8e-6 (rounding the fourth differences at that step underestimate
//! 2×), at h = 4e-3 by 3e-8. A map that is defined on a sliver of u only (GGX α 1e4 refracting
//! into η 0.1) needs the finer rungs instead.
//!
//! Each rung j is the Richardson extrapolation of the steps h·2ʲ, h·2ʲ⁻¹, h·2ʲ⁻², the same
//! [`Density`] as the single stencil's. Its error bound is the larger difference of its value
//! from those of the rungs on either side (`Density::extrapolation`, `Density::finer`), so
//! that a rung whose two neighbours happen to agree with it by chance on one side only is not
//! trusted, plus the rounding bound from the map's noise. The noise is the largest fourth
//! difference of the finest rungs ([`NOISE_RUNGS`]: the map's own fourth derivative contributes
//! nothing measurable there), which bounds the rounding of every rung: the directions the rungs share
//! carry the same rounding whatever the step that reads them.
//!
//! What a rung cannot do is hide a wrong density: a sampler whose density differs from its pdf
//! over a region of u wider than the rung's stencil shows the same difference at every rung; one
//! whose defect is narrower than the stencil makes the rung's differences converge other than as
//! h² (not `Density::resolved`) or its neighbours disagree, which widens its bound.

use crate::check::regime::{
    column_lengths, rounding_bound, BatchMap, Density, DIRECTION_ULPS, NOISE_DIVISOR,
};
use mfh_reference::geometry::Vec3;

/// The finest rung's steps, relative to h: h/64 (f64: 1.6e-6, where the map's rounding shows
/// alone; the sliver of u that GGX α 1e4 refracting into η 0.1 transmits through is ~1e-4 wide).
pub const FINEST: i32 = -6;

/// The steps whose fourth differences measure the map's noise: h·2ʲ for j up to FINEST + 3
/// (f64: 1.6e-6 … 1.25e-5, so 18 fourth differences of three pairs of steps). At those steps a
/// map smooth at the scale of u contributes nothing measurable (w⁗·d⁴ ≈ 1e-20), and a kink
/// or a branch farther than 2.5e-5 from the point none at all: the coarser steps' fourth
/// differences would count a kink within them as noise and bound every rung's rounding by it.
pub const NOISE_RUNGS: i32 = 3;

/// The largest step in u: 0.02 (f64: h·2⁷ = 0.0128; f32: 4e-3·2² = 0.016). A rung whose
/// stencil would leave [0, 1) at a point is not measured there.
pub const TOP: f64 = 0.02;

/// The steps h·2ʲ of the ladder from [`FINEST`] to the largest not above [`TOP`].
fn levels(h: f64) -> Vec<(i32, f64)> {
    (FINEST..)
        .map(|j| (j, h * 2f64.powi(j)))
        .take_while(|(_, d)| *d <= TOP)
        .collect()
}

/// The four stencil offsets of one step along u₁ and u₂: +u₁, −u₁, +u₂, −u₂.
const AXES: [(f64, f64); 4] = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)];

/// The best rung of the ladder at each of `centres` (u₀, u₁, u₂), base step `h`, for a map
/// computed in precision `eps`: the resolved rung (`Density::resolved` at `unresolved`) of
/// smallest `Density::allowance`, or None where no rung is resolved (the map not smooth at any
/// step, or undefined around the point). One call of `map` for all the points.
pub fn ladder(
    centres: &[[f64; 3]],
    h: f64,
    eps: f64,
    unresolved: f64,
    map: &mut BatchMap<'_>,
) -> Vec<Option<Density>> {
    let levels = levels(h);
    // Per point: the index of its centre in the batch and, per level, of its first offset
    // (None where the stencil leaves [0, 1)).
    let mut u = Vec::new();
    let mut at: Vec<(usize, Vec<Option<usize>>)> = Vec::with_capacity(centres.len());
    for c in centres {
        let centre = u.len();
        u.push(*c);
        let inside = |d: f64| [c[1], c[2]].iter().all(|x| *x - d >= 0.0 && *x + d < 1.0);
        let mut first = Vec::with_capacity(levels.len());
        for &(_, d) in &levels {
            if inside(d) {
                first.push(Some(u.len()));
                u.extend(AXES.map(|(a, b)| [c[0], c[1] + a * d, c[2] + b * d]));
            } else {
                first.push(None);
            }
        }
        at.push((centre, first));
    }
    let mut w = vec![None; u.len()];
    map(&u, &mut w);
    at.iter()
        .map(|(centre, first)| {
            let c = w[*centre]?;
            let same_side = |d: &Vec3| (d[2] > 0.0) == (c[2] > 0.0);
            let stencils: Vec<Option<[Vec3; 4]>> = first
                .iter()
                .map(|f| {
                    let s: Option<Vec<Vec3>> = w[(*f)?..(*f)? + 4].iter().copied().collect();
                    let s = s.filter(|s| s.iter().all(same_side))?;
                    Some([s[0], s[1], s[2], s[3]])
                })
                .collect();
            best(&levels, &stencils, c, eps, unresolved)
        })
        .collect()
}

/// Whether a point judged by the single stencil — (error, excess over its allowance,
/// allowance), None where it could not be judged — is settled at `tolerance`: judged, passing,
/// and allowed no more than the tolerance. The others are measured on the ladder.
pub fn settled(judged: Option<(f64, f64, f64)>, tolerance: f64) -> bool {
    judged.is_some_and(|(_, excess, allowance)| excess <= tolerance && allowance <= tolerance)
}

/// Measures the points `which` of `d` (densities at `centres` by the single stencil) again on
/// the ladder, each replaced by its best rung, or by None (unresolved) where no rung is
/// resolved.
pub fn measure_again(
    d: &mut [(Option<Vec3>, Option<Density>)],
    centres: &[[f64; 3]],
    which: &[usize],
    (h, eps, unresolved): (f64, f64, f64),
    map: &mut BatchMap<'_>,
) {
    if which.is_empty() {
        return;
    }
    let retry: Vec<[f64; 3]> = which.iter().map(|&k| centres[k]).collect();
    for (&k, best) in which.iter().zip(ladder(&retry, h, eps, unresolved, map)) {
        d[k].1 = best;
    }
}

/// The best rung of one point from its stencils (`stencils[k]` at step `levels[k]`).
fn best(
    levels: &[(i32, f64)],
    stencils: &[Option<[Vec3; 4]>],
    c: Vec3,
    eps: f64,
    unresolved: f64,
) -> Option<Density> {
    // The noise: the largest fourth difference of consecutive steps up to FINEST + NOISE_RUNGS,
    // along each axis and component (offsets −2d, −d, 0, d, 2d).
    let mut noise: f64 = 0.0;
    for k in 1..levels.len() {
        let (Some(big), Some(small), true) = (
            stencils[k],
            stencils[k - 1],
            levels[k].0 <= FINEST + NOISE_RUNGS,
        ) else {
            continue;
        };
        for axis in [0, 2] {
            for i in 0..3 {
                let f = big[axis][i] - 4.0 * small[axis][i] + 6.0 * c[i] - 4.0 * small[axis + 1][i]
                    + big[axis + 1][i];
                noise = noise.max(f.abs());
            }
        }
    }
    let e = (DIRECTION_ULPS * eps).max(noise / NOISE_DIVISOR);
    let columns = |s: &[Vec3; 4], d: f64| {
        let col = |p: Vec3, q: Vec3| [0, 1, 2].map(|i| (p[i] - q[i]) / (2.0 * d));
        (col(s[0], s[1]), col(s[2], s[3]))
    };
    // |a|, |b| and |a × b| at each step: the density is 1/|a × b|.
    let lengths: Vec<Option<(f64, f64, f64)>> = stencils
        .iter()
        .zip(levels)
        .map(|(s, &(_, d))| Some(column_lengths(columns(s.as_ref()?, d))))
        .collect();
    let triple = |k: usize| -> Option<Density> {
        let at = lengths[k]?;
        Some(Density {
            coarse: 1.0 / at.2,
            fine: 1.0 / lengths[k.checked_sub(1)?]?.2,
            finest: 1.0 / lengths[k.checked_sub(2)?]?.2,
            rounding: rounding_bound(e, levels[k].1, at),
            finer: 0.0,
        })
    };
    (3..levels.len())
        .filter_map(|k| {
            let mut t = triple(k)?;
            let below = triple(k - 1)?;
            let v = t.value();
            t.finer = ((v - below.value()) / v).abs();
            // The rungs converge as d⁴ (their differences in a ratio within [8, 32] of the
            // asymptotic 16), or differ by no more than their rounding.
            let coarser = t.extrapolation();
            let ratio = coarser / t.finer;
            let converging =
                (8.0..=32.0).contains(&ratio) || coarser.max(t.finer) <= 3.0 * t.rounding;
            (v.is_finite() && v > 0.0 && converging && t.resolved(unresolved)).then_some(t)
        })
        .min_by(|a, b| a.allowance().total_cmp(&b.allowance()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::regime;

    /// A map of density 50 whose first component carries a white rounding-like error of up
    /// to 1e-12 (a pseudo-random function of u, thousands of ulps, as a map that cancels
    /// shows): the single stencil at h = 1e-4 is allowed more than the tolerance of 1e-6
    /// there, the ladder finds a coarser rung whose bound is below it and holds.
    #[test]
    fn the_ladder_judges_at_the_rung_whose_bound_is_smallest() {
        let noise = |u: &[f64; 3]| {
            let x = ((u[1] * 12_345.678 + u[2] * 98_765.432).sin() * 43_758.545).fract();
            1e-12 * x
        };
        let mut map = |u: &[[f64; 3]], out: &mut [Option<Vec3>]| {
            for (o, u) in out.iter_mut().zip(u) {
                *o = Some([0.1 * u[1] + noise(u), 0.2 * u[2], 1.0]);
            }
        };
        let c = [[0.5, 0.31, 0.62]];
        let exact = 1.0 / 0.02;
        let base = regime::densities(&c, 1e-4, f64::EPSILON, &mut map)[0]
            .1
            .unwrap();
        let d = ladder(&c, 1e-4, f64::EPSILON, 1e-3, &mut map)[0].unwrap();
        let error = ((d.value() - exact) / exact).abs();
        eprintln!(
            "single stencil: allowance {:.2e}; ladder: error {error:.2e}, allowance {:.2e}",
            base.allowance(),
            d.allowance()
        );
        assert!(base.allowance() > 1e-6, "{base:?}");
        assert!(
            error <= d.allowance() && d.allowance() < 1e-6,
            "{d:?} {error}"
        );
    }

    /// A map with a kink 3e-5 from the point along u₁: the rungs whose stencil reaches across
    /// it are not resolved, a finer one is, and gives the density on the point's side.
    #[test]
    fn a_kink_near_the_point_is_measured_from_its_side() {
        let mut map = |u: &[[f64; 3]], out: &mut [Option<Vec3>]| {
            for (o, u) in out.iter_mut().zip(u) {
                let x = u[1] - 0.5;
                *o = Some([x + 0.3 * (x - 3e-5).abs(), u[2], 1.0]);
            }
        };
        let d = ladder(&[[0.5, 0.5, 0.4]], 1e-4, f64::EPSILON, 1e-3, &mut map)[0].unwrap();
        let exact = 1.0 / 0.7;
        let error = ((d.value() - exact) / exact).abs();
        assert!(
            error <= d.allowance() && d.allowance() < 1e-8,
            "{d:?} {error}"
        );
    }
}
