//! The Student-t partial expectation: an oracle of Λ for the Student-t slope family (document 001)
//! that needs no quadrature, for shapes where quadrature cannot reach the tail.
//!
//! Near γ = 3/2 the integrand (q − μ)P2(q) of Λ decays like q^{−1−2(C−3/2)}: at C = 3/2 + 1e-9
//! half of Λ lies beyond q ≈ e^{3e8}, out of reach of any substitution in double precision.
//! The slope marginal is a scaled Student-t, q = σX with X ~ t_ν, ν = 2C − 2 (document 001 eq 15:
//! P2 ∝ (1 + (q/s)²)^{1/2 − C}), and E[(X − k)⁺] = (ν + k²)/(ν − 1) f_ν(k) − k(1 − F_ν(k)),
//! with f_ν and F_ν from `statrs` (regularized incomplete beta): independent of the ₂F₁
//! routes of the reference, and exact in the 1/(ν − 1) = 1/(2C − 3) blow-up.

use super::Estimate;
use statrs::distribution::{Continuous, ContinuousCDF, StudentsT};
use statrs::function::gamma::ln_gamma;

/// The relative accuracy claimed for this oracle: statrs' incomplete beta and log-gamma are
/// accurate to ~1e-14; the two terms do not cancel for the shapes it serves (C − 3/2 ≤ 0.05,
/// where the first term dominates by the factor 1/(2C − 3)).
pub const RELATIVE_ERROR: f64 = 1e-12;

/// Λ = E[(q − μ)⁺]/μ for a slope marginal P2(q) = N/s (1 + (q/s)²)^{1/2 − C} given by its exponent
/// C (> 3/2) and its value at the origin `p2_at_0` (= N/s: the scale is recovered from it).
pub fn lambda(c: f64, p2_at_0: f64, mu: f64) -> Option<Estimate> {
    if !(c > 1.5 && p2_at_0 > 0.0 && mu > 0.0) {
        return None;
    }
    let nu = 2.0 * c - 2.0;
    // f_σX(0) = Γ((ν+1)/2) / (Γ(ν/2) √(νπ) σ) = P2(0).
    let sigma = (ln_gamma(0.5 * (nu + 1.0)) - ln_gamma(0.5 * nu)).exp()
        / ((nu * std::f64::consts::PI).sqrt() * p2_at_0);
    let t = StudentsT::new(0.0, 1.0, nu).ok()?;
    let k = mu / sigma;
    let partial = (nu + k * k) / (nu - 1.0) * t.pdf(k) - k * t.sf(k);
    let value = sigma * partial / mu;
    Some(Estimate {
        value,
        error_bound: RELATIVE_ERROR * value.abs(),
        evaluations: 1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::quadrature::{integrate_upper, Accuracy};

    /// Against quadrature of its definition where quadrature converges (C = 2.5, 4).
    #[test]
    fn agrees_with_quadrature_of_the_definition() {
        for (c, s, mu) in [(2.5, 0.3, 1.0), (4.0, 0.2, 0.5), (2.5, 0.5, 3.0)] {
            let n = (ln_gamma(c - 0.5) - ln_gamma(c - 1.0)).exp() / std::f64::consts::PI.sqrt();
            let p2 = |q: f64| n / s * (1.0 + (q / s) * (q / s)).powf(0.5 - c);
            let q = integrate_upper(&|q| (q - mu) * p2(q), mu, s, Accuracy::relative(1e-13));
            let e = lambda(c, p2(0.0), mu).unwrap();
            let rel = (e.value - q.value / mu).abs() / (q.value / mu);
            assert!(
                rel < 1e-12,
                "C = {c}: {} vs {} ({rel:e})",
                e.value,
                q.value / mu
            );
        }
    }

    /// The 1/(2C − 3) blow-up: (2C − 3)Λ tends to a finite limit as C → 3/2.
    #[test]
    fn blows_up_like_one_over_two_c_minus_three() {
        let at = |eps: f64| {
            let c = 1.5 + eps;
            let n = (ln_gamma(c - 0.5) - ln_gamma(c - 1.0)).exp() / std::f64::consts::PI.sqrt();
            2.0 * eps * lambda(c, n / 0.3, 0.8).unwrap().value
        };
        let (a, b) = (at(1e-7), at(1e-9));
        assert!(a.is_finite() && (a - b).abs() < 1e-6 * b, "{a} {b}");
        assert!(lambda(1.5, 1.0, 1.0).is_none());
    }
}
