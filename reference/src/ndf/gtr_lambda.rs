//! The routes to Smith Λ and G1 of the GTR NDF (document 004, Dimov 2015): the numerical default
//! valid for every γ, the §3 closed forms for γ = 0, 1, 2, 3, 4 (rearranged without
//! cancellation, and as printed), the §3 "implementation" G1 forms, and the §5–6 spline in γ;
//! also D's normalization constant c, which the numerical route integrates against (the model,
//! `ndf::gtr`, builds on this file).
//!
//! Every route is a function of γ, α and μ = |cot θ_v| ≥ 0 (GTR is isotropic). Λ(0) = ∞
//! (grazing) and Λ(∞) = 0 (normal incidence) on every route: those are the definition's end
//! points, not any formula's.

use crate::error::QueryError;
use crate::special::gauss_kronrod;
use std::f64::consts::PI;

/// The normalization constant c of D_GTR (document 004 eq 1**, 4**) in the form
/// c = expm1(L) / (π · expm1(sL)/s), s = 1 − γ, L = log α², with the limits expm1(sL)/s → L at
/// s = 0 (γ = 1, eq 4**) and c → 1/π at L = 0 (α = 1). No 0/0 anywhere; relative accuracy a few
/// ulps for 0 ≤ γ ≤ 10, 1e-4 ≤ α ≤ 1.
pub fn normalization_constant(gamma: f64, alpha: f64) -> f64 {
    let l = 2.0 * alpha.ln();
    if l == 0.0 {
        return 1.0 / PI;
    }
    let s = 1.0 - gamma;
    let denominator = if s == 0.0 { l } else { (s * l).exp_m1() / s };
    l.exp_m1() / (PI * denominator)
}

/// The named routes with a one-line description; the first is the default.
pub const ROUTES: &[(&str, &str)] = &[
    (
        "exact",
        "Λ = 2cμ²∫ sinψ (sinψ − ψ cosψ)(μ²+cos²ψ)^(γ−2)(μ²+α²cos²ψ)^(−γ) dψ by adaptive \
         Gauss–Kronrod, any γ ≥ 0, relative error ≤ 1e-12",
    ),
    (
        "closed_form",
        "seed 004 §3.1–3.5 Λ^γ, γ ∈ {0, 1, 2, 3, 4}, rearranged without cancellation",
    ),
    (
        "closed_form_printed",
        "seed 004 §3.1–3.5 Λ^γ evaluated exactly as printed, γ ∈ {0, 1, 2, 3, 4}",
    ),
    (
        "implementation",
        "seed 004 §3 simplified G1 forms of the implementation (γ = 1, 3, 4; G1^0 and eq 34* \
         for γ = 0, 2), Λ = 1/G1 − 1",
    ),
    (
        "spline",
        "seed 004 §5–6: natural cubic spline in γ of G1 through γ = 0…4, γ > 4 clamped to 4; \
         claimed ≈0.1 % error",
    ),
];

/// Looks up a route and checks that it applies at (γ, α). Returns Λ(μ) for μ ∈ [0, ∞].
pub fn lambda(route: &str, gamma: f64, alpha: f64, mu: f64) -> Result<f64, QueryError> {
    let unavailable = |reason: String| QueryError::Route {
        route: route.to_string(),
        reason,
    };
    let closed = |name: &str| -> Result<u8, QueryError> {
        integer_gamma(gamma).ok_or_else(|| QueryError::Route {
            route: name.to_string(),
            reason: format!(
                "seed 004 §3 derives closed forms for γ ∈ {{0, 1, 2, 3, 4}} only (got {gamma})"
            ),
        })
    };
    match route {
        "default" | "exact" => Ok(lambda_exact(gamma, alpha, mu)),
        "closed_form" => Ok(lambda_closed_form(closed(route)?, alpha, mu)),
        "closed_form_printed" | "implementation" => {
            let k = closed(route)?;
            if k == 1 && alpha == 1.0 {
                return Err(unavailable(
                    "the printed γ = 1 form divides by log α² = 0 at α = 1 (0/0)".to_string(),
                ));
            }
            Ok(if route == "implementation" {
                lambda_from_g1(g1_implementation(k, alpha, mu))
            } else {
                lambda_closed_form_printed(k, alpha, mu)
            })
        }
        "spline" => Ok(lambda_from_g1(g1_spline(gamma, alpha, mu))),
        _ => {
            let known: Vec<&str> = ROUTES.iter().map(|r| r.0).collect();
            Err(unavailable(format!("known routes: {}", known.join(", "))))
        }
    }
}

/// γ as one of the closed-form cases 0, 1, 2, 3, 4, if it is exactly one of them.
pub fn integer_gamma(gamma: f64) -> Option<u8> {
    [0u8, 1, 2, 3, 4]
        .into_iter()
        .find(|&k| gamma == f64::from(k))
}

/// Λ = 1/G1 − 1 (the routes that approximate or simplify G1, not Λ). Loses the relative
/// accuracy of Λ where Λ ≪ 1 (G1 → 1): compare these routes in G1.
#[inline]
pub fn lambda_from_g1(g1: f64) -> f64 {
    1.0 / g1 - 1.0
}

/// The definition's end points: Λ(μ = 0) = ∞ (grazing), Λ(μ = ∞) = 0 (normal incidence).
#[inline]
fn end_points(mu: f64) -> Option<f64> {
    if mu == 0.0 {
        Some(f64::INFINITY)
    } else if mu == f64::INFINITY {
        Some(0.0)
    } else if mu.is_nan() {
        Some(f64::NAN)
    } else {
        None
    }
}

/// Below this μ the exact route uses Λ(μ) = m₁/μ − ½ + O(μ) with the mean positive slope m₁
/// taken from Λ(MU_SMALL): the O(μ) term, μ P2(0)/2 ≤ 1e4 μ, is below f64 resolution there.
const MU_SMALL: f64 = 1e-100;
/// Above this μ the exact route uses Λ = cπ/(4μ²) (1 + O(γ/μ²)), exact in f64.
const MU_LARGE: f64 = 1e9;

/// The default route: Smith Λ of GTR from its definition (document 004 eq 48*,
/// Λ = (1/μ) ∫_μ^∞ (q − μ) P2(q) dq with P2 = ∫ P22 dp), reduced to one integral. In polar
/// slope coordinates (r, φ), ∫∫_{q>μ} (q − μ) P22 = 2 ∫_μ^∞ r P22(r) (√(r² − μ²) − μ acos(μ/r))
/// dr, and with r = μ / cos ψ:
///
/// ```text
/// Λ(μ) = 2cμ² ∫_0^{π/2} sinψ (sinψ − ψ cosψ) (μ² + cos²ψ)^{γ−2} (μ² + α² cos²ψ)^{−γ} dψ
/// ```
///
/// (c the normalization constant of D). This is evaluated with ψ = gd(s) (r = μ cosh s, so that
/// cos ψ = sech s is exact near the horizon and the scales r ≈ α and r ≈ 1 are evenly spaced in
/// s) by the adaptive G7/K15 rule of `special::gauss_kronrod` (hand-written: the crate may
/// not use the dev-only `quadrature`, which is the tests' independent oracle) on
/// s ∈ [0, asech(1e-17 min(μ, 1))]
/// plus the analytic tail 2c σ_min/μ², asking for an estimated relative error of 1e-14.
/// Beyond μ = 1e9, Λ = cπ/(4μ²); below μ = 1e-100, Λ = m₁/μ − ½. Valid for every γ ≥ 0 and
/// α ∈ (0, 1]; relative error ≤ 1e-12 (measured ≤ 2e-13 against the nested-quadrature integral
/// of P22 in the tests, for 0 ≤ γ ≤ 10, 1e-3 ≤ α ≤ 1, 1e-3 ≤ θ ≤ 1.57).
pub fn lambda_exact(gamma: f64, alpha: f64, mu: f64) -> f64 {
    lambda_exact_with(gamma, alpha, normalization_constant(gamma, alpha), mu)
}

/// `lambda_exact` with the normalization constant c given (the model caches it).
pub fn lambda_exact_with(gamma: f64, alpha: f64, c: f64, mu: f64) -> f64 {
    if let Some(v) = end_points(mu) {
        return v;
    }
    if mu > MU_LARGE {
        return c * PI / 4.0 / mu / mu;
    }
    if mu < MU_SMALL {
        let m1 = MU_SMALL * (lambda_exact_with(gamma, alpha, c, MU_SMALL) + 0.5);
        return m1 / mu - 0.5;
    }
    let a2 = alpha * alpha;
    let mu2 = mu * mu;
    let integrand = |s: f64| {
        let e = (-s).exp();
        let e2 = e * e;
        let sigma = 2.0 * e / (1.0 + e2); // sech s = cos ψ
        let tanh = -(-2.0 * s).exp_m1() / (1.0 + e2); // tanh s = sin ψ
        let psi = s.sinh().atan(); // gd(s)
        let b = sin_minus_psi_cos(psi, tanh, sigma);
        let sig2 = sigma * sigma;
        let den = mu2 + sig2;
        let ratio = den / (mu2 + a2 * sig2);
        2.0 * c * tanh * b * sigma * (mu2 / den) / den * ratio.powf(gamma)
    };
    // Truncate where cos ψ = σ_min ≪ μ: beyond, the integrand is (2c/μ²) sech s (1 + O(σ)), whose
    // integral is 2c·asin(σ_min)/μ² to relative O(σ_min).
    let sigma_min = 1e-17 * mu.min(1.0);
    let s_max = (2.0 / sigma_min).ln();
    let tail = 2.0 * c * sigma_min / mu2;
    let mut points = vec![0.0, s_max];
    // The scales of the integrand: cos ψ ≈ μ (r ≈ 1) and cos ψ ≈ μ/α (r ≈ α).
    for scale in [mu, mu / alpha] {
        if scale < 1.0 {
            let s = ((1.0 + (1.0 - scale * scale).sqrt()) / scale).ln();
            points.extend([s - 3.0, s, s + 3.0]);
        }
    }
    points.retain(|s| (0.0..=s_max).contains(s));
    points.sort_by(f64::total_cmp);
    let points = subdivide(&points, 4.0);
    gauss_kronrod::integrate(&integrand, &points, 1e-14, 0.0).value + tail
}

/// sin ψ − ψ cos ψ given sin ψ and cos ψ; by its series below ψ = 0.25, where the difference
/// cancels (the series Σ_{k≥1} (−1)^{k+1} 2k ψ^{2k+1}/(2k+1)!).
#[inline]
fn sin_minus_psi_cos(psi: f64, sin: f64, cos: f64) -> f64 {
    if psi < 0.25 {
        let p2 = psi * psi;
        let mut term = psi * p2 / 3.0; // k = 1
        let mut sum = term;
        for k in 2..10 {
            let k = k as f64;
            // term_k / term_{k−1} = −ψ² (k/(k−1)) / ((2k)(2k+1))
            term *= -p2 * k / ((k - 1.0) * (2.0 * k) * (2.0 * k + 1.0));
            sum += term;
        }
        sum
    } else {
        sin - psi * cos
    }
}

/// Splits every interval of an increasing list of points into pieces no longer than `max_len`.
pub(crate) fn subdivide(points: &[f64], max_len: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(points.len() * 2);
    for w in points.windows(2) {
        let n = ((w[1] - w[0]) / max_len).ceil().max(1.0) as usize;
        for i in 0..n {
            out.push(w[0] + (w[1] - w[0]) * i as f64 / n as f64);
        }
    }
    if let Some(&last) = points.last() {
        out.push(last);
    }
    out.dedup();
    out
}

/// (e^x − 1)/x, 1 at x = 0.
#[inline]
fn expm1_over(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.exp_m1() / x
    }
}

/// ln(1 + x)/x, 1 at x = 0.
#[inline]
fn ln1p_over(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.ln_1p() / x
    }
}

/// The integrals I_n = (1/μ) ∫_μ^∞ (q − μ)(q² + α²)^{−n/2} dq for n = 3, 5, 7, in closed form
/// without cancellation (S = √(μ² + α²), P = μ + S, and S − μ = α²/P):
///
/// ```text
/// I_3 = 1/(μ P),   I_5 = 1/(3 μ S P²),   I_7 = (3S + μ)/(15 μ S³ P³)
/// ```
fn i_odd(alpha: f64, mu: f64) -> [f64; 3] {
    let s = mu.hypot(alpha);
    let p = mu + s;
    let i3 = 1.0 / (mu * p);
    let i5 = i3 / (3.0 * s * p);
    let i7 = (3.0 * s + mu) / (15.0 * mu * s * s * s * p * p * p);
    [i3, i5, i7]
}

/// Document 004 §3.1–3.5, Λ^γ for γ = 0, 1, 2, 3, 4. The printed forms are correct (the tests check
/// each against the integral of its printed P2); here they are rearranged so that no step
/// cancels. With S = √(μ² + α²), S₁ = √(μ² + 1), β = 1 − α², L = ln α²:
///
/// ```text
/// printed (§3):
///   Λ⁰ = (√(μ²+1) − μ)/(2μ)
///   Λ¹ = (√(μ²+α²) − √(μ²+1) + μ asinh μ − μ log(μ + √(μ²+α²))) / (μ log α²)
///   Λ² = (√(μ²+α²) − μ)/(2μ)
///   Λ³ = (3α⁴ + 2μ(μ − S) + α²(1 + 2μ(μ − S))) / (4(1 + α²) μ S)
///   Λ⁴ = (15α⁸ + 3α⁴ + 8μ³(μ − S) + α⁶(6 + 24μ² − 8μS)
///         + 4α²(α²+1) μ (−2S + μ(3 + 2μ(μ − S)))) / (16(α⁴+α²+1) μ S³)
/// evaluated (P2^γ = K_γ Σ_j a_j (q²+α²)^{−(2j+3)/2}, integrated term by term):
///   Λ⁰ = I_3(α=1)/2,  Λ² = α² I_3 / 2
///   Λ¹ = (expm1(L)/L) (S + μ(1 − ln(1+x)/x)) / (μ (S₁ + S)(μ + S)),  x = β/((S₁+S)(μ+S))
///   Λ³ = α⁴/(4(1+α²)) (4 I_3 + 3β I_5)
///   Λ⁴ = 3α⁶/(16(α⁴+α²+1)) (8 I_3 + 12β I_5 + 5β² I_7)
/// ```
///
/// Valid for α ∈ (0, 1] (Λ¹ at α = 1 is its limit Λ⁰) and every μ ≥ 0 (every term is positive:
/// rounding error a few ulps; measured ≤ 2e-13 against the integral of the printed P2, the
/// oracle's own accuracy).
pub fn lambda_closed_form(k: u8, alpha: f64, mu: f64) -> f64 {
    if let Some(v) = end_points(mu) {
        return v;
    }
    let a2 = alpha * alpha;
    let beta = (1.0 - alpha) * (1.0 + alpha);
    match k {
        0 => 0.5 * i_odd(1.0, mu)[0],
        1 => {
            let s = mu.hypot(alpha);
            let s1 = mu.hypot(1.0);
            let x = beta / ((s1 + s) * (mu + s));
            let l = 2.0 * alpha.ln();
            expm1_over(l) * (s + mu * (1.0 - ln1p_over(x))) / (mu * (s1 + s) * (mu + s))
        }
        2 => 0.5 * a2 * i_odd(alpha, mu)[0],
        3 => {
            let [i3, i5, _] = i_odd(alpha, mu);
            a2 * a2 / (4.0 * (1.0 + a2)) * (4.0 * i3 + 3.0 * beta * i5)
        }
        4 => {
            let [i3, i5, i7] = i_odd(alpha, mu);
            3.0 * a2 * a2 * a2 / (16.0 * (a2 * a2 + a2 + 1.0))
                * (8.0 * i3 + 12.0 * beta * i5 + 5.0 * beta * beta * i7)
        }
        _ => f64::NAN,
    }
}

/// Document 004 §3.1–3.5, Λ^γ evaluated exactly as printed (formulas in `lambda_closed_form`).
/// Mathematically correct; the printed arithmetic subtracts nearly equal terms as μ grows
/// (near normal incidence): e.g. Λ² = (√(μ²+α²) − μ)/(2μ) has relative error ≈ 1e-16 · 4μ²/α²,
/// and Λ³, Λ⁴ cancel in their numerators likewise. Λ¹ is 0/0 at α = 1.
pub fn lambda_closed_form_printed(k: u8, alpha: f64, mu: f64) -> f64 {
    if let Some(v) = end_points(mu) {
        return v;
    }
    let a2 = alpha * alpha;
    let s = (mu * mu + a2).sqrt();
    match k {
        0 => ((mu * mu + 1.0).sqrt() - mu) / (2.0 * mu),
        1 => {
            let l = a2.ln();
            (s - (mu * mu + 1.0).sqrt() + mu * mu.asinh() - mu * (mu + s).ln()) / (mu * l)
        }
        2 => (s - mu) / (2.0 * mu),
        3 => {
            (3.0 * a2 * a2 + 2.0 * mu * (mu - s) + a2 * (1.0 + 2.0 * mu * (mu - s)))
                / (4.0 * (1.0 + a2) * mu * s)
        }
        4 => {
            let a4 = a2 * a2;
            let den = 16.0 * (a4 + a2 + 1.0) * mu * s * s * s;
            (15.0 * a4 * a4
                + 3.0 * a4
                + 8.0 * mu.powi(3) * (mu - s)
                + a4 * a2 * (6.0 + 24.0 * mu * mu - 8.0 * mu * s))
                / den
                + (4.0 * a2 * mu * (-2.0 * s + mu * (3.0 + 2.0 * mu * (mu - s))) * (a2 + 1.0)) / den
        }
        _ => f64::NAN,
    }
}

/// Document 004 §3: the G1 forms "of the implementation", exactly as printed:
///
/// ```text
/// γ = 0:  G1⁰ = 2 / (1 + √(1/μ² + 1))                                         (§3.1)
/// γ = 1:  G1¹ = μ log α² / (A − B + μ log(α²(μ + B)/(μ + A))),  A = √(μ²+α²), B = √(μ²+1)
/// γ = 2:  G1² = 2 / (1 + √(α²/μ² + 1))                                  (§3.3, eq 34*)
/// γ = 3:  G1³ = 4BμA / (α²(3α² + 1) + 2μB(μ + A)),  A = √(μ²+α²), B = α² + 1
/// γ = 4:  G1⁴ = 2AμB³ / (Aμ(B³ + μ³) + 3α²(α²(5α⁴+2α²+1) + 4μ²(2α⁴+α²+1))),
///         A = 8α⁴ + 8α² + 8, B = √(μ²+α²)
/// ```
///
/// Correct (equal to 1/(1 + Λ^γ): measured ≤ 1.4e-13 relative against the exact route in G1).
/// G1¹ is 0/0 at α = 1 and loses ≈ 1e-16/|log α²| relatively near it (the logarithm of a number
/// near 1). Valid for α ∈ (0, 1), μ ≥ 0.
pub fn g1_implementation(k: u8, alpha: f64, mu: f64) -> f64 {
    if mu == 0.0 {
        return 0.0;
    }
    if mu == f64::INFINITY {
        return 1.0;
    }
    let a2 = alpha * alpha;
    match k {
        0 => 2.0 / (1.0 + (1.0 / (mu * mu) + 1.0).sqrt()),
        1 => {
            let a = (mu * mu + a2).sqrt();
            let b = (mu * mu + 1.0).sqrt();
            mu * a2.ln() / (a - b + mu * (a2 * (mu + b) / (mu + a)).ln())
        }
        2 => 2.0 / (1.0 + (a2 / (mu * mu) + 1.0).sqrt()),
        3 => {
            let a = (mu * mu + a2).sqrt();
            let b = a2 + 1.0;
            4.0 * b * mu * a / (a2 * (3.0 * a2 + 1.0) + 2.0 * mu * b * (mu + a))
        }
        4 => {
            let a4 = a2 * a2;
            let a = 8.0 * a4 + 8.0 * a2 + 8.0;
            let b = (mu * mu + a2).sqrt();
            let b3 = b * b * b;
            2.0 * a * mu * b3
                / (a * mu * (b3 + mu.powi(3))
                    + 3.0
                        * a2
                        * (a2 * (5.0 * a4 + 2.0 * a2 + 1.0)
                            + 4.0 * mu * mu * (2.0 * a4 + a2 + 1.0)))
        }
        _ => f64::NAN,
    }
}

/// Document 004 §5–6: G1 for any γ ≥ 0 by spline interpolation in γ of the closed-form G1^γ at
/// γ = 0, 1, 2, 3, 4 (at the same α and μ), with γ > 4 clamped to 4 ("In the current
/// implementation γ is clamped up to 4"):
///
/// ```text
/// G1(γ) ≈ S(min(γ, 4)),  S the natural cubic spline (S'' = 0 at γ = 0 and 4) through
///         (k, G1^k(μ)), k = 0…4, G1^k = 1/(1 + Λ^k) (closed_form route)
/// ```
///
/// An approximation: the document claims "≈0.1 %" ("less than 0.1 % error compared to a
/// numerical Monte Carlo solution"; §5: "the mean difference was 0.001" in G1), and for γ > 4 it
/// is G1 of γ = 4 (§6: |G1⁴ − G1¹⁰| "up to 0.3" in a plot magnified 10×). The document does not
/// say which spline: the natural cubic spline through the five knots is this reading. Measured
/// against the exact route (ERRATA.md E3): on the document's plot domain (α ∈ [0.1, 0.5],
/// μ ∈ (0, 5]) mean |ΔG1| = 4.6e-4 but max |ΔG1| = 2.9e-2 (6 % relative, γ = 0.5, α = 0.1);
/// over α ∈ [0.01, 0.99] max |ΔG1| = 0.17; for γ ∈ (4, 10] (the clamp) max |ΔG1| = 0.28.
/// Exact at γ ∈ {0, 1, 2, 3, 4}.
pub fn g1_spline(gamma: f64, alpha: f64, mu: f64) -> f64 {
    if mu == 0.0 {
        return 0.0;
    }
    if mu == f64::INFINITY {
        return 1.0;
    }
    let y: [f64; 5] = std::array::from_fn(|k| 1.0 / (1.0 + lambda_closed_form(k as u8, alpha, mu)));
    natural_cubic_spline_unit_knots(&y, gamma.clamp(0.0, 4.0))
}

/// The natural cubic spline through (k, y[k]), k = 0…4, evaluated at x ∈ [0, 4].
fn natural_cubic_spline_unit_knots(y: &[f64; 5], x: f64) -> f64 {
    // Second derivatives M_k with M_0 = M_4 = 0 and, for unit spacing,
    // M_{k−1} + 4 M_k + M_{k+1} = 6 (y_{k+1} − 2 y_k + y_{k−1}), k = 1, 2, 3 (Thomas algorithm).
    let r: [f64; 3] = std::array::from_fn(|i| 6.0 * (y[i + 2] - 2.0 * y[i + 1] + y[i]));
    let c1 = 0.25;
    let d1 = r[0] / 4.0;
    let m2_den = 4.0 - c1;
    let c2 = 1.0 / m2_den;
    let d2 = (r[1] - d1) / m2_den;
    let d3 = (r[2] - d2) / (4.0 - c2);
    let m3 = d3;
    let m2 = d2 - c2 * m3;
    let m1 = d1 - c1 * m2;
    let m = [0.0, m1, m2, m3, 0.0];
    let i = (x.floor() as usize).min(3);
    let t = x - i as f64;
    let u = 1.0 - t;
    u * y[i] + t * y[i + 1] + ((u * u * u - u) * m[i] + (t * t * t - t) * m[i + 1]) / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_interpolates_its_knots_and_reproduces_cubics_with_zero_end_curvature() {
        let y = [0.3, -1.0, 2.0, 0.5, 4.0];
        for (k, &v) in y.iter().enumerate() {
            assert!((natural_cubic_spline_unit_knots(&y, k as f64) - v).abs() < 1e-15);
        }
        // A straight line is its own natural spline.
        let line: [f64; 5] = std::array::from_fn(|k| 2.0 - 0.5 * k as f64);
        for x in [0.2, 1.7, 3.9] {
            let v = natural_cubic_spline_unit_knots(&line, x);
            assert!((v - (2.0 - 0.5 * x)).abs() < 1e-15);
        }
        // Continuity of the first derivative at the inner knots.
        let h = 1e-6;
        for k in 1..4 {
            let x = k as f64;
            let left = (natural_cubic_spline_unit_knots(&y, x)
                - natural_cubic_spline_unit_knots(&y, x - h))
                / h;
            let right = (natural_cubic_spline_unit_knots(&y, x + h)
                - natural_cubic_spline_unit_knots(&y, x))
                / h;
            assert!((left - right).abs() < 1e-4, "knot {k}: {left} vs {right}");
        }
    }

    #[test]
    fn the_odd_integrals_match_quadrature() {
        use crate::test_support::{integrate_tail, rel_err};
        for &alpha in &[0.05, 0.3, 1.0] {
            for &mu in &[1e-3, 0.2, 1.0, 30.0] {
                let got = i_odd(alpha, mu);
                for (j, n) in [3.0, 5.0, 7.0].into_iter().enumerate() {
                    let f = |q: f64| (q - mu) * (q * q + alpha * alpha).powf(-n / 2.0);
                    let want = integrate_tail(&f, mu, alpha.max(mu), 1e-14) / mu;
                    let e = rel_err(got[j], want);
                    assert!(
                        e < 1e-12,
                        "I_{n} α={alpha} μ={mu}: {} vs {want} ({e:e})",
                        got[j]
                    );
                }
            }
        }
    }

    #[test]
    fn series_of_sin_minus_psi_cos_joins_the_direct_form() {
        for &psi in &[1e-8, 1e-3, 0.1, 0.2499, 0.25, 0.26] {
            let (s, c) = f64::sin_cos(psi);
            let got = sin_minus_psi_cos(psi, s, c);
            // Reference: the series to many terms in the same arithmetic is the oracle for small
            // ψ; near 0.25 the direct form is accurate to ~1e-14.
            let direct = s - psi * c;
            if psi > 0.1 {
                assert!(((got - direct) / direct).abs() < 1e-13, "ψ={psi}");
            } else {
                let leading = psi.powi(3) / 3.0;
                assert!(((got - leading) / leading).abs() < psi * psi, "ψ={psi}");
            }
        }
    }
}
