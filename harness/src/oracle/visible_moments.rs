//! The visible-slope moments of a Gaussian slope distribution (document 002's D_s) by harness
//! cubature of their definition, D_s ∝ p_s(s)(w_z − s·w_xy)⁺: the one oracle of document 002's
//! closed forms and its pseudocode (`check::ds`, `check::errata`, `mfh cost`).

use super::cubature::{integrate_rectangle, AccuracyGoal};
use super::Estimate;
use mfh_reference::geometry::from_spherical;
use mfh_reference::slopes::gaussian::GaussianSlopes;
use mfh_reference::Vec3;

/// The half-width of the integration window, in standard deviations of the Gaussian
/// (e^{−72} ≈ 5e-32 of the mass lies outside).
const WINDOW: f64 = 12.0;

/// The oracle's moments of D_s with their error bounds,
/// in the order mean x, mean y, var x, var y, cov xy.
#[derive(Debug, Clone)]
pub struct Oracle {
    /// The moments.
    pub values: [f64; 5],
    /// Their error bounds.
    pub bounds: [f64; 5],
    /// The integrand evaluations spent.
    pub evaluations: u64,
}

/// The rotated statistics of N(s̄, Σ) along the view azimuth ô (and ô⊥): used only to place the
/// integration window and to shear it along the Gaussian's ridge; any affine change of
/// variables leaves the integral unchanged, so their rounding does not enter the oracle.
struct Window {
    o: [f64; 2],
    perp: [f64; 2],
    mean_o: f64,
    mean_perp: f64,
    sigma_o: f64,
    slope: f64,
    conditional: f64,
    z0: f64,
}

fn window(mean: [f64; 2], cov: [[f64; 2]; 2], w: Vec3) -> Window {
    let qn = w[0].hypot(w[1]);
    let o = if qn > 0.0 {
        [w[0] / qn, w[1] / qn]
    } else {
        [1.0, 0.0]
    };
    let perp = [-o[1], o[0]];
    let quad = |a: [f64; 2], b: [f64; 2]| {
        a[0] * (cov[0][0] * b[0] + cov[0][1] * b[1]) + a[1] * (cov[1][0] * b[0] + cov[1][1] * b[1])
    };
    let a = quad(o, o);
    let c = quad(perp, o);
    let det = (cov[0][0] * cov[1][1] - cov[0][1] * cov[1][0]).max(0.0);
    let mean_o = mean[0] * o[0] + mean[1] * o[1];
    let sigma_o = a.sqrt();
    let mu = if qn > 0.0 { w[2] / qn } else { f64::INFINITY };
    Window {
        o,
        perp,
        mean_o,
        mean_perp: mean[0] * perp[0] + mean[1] * perp[1],
        sigma_o,
        slope: c / a,
        conditional: (det / a).sqrt(),
        z0: (mu - mean_o) / sigma_o,
    }
}

/// z₀ = (cot θ − s̄_o)/σ_o of N(mean, cov) seen from `w` (+∞ at normal incidence).
pub fn z0(mean: [f64; 2], cov: [[f64; 2]; 2], w: Vec3) -> f64 {
    window(mean, cov, w).z0
}

/// The mean and covariance of D_s seen from `w`, by 2-D adaptive cubature of their definitions
/// (document 002, eq 16, 19–23), with p_s of eq 1 written in the frame that factorizes it (the
/// marginal of s_o times the conditional of s_⊥; evaluating the model's own p22 there instead
/// adds rounding noise of ~1e-12 across the thin direction of a near-singular Σ, which the
/// cubature then chases to its depth limit):
///
/// ```text
/// N       = ∫∫ p_s(s) (ω_z − s·ω_xy)⁺ d²s
/// mean_i  = s̄_i + ∫∫ (s_i − s̄_i) p_s W H d²s / N
/// cov_ij  = ∫∫ (s_i − mean_i)(s_j − mean_j) p_s W H d²s / N      (central: no mean² subtracted)
/// ```
///
/// The integration variables are s_o = u ∈ [lo, min(cot θ, s̄_o + 12σ_o)] (the facets that face
/// ω lie at s_o < cot θ, so the integrand is smooth on the rectangle) and t ∈ [−12, 12] with
/// s_⊥ = s̄_⊥ + (c_o⊥/σ_o²)(u − s̄_o) + t √(|Σ|/σ_o²) (a shear along the Gaussian's ridge, so
/// that a near-singular Σ is a well-resolved band, not a thin diagonal needle); the weight
/// W = ω_z − s·ω_xy is taken from the definition with s = u ô + s_⊥ ô⊥.
pub fn oracle(mean: [f64; 2], cov: [[f64; 2]; 2], w: Vec3) -> Result<Oracle, String> {
    let win = window(mean, cov, w);
    let (sigma_o, h) = (win.sigma_o, win.conditional);
    if !(sigma_o > 0.0 && h > 0.0) {
        return Err(format!("singular covariance (σ_o = {sigma_o}, h = {h})"));
    }
    let mu = win.mean_o + win.z0 * sigma_o;
    let hi = (win.mean_o + WINDOW * sigma_o).min(mu);
    let lo = if win.z0 >= -0.5 * WINDOW {
        win.mean_o - WINDOW * sigma_o
    } else {
        // Deep in the tail the weighted density decays like e^{−|z₀| x}, x = (μ − u)/σ_o.
        mu - 60.0 * sigma_o / win.z0.abs()
    };
    if !(hi > lo) {
        return Err("no facet faces the view direction".into());
    }
    let point = |u: f64, t: f64| -> [f64; 2] {
        let sp = win.mean_perp + win.slope * (u - win.mean_o) + t * h;
        [
            u * win.o[0] + sp * win.perp[0],
            u * win.o[1] + sp * win.perp[1],
        ]
    };
    let weighted = |u: f64, t: f64| -> (f64, [f64; 2]) {
        let s = point(u, t);
        let wt = (w[2] - s[0] * w[0] - s[1] * w[1]).max(0.0);
        // p_s(s) d²s = φ(z) φ(t) / (σ_o h) · h du dt, z = (u − s̄_o)/σ_o.
        let z = (u - win.mean_o) / sigma_o;
        let density = (-0.5 * (z * z + t * t)).exp() / (std::f64::consts::TAU * sigma_o);
        (density * wt, s)
    };
    let mut evaluations = 0u64;
    let mut integrate = |f: &dyn Fn(f64, f64) -> f64, absolute: f64| {
        let e = integrate_rectangle(
            &|u, t| f(u, t),
            [lo, hi],
            [-WINDOW, WINDOW],
            AccuracyGoal {
                absolute,
                relative: 1e-11,
            },
        );
        evaluations += e.evaluations;
        e
    };
    let n = integrate(&|u, t| weighted(u, t).0, 0.0);
    if !(n.value > 0.0) {
        return Err(format!("N = {} is not positive", n.value));
    }
    let scale = [cov[0][0].sqrt(), cov[1][1].sqrt()];
    let mut values = [0.0; 5];
    let mut bounds = [0.0; 5];
    let rel_n = n.error_bound / n.value;
    for i in 0..2 {
        let e = integrate(
            &|u, t| {
                let (f, s) = weighted(u, t);
                (s[i] - mean[i]) * f
            },
            1e-13 * n.value * scale[i],
        );
        let shift = e.value / n.value;
        values[i] = mean[i] + shift;
        bounds[i] = e.error_bound / n.value + shift.abs() * rel_n;
    }
    let m = [values[0], values[1]];
    for i in 0..2 {
        let e = integrate(
            &|u, t| {
                let (f, s) = weighted(u, t);
                let d = s[i] - m[i];
                d * d * f
            },
            0.0,
        );
        values[2 + i] = e.value / n.value;
        bounds[2 + i] = e.error_bound / n.value + values[2 + i] * rel_n;
    }
    let floor = 1e-14 * n.value * (values[2] * values[3]).sqrt();
    let e = integrate(
        &|u, t| {
            let (f, s) = weighted(u, t);
            (s[0] - m[0]) * (s[1] - m[1]) * f
        },
        floor,
    );
    values[4] = e.value / n.value;
    bounds[4] = e.error_bound / n.value + values[4].abs() * rel_n;
    Ok(Oracle {
        values,
        bounds,
        evaluations,
    })
}

/// [`oracle`] of a model at (θ, φ), as estimates in the order (mean x, mean y, σx², cxy, σy²)
/// (NaN with an infinite bound where the oracle has no answer).
pub fn visible_moments_oracle(gs: &GaussianSlopes, theta: f64, phi: f64) -> [Estimate; 5] {
    match oracle(gs.mean(), gs.cov(), from_spherical(theta, phi)) {
        Ok(o) => [0, 1, 2, 4, 3].map(|i| Estimate {
            value: o.values[i],
            error_bound: o.bounds[i],
            evaluations: o.evaluations,
        }),
        Err(_) => {
            [Estimate {
                value: f64::NAN,
                error_bound: f64::INFINITY,
                evaluations: 0,
            }; 5]
        }
    }
}
