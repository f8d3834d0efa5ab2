//! The Kolmogorov distribution: the p-value of a KS statistic.

use std::f64::consts::{PI, TAU};

/// Q_KS(λ) = P(K > λ) = 2 Σ_{k≥1} (−1)^{k−1} e^{−2k²λ²}, the Kolmogorov distribution's upper
/// tail.
///
/// ```text
/// λ ≥ 1.18:  Q = 2 (x − x⁴ + x⁹ − x¹⁶),  x = e^{−2λ²} ≤ 0.062   (next term x²⁵ < 1e-30)
/// λ < 1.18:  Q = 1 − (√(2π)/λ) (y + y⁹ + y²⁵ + y⁴⁹ + y⁸¹),  y = e^{−π²/(8λ²)} ≤ 0.41
///            (the Jacobi-theta form of the CDF; next term y¹²¹ < 1e-46)
/// ```
///
/// Both truncations are below 1e-16 absolute where used (Numerical Recipes, 3rd ed., §6.14).
/// Q(λ ≤ 0) = 1; NaN gives NaN.
pub fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda.is_nan() {
        return f64::NAN;
    }
    if lambda <= 0.0 {
        return 1.0;
    }
    if lambda < 1.18 {
        let y = (-PI * PI / (8.0 * lambda * lambda)).exp();
        let sum: f64 = [1, 9, 25, 49, 81].iter().map(|&k| y.powi(k)).sum();
        (1.0 - (TAU.sqrt() / lambda) * sum).clamp(0.0, 1.0)
    } else {
        let x = (-2.0 * lambda * lambda).exp();
        2.0 * (x - x.powi(4) + x.powi(9) - x.powi(16))
    }
}

/// Stephens' λ = (√N + 0.12 + 0.11/√N)·D: with it the asymptotic Q_KS(λ) is a close
/// approximation of the exact finite-N p-value of D_N (relative error well below 1 % for
/// N ≥ 5 in the upper tail; M. A. Stephens, J. R. Stat. Soc. B 32 (1970) 115–122).
pub fn stephens_lambda(d: f64, n: u64) -> f64 {
    let root = (n as f64).sqrt();
    (root + 0.12 + 0.11 / root) * d
}

/// The p-value of a KS statistic `d` from `n` samples: Q_KS(Stephens' λ).
pub fn ks_p_value(d: f64, n: u64) -> f64 {
    kolmogorov_q(stephens_lambda(d, n))
}
