//! Globally adaptive cubature of many rectangles at once, for integrands with steps (a BSDF's
//! pdf switches a lobe off where a half vector crosses the horizon, or at total internal
//! reflection): the locally adaptive form ([`super::integrate_rectangles_batch`]) gives each
//! quadrant a quarter of its parent's tolerance, and along a step the error of a quadrant is
//! also a quarter of its parent's, so it bisects every piece the step crosses down to
//! [`super::MAX_DEPTH`] — millions of evaluations per cell. Here the pieces compete for one
//! error target and one evaluation budget:
//!
//! 1. Every rectangle is integrated by the G7/K15 product rule (in batches).
//! 2. While the summed error bound exceeds `target` and evaluations remain in `budget`, the
//!    pieces whose error exceeds the mean share target / pieces are candidates; a round
//!    bisects into quadrants the worst of them (by error, or by error times the caller's
//!    weight of its rectangle: [`integrate_global_weighted`]) that carry [`BULK`] of their
//!    summed priority, as many as the remaining budget allows (ties go to the earlier piece:
//!    the result does not depend on scheduling), and evaluates the quadrants in one batch.
//!    A piece at [`GLOBAL_MAX_DEPTH`] is not bisected again.
//! 3. Each rectangle's estimate is the sum of its pieces, with the sum of their error
//!    estimates as its bound — honest whether the target was met or the budget ran out.
//!
//! Along a step each round halves the error of the pieces the step crosses. Bisecting every
//! candidate each round (before 2026-12-05) quadrupled the pieces at once and overshot a
//! caller's own criterion by a round; the bulk rounds stop closer to it.

use super::{evaluate, BatchFn2, Estimate, Node};

/// The share of the refinable pieces' summed error that one round bisects (the worst pieces
/// first): Dörfler's bulk criterion of adaptive finite elements. Bisecting every piece above
/// the mean share in each round (as before) overshot a caller's criterion (`enough`) by
/// rounds that quadrupled the pieces at once.
pub const BULK: f64 = 0.5;

/// The deepest bisection of a piece (its side is 2⁻¹⁶ of the rectangle's).
pub const GLOBAL_MAX_DEPTH: u32 = 16;

/// The result of [`integrate_global`]: per rectangle, and whether the target was met.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalResult {
    /// The estimate of each rectangle (in input order).
    pub estimates: Vec<Estimate>,
    /// Whether the summed error bound met the target (false: the budget or the depth limit
    /// stopped the refinement first).
    pub converged: bool,
    /// Evaluations spent in all.
    pub evaluations: u64,
}

fn node(x: [f64; 2], y: [f64; 2], depth: u32) -> Node {
    Node {
        x,
        y,
        tolerance: 0.0,
        depth,
        value: 0.0,
        error: 0.0,
        children: None,
    }
}

/// Integrates `f` over every rectangle `(x, y)` until the summed error bound is at most
/// `target` or `budget` evaluations are spent (steps 1–3 of the module documentation).
pub fn integrate_global(
    f: &BatchFn2<'_>,
    rectangles: &[([f64; 2], [f64; 2])],
    target: f64,
    budget: u64,
) -> GlobalResult {
    integrate_global_until(f, rectangles, target, budget, &|_| false)
}

/// [`integrate_global`] that also stops, converged, after the first round whose per-rectangle
/// estimates satisfy `enough` (a caller's own accuracy criterion, checked before each round;
/// `target` stays the floor below which no piece is refined).
pub fn integrate_global_until(
    f: &BatchFn2<'_>,
    rectangles: &[([f64; 2], [f64; 2])],
    target: f64,
    budget: u64,
    enough: &dyn Fn(&[Estimate]) -> bool,
) -> GlobalResult {
    integrate_global_weighted(f, rectangles, target, budget, enough, &|_| None)
}

/// [`integrate_global_until`] whose rounds bisect first the pieces whose error costs the
/// caller most: `weights` answers, from the per-rectangle estimates so far, what a unit of
/// error bound in each rectangle adds to the caller's criterion (its derivative; `None`: the
/// same everywhere), and a piece's priority is its error times its rectangle's weight. The
/// bulk marking ([`BULK`]) then takes the pieces that carry half of the summed priority. The
/// bounds are the same honest sums whatever the order; only where the evaluations go changes.
pub fn integrate_global_weighted(
    f: &BatchFn2<'_>,
    rectangles: &[([f64; 2], [f64; 2])],
    target: f64,
    budget: u64,
    enough: &dyn Fn(&[Estimate]) -> bool,
    weights: &dyn Fn(&[Estimate]) -> Option<Vec<f64>>,
) -> GlobalResult {
    let mut owners: Vec<usize> = (0..rectangles.len()).collect();
    let mut leaves: Vec<Node> = rectangles.iter().map(|&(x, y)| node(x, y, 0)).collect();
    evaluate(f, &mut leaves);
    let mut evaluations = 225 * leaves.len() as u64;
    let mut converged;
    loop {
        crate::deadline::checkpoint();
        let total: f64 = leaves.iter().map(|n| n.error).sum();
        let so_far = per_rectangle(rectangles.len(), &leaves, &owners);
        converged = total <= target || enough(&so_far);
        if converged || evaluations >= budget || !total.is_finite() {
            break;
        }
        let share = target / leaves.len() as f64;
        let mut split: Vec<usize> = (0..leaves.len())
            .filter(|&i| leaves[i].error > share && leaves[i].depth < GLOBAL_MAX_DEPTH)
            .collect();
        if split.is_empty() {
            break;
        }
        let priority = priorities(&leaves, &owners, &split, weights(&so_far));
        split.sort_by(|&a, &b| priority[b].total_cmp(&priority[a]).then(a.cmp(&b)));
        // Bulk marking: the first pieces that carry BULK of the candidates' priority.
        let candidates: f64 = split.iter().map(|&i| priority[i]).sum();
        let (mut carried, mut marked) = (0.0, 0);
        for &i in &split {
            if carried >= BULK * candidates {
                break;
            }
            carried += priority[i];
            marked += 1;
        }
        let affordable = ((budget - evaluations) / (4 * 225)).max(1) as usize;
        split.truncate(marked.clamp(1, affordable));
        split.sort_unstable();
        let mut children = Vec::with_capacity(4 * split.len());
        let mut child_owners = Vec::with_capacity(4 * split.len());
        for &i in &split {
            let n = &leaves[i];
            let (x, y) = (n.x, n.y);
            let (xm, ym) = (0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1]));
            for xs in [[x[0], xm], [xm, x[1]]] {
                for ys in [[y[0], ym], [ym, y[1]]] {
                    children.push(node(xs, ys, n.depth + 1));
                    child_owners.push(owners[i]);
                }
            }
        }
        evaluate(f, &mut children);
        evaluations += 225 * children.len() as u64;
        // The split leaves give way to their children (kept leaves first, then children).
        let mut keep = vec![true; leaves.len()];
        for &i in &split {
            keep[i] = false;
        }
        let (mut next, mut next_owners) = (Vec::new(), Vec::new());
        for (i, n) in leaves.into_iter().enumerate() {
            if keep[i] {
                next.push(n);
                next_owners.push(owners[i]);
            }
        }
        next.extend(children);
        next_owners.extend(child_owners);
        leaves = next;
        owners = next_owners;
    }
    let mut estimates = per_rectangle(rectangles.len(), &leaves, &owners);
    let mut count = vec![0u64; rectangles.len()];
    for &o in &owners {
        count[o] += 1;
    }
    // Evaluations are shared out among the rectangles by their final pieces (the interior
    // nodes of the trees are not kept): the total is exact, the split an approximation.
    let pieces: u64 = count.iter().sum::<u64>().max(1);
    for (e, c) in estimates.iter_mut().zip(&count) {
        e.evaluations = evaluations * c / pieces;
    }
    GlobalResult {
        estimates,
        converged,
        evaluations,
    }
}

/// Each leaf's priority (its error, times its rectangle's weight when the weights are given,
/// finite, non-negative and not all zero over the candidates `split`; else its error alone).
fn priorities(
    leaves: &[Node],
    owners: &[usize],
    split: &[usize],
    weights: Option<Vec<f64>>,
) -> Vec<f64> {
    let raw: Vec<f64> = leaves.iter().map(|n| n.error).collect();
    let Some(w) = weights.filter(|w| owners.iter().all(|&o| o < w.len())) else {
        return raw;
    };
    let weighted: Vec<f64> = leaves
        .iter()
        .zip(owners)
        .map(|(n, &o)| n.error * w[o])
        .collect();
    let sum: f64 = split.iter().map(|&i| weighted[i]).sum();
    let sane = split.iter().all(|&i| weighted[i] >= 0.0) && sum.is_finite() && sum > 0.0;
    if sane {
        weighted
    } else {
        raw
    }
}

/// The sums of the leaves' values and error estimates per rectangle (evaluations 0).
fn per_rectangle(rectangles: usize, leaves: &[Node], owners: &[usize]) -> Vec<Estimate> {
    let mut estimates = vec![Estimate::default(); rectangles];
    for (n, &o) in leaves.iter().zip(owners) {
        estimates[o].value += n.value;
        estimates[o].error_bound += n.error;
    }
    estimates
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_along_a_curve_meets_its_target_within_a_budget() {
        // The indicator of the disc x² + y² < 0.5 on [0, 1]²: area π/8.
        let f = |p: &[[f64; 2]], out: &mut [f64]| {
            for (o, &[x, y]) in out.iter_mut().zip(p) {
                *o = f64::from(u8::from(x * x + y * y < 0.5));
            }
        };
        let r = integrate_global(&f, &[([0.0, 1.0], [0.0, 1.0])], 1e-6, 20_000_000);
        let e = r.estimates[0];
        let truth = std::f64::consts::PI / 8.0;
        assert!(r.converged, "{r:?}");
        assert!((e.value - truth).abs() <= e.error_bound, "{e:?} vs {truth}");
        assert!(e.error_bound <= 1e-6);
        assert!(r.evaluations < 20_000_000);
        // With a budget too small the target is not met and the bound stays honest.
        let r = integrate_global(&f, &[([0.0, 1.0], [0.0, 1.0])], 1e-12, 100_000);
        let e = r.estimates[0];
        assert!(!r.converged);
        assert!((e.value - truth).abs() <= e.error_bound, "{e:?}");
        assert!(r.evaluations <= 100_000 + 4 * 225);
    }

    #[test]
    fn a_caller_criterion_stops_the_refinement_early() {
        let f = |p: &[[f64; 2]], out: &mut [f64]| {
            for (o, &[x, y]) in out.iter_mut().zip(p) {
                *o = f64::from(u8::from(x * x + y * y < 0.5));
            }
        };
        let rect = [([0.0, 1.0], [0.0, 1.0])];
        let full = integrate_global(&f, &rect, 1e-9, 20_000_000);
        let early =
            integrate_global_until(&f, &rect, 1e-9, 20_000_000, &|e| e[0].error_bound <= 1e-5);
        assert!(early.converged);
        let e = early.estimates[0];
        assert!(e.error_bound <= 1e-5 && e.error_bound > 1e-9, "{e:?}");
        assert!((e.value - std::f64::consts::PI / 8.0).abs() <= e.error_bound);
        assert!(
            early.evaluations * 4 < full.evaluations,
            "{} vs {}",
            early.evaluations,
            full.evaluations
        );
    }

    #[test]
    fn a_smooth_integrand_over_several_rectangles_is_summed_per_rectangle() {
        let f = |p: &[[f64; 2]], out: &mut [f64]| {
            for (o, &[x, y]) in out.iter_mut().zip(p) {
                *o = (x + 2.0 * y).exp();
            }
        };
        let rects = [([0.0, 0.5], [0.0, 1.0]), ([0.5, 1.0], [0.0, 1.0])];
        let r = integrate_global(&f, &rects, 1e-12, 1_000_000);
        let exact = |a: f64, b: f64| (b.exp() - a.exp()) * (2f64.exp() - 1.0) / 2.0;
        assert!((r.estimates[0].value - exact(0.0, 0.5)).abs() < 1e-12);
        assert!((r.estimates[1].value - exact(0.5, 1.0)).abs() < 1e-12);
    }
}
