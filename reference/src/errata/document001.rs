//! Document 001 (STD): derivation steps that no route evaluates, as printed and corrected (the
//! printed forms of evaluated routes are routes: `table1_printed`, `half_integer_printed`,
//! `sample_wm_printed`, `2f1_algorithm2`). Variables are the document's: σ the roughness, μ =
//! cot θ, t₀ = μ/√((γ−1)σ²).

use crate::ndf::student_lambda::alternating_tail_sum;
use crate::special::gamma_ratio::gamma_half_ratio;
use crate::special::hyp2f1::hyp2f1_lambda;
use crate::special::student_tail::student_lambda;
use std::f64::consts::PI;

/// Eq 20 as printed: ∫_{t₀}^∞ (1 + t²)^{½−γ} dt = √πΓ(γ−1)/(2Γ(γ−½))
/// − (μ/2) ₂F₁(½, γ−½; 3/2; −t₀²)/√((γ−1)σ²) (ERRATA 001-5: a spurious ½).
pub fn eq20_tail_printed(g: f64, sigma: f64, mu: f64) -> f64 {
    let k = (g - 1.0) * sigma * sigma;
    let t0 = mu / k.sqrt();
    PI.sqrt() / (2.0 * gamma_half_ratio(g - 1.0)) - mu / 2.0 * hyp2f1_lambda(g, -t0 * t0) / k.sqrt()
}

/// Eq 20 corrected: … − t₀ ₂F₁(½, γ−½; 3/2; −t₀²).
pub fn eq20_tail_corrected(g: f64, sigma: f64, mu: f64) -> f64 {
    let t0 = mu / ((g - 1.0) * sigma * sigma).sqrt();
    PI.sqrt() / (2.0 * gamma_half_ratio(g - 1.0)) - t0 * hyp2f1_lambda(g, -t0 * t0)
}

/// Eq 28's last line as printed (integer γ ≥ 2): Σ C(γ−2, k)(−1)^k/(2k+1)(1 − s^{2k+1}) with
/// s = μ/(σ√(γ−1) + μ²/σ²) (ERRATA 001-4: the square root misplaced).
pub fn eq28_tail_printed(g: u64, sigma: f64, mu: f64) -> f64 {
    let gf = g as f64;
    alternating_tail_sum(
        g - 2,
        mu / (sigma * (gf - 1.0).sqrt() + mu * mu / (sigma * sigma)),
    )
}

/// Eq 28 corrected: s = μ/(σ√((γ−1) + μ²/σ²)) = sin(arctan t₀)… as eq 30's A3 has it.
pub fn eq28_tail_corrected(g: u64, sigma: f64, mu: f64) -> f64 {
    let gf = g as f64;
    alternating_tail_sum(
        g - 2,
        mu / (sigma * ((gf - 1.0) + mu * mu / (sigma * sigma)).sqrt()),
    )
}

/// §7.1's cdf of visible slopes C²_ωi(p) (σ = 1, θ the incidence) as printed: the ₂F₁ term
/// carries (γ−1)^{γ−½} (ERRATA 001-7).
pub fn sec71_cdf_printed(g: f64, theta: f64, p: f64) -> f64 {
    sec71_cdf(g, theta, p, g - 0.5)
}

/// §7.1's C²_ωi(p) corrected: (γ−1)^{½−γ}.
pub fn sec71_cdf_corrected(g: f64, theta: f64, p: f64) -> f64 {
    sec71_cdf(g, theta, p, 0.5 - g)
}

fn sec71_cdf(g: f64, theta: f64, p: f64, exponent: f64) -> f64 {
    let t = theta.tan();
    let g1 = 1.0 / (1.0 + student_lambda(g, 1.0 / (t * (g - 1.0).sqrt())));
    let c = g1 * (g - 1.0).powf(g) / (PI.sqrt() * (g - 1.0)) * gamma_half_ratio(g - 1.0);
    let f = hyp2f1_lambda(g, -p * p / (g - 1.0));
    let rest = PI.sqrt() / (2.0 * (g - 1.0).powf(g) / (g - 1.0) * gamma_half_ratio(g - 1.0))
        + t / ((2.0 * g - 3.0) * (p * p + g - 1.0).powf(g - 1.5));
    c * ((g - 1.0).powf(exponent) * p * f + rest)
}

/// §7.1's kernel of C^{2|2}(q | p) as printed: (1/(γ−1) + p² + q²)^{−γ} (ERRATA 001-8).
pub fn sec71_kernel_printed(g: f64, p: f64, q: f64) -> f64 {
    (1.0 / (g - 1.0) + p * p + q * q).powf(-g)
}

/// §7.1's kernel corrected: (γ − 1 + p² + q²)^{−γ} (∝ P22's (1 + (p² + q²)/(γ−1))^{−γ}).
pub fn sec71_kernel_corrected(g: f64, p: f64, q: f64) -> f64 {
    (g - 1.0 + p * p + q * q).powf(-g)
}

/// Table 1's anisotropic Beckmann D as printed, at (θ, φ): exp(−tan²(cos²φ/σx² + sin²φ/σy²))
/// / (πσxσy cos⁴θ) (ERRATA 001-9: tan² of the bracket).
pub fn table1_aniso_beckmann_printed(sx: f64, sy: f64, theta: f64, phi: f64) -> f64 {
    let a = (phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2);
    (-a.tan().powi(2)).exp() / (PI * sx * sy * theta.cos().powi(4))
}

/// Table 1's anisotropic Beckmann D corrected: exp(−tan²θ (cos²φ/σx² + sin²φ/σy²)) / (πσxσy
/// cos⁴θ).
pub fn table1_aniso_beckmann_corrected(sx: f64, sy: f64, theta: f64, phi: f64) -> f64 {
    let a = (phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2);
    (-theta.tan().powi(2) * a).exp() / (PI * sx * sy * theta.cos().powi(4))
}

/// Eq 41 as printed: 2π ∫₀^θ D cos t sin t dt at fixed φ = (1 − (1 + A tan²θ)^{1−γ}) /
/// (σxσy(cos²φ/σx² + sin²φ/σy²)), A = (cos²φ/σx² + sin²φ/σy²)/(γ−1). Not a normalized cdf (it
/// tends to 1/(σxσy(…)) = 2π p(φ)), but eq 42 divides ξ₂ by the same factor, so the pair
/// samples right (formerly ERRATA 001-11, withdrawn).
pub fn eq41_theta_cdf_printed(g: f64, sx: f64, sy: f64, phi: f64, theta: f64) -> f64 {
    let a_phi = (phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2);
    (1.0 - (1.0 + a_phi / (g - 1.0) * theta.tan().powi(2)).powf(1.0 - g)) / (sx * sy * a_phi)
}

/// Eq 42 as printed: θ_m = arctan √(((1 − ξ₂)^{1/(1−γ)} − 1)/A), the solution of
/// ξ₂/(σxσy(cos²φ/σx² + sin²φ/σy²)) = eq 41.
pub fn eq42_theta_printed(g: f64, sx: f64, sy: f64, phi: f64, xi2: f64) -> f64 {
    let a = ((phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2)) / (g - 1.0);
    (((1.0 - xi2).powf(1.0 / (1.0 - g)) - 1.0) / a)
        .sqrt()
        .atan()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{integrate, integrate_tail, rel_err};

    #[test]
    fn eq41_and_eq42_as_printed_sample_the_conditional_cdf() {
        // The conditional cdf of θ given φ by quadrature of D cos θ sin θ (in u = tan θ:
        // (1 + A u²)^{−γ} u du); eq 42 as printed must invert it (ξ₂ = F(θ(ξ₂))).
        let (g, sx, sy) = (3.0f64, 0.2f64, 0.5f64);
        for &phi in &[0.0f64, 0.7, 2.0] {
            let a = ((phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2)) / (g - 1.0);
            let f = |u: f64| (1.0 + a * u * u).powf(-g) * u;
            let whole = integrate_tail(&f, 0.0, 1.0 / a.sqrt(), 1e-13);
            for &xi in &[0.05f64, 0.3, 0.5, 0.77, 0.95] {
                let theta = eq42_theta_printed(g, sx, sy, phi, xi);
                let cdf = integrate(&f, 0.0, theta.tan(), 1e-13, 0.0).0 / whole;
                assert!(rel_err(cdf, xi) < 1e-10, "φ={phi} ξ={xi}: {cdf}");
                // eq 41 is 2π p(φ) × the conditional cdf, and eq 42 divides it out.
                let a_phi = a * (g - 1.0);
                let printed = eq41_theta_cdf_printed(g, sx, sy, phi, theta);
                assert!(rel_err(printed * sx * sy * a_phi, xi) < 1e-12);
            }
        }
    }
}
