//! Test-only quadrature for the slope tests: test_support's adaptive integrator applied panel
//! by panel (1-D), and composite Gauss–Legendre tensor rules checked by panel halving (2-D).
//!
//! Why panels: over a long interval with the mass in its interior, the double-exponential error
//! estimate under-reports (∫_{−20}^{20} (t + 20) φ(t) dt came out 2.6e-13 low while claiming
//! 1e-13), and a target below its noise floor makes the bisection branch without bound (rel
//! 1e-14 there, or a negligible-but-non-zero tail piece with its own relative target, hangs).
//! Panels no wider than the integrand's scale and an absolute floor from a first estimate of
//! the total avoid both.

use crate::test_support::integrate;

/// The n-point Gauss–Legendre rule on [−1, 1] (nodes by Newton's method on P_n).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / derivative;
            x -= step;
            if step.abs() < 1e-17 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * derivative * derivative)));
    }
    rule
}

/// Nodes and weights of the composite 12-point Gauss–Legendre rule on [a, b] with panels no
/// wider than `width`.
pub fn composite(a: f64, b: f64, width: f64) -> Vec<(f64, f64)> {
    let rule = gauss_legendre(12);
    let n = ((b - a) / width).ceil().max(1.0) as usize;
    let h = (b - a) / n as f64;
    let mut out = Vec::with_capacity(12 * n);
    for i in 0..n {
        let centre = a + (i as f64 + 0.5) * h;
        for &(x, w) in &rule {
            out.push((centre + 0.5 * h * x, 0.5 * h * w));
        }
    }
    out
}

/// ∫_a^b f by test_support's adaptive integrator (relative target 1e-12) on panels no wider
/// than `width`, each scaled to an integral of magnitude ~1 by a first Gauss–Legendre estimate
/// of ∫|f| over it (the double-exponential convergence test compares ln δ_k with 2 ln δ_{k−1},
/// which holds only for integrals of order 1: unscaled, ∫_{−12}^{−3} (−3 − t) φ(t) dt ≈ 3.8e-4
/// on panels of width ⅓ came out 1.3e-11 wrong), with an absolute floor of 1e-15 ∫|f|.
pub fn quad(f: &dyn Fn(f64) -> f64, a: f64, b: f64, width: f64) -> f64 {
    let n = ((b - a) / width).ceil().max(1.0) as usize;
    let h = (b - a) / n as f64;
    let bounds = |i: usize| {
        (
            a + i as f64 * h,
            if i + 1 == n {
                b
            } else {
                a + (i + 1) as f64 * h
            },
        )
    };
    let magnitude = |i: usize| {
        let (lo, hi) = bounds(i);
        composite(lo, hi, hi - lo)
            .iter()
            .map(|&(x, w)| w * f(x).abs())
            .sum::<f64>()
    };
    let sizes: Vec<f64> = (0..n).map(magnitude).collect();
    let total: f64 = sizes.iter().sum();
    (0..n)
        .filter(|&i| sizes[i] > 0.0)
        .map(|i| {
            let (lo, hi) = bounds(i);
            let s = sizes[i];
            s * integrate(&|x| f(x) / s, lo, hi, 1e-12, 1e-15 * total / s).0
        })
        .sum()
}

#[test]
fn gauss_legendre_is_exact_for_polynomials() {
    let rule = gauss_legendre(12);
    for k in 0..24 {
        let got: f64 = rule.iter().map(|&(x, w)| w * x.powi(k)).sum();
        let want = if k % 2 == 1 {
            0.0
        } else {
            2.0 / (k as f64 + 1.0)
        };
        assert!((got - want).abs() < 1e-15, "x^{k}: {got} vs {want}");
    }
    let phi = |t: f64| (-0.5 * t * t).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let tail = quad(&|t| (t + 20.0) * phi(t), -20.0, 20.0, 1.0);
    assert!((tail - 20.0).abs() < 20.0 * 1e-12, "{tail}");
}
