//! Smith Λ of the standardized Student slope distribution and of the Gaussian (Beckmann), free
//! of the cancellation that the printed closed forms suffer near normal incidence.
//!
//! Written by hand: Λ is the small difference of two nearly equal terms (document 001 eq 21, and
//! ½(e^{−a²}/(a√π) − erfc a) for Beckmann); no crate evaluates that difference directly.
//!
//! Standardized form (document 001 eq 15 and 21 with σ√(γ−1) = 1, C = γ): with
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

use super::beckmann_fit::PIECES;
use super::hyp2f1::{
    beta_cf_delta_tabulated, beta_cf_k_denominator, lambda_edges, pfaff_series, student_norm,
    use_pfaff, BetaCfTable,
};
use std::f64::consts::PI;

/// Λ_C(x) of the standardized Student slope distribution, C > 3/2, x ≥ 0 (x = +∞ gives 0,
/// x = 0 gives +∞). Relative error ≤ 2e-14 against mpmath over C ∈ (1.5, 10⁸],
/// x ∈ (0, ∞) wherever Λ is a normal f64 (`reference/golden/student.json`); the worst case is
/// at the switch between the two forms for large C (a = x√(C−1) ≈ 1.2), where the Pfaff form
/// cancels by a factor ≈ 100, and at a ≳ 10 for C ≥ 10⁶, where Λ ≈ e^{−a²} is itself
/// ill-conditioned in x (condition number 2a²).
///
/// Cost: see the criterion benchmark `closed_forms` (the continued fraction takes 2 × 4–60
/// steps; N_C alone costs up to 30 divisions, see `student_lambda_with_norm`).
pub fn student_lambda(c: f64, x: f64) -> f64 {
    student_lambda_with_norm(c, student_norm(c), x)
}

/// `student_lambda` with the constant N_C = Γ(C − ½)/(√π Γ(C − 1)) given (`n` must be
/// `hyp2f1::student_norm(c)`, which a model computes once): the same value, bit for bit.
pub fn student_lambda_with_norm(c: f64, n: f64, x: f64) -> f64 {
    student_lambda_tabulated(c, n, None, x)
}

/// `student_lambda_with_norm` with the continued fraction's coefficients read from `table`
/// (`BetaCfTable::new(c)`, which a model builds once): no division per level; the same value
/// to an ulp or two.
pub fn student_lambda_tabulated(c: f64, n: f64, table: Option<&BetaCfTable>, x: f64) -> f64 {
    if let Some(edge) = lambda_edges(c, x) {
        return edge;
    }
    let x2 = x * x;
    let s = x2 / (1.0 + x2);
    let w_power = w_power(c, x2); // w^{C − 3/2}
    if use_pfaff(c, s) {
        let a = n * w_power / ((2.0 * c - 3.0) * x);
        let nxf = n * x * (-x2.ln_1p()).exp() * w_power * pfaff_series(c, s);
        return (a + nxf) - 0.5;
    }
    let w = 1.0 / (1.0 + x2);
    let delta = beta_cf_delta_tabulated(c, s, w, table);
    let numerator = c - w + c * delta * (1.0 + (2.0 * c - 3.0) * w);
    let denominator = (2.0 * c - 3.0) * (2.0 * c - 2.0) * beta_cf_k_denominator(c, s, w, delta);
    n * w_power / x * numerator / denominator
}

/// The largest 2C − 3 for which w^{C−3/2} is a product of powers: C = 2, 5/2, 3 (GGX and the
/// common Student shapes). Beyond, the extra roundings of the powers cost accuracy next to the
/// switch where the Pfaff form cancels (measured with mpmath: C = 4 2.7e-15 against 1.1e-15,
/// C = 7.5 7.9e-15 against 5.5e-15, × condition).
const SMALL_EXPONENT: f64 = 3.0;

/// w^{C−3/2} = (1 + x²)^{−(2C−3)/2}. For 2C − 3 = k an integer ≤ `SMALL_EXPONENT` as
/// 1/(b^⌊k/2⌋ √b^{k mod 2}) · (1 − (k/2) e/b) with 1 + x² = b + e exactly (TwoSum): a square
/// root and a division instead of `ln_1p` and `exp`, as accurate (C = 2: 3.3e-16 → 2.2e-16,
/// C = 2.5, 3 unchanged against mpmath); otherwise exp((3/2 − C) ln(1 + x²)).
#[inline]
fn w_power(c: f64, x2: f64) -> f64 {
    let k2 = 2.0 * c - 3.0;
    if k2 <= SMALL_EXPONENT && k2.fract() == 0.0 && x2 < 1e18 {
        let b = 1.0 + x2;
        let bb = b - 1.0;
        let e = (1.0 - (b - bb)) + (x2 - bb);
        let k = k2 as i32;
        let power = if k % 2 == 0 {
            b.powi(k / 2)
        } else {
            b.powi(k / 2) * b.sqrt()
        };
        return (1.0 - 0.5 * k2 * (e / b)) / power;
    }
    ((1.5 - c) * x2.ln_1p()).exp()
}

/// Below this, Beckmann Λ is the direct difference (which cancels by at most a factor 2.2
/// here); above, the fitted polynomials of `special::beckmann_fit`.
const BECKMANN_SWITCH: f64 = 0.5;

/// Above this, Beckmann Λ < e^{−a²} underflows to 0.
const BECKMANN_ZERO: f64 = 28.0;

/// a² = hi + lo exactly (Dekker's product; no FMA needed), for |a| ≤ 1e150.
#[inline]
pub(crate) fn exact_square(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2²⁷ + 1: splits a into two 26-bit halves
    let high = c - (c - a);
    let low = a - high;
    let hi = a * a;
    let lo = ((high * high - hi) + 2.0 * high * low) + low * low;
    (hi, lo)
}

/// e^{−a²} with a² taken exactly: e^{−hi}(1 − lo), |lo| ≤ ulp(hi)/2 (e^{−a·a} would carry the
/// rounding of a·a, a relative error up to a² × 1.1e-16).
#[inline]
fn exp_minus_square(a: f64) -> f64 {
    let (hi, lo) = exact_square(a);
    (-hi).exp() * (1.0 - lo)
}

/// Beckmann Smith Λ(a), a = cot θ / α ≥ 0 (document 001 Table 1, γ = ∞; Walter et al. 2007):
///
/// ```text
/// Λ(a) = ½ (e^{−a²}/(a√π) − erfc a)                          a < ½
///      = e^{−a²} F(a) / (4√π a³),  F(a) = 2a² − 2√π a³ erfcx(a)   a ≥ ½
/// ```
///
/// The first line with erfc from `libm` (statrs' erfc is off by up to 1e-10 relative on
/// [0.5, 1.5]); it cancels by at most a factor 2.2 below a = ½. On a ≥ ½ the difference is
/// never formed: F ∈ [0.22, 1) is read from fitted polynomials (`special::beckmann_fit`,
/// generated with mpmath; a table because the alternatives are slow: the continued fraction
/// of erfc needs ~100 steps at a = 1.5, ~25 at a = 4). In both lines e^{−a²} uses a² split
/// exactly into two doubles. Relative error ≤ 1e-15 for a ∈ (0, ∞) where Λ is normal
/// (against mpmath, `reference/golden/beckmann.json`: max 6e-16).
pub fn beckmann_lambda(a: f64) -> f64 {
    if a.is_nan() || a < 0.0 {
        return f64::NAN;
    }
    if a == 0.0 {
        return f64::INFINITY;
    }
    if a > BECKMANN_ZERO {
        return 0.0;
    }
    let sqrt_pi = PI.sqrt();
    if a < BECKMANN_SWITCH {
        return 0.5 * (exp_minus_square(a) / (a * sqrt_pi) - libm::erfc(a));
    }
    exp_minus_square(a) * beckmann_scaled(a) / (4.0 * sqrt_pi * (a * a * a))
}

/// F(a) = 4√π a³ e^{a²} Λ(a) = 2a² − 2√π a³ erfcx(a) for a ≥ ½ (F ∈ [0.22, 1), → 1 as
/// a → ∞), from the fitted polynomials of `special::beckmann_fit` (relative error ≤ 2.4e-16).
#[inline]
pub(crate) fn beckmann_scaled(a: f64) -> f64 {
    let (piece, x) = if a < 4.0 {
        (&PIECES[((a - 0.5) * 2.0) as usize], a)
    } else {
        (&PIECES[7], 1.0 / (a * a))
    };
    let s = (x - piece.mid) * piece.inv_half;
    piece
        .coefficients
        .iter()
        .rev()
        .fold(0.0, |acc, &c| acc * s + c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{golden, golden_beckmann, integrate_tail, rel_err};

    #[test]
    fn student_lambda_matches_mpmath() {
        // Untabulated (student_lambda) and with the model's coefficient table.
        let mut worst = [(0.0, 0.0, 0.0); 2];
        for row in golden("lambda") {
            let c = row["c"].as_f64().unwrap();
            let x = row["x"].as_f64().unwrap();
            let want: f64 = row["lambda"].as_str().unwrap().parse().unwrap();
            if !want.is_normal() {
                continue;
            }
            let table = BetaCfTable::new(c);
            let tabulated = student_lambda_tabulated(c, student_norm(c), Some(&table), x);
            for (k, got) in [student_lambda(c, x), tabulated].into_iter().enumerate() {
                // Λ's condition number in x: |d ln Λ / d ln x| ≤ 1 + (2C − 1) s,
                // s = x²/(1+x²) (≈ 2a² near normal incidence for large C): one ulp of x
                // moves Λ that much.
                let condition = 1.0 + (2.0 * c - 1.0) * x * x / (1.0 + x * x);
                let e = rel_err(got, want) / condition;
                if e > worst[k].0 {
                    worst[k] = (e, c, x);
                }
                assert!(
                    e < 1e-14,
                    "C = {c}, x = {x}: {got} vs {want} ({e:e} × condition, tabulated: {})",
                    k == 1
                );
            }
        }
        for (k, w) in worst.iter().enumerate() {
            eprintln!(
                "Λ_C{} max relative error / condition number {:.2e} at C = {}, x = {}",
                if k == 1 { " (tabulated)" } else { "" },
                w.0,
                w.1,
                w.2
            );
        }
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
        for &a in &[
            1e-6, 0.1, 0.49, 0.5, 0.7, 1.49, 1.5, 1.51, 2.5, 3.99, 4.0, 6.0, 20.0,
        ] {
            let f = |q: f64| (q - a) * (-q * q).exp() / PI.sqrt();
            let want = integrate_tail(&f, a, 1.0 / (1.0 + a), 1e-14) / a;
            let e = rel_err(beckmann_lambda(a), want);
            assert!(
                e < 1e-12,
                "a = {a}: {} vs {want} ({e:e})",
                beckmann_lambda(a)
            );
        }
        // Continuity across the switch and the ends of the pieces (Λ's condition number in a
        // is 1 … 3 + 2a²: a step of 1e-15 in a moves Λ by about that much).
        for &a in &[BECKMANN_SWITCH, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0] {
            let below = beckmann_lambda(a * (1.0 - 1e-15));
            let above = beckmann_lambda(a);
            let e = rel_err(below, above);
            assert!(e < 1e-15 * (5.0 + 2.0 * a * a), "a = {a}: {e:e}");
        }
        assert_eq!(beckmann_lambda(BECKMANN_ZERO * (1.0 + 1e-15)), 0.0);
        assert!(beckmann_lambda(BECKMANN_ZERO) < 1e-300);
    }

    #[test]
    fn beckmann_lambda_matches_mpmath() {
        // a is exact in the golden file: no condition-number allowance (e^{−a²} is computed
        // from the exact a²).
        let mut worst = (0.0, 0.0);
        for row in golden_beckmann() {
            let a = row["a"].as_f64().unwrap();
            let want: f64 = row["lambda"].as_str().unwrap().parse().unwrap();
            if !want.is_normal() {
                continue;
            }
            let e = rel_err(beckmann_lambda(a), want);
            if e > worst.0 {
                worst = (e, a);
            }
            assert!(
                e < 1e-15,
                "a = {a}: {} vs {want} ({e:e})",
                beckmann_lambda(a)
            );
        }
        eprintln!(
            "Beckmann Λ: max relative error {:.2e} at a = {}",
            worst.0, worst.1
        );
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
