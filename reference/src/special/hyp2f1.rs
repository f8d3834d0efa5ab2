//! PROVISIONAL: ₂F₁(½, c−½; 3/2; z) through the incomplete beta function (replaced by the
//! hand-written evaluator).

/// ₂F₁(½, c−½; 3/2; z) for z ≤ 0.
pub fn hyp2f1_lambda(c: f64, z: f64) -> f64 {
    if z == 0.0 {
        return 1.0;
    }
    let x = (-z).sqrt();
    let s = x * x / (1.0 + x * x);
    let b = statrs::function::beta::beta(0.5, c - 1.0);
    0.5 * b * statrs::function::beta::beta_reg(0.5, c - 1.0, s) / x
}

/// Placeholder for Algorithm 2.
pub fn hyp2f1_lambda_algorithm2(c: f64, z: f64) -> f64 {
    hyp2f1_lambda(c, z)
}
