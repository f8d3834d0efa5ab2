//! The finite-difference densities of a sampling map at many points in one batch: first by one
//! stencil ([`densities`], steps h, h/2, h/4); where that cannot judge a point, or judges it
//! failing, the point is measured again on a ladder of steps h·2ʲ, j from [`FINEST`] up to [`TOP`] in u, and
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
    let steps: Vec<f64> = levels.iter().map(|l| l.1).collect();
    stencils(centres, &steps, map)
        .into_iter()
        .map(|(c, at)| {
            // The noise of the finest rungs (FINEST + NOISE_RUNGS at the most).
            let fine = levels
                .iter()
                .filter(|l| l.0 <= FINEST + NOISE_RUNGS)
                .count();
            let rungs = Rungs::new(&steps, &at, c?, eps, fine);
            best(&rungs, unresolved)
        })
        .collect()
}

/// The directions of one point: its centre (None where the map fails there) and, at each
/// step, the four offsets (+u₁, −u₁, +u₂, −u₂), None where the stencil leaves [0, 1), the map
/// fails, or a direction is not on the centre's side of the surface.
type PointStencils = (Option<Vec3>, Vec<Option<[Vec3; 4]>>);

/// The stencils of every point of `centres` at `steps`, in one call of `map`.
fn stencils(centres: &[[f64; 3]], steps: &[f64], map: &mut BatchMap<'_>) -> Vec<PointStencils> {
    // Per point: the index of its centre in the batch and, per step, of its first offset.
    let mut u = Vec::new();
    let mut at: Vec<(usize, Vec<Option<usize>>)> = Vec::with_capacity(centres.len());
    for c in centres {
        let centre = u.len();
        u.push(*c);
        let inside = |d: f64| [c[1], c[2]].iter().all(|x| *x - d >= 0.0 && *x + d < 1.0);
        let mut first = Vec::with_capacity(steps.len());
        for &d in steps {
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
            let Some(c) = w[*centre] else {
                return (None, vec![None; first.len()]);
            };
            let same_side = |d: &Vec3| (d[2] > 0.0) == (c[2] > 0.0);
            let stencils = first
                .iter()
                .map(|f| {
                    let s: Option<Vec<Vec3>> = w[(*f)?..(*f)? + 4].iter().copied().collect();
                    let s = s.filter(|s| s.iter().all(same_side))?;
                    Some([s[0], s[1], s[2], s[3]])
                })
                .collect();
            (Some(c), stencils)
        })
        .collect()
}

/// The densities of one point's stencils at ascending `steps`, with the rounding of its
/// directions: the largest fourth difference (offsets −2d, −d, 0, d, 2d along each axis and
/// component) of the pairs of consecutive steps among the first `noisy`, over
/// [`NOISE_DIVISOR`], at least [`DIRECTION_ULPS`] ε.
struct Rungs<'a> {
    steps: &'a [f64],
    /// |a|, |b| and |a × b| of the columns at each step (the density is 1/|a × b|).
    lengths: Vec<Option<(f64, f64, f64)>>,
    /// The rounding of each direction component.
    e: f64,
}

impl<'a> Rungs<'a> {
    fn new(
        steps: &'a [f64],
        stencils: &[Option<[Vec3; 4]>],
        c: Vec3,
        eps: f64,
        noisy: usize,
    ) -> Self {
        let mut noise: f64 = 0.0;
        for k in 1..noisy.min(stencils.len()) {
            let (Some(big), Some(small)) = (stencils[k], stencils[k - 1]) else {
                continue;
            };
            for axis in [0, 2] {
                for i in 0..3 {
                    let f = big[axis][i] - 4.0 * small[axis][i] + 6.0 * c[i]
                        - 4.0 * small[axis + 1][i]
                        + big[axis + 1][i];
                    noise = noise.max(f.abs());
                }
            }
        }
        let columns = |s: &[Vec3; 4], d: f64| {
            let col = |p: Vec3, q: Vec3| [0, 1, 2].map(|i| (p[i] - q[i]) / (2.0 * d));
            (col(s[0], s[1]), col(s[2], s[3]))
        };
        Rungs {
            steps,
            lengths: stencils
                .iter()
                .zip(steps)
                .map(|(s, &d)| Some(column_lengths(columns(s.as_ref()?, d))))
                .collect(),
            e: (DIRECTION_ULPS * eps).max(noise / NOISE_DIVISOR),
        }
    }

    /// The Richardson triple whose coarsest step is `steps[k]` (with k − 1 and k − 2).
    fn triple(&self, k: usize) -> Option<Density> {
        let at = self.lengths[k]?;
        Some(Density {
            coarse: 1.0 / at.2,
            fine: 1.0 / self.lengths[k.checked_sub(1)?]?.2,
            finest: 1.0 / self.lengths[k.checked_sub(2)?]?.2,
            rounding: rounding_bound(self.e, self.steps[k], at),
            finer: 0.0,
        })
    }
}

/// The directions at `centres` (u₀ fixed, u₁ and u₂ the coordinates of the map) and, where the
/// map is defined on the whole stencil and stays on the centre's side of the surface there,
/// its density by central differences with steps `h`, h/2 and h/4 (the single stencil), for a
/// map computed in precision `eps` (its ε), with the bound of its rounding from the noise the
/// stencil shows ([`NOISE_DIVISOR`]) or [`DIRECTION_ULPS`], whichever is larger. `map` is one
/// batch call: `out[k]` the direction of `u[k]`, None where the map fails. A point this
/// stencil cannot judge, or judges failing, is measured again on the ladder
/// ([`measure_again`]).
pub fn densities(
    centres: &[[f64; 3]],
    h: f64,
    eps: f64,
    map: &mut BatchMap<'_>,
) -> Vec<(Option<Vec3>, Option<Density>)> {
    let steps = [h / 4.0, h / 2.0, h];
    stencils(centres, &steps, map)
        .into_iter()
        .map(|(c, at)| {
            let density = c.and_then(|c| Rungs::new(&steps, &at, c, eps, 3).triple(2));
            (c, density)
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

/// The best rung of one point: among the triples with both neighbours, resolved and converging
/// as d⁴ (their differences in a ratio within [8, 32] of the asymptotic 16) or within their
/// rounding, the one of smallest allowance.
fn best(rungs: &Rungs<'_>, unresolved: f64) -> Option<Density> {
    (3..rungs.steps.len())
        .filter_map(|k| {
            let mut t = rungs.triple(k)?;
            let below = rungs.triple(k - 1)?;
            let v = t.value();
            t.finer = ((v - below.value()) / v).abs();
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
        let base = densities(&c, 1e-4, f64::EPSILON, &mut map)[0].1.unwrap();
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

    #[test]
    fn the_densities_of_a_linear_map_are_exact() {
        // u ↦ (u₁, 2u₂, 1) (not unit, but a map): density 1/2 everywhere.
        let c = [[0.5, 0.3, 0.6]];
        let d = densities(&c, 1e-3, f64::EPSILON, &mut |u, out| {
            for (o, u) in out.iter_mut().zip(u) {
                *o = Some([u[1], 2.0 * u[2], 1.0]);
            }
        });
        let density = d[0].1.unwrap();
        assert!((density.value() - 0.5).abs() < 1e-9, "{density:?}");
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
