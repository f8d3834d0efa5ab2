//! Demonstrations of the errata of document 001 found in derivation steps (equations that no route
//! evaluates): each test evaluates the printed formula and the corrected one against an
//! independent integral, and asserts that the printed one fails and the corrected one holds.
//! The errata of evaluated routes are demonstrated beside them (ERRATA.md names every test).

use crate::errata::document001;
use crate::ndf::student_lambda::eq33_prefactor;
use crate::special::gamma_ratio::gamma_half_ratio;
use crate::special::hyp2f1::student_norm;
use crate::test_support::{integrate, integrate_tail, rel_err};
use std::f64::consts::PI;

/// ∫_{t0}^∞ (1 + t²)^{½−γ} dt by quadrature.
fn tail_integral(g: f64, t0: f64) -> f64 {
    integrate_tail(&|t: f64| (1.0 + t * t).powf(0.5 - g), t0, 1.0, 1e-13)
}

/// STD in the document's variables: the unnormalized ∫_μ^∞ (q − μ) ((γ−1)σ² + q²)^{½−γ} dq
/// times the P2 constant, over μ: Λ by its definition (eq 17).
fn lambda_definition(g: f64, sigma: f64, mu: f64) -> f64 {
    let k = (g - 1.0) * sigma * sigma;
    // P2 = N/√k (1 + q²/k)^{½−γ}
    let n = student_norm(g) / k.sqrt();
    let f = |q: f64| (q - mu) * n * (1.0 + q * q / k).powf(0.5 - g);
    integrate_tail(&f, mu, k.sqrt(), 1e-13) / mu
}

/// The demonstration every test here ends with: the corrected form meets `truth` to `tolerance`
/// (relative) and the printed one misses it by more than 1e-2 (`what` names the case).
fn shown(printed: f64, corrected: f64, truth: f64, tolerance: f64, what: &str) {
    assert!(
        rel_err(corrected, truth) < tolerance,
        "{what}: corrected {corrected} vs {truth}"
    );
    assert!(
        rel_err(printed, truth) > 1e-2,
        "{what}: printed {printed} agreed with {truth}"
    );
}

#[test]
fn eq20_has_a_spurious_half_on_the_2f1_term() {
    // I2 = μ/((γ−1)σ²)^{γ−1} ∫_{t0}^∞ (1+t²)^{½−γ} dt, t0 = μ/√((γ−1)σ²). Eq 20 writes the
    // integral as √π Γ(γ−1)/(2Γ(γ−½)) − (μ/2) ₂F₁(…)/√((γ−1)σ²); it is … − t0 ₂F₁(…).
    for &(g, sigma, mu) in &[(2.5f64, 0.3f64, 0.4f64), (4.0, 0.5, 0.2), (7.5, 0.2, 0.3)] {
        let t0 = mu / ((g - 1.0) * sigma * sigma).sqrt();
        let printed = document001::eq20_tail_printed(g, sigma, mu);
        let corrected = document001::eq20_tail_corrected(g, sigma, mu);
        let truth = tail_integral(g, t0);
        shown(printed, corrected, truth, 1e-11, &format!("γ={g}, eq 20"));
    }
}

#[test]
fn eq28_last_line_misplaces_the_square_root() {
    // Last line of eq 28: (μ / (σ√(γ−1) + μ²/σ²))^{2k+1}; the previous line, eq 30 (A3) and
    // sin(arctan t0) give μ / (σ √((γ−1) + μ²/σ²)).
    for &(g, sigma, mu) in &[(3.0f64, 0.3f64, 0.4f64), (5.0, 0.6, 0.5)] {
        let t0 = mu / ((g - 1.0).sqrt() * sigma);
        let truth = tail_integral(g, t0);
        let printed = document001::eq28_tail_printed(g as u64, sigma, mu);
        let corrected = document001::eq28_tail_corrected(g as u64, sigma, mu);
        shown(printed, corrected, truth, 1e-11, &format!("γ={g}, eq 28"));
    }
}

#[test]
fn eq33_prefactor_keeps_q_and_drops_one_over_mu_and_one_over_2k_plus_1() {
    // Eq 33 (half-integer γ): prefactor 2(γ−1)^γ σ^{2γ−2} / (π ((γ−1)σ² + q²)^{γ−½}) Σ C(n,k)(−1)^k
    // with a free q. The right prefactor is 2(γ−1)^γ σ^{2γ−2}/(π μ) Σ C(n,k)(−1)^k/(2k+1)
    // (eq 31's constant, the 1/μ of eq 17). Binding q := μ, the printed form is far off.
    for &(g, sigma, mu) in &[(2.5f64, 0.3f64, 0.4f64), (3.5, 0.5, 0.6)] {
        let k2 = (g - 1.0) * sigma * sigma;
        let t0 = mu / k2.sqrt();
        let bracket = (k2 + mu * mu).powf(1.5 - g) / (2.0 * g - 3.0)
            - mu / k2.powf(g - 1.0) * tail_integral(g, t0);
        let printed = eq33_prefactor(g, sigma, mu, true) * bracket;
        let corrected = eq33_prefactor(g, sigma, mu, false) * bracket;
        let truth = lambda_definition(g, sigma, mu);
        shown(printed, corrected, truth, 1e-10, &format!("γ={g}, eq 33"));
    }
}

#[test]
fn eq36_37_arctan_argument_depends_on_sigma_alone() {
    // Printed arctan(μ/√((γ−1)σ)); right arctan(μ/(σ√(γ−1))). The two agree only at σ = 1.
    use super::student_lambda::{lambda_half_integer, lambda_half_integer_printed, lambda_stable};
    for &g in &[2.5f64, 3.5, 5.5] {
        for &(sigma, mu) in &[(0.3f64, 0.5f64), (0.1, 0.2), (1.0, 0.7)] {
            let x: f64 = mu / (sigma * (g - 1.0f64).sqrt());
            let truth = lambda_definition(g, sigma, mu);
            assert!(rel_err(lambda_stable(g, x), truth) < 1e-10);
            assert!(rel_err(lambda_half_integer(g, x), truth) < 1e-10);
            let printed = lambda_half_integer_printed(g, x, sigma);
            if sigma == 1.0 {
                assert!(rel_err(printed, truth) < 1e-10);
            } else {
                assert!(
                    rel_err(printed, truth) > 1e-3,
                    "γ={g} σ={sigma}: printed agreed"
                );
            }
        }
    }
}

#[test]
fn table1_anisotropic_beckmann_d_lacks_tan2_theta() {
    // Printed: exp(−tan²(cos²φ/σx² + sin²φ/σy²)) / (π σx σy cos⁴θ) — tan² of the bracket, not
    // tan²θ times it. Normalization ∫ D cosθ dω = 1 shows it: the printed D does not decay
    // towards the horizon, and its integral over θ ≤ 1.3 alone already exceeds 1.
    let (sx, sy) = (0.2, 0.5);
    let norm = |printed: bool| -> f64 {
        let theta_max = if printed { 1.3 } else { PI / 2.0 - 1e-9 };
        let inner = |phi: f64| -> f64 {
            let f = |theta: f64| -> f64 {
                let (s, c) = theta.sin_cos();
                let d = if printed {
                    document001::table1_aniso_beckmann_printed(sx, sy, theta, phi)
                } else {
                    document001::table1_aniso_beckmann_corrected(sx, sy, theta, phi)
                };
                d * c * s
            };
            integrate(&f, 0.0, theta_max, 1e-12, 0.0).0
        };
        integrate(&inner, 0.0, 2.0 * PI, 1e-11, 0.0).0
    };
    assert!(
        rel_err(norm(false), 1.0) < 1e-9,
        "corrected: {}",
        norm(false)
    );
    assert!(norm(true) > 1.1, "printed: {}", norm(true));
}

// Eq 41–42 (formerly ERRATA 001-11) are right as a pair: `errata::document001::tests::
// eq41_and_eq42_as_printed_sample_the_conditional_cdf`.

/// P2 of §7.1 (σ = 1): (γ−1)^γ Γ(γ−½) / (√π Γ(γ) (γ − 1 + p²)^{γ−½}).
fn p2_sec71(g: f64, p: f64) -> f64 {
    // (γ−1)^γ Γ(γ−½)/Γ(γ) = (γ−1)^{γ−1} Γ(γ−½)/Γ(γ−1), in logarithms.
    let ln = (g - 1.0) * (g - 1.0).ln() + gamma_half_ratio(g - 1.0).ln()
        - (g - 0.5) * (g - 1.0 + p * p).ln();
    ln.exp() / PI.sqrt()
}

#[test]
fn sec71_visible_slope_cdf_has_the_wrong_sign_of_exponent() {
    // C²_ωi(p) = ∫_{−∞}^p G1 (1 − p' tanθ) P2(p') dp'. Printed: the ₂F₁ term carries
    // (γ−1)^{γ−½}; right: (γ−1)^{½−γ}.
    let (g, theta, p) = (3.0f64, 0.8f64, 0.3f64);
    let t = theta.tan();
    let density = |q: f64| (1.0 - q * t) * p2_sec71(g, q);
    let lam = {
        let x = 1.0 / (t * (g - 1.0).sqrt());
        crate::special::student_tail::student_lambda(g, x)
    };
    let g1 = 1.0 / (1.0 + lam);
    let truth = g1 * integrate_tail(&|u: f64| density(p - u), 0.0, 1.0, 1e-13);
    let printed = document001::sec71_cdf_printed(g, theta, p);
    let corrected = document001::sec71_cdf_corrected(g, theta, p);
    shown(printed, corrected, truth, 1e-10, "§7.1 visible-slope cdf");
}

#[test]
fn sec71_conditional_cdf_substitution_is_wrong() {
    // (1 + p²/(γ−1) + q²/(γ−1))^{−γ} ∝ (γ − 1 + p² + q²)^{−γ}; printed (1/(γ−1) + p² + q²)^{−γ}.
    let (g, p, q) = (3.0f64, 0.7f64, 0.2f64);
    let cdf = |h: &dyn Fn(f64) -> f64| -> f64 {
        let below = integrate_tail(&|u: f64| h(q - u), 0.0, 1.0, 1e-13);
        let all = below + integrate_tail(&|u: f64| h(q + u), 0.0, 1.0, 1e-13);
        below / all
    };
    let truth = cdf(&|s: f64| (1.0 + p * p / (g - 1.0) + s * s / (g - 1.0)).powf(-g));
    let printed = cdf(&|s: f64| document001::sec71_kernel_printed(g, p, s));
    let corrected = cdf(&|s: f64| document001::sec71_kernel_corrected(g, p, s));
    assert!(rel_err(corrected, truth) < 1e-10);
    assert!(rel_err(printed, truth) > 1e-3, "{printed} vs {truth}");
}
