//! Adaptive cubature over rectangles with an error bound: the tensor product of the
//! Gauss–Kronrod G7/K15 pair, bisected into quadrants until the estimate meets the tolerance.

// The G7/K15 pair written here, not imported from `mfh_reference::special::gauss_kronrod`:
// an oracle owes nothing to the code it checks. Values: QUADPACK's `dqk15`
// (Piessens, de Doncker-Kapenga, Überhuber, Kahaner 1983, "QUADPACK", Springer, §2.2;
// the netlib source lists them to 33 digits), rounded to f64. `tests::rule_degrees` checks them
// by the degrees they integrate exactly (K15: 22, G7: 13) and by the known moments.

/// K15 abscissae on [−1, 1], descending; the odd-indexed ones are the G7 nodes.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_5,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_48,
    0.0,
];
/// K15 weights of the abscissae [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_224,
    0.063_092_092_629_978_56,
    0.104_790_010_322_250_19,
    0.140_653_259_715_525_92,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_42,
    0.204_432_940_075_298_89,
    0.209_482_141_084_727_82,
];
/// G7 weights of the abscissae XGK[1], XGK[3], XGK[5], XGK[7].
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_64,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// The deepest quadrant bisection; past it the estimate is accepted with its error.
pub const MAX_DEPTH: u32 = 10;

/// The most rectangles one call of [`integrate_rectangles_batch`] may create by bisection
/// (each 225 evaluations and one 80-byte node): 2¹⁸ ≈ 2.6·10⁵ rectangles, 5.9·10⁷
/// evaluations, 21 MB. Past it no rectangle is bisected further and the leaves keep their
/// (honest) error estimates. A correct model's chi-square masses at the `ci` profile create
/// ~10³–10⁴; a density that oscillates faster than any cell (GGX × (1 + ½ sin(10⁴ x))) or is
/// rounding noise asked for 1e-9 (a float32 pdf) would create 4¹⁰ per piece: the tree grew to
/// 20 GB.
pub const MAX_RECTANGLES: usize = 1 << 18;

pub use super::Estimate;

pub mod global;

/// The 15 nodes and K15 / G7 weights on [a, b] (G7 weight 0 at the Kronrod-only nodes).
fn rule(a: f64, b: f64) -> ([f64; 15], [f64; 15], [f64; 15]) {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut x = [0.0; 15];
    let mut wk = [0.0; 15];
    let mut wg = [0.0; 15];
    for i in 0..8 {
        let g = if i % 2 == 1 { WG[i / 2] } else { 0.0 };
        x[i] = c - h * XGK[i];
        x[14 - i] = c + h * XGK[i];
        wk[i] = h * WGK[i];
        wk[14 - i] = h * WGK[i];
        wg[i] = h * g;
        wg[14 - i] = h * g;
    }
    (x, wk, wg)
}

/// The G7 × G7 product rule's estimate of each rectangle `(x, y)` (49 nodes a rectangle, one
/// call of `f` for all of them), without an error estimate: for sums that only place things
/// (the chi-square's layout strips, `chi2/cells.rs`), where a rough value costs balance, not
/// validity, and the K15 rule's 225 nodes were most of a BSDF chi-square's evaluations.
pub fn gauss7_products(f: &BatchFn2<'_>, rectangles: &[([f64; 2], [f64; 2])]) -> Vec<f64> {
    let mut points = Vec::with_capacity(49 * rectangles.len());
    let mut weights = Vec::with_capacity(49 * rectangles.len());
    for &(x, y) in rectangles {
        let (xs, _, xg) = rule(x[0], x[1]);
        let (ys, _, yg) = rule(y[0], y[1]);
        for i in (1..15).step_by(2) {
            for j in (1..15).step_by(2) {
                points.push([xs[i], ys[j]]);
                weights.push(xg[i] * yg[j]);
            }
        }
    }
    let mut values = vec![0.0; points.len()];
    f(&points, &mut values);
    values
        .chunks(49)
        .zip(weights.chunks(49))
        .map(|(v, w)| v.iter().zip(w).map(|(v, w)| v * w).sum())
        .collect()
}

fn product_rule(f: &impl Fn(f64, f64) -> f64, x: [f64; 2], y: [f64; 2]) -> (f64, f64) {
    let (xs, xk, xg) = rule(x[0], x[1]);
    let (ys, yk, yg) = rule(y[0], y[1]);
    let (mut k, mut g) = (0.0, 0.0);
    for i in 0..15 {
        let (mut ki, mut gi) = (0.0, 0.0);
        for j in 0..15 {
            let v = f(xs[i], ys[j]);
            ki += yk[j] * v;
            gi += yg[j] * v;
        }
        k += xk[i] * ki;
        g += xg[i] * gi;
    }
    (k, (k - g).abs())
}

/// The accuracy asked of [`integrate_rectangle`]: the larger of an absolute error and a
/// relative error (relative to the first K15 × K15 estimate of the whole rectangle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccuracyGoal {
    /// Absolute error.
    pub absolute: f64,
    /// Relative error.
    pub relative: f64,
}

/// ∫∫ f(x, y) dy dx over [x0, x1] × [y0, y1], bisecting into quadrants until the error
/// estimate of each piece is at most its share of the tolerance, or [`MAX_DEPTH`] is reached
/// (the returned error then still sums the estimates, so it stays honest).
pub fn integrate_rectangle(
    f: &impl Fn(f64, f64) -> f64,
    x: [f64; 2],
    y: [f64; 2],
    tolerance: AccuracyGoal,
) -> Estimate {
    fn go(
        f: &impl Fn(f64, f64) -> f64,
        x: [f64; 2],
        y: [f64; 2],
        tolerance: f64,
        depth: u32,
        whole: Option<(f64, f64)>,
    ) -> Estimate {
        let (value, error) = whole.unwrap_or_else(|| product_rule(f, x, y));
        let mut out = Estimate {
            value,
            error_bound: error,
            evaluations: if whole.is_some() { 0 } else { 225 },
        };
        if !(error > tolerance) || depth >= MAX_DEPTH {
            return out;
        }
        let (xm, ym) = (0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1]));
        let mut sum = Estimate {
            evaluations: out.evaluations,
            ..Estimate::default()
        };
        for xs in [[x[0], xm], [xm, x[1]]] {
            for ys in [[y[0], ym], [ym, y[1]]] {
                let part = go(f, xs, ys, 0.25 * tolerance, depth + 1, None);
                sum.value += part.value;
                sum.error_bound += part.error_bound;
                sum.evaluations += part.evaluations;
            }
        }
        out = sum;
        out
    }
    let whole = product_rule(f, x, y);
    let tol = tolerance.absolute.max(tolerance.relative * whole.0.abs());
    let mut e = go(f, x, y, tol, 0, Some(whole));
    e.evaluations += 225;
    e
}

/// A batch integrand over rectangles: writes f(x\[i\], y\[i\]) into out\[i\] for each `[x, y]`.
pub type BatchFn2<'a> = dyn Fn(&[[f64; 2]], &mut [f64]) + 'a;

/// The most rectangles whose rules are evaluated in one call of a batch integrand (225 nodes
/// each: ≈ 230 000 points, 5.5 MB).
const RECTANGLES_PER_CALL: usize = 1024;

/// One rectangle of the bisection tree of [`integrate_rectangles_batch`].
struct Node {
    x: [f64; 2],
    y: [f64; 2],
    tolerance: f64,
    depth: u32,
    value: f64,
    error: f64,
    children: Option<usize>,
}

/// The product rule's sums from the values at its 15 × 15 nodes (x-major), as
/// [`product_rule`] adds them.
fn product_sums(x: [f64; 2], y: [f64; 2], v: &[f64]) -> (f64, f64) {
    let (_, xk, xg) = rule(x[0], x[1]);
    let (_, yk, yg) = rule(y[0], y[1]);
    let (mut k, mut g) = (0.0, 0.0);
    for i in 0..15 {
        let (mut ki, mut gi) = (0.0, 0.0);
        for j in 0..15 {
            ki += yk[j] * v[15 * i + j];
            gi += yg[j] * v[15 * i + j];
        }
        k += xk[i] * ki;
        g += xg[i] * gi;
    }
    (k, (k - g).abs())
}

/// Evaluates the product rules of `nodes[range]` in calls of at most [`RECTANGLES_PER_CALL`]
/// rectangles.
fn evaluate(f: &BatchFn2<'_>, nodes: &mut [Node]) {
    let mut points = Vec::new();
    let mut values = Vec::new();
    for group in nodes.chunks_mut(RECTANGLES_PER_CALL) {
        points.clear();
        for n in group.iter() {
            let (xs, _, _) = rule(n.x[0], n.x[1]);
            let (ys, _, _) = rule(n.y[0], n.y[1]);
            for &x in &xs {
                points.extend(ys.iter().map(|&y| [x, y]));
            }
        }
        values.clear();
        values.resize(points.len(), 0.0);
        f(&points, &mut values);
        for (n, v) in group.iter_mut().zip(values.chunks(225)) {
            (n.value, n.error) = product_sums(n.x, n.y, v);
        }
    }
}

/// [`integrate_rectangle`] for many rectangles `(x, y, tolerance)` and a batch integrand: the
/// bisection trees of all of them grow level by level, each level's product rules evaluated in
/// a few calls of `f`, and each estimate is summed as the recursive form sums it — so the
/// results equal [`integrate_rectangle`]'s bit for bit (a test checks), while an external model
/// pays a round trip per level and 1024 rectangles, not per rectangle.
pub fn integrate_rectangles_batch(
    f: &BatchFn2<'_>,
    rectangles: &[([f64; 2], [f64; 2], AccuracyGoal)],
) -> Vec<Estimate> {
    integrate_rectangles_batch_budgeted(f, rectangles).0
}

/// A bisection that [`MAX_RECTANGLES`] stopped: some rectangle above its tolerance (and
/// above [`MAX_DEPTH`]) was left unrefined, so the estimates' summed `bound` may exceed the
/// summed `target` the caller asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BudgetHit {
    /// The rectangles bisection created (≥ [`MAX_RECTANGLES`] − 4).
    pub rectangles: usize,
    /// The summed error bound of the estimates.
    pub bound: f64,
    /// The summed tolerance of the input rectangles (each max(absolute, relative × |first
    /// estimate|)).
    pub target: f64,
}

/// [`integrate_rectangles_batch`], and whether [`MAX_RECTANGLES`] stopped the bisection.
pub fn integrate_rectangles_batch_budgeted(
    f: &BatchFn2<'_>,
    rectangles: &[([f64; 2], [f64; 2], AccuracyGoal)],
) -> (Vec<Estimate>, Option<BudgetHit>) {
    let mut nodes: Vec<Node> = rectangles
        .iter()
        .map(|&(x, y, _)| Node {
            x,
            y,
            tolerance: 0.0,
            depth: 0,
            value: 0.0,
            error: 0.0,
            children: None,
        })
        .collect();
    evaluate(f, &mut nodes);
    for (n, (_, _, t)) in nodes.iter_mut().zip(rectangles) {
        n.tolerance = t.absolute.max(t.relative * n.value.abs());
    }
    let target: f64 = nodes.iter().map(|n| n.tolerance).sum();
    let mut level = 0..nodes.len();
    let budget = rectangles.len() + MAX_RECTANGLES;
    let mut denied = false;
    while !level.is_empty() {
        crate::deadline::checkpoint();
        let start = nodes.len();
        for i in level.clone() {
            let n = &nodes[i];
            if !(n.error > n.tolerance) || n.depth >= MAX_DEPTH {
                continue;
            }
            if nodes.len() + 4 > budget {
                denied = true;
                continue;
            }
            let (x, y, tolerance, depth) = (n.x, n.y, 0.25 * n.tolerance, n.depth + 1);
            let (xm, ym) = (0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1]));
            nodes[i].children = Some(nodes.len());
            for xs in [[x[0], xm], [xm, x[1]]] {
                for ys in [[y[0], ym], [ym, y[1]]] {
                    nodes.push(Node {
                        x: xs,
                        y: ys,
                        tolerance,
                        depth,
                        value: 0.0,
                        error: 0.0,
                        children: None,
                    });
                }
            }
        }
        evaluate(f, &mut nodes[start..]);
        level = start..nodes.len();
    }
    // The recursive sums, deepest first (children always follow their parent).
    let mut sums: Vec<Estimate> = vec![Estimate::default(); nodes.len()];
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        let own = if i < rectangles.len() { 0 } else { 225 };
        sums[i] = match n.children {
            None => Estimate {
                value: n.value,
                error_bound: n.error,
                evaluations: own,
            },
            Some(c) => {
                let mut sum = Estimate {
                    evaluations: own,
                    ..Estimate::default()
                };
                for part in &sums[c..c + 4] {
                    sum.value += part.value;
                    sum.error_bound += part.error_bound;
                    sum.evaluations += part.evaluations;
                }
                sum
            }
        };
    }
    sums.truncate(rectangles.len());
    for s in &mut sums {
        s.evaluations += 225;
    }
    let hit = denied.then(|| BudgetHit {
        rectangles: nodes.len() - rectangles.len(),
        bound: sums.iter().map(|s| s.error_bound).sum(),
        target,
    });
    (sums, hit)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn abs(t: f64) -> AccuracyGoal {
        AccuracyGoal {
            absolute: t,
            relative: 0.0,
        }
    }

    #[test]
    fn rule_degrees() {
        // ∫_{-1}^{1} x^k = 2/(k+1) for even k: K15 is exact to degree 22 (3·7 + 1), G7 to 13.
        let (x, wk, wg) = rule(-1.0, 1.0);
        for k in (0..=30).step_by(2) {
            let exact = 2.0 / (k as f64 + 1.0);
            let kronrod: f64 = (0..15).map(|i| wk[i] * x[i].powi(k)).sum();
            let gauss: f64 = (0..15).map(|i| wg[i] * x[i].powi(k)).sum();
            if k <= 22 {
                assert!((kronrod - exact).abs() < 4e-16, "K15 degree {k}: {kronrod}");
            } else {
                assert!(
                    (kronrod - exact).abs() > 1e-12,
                    "K15 is not exact at degree {k}"
                );
            }
            if k <= 13 {
                assert!((gauss - exact).abs() < 4e-16, "G7 degree {k}: {gauss}");
            } else {
                assert!(
                    (gauss - exact).abs() > 1e-9,
                    "G7 is not exact at degree {k}"
                );
            }
        }
        // Odd moments vanish by symmetry; the G7 nodes are the K15 odd-indexed ones.
        let odd: f64 = (0..15).map(|i| wk[i] * x[i].powi(7)).sum();
        assert!(odd.abs() < 1e-16);
        assert_eq!((0..15).filter(|&i| wg[i] != 0.0).count(), 7);
    }

    #[test]
    fn polynomials_and_a_peak() {
        let e = integrate_rectangle(
            &|x, y| x.powi(5) * y.powi(3),
            [0.0, 2.0],
            [1.0, 3.0],
            abs(1e-12),
        );
        assert!((e.value - 64.0 / 6.0 * 20.0).abs() < 1e-11, "{e:?}");
        assert_eq!(e.evaluations, 225);
        let f = |x: f64, y: f64| 1.0 / (1e-3 + x * x + y * y);
        // ∫∫ over [−1,1]² of 1/(ε + r²): reference from the polar split, checked by refinement.
        let e = integrate_rectangle(&f, [-1.0, 1.0], [-1.0, 1.0], abs(1e-9));
        let fine = integrate_rectangle(&f, [-1.0, 1.0], [-1.0, 1.0], abs(1e-12));
        assert!(e.evaluations > 225);
        assert!(
            (e.value - fine.value).abs() <= e.error_bound.max(1e-9),
            "{e:?} {fine:?}"
        );
        // The batch form: the same estimates bit for bit, refined or not.
        let rects = [
            ([-1.0, 1.0], [-1.0, 1.0], abs(1e-9)),
            ([0.0, 2.0], [1.0, 3.0], abs(1e-12)),
            (
                [-0.5, 0.7],
                [0.1, 0.9],
                AccuracyGoal {
                    absolute: 0.0,
                    relative: 1e-10,
                },
            ),
        ];
        let batch = integrate_rectangles_batch(
            &|p: &[[f64; 2]], out: &mut [f64]| {
                for (o, &[x, y]) in out.iter_mut().zip(p) {
                    *o = f(x, y);
                }
            },
            &rects,
        );
        for ((x, y, t), b) in rects.iter().zip(&batch) {
            let s = integrate_rectangle(&f, *x, *y, *t);
            assert_eq!(s.value.to_bits(), b.value.to_bits(), "{s:?} {b:?}");
            assert_eq!(s.error_bound.to_bits(), b.error_bound.to_bits());
            assert_eq!(s.evaluations, b.evaluations);
        }
        let g = |x: f64, y: f64| (x + 2.0 * y).exp();
        let e = integrate_rectangle(&g, [0.0, 1.0], [0.0, 1.0], abs(1e-13));
        let exact = (1f64.exp() - 1.0) * (2f64.exp() - 1.0) / 2.0;
        assert!((e.value - exact).abs() < 1e-13, "{e:?}");
    }
}
