//! PROVISIONAL stable Λ (replaced by the hand-written regime-split evaluator).

/// ln(Γ(c−½)/Γ(c−1)).
pub fn ln_gamma_ratio(c: f64) -> f64 {
    statrs::function::gamma::ln_gamma(c - 0.5) - statrs::function::gamma::ln_gamma(c - 1.0)
}

/// Λ_c(x).
pub fn student_lambda(c: f64, x: f64) -> f64 {
    if x == 0.0 {
        return f64::INFINITY;
    }
    if x == f64::INFINITY {
        return 0.0;
    }
    let n = ln_gamma_ratio(c).exp() / std::f64::consts::PI.sqrt();
    let w = 1.0 / (1.0 + x * x);
    n * ((1.5 - c) * (x * x).ln_1p()).exp() / ((2.0 * c - 3.0) * x)
        - 0.5 * statrs::function::beta::beta_reg(c - 1.0, 0.5, w)
}

/// Beckmann Λ(a).
pub fn beckmann_lambda(a: f64) -> f64 {
    if a == 0.0 {
        return f64::INFINITY;
    }
    0.5 * ((-a * a).exp() / (a * std::f64::consts::PI.sqrt()) - statrs::function::erf::erfc(a))
}
