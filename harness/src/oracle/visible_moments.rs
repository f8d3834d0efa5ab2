//! The visible-slope moments of a Gaussian slope distribution (seed 002's D_s) by harness
//! cubature of their definition, D_s ∝ p_s(s)(w_z − s·w_xy)⁺: the oracle of seed 002's closed
//! forms and its pseudocode (check::ds, check::errata).

use super::cubature::{integrate_rectangle, Tolerance as CubatureTolerance};
use super::Estimate;
use mfh_reference::slopes::gaussian::GaussianSlopes;

/// The visible-slope moments (mean x, mean y, σx², cxy, σy²) of D_s ∝ p_s(s)(w_z − s·w_xy)⁺ by
/// harness cubature in the frame of w's azimuth (u along, v across; the cut is u = cot θ).
pub fn visible_moments_oracle(gs: &GaussianSlopes, theta: f64, phi: f64) -> [Estimate; 5] {
    let (sp, cp) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let mean = gs.mean();
    let cov = gs.cov();
    let mu_u = mean[0] * cp + mean[1] * sp;
    let mu_v = -mean[0] * sp + mean[1] * cp;
    let var_u = cov[0][0] * cp * cp + 2.0 * cov[0][1] * sp * cp + cov[1][1] * sp * sp;
    let var_v = cov[0][0] * sp * sp - 2.0 * cov[0][1] * sp * cp + cov[1][1] * cp * cp;
    let (wu, wv) = (12.0 * var_u.sqrt(), 12.0 * var_v.sqrt());
    let cut = ct / st;
    let hi = (mu_u + wu).min(cut);
    let tol = CubatureTolerance {
        absolute: 1e-14,
        relative: 1e-11,
    };
    let moment = |f: &dyn Fn(f64, f64) -> f64| {
        integrate_rectangle(
            &|u: f64, v: f64| {
                let s = [u * cp - v * sp, u * sp + v * cp];
                gs.ps(s) * (ct - st * u) * f(s[0], s[1])
            },
            [mu_u - wu, hi],
            [mu_v - wv, mu_v + wv],
            tol,
        )
    };
    let n = moment(&|_, _| 1.0);
    let mx = moment(&|x, _| x);
    let my = moment(&|_, y| y);
    let xx = moment(&|x, _| x * x);
    let xy = moment(&|x, y| x * y);
    let yy = moment(&|_, y| y * y);
    let e = |a: Estimate| a.error_bound / n.value + a.value.abs() * n.error_bound / n.value.powi(2);
    let (ex, ey) = (mx.value / n.value, my.value / n.value);
    let est = |value: f64, error_bound: f64| Estimate {
        value,
        error_bound,
        evaluations: n.evaluations,
    };
    [
        est(ex, e(mx)),
        est(ey, e(my)),
        est(xx.value / n.value - ex * ex, e(xx) + 2.0 * ex.abs() * e(mx)),
        est(
            xy.value / n.value - ex * ey,
            e(xy) + ex.abs() * e(my) + ey.abs() * e(mx),
        ),
        est(yy.value / n.value - ey * ey, e(yy) + 2.0 * ey.abs() * e(my)),
    ]
}
