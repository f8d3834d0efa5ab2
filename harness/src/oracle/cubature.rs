//! Adaptive cubature over rectangles with an error bound: the tensor product of the
//! Gauss–Kronrod G7/K15 pair, bisected into quadrants until the estimate meets the tolerance.

// The G7/K15 pair written here, not imported from `mfh_reference::special::gauss_kronrod`:
// an oracle owes nothing to the code it checks (issue 11). Values: QUADPACK's `dqk15`
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

pub use super::Estimate;

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
pub struct Tolerance {
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
    tolerance: Tolerance,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn abs(t: f64) -> Tolerance {
        Tolerance {
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
        let g = |x: f64, y: f64| (x + 2.0 * y).exp();
        let e = integrate_rectangle(&g, [0.0, 1.0], [0.0, 1.0], abs(1e-13));
        let exact = (1f64.exp() - 1.0) * (2f64.exp() - 1.0) / 2.0;
        assert!((e.value - exact).abs() < 1e-13, "{e:?}");
    }
}
