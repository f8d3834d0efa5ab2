//! The standard normal density weighted by a linear ramp and cut at a point: the
//! one-dimensional core of the visible-slope moments (document 002, eq 59–69) and of Smith Λ for
//! Gaussian slopes, evaluated without cancellation in every regime.
//!
//! With φ the standard normal density and
//!
//! ```text
//! K_k(u) = ∫_0^∞ e^k exp(−u e − e²/2) de       (so that ∫_u^∞ (t − u)^k φ(t) dt = φ(u) K_k(u))
//! F_k(u) = K_k(u) / K_{k−1}(u) = k / (u + F_{k+1}(u))      (Laplace's continued fraction)
//! ```
//!
//! the closed forms in φ and erfc subtract nearly equal numbers once the cut lies far in the
//! lower tail; there the ratios F_k are evaluated by the backward recurrence above instead.

use crate::special::student_tail::{beckmann_scaled, exact_square};
use libm::erfc;
use std::f64::consts::SQRT_2;

/// √(2π).
const SQRT_TAU: f64 = 2.506_628_274_631_000_5;

/// Below −SWITCH (ramp moments) and above +SWITCH (normal loss) the continued fraction is used;
/// on the other side the closed forms lose at most ~2e-14 relative (measured with mpmath).
const SWITCH: f64 = 1.5;

/// The standard normal density φ(z).
#[inline]
pub(crate) fn phi(z: f64) -> f64 {
    (-0.5 * z * z).exp() / SQRT_TAU
}

/// The standard normal distribution function Φ(z) = ½ erfc(−z/√2), accurate in both tails.
#[inline]
pub(crate) fn cdf(z: f64) -> f64 {
    0.5 * erfc(-z / SQRT_2)
}

/// (F_1, F_2, F_3)(u) for u ≥ SWITCH by the backward recurrence F_k = k/(u + F_{k+1}), started
/// at the fixed point of F = (n+1)/(u+F). The depth n gives full double precision (checked
/// against mpmath at 50 digits: n = 160 suffices at u = 1.5, 80 at u = 3, 20 at u = 10).
fn ratios(u: f64) -> [f64; 3] {
    let n: u32 = if u < 3.0 {
        240
    } else if u < 6.0 {
        100
    } else {
        40
    };
    let top = (n + 1) as f64;
    let mut f = 2.0 * top / (u + (u * u + 4.0 * top).sqrt());
    let mut out = [0.0; 3];
    for k in (1..=n).rev() {
        f = k as f64 / (u + f);
        if k <= 3 {
            out[k as usize - 1] = f;
        }
    }
    out
}

/// The normal loss function L(x) = ∫_x^∞ (t − x) φ(t) dt = φ(x) − x (1 − Φ(x)) > 0.
///
/// ```text
/// L(x) = φ(x) − x · ½ erfc(x/√2)      x ≤ 1.5
/// L(x) = φ(x) F(x/√2) / x²             x > 1.5   (no cancellation)
/// ```
///
/// where F(a) = 4√π a³ e^{a²} Λ_B(a) is the scaled Beckmann Λ (L(x) = x Λ_B(x/√2)), read from
/// its fitted polynomials (`special::student_tail::beckmann_scaled`, ≤ 2.4e-16), and φ(x)
/// there takes x² split exactly into two doubles (e^{−x·x/2} would carry the rounding of x·x,
/// up to x²/2 × 1.1e-16 relative). L(−∞) = +∞, L(+∞) = 0; relative error ≤ ~2e-15 over the
/// real line.
pub(crate) fn normal_loss(x: f64) -> f64 {
    if x == f64::INFINITY {
        return 0.0;
    }
    if x == f64::NEG_INFINITY {
        return f64::INFINITY;
    }
    if x <= SWITCH {
        phi(x) - x * 0.5 * erfc(x / SQRT_2)
    } else if x > 40.0 {
        0.0 // φ(x) < 1e-348
    } else {
        let (hi, lo) = exact_square(x);
        let p = (-0.5 * hi).exp() * (1.0 - 0.5 * lo) / SQRT_TAU;
        p * beckmann_scaled(x / SQRT_2) / (x * x)
    }
}

/// Moments of t under the density ∝ φ(t) (z₀ − t)⁺ (a standard normal seen through a linear
/// ramp that vanishes at z₀).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RampMoments {
    /// E[t] (< 0).
    pub tau: f64,
    /// Var[t] ∈ (0, 1].
    pub var: f64,
    /// E[z₀ − t] = z₀ − τ (> 0), the mean distance to the cut; +∞ when z₀ = +∞.
    pub gap: f64,
}

/// The mean, variance and mean distance to the cut of t ~ φ(t)(z₀ − t)⁺ / L(−z₀).
///
/// ```text
/// z₀ ≥ −1.5:  h = φ(z₀)/Φ(z₀),  g = z₀ + h,
///             τ = −1/g,  Var = 1 − (1 − h g)/g²,  gap = z₀ + 1/g
/// z₀ < −1.5:  u = −z₀,  τ = −(u + F_2(u)),  Var = F_2 (F_3 − F_2),  gap = F_2(u)
/// z₀ = +∞:    τ = 0, Var = 1 (no cut: the plain normal)
/// ```
///
/// Derivation: with M_k = ∫_{−∞}^{z₀} t^k (z₀ − t) φ(t) dt, M_0 = φ + z₀Φ, M_1 = −Φ,
/// M_2 = z₀Φ + 2φ (at z₀); for z₀ → −∞, t = z₀ − e and e ~ e exp(−ue − e²/2), whose moments
/// are K_2/K_1 = F_2 and K_3/K_1 = F_2 F_3. Relative error ≤ ~3e-14 (Var), ≤ ~1e-15 (τ, gap).
/// `z₀` must not be NaN or −∞ (then no mass remains).
pub(crate) fn ramp_moments(z0: f64) -> RampMoments {
    if z0 == f64::INFINITY {
        return RampMoments {
            tau: 0.0,
            var: 1.0,
            gap: f64::INFINITY,
        };
    }
    if z0 >= -SWITCH {
        let h = phi(z0) / cdf(z0);
        let g = z0 + h;
        let var = 1.0 - (1.0 - h * g) / (g * g);
        RampMoments {
            tau: -1.0 / g,
            var,
            gap: z0 + 1.0 / g,
        }
    } else {
        let u = -z0;
        let [_, f2, f3] = ratios(u);
        RampMoments {
            tau: -(u + f2),
            var: f2 * (f3 - f2),
            gap: f2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slopes::test_quadrature::quad;
    use crate::test_support::rel_err;

    /// Independent values: the defining integrals by adaptive quadrature.
    fn moments_by_quadrature(z0: f64) -> (f64, f64, f64) {
        // The mass lies within min(40/|z₀|, 9) of the cut when z₀ ≪ 0, else in [−9, z₀].
        let (lo, width) = if z0 < -1.0 {
            (z0 - (40.0 / -z0).min(9.0), (1.0 / -z0).min(1.0))
        } else {
            (-9.0, 1.0)
        };
        let hi = z0.min(9.0);
        let w = |t: f64| phi(t) * (z0 - t);
        let m0 = quad(&w, lo, hi, width);
        // Central moments about a first estimate, so that the variance does not cancel.
        let mean = quad(&|t| t * w(t), lo, hi, width) / m0;
        let var = quad(&|t| (t - mean).powi(2) * w(t), lo, hi, width) / m0;
        let gap = quad(&|t| (z0 - t) * w(t), lo, hi, width) / m0;
        (mean, var, gap)
    }

    #[test]
    fn ramp_moments_match_their_integrals_in_both_regimes() {
        let mut worst: f64 = 0.0;
        for z0 in [
            -30.0, -8.0, -3.0, -1.5001, -1.5, -1.0, -0.2, 0.0, 0.7, 2.0, 6.0, 11.0,
        ] {
            let r = ramp_moments(z0);
            let (tau, var, gap) = moments_by_quadrature(z0);
            for (got, want, what) in [
                (r.tau, tau, "tau"),
                (r.var, var, "var"),
                (r.gap, gap, "gap"),
            ] {
                let e = rel_err(got, want);
                assert!(
                    e < 1e-12,
                    "z0 = {z0}: {what} = {got:e}, quadrature {want:e}, {e:e}"
                );
                worst = worst.max(e);
            }
        }
        eprintln!("ramp moments: max rel err {worst:.1e}");
        let r = ramp_moments(f64::INFINITY);
        assert_eq!((r.tau, r.var), (0.0, 1.0));
        let r = ramp_moments(-1e6);
        assert!(r.var > 0.0 && (r.var * 1e12 - 2.0).abs() < 1e-5, "{r:?}");
        assert!((r.gap * 1e6 - 2.0).abs() < 1e-5);
    }

    #[test]
    fn normal_loss_matches_its_integral() {
        for x in [-20.0f64, -2.0, -0.3, 0.0, 1.0, 1.5, 1.6, 3.0, 8.0, 25.0] {
            let (hi, width) = if x > 1.0 {
                (x + 40.0 / x, 1.0 / x)
            } else {
                (x.max(0.0) + 12.0, 1.0)
            };
            let want = quad(&|t| (t - x) * phi(t), x, hi, width);
            let got = normal_loss(x);
            assert!(
                rel_err(got, want) < 1e-12,
                "L({x}) = {got:e}, quadrature {want:e}"
            );
        }
        assert_eq!(normal_loss(f64::INFINITY), 0.0);
        assert_eq!(normal_loss(40.0), 0.0);
        assert_eq!(normal_loss(f64::NEG_INFINITY), f64::INFINITY);
    }
}
