//! ₂F₁(½, C − ½; 3/2; z) for z ∈ (−∞, 0] and C > 1, the hypergeometric function in Λ of the
//! Student family (document 001, eq 21), plus the document's own §8 Algorithm 2, printed and
//! corrected, kept so that the harness can measure where it fails.
//!
//! Written by hand: no maintained Rust crate evaluates ₂F₁ over the whole negative half-line
//! (the Gauss series converges only for |z| < 1, and the z → 1/z transformation of
//! Abramowitz–Stegun 15.3.7 that §8 uses hits the poles of Γ(1 − C), Γ(2 − C) at every integer
//! C). Here two representations without poles cover the half-line, with x² = −z,
//! s = x²/(1+x²), w = 1/(1+x²) = 1 − s:
//!
//! ```text
//! (P) Pfaff (A&S 15.3.5):  F = (1 + x²)^{½−C} Σₙ (C−½)ₙ/(3/2)ₙ sⁿ          all terms > 0
//! (T) the upper tail:      N x F = ½ − T(x),  T(x) = N ∫ₓ^∞ (1+q²)^{½−C} dq = ½ I_w(C−1, ½)
//!                          T = N x w^{C−½} K / (2(C−1)),  K = 1/(1 + d₁/(1 + d₂/(1 + …)))
//! ```
//!
//! with N = Γ(C−½)/(√π Γ(C−1)) and the continued fraction of the incomplete beta function
//! (d_{2m+1} = −(α+m)(α+β+m)w/((α+2m)(α+2m+1)), d_{2m} = m(β−m)w/((α+2m−1)(α+2m)),
//! α = C − 1, β = ½). (P) converges fast where s (C + 3/2) is small, (T) where it is large;
//! `SWITCH` picks between them. Neither involves Γ at negative arguments, so integer C needs
//! no limiting form.

use super::gamma_ratio::gamma_half_ratio;
use std::f64::consts::PI;

/// (P) is used where s (C + 3/2) ≤ SWITCH, (T) elsewhere: the continued fraction converges
/// fast where w < (α+1)/(α+β+2) = C/(C + 3/2), i.e. s (C + 3/2) > 3/2. At the switch (P)
/// needs about 40 terms and (T) about 60.
pub const SWITCH: f64 = 1.5;

/// The most terms or continued-fraction steps any evaluation takes before giving up (NaN).
const MAX_TERMS: usize = 100_000;

/// N_C = Γ(C − ½)/(√π Γ(C − 1)), the constant of the standardized Student P2 (document 001 eq 15
/// with σ√(γ−1) = 1); accurate to a few ulps for every C > 1.
pub fn student_norm(c: f64) -> f64 {
    gamma_half_ratio(c - 1.0) / PI.sqrt()
}

/// Whether (P) rather than (T) serves the point s = x²/(1 + x²).
#[inline]
pub(crate) fn use_pfaff(c: f64, s: f64) -> bool {
    s * (c + 1.5) <= SWITCH
}

/// Σₙ (C−½)ₙ/(3/2)ₙ sⁿ for 0 ≤ s < 1: the Pfaff-transformed series (P), all terms positive.
pub(crate) fn pfaff_series(c: f64, s: f64) -> f64 {
    let mut term = 1.0;
    let mut sum = 1.0;
    for n in 0..MAX_TERMS {
        let k = n as f64;
        term *= (c - 0.5 + k) / (1.5 + k) * s;
        sum += term;
        if term <= sum * 1e-17 {
            return sum;
        }
    }
    f64::NAN
}

/// δ = τ − 1 where τ = 1 + d₂/(1 + d₃/(1 + …)) is the tail of the incomplete-beta continued
/// fraction for I_w(C − 1, ½) after its first step. Computing δ rather than τ keeps the
/// O(1/C²) correction that Λ depends on.
///
/// Forward, the continuants Aₙ = Aₙ₋₁ + dₙAₙ₋₂ (and Bₙ) of t₃ = 1 + d₃/(1 + d₄/(1 + …)) run
/// until |fₙ/fₙ₋₁ − 1| < 1e-16, i.e. |Π dₖ| < 1e-16 |Aₙ₋₁ Bₙ| (the determinant
/// AₙBₙ₋₁ − Aₙ₋₁Bₙ = (−1)ⁿ Π dₖ): the stopping rule of modified Lentz without its two chained
/// divisions per step. Up to C = `FORWARD_MAX`, δ = d₂ Bₙ/Aₙ. Above, where the forward value
/// loses digits, a second pass backward (stable), with half as many terms again, in which
/// every odd level 1 + d_{2m+1}/t uses 1 + d_{2m+1} written without cancellation,
///
/// ```text
/// 1 + d_{2m+1} = ((α+2m)(α+2m+1) s + w (α(2m+½) + 3m² + 3m/2)) / ((α+2m)(α+2m+1))
/// ```
///
/// (s = 1 − w given separately): for large C and w → 1 the plain 1 + d_{2m+1} loses
/// log₁₀ C digits. The backward pass carries t as a fraction P/Q with every denominator
/// multiplied out, so it divides once at the end (an even and an odd level at a time:
/// t' = (r q P + p n Q) / (p (q P + n Q)) with d_even = n/q, 1 + d_odd = r/p), rescaling P, Q
/// by powers of two, which leaves P/Q exact.
pub(crate) fn beta_cf_delta(c: f64, s: f64, w: f64) -> f64 {
    beta_cf_delta_tabulated(c, s, w, None)
}

/// The w-free factors of the continued-fraction coefficients of `beta_cf_delta` for one C:
/// d_j = κ_j w, tabulated in pairs (κ_{2m+1}, κ_{2m+2}), m = 1 … `TABLE_PAIRS`, so that a model
/// evaluating Λ many times at one C spends no division per level.
#[derive(Debug, Clone, PartialEq)]
pub struct BetaCfTable {
    pairs: Vec<[f64; 2]>,
}

/// Pairs of levels tabulated (the fraction rarely needs more than 60 levels for C ≤ 100).
const TABLE_PAIRS: usize = 64;

impl BetaCfTable {
    /// The table for C (> 1).
    pub fn new(c: f64) -> Self {
        let alpha = c - 1.0;
        let beta = 0.5;
        let pairs = (1..=TABLE_PAIRS)
            .map(|m| {
                let m = m as f64;
                let (e0, e1, e2) = (
                    alpha + 2.0 * m,
                    alpha + 2.0 * m + 1.0,
                    alpha + 2.0 * m + 2.0,
                );
                [
                    -(alpha + m) * (alpha + beta + m) / (e0 * e1),
                    (m + 1.0) * (beta - m - 1.0) / (e1 * e2),
                ]
            })
            .collect();
        Self { pairs }
    }
}

/// `beta_cf_delta` with the coefficients of the first levels read from `table` (which must
/// be `BetaCfTable::new(c)`), where given.
pub(crate) fn beta_cf_delta_tabulated(c: f64, s: f64, w: f64, table: Option<&BetaCfTable>) -> f64 {
    /// Up to this C the forward value serves: its errors against mpmath are those of the
    /// backward pass (`reference/golden/student.json`, C ≤ 100, and 280 more points at
    /// C ∈ {1.7, 2.5, 3, 7.5, 20, 50, 100}, a = 0.3 … 25: the same maxima to three digits);
    /// at C = 10⁴ it loses up to 4e-14 (1 + d_{2m+1} cancels).
    const FORWARD_MAX: f64 = 100.0;
    let alpha = c - 1.0;
    let beta = 0.5;
    // d_{2m} = n/q and 1 + d_{2m+1} = r/p, numerators and denominators apart.
    let even = |m: f64| -> (f64, f64) {
        (
            m * (beta - m) * w,
            (alpha + 2.0 * m - 1.0) * (alpha + 2.0 * m),
        )
    };
    let odd = |m: f64| -> (f64, f64) {
        let p = (alpha + 2.0 * m) * (alpha + 2.0 * m + 1.0);
        (
            p * s + w * (alpha * (2.0 * m + 0.5) + 3.0 * m * m + 1.5 * m),
            p,
        )
    };
    // Forward: continuants of 1 + d₃/(1 + d₄/(1 + …)) from A₋₁ = 1, B₋₁ = 0, A₀ = B₀ = 1; the
    // determinant starts at −1. Rescaled (all by the same power of two, the determinant by its
    // square) if they leave [1e-100, 1e100].
    const BIG: f64 = 8.749_002_899_132_048e99; // 2^332
    const SMALL: f64 = 1.142_987_391_282_275e-100; // 2^-332
    let (mut a_prev, mut b_prev, mut a, mut b) = (1.0, 0.0, 1.0, 1.0);
    let mut det: f64 = -1.0;
    let mut needed = None;
    // Levels in pairs j = 2m+1, 2m+2 (m = 1, 2, …), sharing one division:
    // d_{2m+1} = −(α+m)(α+β+m)w (α+2m+2) / P,  d_{2m+2} = (m+1)(β−m−1)w (α+2m) / P,
    // P = (α+2m)(α+2m+1)(α+2m+2).
    let mut j = 3;
    'pairs: while j < MAX_TERMS {
        let pair = match table.and_then(|t| t.pairs.get(j / 2 - 1)) {
            Some(&[odd, even]) => [odd * w, even * w],
            None => {
                let m = (j / 2) as f64;
                let (e0, e1, e2) = (
                    alpha + 2.0 * m,
                    alpha + 2.0 * m + 1.0,
                    alpha + 2.0 * m + 2.0,
                );
                let inverse = w / (e0 * e1 * e2);
                [
                    -(alpha + m) * (alpha + beta + m) * e2 * inverse,
                    (m + 1.0) * (beta - m - 1.0) * e0 * inverse,
                ]
            }
        };
        for (k, d) in pair.into_iter().enumerate() {
            let (a_next, b_next) = (a + d * a_prev, b + d * b_prev);
            det *= -d;
            (a_prev, b_prev, a, b) = (a, b, a_next, b_next);
            if det.abs() < 1e-16 * (a_prev * b).abs() {
                needed = Some(j + k);
                break 'pairs;
            }
        }
        let size = b.abs();
        if size > BIG {
            (a_prev, b_prev, a, b) = (a_prev * SMALL, b_prev * SMALL, a * SMALL, b * SMALL);
            det *= SMALL * SMALL;
        } else if size < SMALL {
            (a_prev, b_prev, a, b) = (a_prev * BIG, b_prev * BIG, a * BIG, b * BIG);
            det *= BIG * BIG;
        }
        j += 2;
    }
    let Some(needed) = needed else {
        return f64::NAN;
    };
    if c <= FORWARD_MAX {
        // t₃ = Aₙ/Bₙ: the forward value is as accurate as the backward one here.
        let (n, q) = even(1.0);
        return n * b / (q * a);
    }
    // Backward from an odd depth 2M + 1: t = (1 + d_{2M+1}) = r/p, then pairs of levels.
    let depth = (needed + needed / 2 + 10) | 1;
    let (r, p) = odd((depth / 2) as f64);
    let (mut big_p, mut big_q) = (r, p);
    for m in (1..depth / 2).rev() {
        let m = m as f64;
        let (n, q) = even(m + 1.0);
        let (r, p) = odd(m);
        let qp_nq = q * big_p + n * big_q;
        (big_p, big_q) = (r * q * big_p + p * n * big_q, p * qp_nq);
        if big_q > BIG {
            (big_p, big_q) = (big_p * SMALL, big_q * SMALL);
        }
    }
    // δ = d₂ / t₃.
    let (n, q) = even(1.0);
    n * big_q / (q * big_p)
}

/// The denominator Cτ − (C − ½)w of K, as C s + w/2 + Cδ (no cancellation for large C).
#[inline]
pub(crate) fn beta_cf_k_denominator(c: f64, s: f64, w: f64, delta: f64) -> f64 {
    c * s + 0.5 * w + c * delta
}

/// K = 1/(1 + d₁/τ) = Cτ/(Cτ − (C − ½)w), the continued fraction of (T).
#[inline]
pub(crate) fn beta_cf_k(c: f64, s: f64, w: f64, delta: f64) -> f64 {
    c * (1.0 + delta) / beta_cf_k_denominator(c, s, w, delta)
}

/// ₂F₁(½, C − ½; 3/2; z) for z ≤ 0 and C > 1 (document 001 eq 21 needs C > 3/2).
///
/// ```text
/// ₂F₁(½, C−½; 3/2; −x²) = (1/x) ∫₀ˣ (1 + q²)^{½−C} dq
/// ```
///
/// by (P) or (T) of the module comment. Relative error ≤ 2e-15 against mpmath over
/// C ∈ (1.5, 10⁸], z ∈ (−∞, 0] (`reference/golden/student.json`); NaN for C ≤ 1, z > 0 or NaN
/// arguments. Cost: 40–100 ns for C ≤ 20; up to ~2 µs for C ≥ 10⁴ where (T) needs ~85/a²
/// continued-fraction steps, a = x √(C−1) ≈ 1.
pub fn hyp2f1_lambda(c: f64, z: f64) -> f64 {
    if !(c > 1.0) || !(z <= 0.0) {
        return f64::NAN;
    }
    if z == 0.0 {
        return 1.0;
    }
    if z == f64::NEG_INFINITY {
        return 0.0;
    }
    let x2 = -z;
    if use_pfaff(c, x2 / (1.0 + x2)) {
        pfaff_form(c, x2)
    } else {
        tail_form(c, x2)
    }
}

/// (P): (1 + x²)^{½−C} Σₙ (C−½)ₙ/(3/2)ₙ sⁿ.
fn pfaff_form(c: f64, x2: f64) -> f64 {
    ((0.5 - c) * x2.ln_1p()).exp() * pfaff_series(c, x2 / (1.0 + x2))
}

/// (T): 1/(2 N x) − w^{C−½} K / (2(C − 1)).
fn tail_form(c: f64, x2: f64) -> f64 {
    let x = x2.sqrt();
    let s = x2 / (1.0 + x2);
    let w = 1.0 / (1.0 + x2);
    let k = beta_cf_k(c, s, w, beta_cf_delta(c, s, w));
    let w_power = ((0.5 - c) * x2.ln_1p()).exp();
    0.5 / (student_norm(c) * x) - w_power * k / (2.0 * (c - 1.0))
}

/// The Gauss series Σ (a)ₙ(b)ₙ/((c)ₙ n!) zⁿ for |z| < 1: the stand-in for GSL's
/// `gsl_sf_hyperg_2F1` in Algorithm 2 (which sums the same series there). NaN where c is a
/// non-positive integer (a pole, GSL's domain error) or |z| ≥ 1.
pub fn gauss_series(a: f64, b: f64, c: f64, z: f64) -> f64 {
    if !(z.abs() < 1.0) || (c <= 0.0 && c.fract() == 0.0) {
        return f64::NAN;
    }
    let mut term = 1.0;
    let mut sum = 1.0;
    for n in 0..MAX_TERMS {
        let k = n as f64;
        term *= (a + k) * (b + k) / ((c + k) * (k + 1.0)) * z;
        sum += term;
        if term == 0.0 || term.abs() <= sum.abs() * 1e-17 {
            return sum;
        }
    }
    f64::NAN
}

/// Γ by statrs (Lanczos; NaN or ±∞ at the poles 0, −1, −2, …).
fn gamma(x: f64) -> f64 {
    statrs::function::gamma::gamma(x)
}

/// Document 001 §8 Algorithm 2 **as printed** (a = ½, b = γ − ½, c = 3/2; GSL's 2F1 replaced by
/// `gauss_series`):
///
/// ```text
/// 1:  if z == 0 then return ∞
/// 4:  if z ≤ −1 then normalZ ← z/(z − 1)
/// 5:    if γ ≥ 12 ∥ normalZ ≥ 0.99 then                       // A&S 15.3.7
/// 6:      x ← Γ(3/2)Γ(γ)/Γ(γ−½) (−z)^{−a} 2F1(½, γ−½, 2−γ, 1/z)
/// 7:      y ← Γ(3/2)Γ(1−γ)/(Γ(½)Γ(2−γ)) (−z)^{−b} 2F1(γ−½, γ−1, γ, 1/z)
/// 9:      return x + y
/// 9:    else if γ = 2 ∥ γ ≥ 12 then return (1−z)^{−b} 2F1(γ−½, 1, 3/2, normalZ)   // 15.3.5
/// 12:   else return (1−z)^{−a} 2F1(γ−½, 2−γ, 3/2, normalZ)                     // 15.3.4
/// 15: else return 2F1(½, γ−½, 3/2, z)
/// ```
///
/// Wrong as printed (ERRATA.md): line 1 (₂F₁(…; 0) = 1), line 6 (the prefactor is
/// Γ(3/2)Γ(γ−1)/Γ(γ−½) and the series is ₂F₁(½, 0; 2−γ; 1/z) = 1), line 12 (the first
/// parameter is ½), line 7 at integer γ (Γ(1−γ)/Γ(2−γ) is a 0/0 pole ratio whose limit is
/// 1/(1−γ)), and the unreachable `γ ≥ 12` of line 9. Kept only to measure.
pub fn hyp2f1_lambda_algorithm2(c: f64, z: f64) -> f64 {
    if z == 0.0 {
        return f64::INFINITY;
    }
    let (a, b) = (0.5, c - 0.5);
    if z <= -1.0 {
        let normal_z = z / (z - 1.0);
        if c >= 12.0 || normal_z >= 0.99 {
            let x = gamma(1.5) * gamma(c) / gamma(c - 0.5)
                * (-z).powf(-a)
                * gauss_series(0.5, c - 0.5, 2.0 - c, 1.0 / z);
            let y = gamma(1.5) * gamma(1.0 - c) / (gamma(0.5) * gamma(2.0 - c))
                * (-z).powf(-b)
                * gauss_series(c - 0.5, c - 1.0, c, 1.0 / z);
            x + y
        } else if c == 2.0 || c >= 12.0 {
            (1.0 - z).powf(-b) * gauss_series(c - 0.5, 1.0, 1.5, normal_z)
        } else {
            (1.0 - z).powf(-a) * gauss_series(c - 0.5, 2.0 - c, 1.5, normal_z)
        }
    } else {
        gauss_series(0.5, c - 0.5, 1.5, z)
    }
}

/// The most terms the positive series of the corrected Algorithm 2 may take (about 0.3 s):
/// beyond, `lambda_algorithm2_corrected` returns NaN and the route answers a typed error
/// (`algorithm2_terms_needed`).
pub const ALGORITHM2_MAX_TERMS: f64 = 1e8;

/// Σₘ (a)ₘ/(c)ₘ zᵐ (b = 1) for 0 ≤ z < 1 and a, c > 0: ₂F₁(a, 1; c; z), every term
/// positive, summed until the tail cannot change the sum: the ratios of successive terms
/// (a+n)z/(c+n) move monotonically towards z, so past the n-th term they stay below
/// r = max(z, (a+n)z/(c+n)) and the tail is below term·r/(1 − r).
fn series_b1(a: f64, c: f64, z: f64) -> f64 {
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut n = 0.0;
    while n < ALGORITHM2_MAX_TERMS {
        term *= (a + n) / (c + n) * z;
        sum += term;
        n += 1.0;
        let r = z.max((a + n) / (c + n) * z);
        if r < 1.0 && term * r <= sum * 1e-17 * (1.0 - r) {
            return sum;
        }
    }
    f64::NAN
}

/// The terms `series_b1` needs at ratio ≤ w = 1/(1 + x²) (the 15.3.7 form of
/// `lambda_algorithm2_corrected`): ln(1e-17 (1 − w))/ln w + 1.
pub fn algorithm2_terms_needed(x: f64) -> f64 {
    let w = 1.0 / (1.0 + x * x);
    let one_minus_w = x * x / (1.0 + x * x);
    (1e-17 * one_minus_w).ln() / w.ln() + 1.0
}

/// Document 001 §8 Algorithm 2 with its printed errors corrected (line 1 returns 1; line 6 is
/// Γ(3/2)Γ(γ−1)/Γ(γ−½) (−z)^{−½}, the series ₂F₁(½, 0; 2−γ; 1/z) = 1; line 7 uses
/// Γ(1−γ)/Γ(2−γ) = 1/(1−γ)), and with every series put in a form whose terms are all positive
/// (the issue-12 defect: the Gauss series of line 15 and of line 7 alternate, and for γ = 50
/// cancel to Λ = −1.5e11 where Λ = 1.3e-15):
///
/// ```text
/// z ≤ −1 (lines 4–9, A&S 15.3.7, then 15.3.4 on the second series, w = 1/(1 − z)):
///   ₂F₁ = 1/(2 N x) − (1 − z)^{½−γ} ₂F₁(γ−½, 1; γ; w) / (2(γ − 1))
/// −1 < z ≤ 0 (line 10, A&S 15.3.5, for every γ, not only γ = 2; s = z/(z − 1)):
///   ₂F₁ = (1 − z)^{½−γ} ₂F₁(γ−½, 1; 3/2; s)
/// ```
///
/// with x = √(−z), N = Γ(γ−½)/(√π Γ(γ−1)). NaN for γ ≤ 1 or z > 0.
pub fn hyp2f1_lambda_algorithm2_corrected(c: f64, z: f64) -> f64 {
    if !(c > 1.0) || !(z <= 0.0) {
        return f64::NAN;
    }
    if z == 0.0 {
        return 1.0;
    }
    let x2 = -z;
    let power = ((0.5 - c) * x2.ln_1p()).exp();
    if z <= -1.0 {
        let w = 1.0 / (1.0 + x2);
        0.5 / (student_norm(c) * x2.sqrt()) - power * series_b1(c - 0.5, c, w) / (2.0 * (c - 1.0))
    } else {
        power * series_b1(c - 0.5, 1.5, x2 / (1.0 + x2))
    }
}

/// Λ_C(x) where no route needs computing, shared by every Λ_C route (`student_tail`'s and
/// [`lambda_algorithm2_corrected`]): NaN outside the domain (C ≤ 3/2, x NaN or < 0), +∞
/// at x = 0 (grazing), 0 at x = +∞ (normal incidence); None inside (0, ∞).
pub fn lambda_edges(c: f64, x: f64) -> Option<f64> {
    if !(c > 1.5) || x.is_nan() || x < 0.0 {
        Some(f64::NAN)
    } else if x == 0.0 {
        Some(f64::INFINITY)
    } else if x == f64::INFINITY {
        Some(0.0)
    } else {
        None
    }
}

/// Λ_C(x) by document 001 eq 21 with ₂F₁ from the corrected Algorithm 2
/// (`hyp2f1_lambda_algorithm2_corrected`), the difference of eq 21 taken where it cancels:
///
/// In the 15.3.7 form, N x · Γ(3/2)Γ(γ−1)/Γ(γ−½) (−z)^{−½} = ½ exactly, so eq 21's − ½ cancels
/// algebraically, and with ₂F₁(γ−½, 1; γ; w)(1 − w) = 1 − Σ_{n≥1} (γ−½)_{n−1}/(γ)_{n−1}
/// wⁿ/(2(γ+n−1)) (the 15.3.4 series times 1 − w, term by term) the remaining difference
/// 1/(2γ−3) − 1/(2γ−2) is exact too:
///
/// ```text
/// Λ = N (1 + x²)^{3/2−γ} / x · [ 1/((2γ−3)(2γ−2)) + w ₂F₁(γ−½, 1; γ+1; w) / (4γ(γ−1)) ]
/// ```
///
/// every term positive (w = 1/(1 + x²)). It serves wherever the line-10 form would cancel
/// (Λ < 0.02, or γ s > 2 where its series grows before it converges); elsewhere eq 21 is
/// summed as printed with the line-10 ₂F₁ (relative error ≤ 32ε/Λ ≤ 2e-13 there). Measured
/// against the stable route: see `tests::algorithm2_corrected_at_the_stress_gammas`. NaN where
/// the series would need more than `ALGORITHM2_MAX_TERMS` terms.
pub fn lambda_algorithm2_corrected(c: f64, x: f64) -> f64 {
    if let Some(edge) = lambda_edges(c, x) {
        return edge;
    }
    let x2 = x * x;
    let n = student_norm(c);
    let s = x2 / (1.0 + x2);
    let w = 1.0 / (1.0 + x2);
    // (1 + x²)^{3/2−C}
    let power = ((1.5 - c) * x2.ln_1p()).exp();
    if x2 < 1.0 && c * s <= 2.0 {
        let f = ((0.5 - c) * x2.ln_1p()).exp() * series_b1(c - 0.5, 1.5, s);
        let eq21 = n * power / ((2.0 * c - 3.0) * x) + n * x * f - 0.5;
        if eq21 >= EQ21_MIN {
            return eq21;
        }
    }
    if algorithm2_terms_needed(x) > ALGORITHM2_MAX_TERMS {
        return f64::NAN;
    }
    let bracket =
        1.0 / ((2.0 * c - 3.0) * (2.0 * c - 2.0)) + w * tail_series(c, x2) / (4.0 * c * (c - 1.0));
    n * power / x * bracket
}

/// ₂F₁(C−½, 1; C+1; w), w = 1/(1 + x²), the positive series of the 15.3.7 form. Near w = 1
/// (large C, a = x√(C−1) ≈ 1–6) it takes 10⁴–10⁷ terms, and a running product of the term
/// ratios would carry n roundings and the rounding of w to the n-th power (1.1e-13 measured at
/// C = 1000, a = 1.08). So every `ANCHOR` terms the term is recomputed from
///
/// ```text
/// (C−½)ₙ/(C+1)ₙ = C g(C−½) / ((C+n) g(C+n−½)),   g(y) = Γ(y+½)/Γ(y),   wⁿ = e^{−n ln(1+x²)}
/// ```
///
/// (`gamma_half_ratio`, a few ulps), and the running product only bridges the gaps.
fn tail_series(c: f64, x2: f64) -> f64 {
    const ANCHOR: u64 = 64;
    let l = x2.ln_1p();
    let w = 1.0 / (1.0 + x2);
    let one_minus_w = x2 / (1.0 + x2);
    let base = c * gamma_half_ratio(c - 0.5);
    let (mut sum, mut comp) = (1.0f64, 0.0f64);
    let mut term = 1.0;
    let mut n = 0.0;
    while n < ALGORITHM2_MAX_TERMS {
        term *= (c - 0.5 + n) / (c + 1.0 + n) * w;
        n += 1.0;
        // n is an integer below 2⁵³: its remainder in integers (an f64 `%` is a libm `fmod`
        // call per term, 1.5 % of the quick audit).
        if n as u64 % ANCHOR == 0 {
            term = base / ((c + n) * gamma_half_ratio(c + n - 0.5)) * (-n * l).exp();
        }
        // Neumaier's compensated sum.
        let t = sum + term;
        comp += (sum - t) + term;
        sum = t;
        if term * w <= (sum + comp) * 1e-17 * one_minus_w {
            return sum + comp;
        }
    }
    f64::NAN
}

/// Below this Λ, `lambda_algorithm2_corrected` leaves eq 21's difference for the
/// cancellation-free 15.3.7 form (eq 21's absolute error ≈ 4ε).
const EQ21_MIN: f64 = 0.02;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{golden, rel_err};

    #[test]
    fn matches_mpmath_over_the_half_line() {
        let mut worst: (f64, f64, f64) = (0.0, 0.0, 0.0);
        for row in golden("hyp2f1") {
            let c = row["c"].as_f64().unwrap();
            let z = row["z"].as_f64().unwrap();
            let want: f64 = row["value"].as_str().unwrap().parse().unwrap();
            let e = rel_err(hyp2f1_lambda(c, z), want);
            if e > worst.0 {
                worst = (e, c, z);
            }
            assert!(
                e < 2e-15,
                "C = {c}, z = {z}: {} vs {want} ({e:e})",
                hyp2f1_lambda(c, z)
            );
        }
        eprintln!(
            "₂F₁ max relative error {:.2e} at C = {}, z = {}",
            worst.0, worst.1, worst.2
        );
    }

    #[test]
    fn continuous_across_the_switch_and_at_integer_c() {
        for &c in &[2.0, 3.0, 12.0, 12.5, 1e3] {
            // s (C + 3/2) = SWITCH ⇔ x² = SWITCH/(C + 3/2 − SWITCH)
            let x2 = SWITCH / (c + 1.5 - SWITCH);
            let (p, t) = (pfaff_form(c, x2), tail_form(c, x2));
            assert!(rel_err(p, t) < 4e-15, "C = {c}: {p} vs {t}");
        }
        // Integer and near-integer C agree (no Γ poles in either representation).
        for &z in &[-0.5, -2.0, -50.0] {
            let at = hyp2f1_lambda(3.0, z);
            let near = hyp2f1_lambda(3.0 + 1e-12, z);
            assert!(rel_err(at, near) < 1e-11, "z = {z}: {at} vs {near}");
        }
    }

    #[test]
    fn domain_and_end_points() {
        assert_eq!(hyp2f1_lambda(2.5, 0.0), 1.0);
        assert_eq!(hyp2f1_lambda(2.5, f64::NEG_INFINITY), 0.0);
        assert!(hyp2f1_lambda(2.5, 0.5).is_nan());
        assert!(hyp2f1_lambda(1.0, -1.0).is_nan());
        assert!(hyp2f1_lambda(f64::NAN, -1.0).is_nan());
        // C = 2: ₂F₁(½, 3/2; 3/2; z) = (1 − z)^{−½}.
        for &z in &[-1e-10f64, -0.3, -1.0, -7.0, -1e12] {
            let want = (1.0 - z).powf(-0.5);
            assert!(rel_err(hyp2f1_lambda(2.0, z), want) < 1e-15);
        }
    }

    #[test]
    fn printed_algorithm2_fails_where_errata_say() {
        // Line 1: returns ∞ at z = 0 where ₂F₁ = 1.
        assert_eq!(hyp2f1_lambda_algorithm2(2.5, 0.0), f64::INFINITY);
        // Line 12 (γ = 5/2, z = −3): wrong first parameter.
        let want = hyp2f1_lambda(2.5, -3.0);
        assert!(rel_err(hyp2f1_lambda_algorithm2(2.5, -3.0), want) > 1e-3);
        assert!(rel_err(hyp2f1_lambda_algorithm2_corrected(2.5, -3.0), want) < 1e-13);
        // Line 6 (γ = 12.5, z = −3: 15.3.7 branch): wrong prefactor and series.
        let want = hyp2f1_lambda(12.5, -3.0);
        let printed = hyp2f1_lambda_algorithm2(12.5, -3.0);
        assert!(!(rel_err(printed, want) < 1e-3), "{printed} vs {want}");
        let corrected = hyp2f1_lambda_algorithm2_corrected(12.5, -3.0);
        assert!(rel_err(corrected, want) < 1e-8, "{corrected} vs {want}");
        // Integer γ in the 15.3.7 branch: Γ(1 − γ)/Γ(2 − γ) at the poles.
        assert!(
            !hyp2f1_lambda_algorithm2(12.0, -3.0).is_finite()
                || rel_err(
                    hyp2f1_lambda_algorithm2(12.0, -3.0),
                    hyp2f1_lambda(12.0, -3.0)
                ) > 1e-3
        );
        // Where the printed algorithm is right (|z| < 1, γ = 2 branch) it agrees.
        assert!(
            rel_err(
                hyp2f1_lambda_algorithm2(3.5, -0.5),
                hyp2f1_lambda(3.5, -0.5)
            ) < 1e-13
        );
        assert!(
            rel_err(
                hyp2f1_lambda_algorithm2(2.0, -5.0),
                hyp2f1_lambda(2.0, -5.0)
            ) < 1e-13
        );
    }

    /// The corrected Algorithm 2 against the stable route (itself ≤ 2e-14 against mpmath) at
    /// the stress shapes (γ ∈ {20, 50, 90}), over θ from 1e-6 to π/2 − 1e-6 and three roughnesses.
    #[test]
    fn algorithm2_corrected_at_the_stress_gammas() {
        use crate::special::student_tail::student_lambda;
        let mut overall: f64 = 0.0;
        for &c in &[1.6, 2.0, 2.5, 3.0, 7.5, 20.0, 50.0, 90.0, 171.8, 1e3, 1e6] {
            let mut worst: (f64, f64) = (0.0, 0.0);
            for &alpha in &[0.05, 0.3, 1.0] {
                let scale = alpha * (c - 1.0f64).sqrt();
                let thetas = (0..=24)
                    .map(|i| 1e-6 + (std::f64::consts::FRAC_PI_2 - 2e-6) * i as f64 / 24.0)
                    .chain([1e-3, 0.5, 1.2, 1.5, std::f64::consts::FRAC_PI_2 - 1e-6]);
                for theta in thetas {
                    let x = 1.0 / (theta.tan() * scale);
                    let want = student_lambda(c, x);
                    if !(want >= 1e-300) {
                        continue;
                    }
                    let got = lambda_algorithm2_corrected(c, x);
                    let e = rel_err(got, want);
                    assert!(
                        e <= 1e-13,
                        "γ = {c}, α = {alpha}, θ = {theta}, x = {x}: {got:e} vs {want:e} ({e:.1e})"
                    );
                    if e > worst.0 {
                        worst = (e, x);
                    }
                }
            }
            eprintln!(
                "algorithm2_corrected γ = {c}: max rel err {:.2e} (at x = {:.3e})",
                worst.0, worst.1
            );
            overall = overall.max(worst.0);
        }
        // The two stress-case defects: γ = 50, θ = 0.5 and γ = 90 (STD, α = 0.3).
        for &(c, theta) in &[(50.0, 0.5), (90.0, 0.5), (90.0, 1.2)] {
            let x = 1.0 / (f64::tan(theta) * 0.3 * (c - 1.0f64).sqrt());
            let (got, want) = (lambda_algorithm2_corrected(c, x), student_lambda(c, x));
            assert!(rel_err(got, want) < 1e-13, "γ = {c}: {got:e} vs {want:e}");
        }
        assert!(overall > 0.0);
    }

    #[test]
    fn gauss_series_domain() {
        assert!(gauss_series(0.5, 1.0, -2.0, 0.3).is_nan());
        assert!(gauss_series(0.5, 1.0, 1.5, 1.0).is_nan());
        assert!(rel_err(gauss_series(1.0, 1.0, 2.0, -0.5), 1.5f64.ln() / 0.5) < 1e-15);
    }
}
