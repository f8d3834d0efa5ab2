//! Smith Λ of the eq-1 blends of document 000 (piecewise-linear and analytic profiles): the exact
//! back-facing integral, the document's domain split (eq 10–29, 34) and the slope-space form
//! (eq 30–32).
//!
//! Every route computes Λ(w) for w = (θ_o, φ_o) in the upper hemisphere; the NDF enters as
//! D(θ, φ) = k_x cos²φ D_x(θ) + k_y sin²φ D_y(θ) (eq 1), and only cos 2φ_o matters. The
//! piecewise-linear model's `Smith` implementation, which names the routes, is here too: the
//! routes read the model's tables, so the model's file (`ndf::piecewise`) does not name them.

use crate::error::QueryError;
use crate::geometry::Vec3;
use crate::model::Smith;
use crate::ndf::piecewise::{segment_cos_sin, segment_sin2, PiecewiseLinear};
use crate::special::gauss_kronrod::integrate;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Relative accuracy requested from the adaptive quadrature of the "exact" route.
pub const EXACT_REL: f64 = 1e-13;

/// Splits w into (θ, cos 2φ) and applies Λ(−w) = −1 − Λ(w) below the horizon.
pub(crate) fn both_hemispheres(w: Vec3, upper: impl Fn(f64, f64) -> f64) -> f64 {
    let r2 = w[0] * w[0] + w[1] * w[1];
    let cos2phi = if r2 > 0.0 {
        (w[0] * w[0] - w[1] * w[1]) / r2
    } else {
        1.0
    };
    let theta = r2.sqrt().atan2(w[2].abs());
    if w[2] >= 0.0 {
        upper(theta, cos2phi)
    } else {
        -1.0 - upper(theta, cos2phi)
    }
}

/// K₀(γ) = ∫_{−γ}^{γ} (cos s − cos γ) ds = 2 (sin γ − γ cos γ), by its series below γ = ½.
pub(crate) fn k0(g: f64) -> f64 {
    if g >= 0.5 {
        return 2.0 * (g.sin() - g * g.cos());
    }
    // 2 Σ_{k≥1} (−1)^{k+1} 2k γ^{2k+1}/(2k+1)!
    let g2 = g * g;
    let mut term = g;
    let mut sum = 0.0;
    for k in 1..20 {
        term *= g2 / ((2 * k) as f64 * (2 * k + 1) as f64);
        let t = if k % 2 == 1 { 1.0 } else { -1.0 } * (2 * k) as f64 * term;
        sum += t;
        if t.abs() <= 1e-18 * sum.abs() {
            break;
        }
    }
    2.0 * sum
}

/// K₂(γ) = ∫_{−γ}^{γ} (cos s − cos γ) cos 2s ds = sin γ / 2 − sin 3γ / 6, by its series below
/// γ = ½.
pub(crate) fn k2(g: f64) -> f64 {
    if g >= 0.5 {
        return 0.5 * g.sin() - (3.0 * g).sin() / 6.0;
    }
    // Σ_{k≥1} (−1)^{k+1} γ^{2k+1} (3^{2k+1} − 3) / (6 (2k+1)!)
    let g2 = g * g;
    let mut term = g;
    let mut three = 3.0;
    let mut sum = 0.0;
    for k in 1..20 {
        term *= g2 / ((2 * k) as f64 * (2 * k + 1) as f64);
        three *= 9.0;
        let t = if k % 2 == 1 { 1.0 } else { -1.0 } * term * (three - 3.0) / 6.0;
        sum += t;
        if t.abs() <= 1e-18 * sum.abs() {
            break;
        }
    }
    sum
}

/// Λ of an eq-1 blend by adaptive quadrature of the back-facing projected area (document 000
/// eq 10–13: ∫⟨o·m⟩D dm = cos θ_o (1 + Λ), and ∫(o·m)D dm = cos θ_o since D(θ, φ + π) =
/// D(θ, φ), so Λ is the back-facing part alone, with no cancellation near normal incidence):
///
/// ```text
/// Λ(o) = 1/cos θ_o ∫_{θ_m > E} ∫_{o·m < 0} −(o·m) D(m) sin θ_m dφ_m dθ_m,   E = π/2 − θ_o
///      = tan θ_o / 2 ∫_E^{π/2} sin²θ_m [(k_x D_x + k_y D_y) K₀(γ)
///                                       + cos 2φ_o (k_x D_x − k_y D_y) K₂(γ)] dθ_m
/// γ    = arccos(cot θ_o cot θ_m) = 2 atan √(sin δ / sin(2θ_o − δ)),  δ = θ_m − E
/// ```
///
/// The azimuthal integral over the back-facing arc |φ_m − φ_o − π| < γ is closed (K₀, K₂ above;
/// the sin 2(φ_m − φ_o) part is odd and vanishes). The θ integral is taken in u = √δ (the
/// integrand behaves as δ^{3/2} at E) with the profile breakpoints `breaks` as interval ends,
/// by `special::gauss_kronrod` to relative accuracy `rel`. `dxy(θ, π/2 − θ)` = (k_x D_x(θ),
/// k_y D_y(θ)); the co-angle π/2 − θ_m = θ_o − δ is passed exactly, for profiles that vanish at
/// the horizon (see `PiecewiseLinear::d_xy_co`).
/// Domain: θ_o ∈ [0, π/2] (0 at θ_o = 0, +∞ at π/2).
pub(crate) fn lambda_exact(
    theta_o: f64,
    cos2phi: f64,
    dxy: &dyn Fn(f64, f64) -> (f64, f64),
    breaks: &[f64],
    rel: f64,
) -> f64 {
    if !(theta_o > 0.0) {
        return 0.0;
    }
    if theta_o >= FRAC_PI_2 {
        return f64::INFINITY;
    }
    let e = FRAC_PI_2 - theta_o;
    let mut us = vec![0.0];
    us.extend(
        breaks
            .iter()
            .filter(|&&b| b > e && b < FRAC_PI_2)
            .map(|&b| (b - e).sqrt()),
    );
    us.push(theta_o.sqrt());
    let f = |u: f64| {
        let delta = u * u;
        let tm = e + delta;
        let ratio = delta.sin() / (2.0 * theta_o - delta).sin();
        let gamma = 2.0 * ratio.max(0.0).sqrt().atan();
        let s = tm.sin();
        let (a, b) = dxy(tm, theta_o - delta);
        2.0 * u * s * s * ((a + b) * k0(gamma) + cos2phi * (a - b) * k2(gamma))
    };
    0.5 * theta_o.tan() * integrate(&f, &us, rel, 0.0).value
}

/// The exact route for the piecewise-linear model.
pub(crate) fn lambda_exact_piecewise(p: &PiecewiseLinear, theta_o: f64, cos2phi: f64) -> f64 {
    lambda_exact(
        theta_o,
        cos2phi,
        &|_, eps| {
            let (dx, dy) = p.d_xy_co(eps);
            (p.kx * dx, p.ky * dy)
        },
        &p.grid,
        EXACT_REL,
    )
}

/// How the domain split evaluates the integral it cannot close (eq 27).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Remaining {
    /// The document's trapezoid rule on the breakpoints (eq 28).
    Trapezoid,
    /// Adaptive Gauss–Kronrod (exact to ~1e-13).
    Adaptive,
}

/// The parts of document 000's domain split of ∫⟨o·m⟩D dm (eq 13, 19) and the results.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomainSplit {
    /// I₁₁ = I₁ − cos θ_o / 2 (eq 16, 34).
    pub i11: f64,
    /// I₂¹ (eq 23): θ_m ∈ [0, E], the back half of the azimuths, no Heaviside.
    pub i2_1: f64,
    /// I₂² (eq 26): θ_m ∈ [E, π/2], the front-facing part of the back half.
    pub i2_2: f64,
    /// Smith Λ by eq 34: (I₁₁ + I₂¹ + I₂²)/cos θ_o − ½.
    pub lambda: f64,
    /// G₁ by eq 29: cos θ_o / (I₁ + I₂¹ + I₂²).
    pub g1: f64,
}

/// Document 000's domain split (eq 13–29) of ∫⟨o·m⟩D dm, combined by eq 34:
///
/// ```text
/// I₁₁  = sin θ_o [k_x (3 + cos 2φ_o)/3 A_xⁿ + k_y (3 − cos 2φ_o)/3 A_yⁿ]            (eq 15–16)
/// I₂¹  = −sin θ_o [k_x (3 + cos 2φ_o)/3 A_x(E) + k_y (3 − cos 2φ_o)/3 A_y(E)]
///        + cos θ_o/4 · 2π [k_x T_x(E) + k_y T_y(E)]                                  (eq 22–23)
/// I₂²  = Λ_doc − cos θ_o/4 · 2π [k_x (T_xⁿ − T_x(E)) + k_y (T_yⁿ − T_y(E))]          (eq 26)
/// Λ_doc = sin θ_o/3 ∫_E^{π/2} sin²θ (sin C − 1)[k_x D_x (3 + c₂ q) + k_y D_y (3 − c₂ q)] dθ
///       + cos θ_o ∫_E^{π/2} cos θ sin θ [k_x D_x (C + ½ c₂ sin 2C)
///                                       + k_y D_y (C − ½ c₂ sin 2C)] dθ              (eq 27)
/// C = arccos(−cot θ_o cot θ), q = cos 2C − 2 sin C, c₂ = cos 2φ_o
/// Λ    = (I₁₁ + I₂¹ + I₂²)/cos θ_o − ½                                                (eq 34)
/// ```
///
/// with A(E) = ∫₀^E D sin²θ dθ, T(E) = ∫₀^E D cos θ sin θ dθ in closed form (tables up to
/// the segment of E, eq 15, plus the partial segment, eq 23). Λ_doc is by the trapezoid rule on
/// E and the breakpoints above it (eq 28) or adaptively. The trapezoid route is the
/// document's approximation: measured relative error of G₁ ≤ 3.3e-2 with 5–11 irregular
/// breakpoints and ≤ 3.2e-4 with 64 equal ones over θ_o ∈ [1e-3, 1.57] (largest where
/// [E, π/2] falls in one coarse segment; ERRATA-000 E10); adaptively it is exact. The
/// argument of arccos is clamped to [−1, 1] (rounding at θ = E). Near normal incidence the
/// subtraction in eq 34 cancels: absolute accuracy ~1e-16/cos θ_o, not relative.
pub fn domain_split(
    p: &PiecewiseLinear,
    theta_o: f64,
    cos2phi: f64,
    remaining: Remaining,
) -> DomainSplit {
    let (so, co) = theta_o.sin_cos();
    let last = p.grid.len() - 1;
    let c2 = cos2phi;
    let wx = p.kx * (3.0 + c2) / 3.0;
    let wy = p.ky * (3.0 - c2) / 3.0;
    let i11 = so * (wx * p.ax[last] + wy * p.ay[last]);
    let e = FRAC_PI_2 - theta_o;
    let (k, _) = p.locate(e);
    let (dxe, dye) = (p.d_x(e), p.d_y(e));
    let tk = p.grid[k];
    let a_x = p.ax[k] + segment_sin2(tk, e, p.gx[k], dxe);
    let a_y = p.ay[k] + segment_sin2(tk, e, p.gy[k], dye);
    let t_x = p.tx[k] + segment_cos_sin(tk, e, p.gx[k], dxe);
    let t_y = p.ty[k] + segment_cos_sin(tk, e, p.gy[k], dye);
    let i2_1 = -so * (wx * a_x + wy * a_y) + co / 4.0 * TAU * (p.kx * t_x + p.ky * t_y);
    let t_rest = TAU * (p.kx * (p.tx[last] - t_x) + p.ky * (p.ty[last] - t_y));
    let cot_o = co / so;
    let part = |t: f64| {
        let (st, ct) = t.sin_cos();
        let c = (-cot_o * ct / st).clamp(-1.0, 1.0).acos();
        let sc = c.sin();
        let q = (2.0 * c).cos() - 2.0 * sc;
        let (a, b) = (p.kx * p.d_x(t), p.ky * p.d_y(t));
        let part1 = st * st * (sc - 1.0) * (a * (3.0 + c2 * q) + b * (3.0 - c2 * q));
        let h = 0.5 * c2 * (2.0 * c).sin();
        let part2 = ct * st * (a * (c + h) + b * (c - h));
        so / 3.0 * part1 + co * part2
    };
    let mut nodes = vec![e];
    nodes.extend(p.grid.iter().copied().filter(|&t| t > e));
    let lambda_doc = match remaining {
        Remaining::Trapezoid => nodes
            .windows(2)
            .map(|w| 0.5 * (w[1] - w[0]) * (part(w[0]) + part(w[1])))
            .sum(),
        Remaining::Adaptive => {
            // u = √(θ − E): C has a square-root singularity at E.
            let us: Vec<f64> = nodes.iter().map(|&t| (t - e).max(0.0).sqrt()).collect();
            let f = |u: f64| 2.0 * u * part(e + u * u);
            integrate(&f, &us, EXACT_REL, 0.0).value
        }
    };
    let i2_2 = lambda_doc - co / 4.0 * t_rest;
    let (lambda, g1) = if co > 0.0 {
        let sum = i11 + i2_1 + i2_2;
        (sum / co - 0.5, co / (0.5 * co + sum))
    } else {
        (f64::INFINITY, 0.0)
    };
    DomainSplit {
        i11,
        i2_1,
        i2_2,
        lambda,
        g1,
    }
}

/// P₂(q) along the azimuth with cos 2φ = `cos2phi` (document 000 eq 30–31, with the slopes
/// rotated so that q runs along φ and p across it, ERRATA-000 E8):
///
/// ```text
/// P22(p, q) = cos⁴θ_m D(m),    P₂(q) = ∫_{−∞}^{∞} P22(p, q) dp
///           = ∫_{atan|q|}^{π/2} 2 cos³θ / (p sin θ) [k_x D_x (q² cos²φ + p² sin²φ)
///                                                  + k_y D_y (q² sin²φ + p² cos²φ)] dθ
/// ```
///
/// with p = √(tan²θ − q²) (both signs of p summed), taken in v = √(θ − atan|q|) (p ~ v at
/// the lower end) with the breakpoints as interval ends; relative accuracy `rel`.
pub fn p2(p: &PiecewiseLinear, q: f64, cos2phi: f64, rel: f64) -> f64 {
    let q = q.abs();
    let eq = if q == 0.0 {
        FRAC_PI_2
    } else {
        (1.0 / q).atan()
    };
    p2_co(p, q, eq, cos2phi, rel)
}

/// `p2` given also ε_q = π/2 − atan q (= atan(1/q)), so that cos θ = sin(ε_q − v²) keeps its
/// relative accuracy for huge q (θ next to the horizon).
fn p2_co(p: &PiecewiseLinear, q: f64, eq: f64, cos2phi: f64, rel: f64) -> f64 {
    let (cv2, sv2) = (0.5 * (1.0 + cos2phi), 0.5 * (1.0 - cos2phi));
    let tq = FRAC_PI_2 - eq;
    let cos_tq = eq.sin();
    let mut vs = vec![0.0];
    vs.extend(
        p.grid
            .iter()
            .filter(|&&t| t > tq && t < FRAC_PI_2)
            .map(|&t| (eq - (FRAC_PI_2 - t)).max(0.0).sqrt()),
    );
    vs.push(eq.sqrt());
    let q2 = q * q;
    let f = |v: f64| {
        let d = v * v;
        let (c, s) = (eq - d).sin_cos(); // cos θ, sin θ
        let pp2 = d.sin() / (c * cos_tq) * (s / c + q);
        let pv = pp2.sqrt();
        let (dx, dy) = p.d_xy_co(eq - d); // π/2 − θ, exactly
        let (a, b) = (p.kx * dx, p.ky * dy);
        let val = 4.0 * v * c * c * c / (pv * s)
            * (a * (q2 * cv2 + pp2 * sv2) + b * (q2 * sv2 + pp2 * cv2));
        if val.is_finite() {
            val
        } else {
            0.0
        }
    };
    integrate(&f, &vs, rel, 0.0).value
}

/// Λ by the slope-space form (document 000 eq 32 with the lower limit corrected to μ, ERRATA-000
/// E7):
///
/// ```text
/// Λ(o) = 1/μ ∫_μ^∞ (q − μ) P₂(q) dq,   μ = cot θ_o
///      = ∫_0^{θ_o} sin(θ_o − ε) P₂(cot ε) / (sin³ε cos θ_o) dε      (q = cot ε)
/// ```
///
/// P₂ by `p2` (relative 1e-13), the outer integral to relative 1e-12 with π/2 − θᵢ as interval
/// ends (P₂(cot ε) is not smooth where atan q crosses a breakpoint). The co-angle ε keeps cos β
/// and huge q accurate next to the horizon. Nested quadrature (~10⁴–10⁵ evaluations of D): a
/// cross-check of the exact route, not a fast path.
pub fn lambda_slope_space(p: &PiecewiseLinear, theta_o: f64, cos2phi: f64) -> f64 {
    if !(theta_o > 0.0) {
        return 0.0;
    }
    if theta_o >= FRAC_PI_2 {
        return f64::INFINITY;
    }
    // β = π/2 − ε: cos β = sin ε and q = cot ε stay accurate next to the horizon.
    let se = theta_o.cos();
    let mut cuts = vec![0.0];
    let mut inner: Vec<f64> = p
        .grid
        .iter()
        .map(|&t| FRAC_PI_2 - t)
        .filter(|&x| x > 0.0 && x < theta_o)
        .collect();
    inner.reverse();
    cuts.extend(inner);
    cuts.push(theta_o);
    let f = |eps: f64| {
        let sb = eps.sin();
        let q = 1.0 / eps.tan();
        let v = (theta_o - eps).sin() * p2_co(p, q, eps, cos2phi, 1e-13) / (sb * sb * sb * se);
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    integrate(&f, &cuts, 1e-12, 0.0).value
}

impl Smith for PiecewiseLinear {
    /// The "exact" route (see `lambda_routes`).
    fn lambda(&self, w: Vec3) -> f64 {
        both_hemispheres(w, |t, c2| lambda_exact_piecewise(self, t, c2))
    }

    /// `exact` (default; adaptive Gauss–Kronrod of the back-facing projected area, eq 10–13,
    /// relative accuracy 1e-13), `domain_split` (eq 16, 23, 26 and the trapezoid rule of eq 28,
    /// combined by eq 34 — the document's approximation), `domain_split_adaptive` (the same
    /// split with the remaining integral of eq 27 by adaptive quadrature: exact), `slope_space`
    /// (eq 30–32 corrected, nested adaptive quadrature over P2 along the azimuth of w).
    fn lambda_routes(&self) -> Vec<&'static str> {
        vec![
            "exact",
            "domain_split",
            "domain_split_adaptive",
            "slope_space",
        ]
    }

    fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        Ok(match route {
            "exact" | "default" => self.lambda(w),
            "domain_split" => both_hemispheres(w, |t, c2| {
                domain_split(self, t, c2, Remaining::Trapezoid).lambda
            }),
            "domain_split_adaptive" => both_hemispheres(w, |t, c2| {
                domain_split(self, t, c2, Remaining::Adaptive).lambda
            }),
            "slope_space" => both_hemispheres(w, |t, c2| lambda_slope_space(self, t, c2)),
            _ => {
                return Err(QueryError::Route {
                    route: route.to_string(),
                    reason: format!(
                        "piecewise-linear Λ routes: {}",
                        self.lambda_routes().join(", ")
                    ),
                })
            }
        })
    }
}
