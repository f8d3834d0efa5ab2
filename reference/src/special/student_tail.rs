//! Smith Λ of the standardized Student slope distribution and of the Gaussian (Beckmann), free
//! of the cancellation that the printed closed forms suffer near normal incidence.
//!
//! Written by hand: Λ is the small difference of two nearly equal terms (seed 001 eq 21, and
//! ½(e^{−a²}/(a√π) − erfc a) for Beckmann); no crate evaluates that difference directly.
//!
//! Standardized form (seed 001 eq 15 and 21 with σ√(γ−1) = 1, C = γ): with
//! P2(q) = N (1+q²)^{½−C}, N = Γ(C−½)/(√π Γ(C−1)), w = 1/(1+x²),
//!
//! ```text
//! Λ_C(x) = (1/x) ∫ₓ^∞ (q − x) P2(q) dq = A − T,
//! A = N w^{C−3/2} / ((2C − 3) x),   T = ∫ₓ^∞ P2 = ½ I_w(C−1, ½)
//! ```
//!
//! With T written by the incomplete-beta continued fraction (special::hyp2f1, (T)),
//! T = N x w^{C−½} K/(2(C−1)), K = Cτ/(Cτ − (C−½)w), τ = 1 + δ, the difference A − T
//! simplifies exactly to
//!
//! ```text
//! Λ = N w^{C−3/2} / x · (C − w + Cδ (1 + (2C−3) w)) / ((2C−3)(2C−2)(Cτ − (C−½) w))
//! ```
//!
//! in which the leading terms have cancelled algebraically (1/(2C−3) − 1/(2C−2) =
//! 1/((2C−3)(2C−2)) and (2C−3)C − (2C−2)(C−½) = −1): relative error stays at the 1e-15 level
//! however small Λ is. Near grazing incidence, where Λ is large and the continued fraction
//! converges slowly, Λ = A − ½ + N x ₂F₁ (Pfaff series) has no harmful cancellation.

use super::hyp2f1::{beta_cf_delta, beta_cf_k_denominator, pfaff_series, student_norm, use_pfaff};
use std::f64::consts::PI;

/// Λ_C(x) of the standardized Student slope distribution, C > 3/2, x ≥ 0 (x = +∞ gives 0,
/// x = 0 gives +∞). Relative error ≤ 2e-14 against mpmath over C ∈ (1.5, 10⁸],
/// x ∈ (0, ∞) wherever Λ is a normal f64 (`reference/golden/student.json`); the worst case is
/// at the switch between the two forms for large C (a = x√(C−1) ≈ 1.2), where the Pfaff form
/// cancels by a factor ≈ 100, and at a ≳ 10 for C ≥ 10⁶, where Λ ≈ e^{−a²} is itself
/// ill-conditioned in x (condition number 2a²).
///
/// Cost: see the criterion benchmark `closed_forms` (the continued fraction takes 2 × 4–60
/// steps).
pub fn student_lambda(c: f64, x: f64) -> f64 {
    if !(c > 1.5) || x.is_nan() || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        return f64::INFINITY;
    }
    if x == f64::INFINITY {
        return 0.0;
    }
    let x2 = x * x;
    let s = x2 / (1.0 + x2);
    let n = student_norm(c);
    let w_power = ((1.5 - c) * x2.ln_1p()).exp(); // w^{C − 3/2}
    if use_pfaff(c, s) {
        let a = n * w_power / ((2.0 * c - 3.0) * x);
        let nxf = n * x * (-x2.ln_1p()).exp() * w_power * pfaff_series(c, s);
        return (a + nxf) - 0.5;
    }
    let w = 1.0 / (1.0 + x2);
    let delta = beta_cf_delta(c, s, w);
    let numerator = c - w + c * delta * (1.0 + (2.0 * c - 3.0) * w);
    let denominator = (2.0 * c - 3.0) * (2.0 * c - 2.0) * beta_cf_k_denominator(c, s, w, delta);
    n * w_power / x * numerator / denominator
}

/// Below this, Beckmann Λ is the direct difference; above, the continued fraction.
const BECKMANN_SWITCH: f64 = 1.5;

/// Beckmann Smith Λ(a), a = cot θ / α ≥ 0 (seed 001 Table 1, γ = ∞; Walter et al. 2007):
///
/// ```text
/// Λ(a) = ½ (e^{−a²}/(a√π) − erfc a)
///      = e^{−a²}/(2√π) · r / (a (a + r)),   r = (1/2)/(a + 1/(a + (3/2)/(a + 2/(a + …))))
/// ```
///
/// the second line from the continued fraction erfc a = e^{−a²}/√π · 1/(a + r), which removes
/// the cancellation for a ≥ 1.5; below, erfc comes from `libm` (statrs' erfc is off by up to
/// 1e-10 relative on [0.5, 1.5]). Relative error ≤ 3e-15 for a ∈ (0, ∞) where Λ is normal.
pub fn beckmann_lambda(a: f64) -> f64 {
    if a.is_nan() || a < 0.0 {
        return f64::NAN;
    }
    if a == 0.0 {
        return f64::INFINITY;
    }
    if a == f64::INFINITY {
        return 0.0;
    }
    let sqrt_pi = PI.sqrt();
    if a < BECKMANN_SWITCH {
        return 0.5 * ((-a * a).exp() / (a * sqrt_pi) - libm::erfc(a));
    }
    // r = ½ / R, R = a + 1/(a + (3/2)/(a + …)) by modified Lentz: partial numerators k/2,
    // k = 2, 3, …, partial denominators a.
    const TINY: f64 = 1e-300;
    let mut f = a;
    let mut cc = f;
    let mut dd = 0.0;
    for k in 2..10_000 {
        let num = k as f64 * 0.5;
        dd = a + num * dd;
        if dd.abs() < TINY {
            dd = TINY;
        }
        cc = a + num / cc;
        if cc.abs() < TINY {
            cc = TINY;
        }
        dd = 1.0 / dd;
        let delta = cc * dd;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    let r = 0.5 / f;
    (-a * a).exp() / (2.0 * sqrt_pi) * r / (a * (a + r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{golden, integrate_tail, rel_err};

    #[test]
    fn student_lambda_matches_mpmath() {
        let mut worst: (f64, f64, f64) = (0.0, 0.0, 0.0);
        for row in golden("lambda") {
            let c = row["c"].as_f64().unwrap();
            let x = row["x"].as_f64().unwrap();
            let want: f64 = row["lambda"].as_str().unwrap().parse().unwrap();
            if !want.is_normal() {
                continue;
            }
            let got = student_lambda(c, x);
            // Λ's condition number in x: |d ln Λ / d ln x| ≤ 1 + (2C − 1) s, s = x²/(1+x²)
            // (≈ 2a² near normal incidence for large C): one ulp of x moves Λ that much.
            let condition = 1.0 + (2.0 * c - 1.0) * x * x / (1.0 + x * x);
            let e = rel_err(got, want) / condition;
            if e > worst.0 {
                worst = (e, c, x);
            }
            assert!(
                e < 1e-14,
                "C = {c}, x = {x}: {got} vs {want} ({e:e} × condition)"
            );
        }
        eprintln!(
            "Λ_C max relative error / condition number {:.2e} at C = {}, x = {}",
            worst.0, worst.1, worst.2
        );
    }

    #[test]
    fn printed_eq21_cancels_near_normal_incidence() {
        // At C = 3, a = 30 the two terms of eq 21 agree to ~6 digits: eq 21 loses them.
        let (c, x) = (3.0, 30.0 / 2f64.sqrt());
        let stable = student_lambda(c, x);
        let printed = crate::ndf::student_lambda::lambda_2f1(c, x);
        assert!(rel_err(printed, stable) > 1e-12, "{printed} vs {stable}");
        // …but agrees where Λ is not small.
        let x = 0.5;
        assert!(
            rel_err(
                crate::ndf::student_lambda::lambda_2f1(c, x),
                student_lambda(c, x)
            ) < 1e-14
        );
    }

    #[test]
    fn beckmann_lambda_against_its_integral() {
        // Λ(a) = (1/a) ∫_a^∞ (q − a) e^{−q²}/√π dq.
        for &a in &[1e-6, 0.1, 0.7, 1.49, 1.5, 1.51, 2.5, 6.0, 20.0] {
            let f = |q: f64| (q - a) * (-q * q).exp() / PI.sqrt();
            let want = integrate_tail(&f, a, 1.0 / (1.0 + a), 1e-14) / a;
            let e = rel_err(beckmann_lambda(a), want);
            assert!(
                e < 1e-12,
                "a = {a}: {} vs {want} ({e:e})",
                beckmann_lambda(a)
            );
        }
        // Continuity across the switch.
        let below = beckmann_lambda(BECKMANN_SWITCH * (1.0 - 1e-15));
        let above = beckmann_lambda(BECKMANN_SWITCH);
        assert!(rel_err(below, above) < 1e-14);
    }

    #[test]
    fn beckmann_is_the_large_c_limit() {
        // Λ_C(a/√(C−1)) → Λ_Beckmann(a) at rate 1/C.
        for &a in &[0.5, 1.0, 2.0] {
            let e = |c: f64| rel_err(student_lambda(c, a / (c - 1.0).sqrt()), beckmann_lambda(a));
            let ratio = e(1e4) / e(1e6);
            assert!((80.0..120.0).contains(&ratio), "a = {a}: {ratio}");
        }
    }

    #[test]
    fn domain() {
        assert!(student_lambda(1.5, 1.0).is_nan());
        assert!(student_lambda(2.0, -1.0).is_nan());
        assert!(student_lambda(f64::NAN, 1.0).is_nan());
        assert_eq!(student_lambda(2.0, 0.0), f64::INFINITY);
        assert_eq!(student_lambda(2.0, f64::INFINITY), 0.0);
        assert!(beckmann_lambda(f64::NAN).is_nan());
        assert_eq!(beckmann_lambda(0.0), f64::INFINITY);
        assert_eq!(beckmann_lambda(f64::INFINITY), 0.0);
    }
}
