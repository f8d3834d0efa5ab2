//! The piecewise-linear NDF of document 000 (Ribardière et al., "A Piecewise-Linear NDF"):
//! isotropic profiles linear between breakpoints (eq 4–5), their anisotropic blend (eq 1–3),
//! importance sampling (eq 6–9, Algorithms 1–2); the Smith Λ routes (eq 10–34) and the model's
//! `Smith` implementation are in `piecewise_lambda`, which builds on this file.

use crate::error::ParamError;
use crate::family::{FamilyInfo, FamilySpec, SamplerCost};
use crate::geometry::Vec3;
use crate::model::{Model, Ndf, NormalSampler, Smith};
use crate::ndf::angular_profile::AngularProfile;
use crate::spec::ModelSpec;
/// The family's spec type (declared with every family's in `crate::spec`).
pub use crate::spec::PiecewiseSpec;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The default inversion tolerance of the samplers: the largest accepted |cdf(x) − ξ| (document 000
/// Algorithms 1–2 print 1e-5).
pub const DEFAULT_TOLERANCE: f64 = 1e-12;

/// The piecewise-linear NDF of document 000 with one profile (isotropic) or two (the anisotropic
/// blend of eq 1).
///
/// ```text
/// D_iso(θ) = (aᵢ θ + bᵢ) / c_iso,            θ ∈ [θᵢ₋₁, θᵢ]                          (eq 4)
/// c_iso    = 2π Σᵢ ∫ (aᵢθ + bᵢ) cos θ sin θ dθ
///          = π/4 Σᵢ 2(aᵢθᵢ₋₁ + bᵢ) cos 2θᵢ₋₁ − 2(aᵢθᵢ + bᵢ) cos 2θᵢ
///                 + aᵢ (sin 2θᵢ − sin 2θᵢ₋₁)                                          (eq 5)
/// D(m)     = (cos²φ D_x(θ) D_y(0) + sin²φ D_y(θ) D_x(0)) / c                         (eq 1)
/// c        = (D_x(0) + D_y(0)) / 2                                                    (eq 3)
/// D(m)     = cos²φ D_x(θ) + sin²φ D_y(θ)        if D_x(0) = D_y(0) = 0              (§1.1)
/// ```
///
/// Internally D(m) = k_x cos²φ D_x(θ) + k_y sin²φ D_y(θ) with k_x = D_y(0)/c, k_y = D_x(0)/c
/// (k_x = k_y = 1 in the zero case and for one profile); k_x + k_y = 2 always. The segment
/// integrals of eq 5 (and eq 9, 15) are evaluated in a midpoint form that is free of the
/// cancellation of the printed difference of end-point terms (same value; see
/// `c_iso_eq5_printed`). Breakpoints of the two profiles may differ: they are merged.
///
/// Domain: each profile has ≥ 2 breakpoints from exactly 0 to π/2 (within 1e-15), strictly
/// increasing, values finite and ≥ 0, not all zero. D is continuous in θ, π-periodic in φ.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    /// The profiles as given (for `spec`).
    pub(super) x: AngularProfile,
    pub(super) y: Option<AngularProfile>,
    /// c_iso of each profile (eq 5).
    pub(super) c_iso_x: f64,
    pub(super) c_iso_y: f64,
    /// c of eq 3 (None in the zero case D_x(0) = D_y(0) = 0 and for one profile).
    pub(super) c: Option<f64>,
    /// The weights k_x = D_y(0)/c, k_y = D_x(0)/c.
    pub(super) kx: f64,
    pub(super) ky: f64,
    /// The merged breakpoints (θ₀ = 0 … π/2).
    pub(super) grid: Vec<f64>,
    /// Normalized D_x, D_y at the merged breakpoints.
    pub(super) gx: Vec<f64>,
    pub(super) gy: Vec<f64>,
    /// T_j[i] = ∫₀^{θᵢ} D_j(θ) cos θ sin θ dθ (the document's T tables of eq 9 up to the factor
    /// 2π k_j).
    pub(super) tx: Vec<f64>,
    pub(super) ty: Vec<f64>,
    /// A_j[i] = ∫₀^{θᵢ} D_j(θ) sin²θ dθ (the document's A tables, eq 15).
    pub(super) ax: Vec<f64>,
    pub(super) ay: Vec<f64>,
    /// The inversion tolerance of the samplers (largest |cdf − ξ|).
    pub(super) tolerance: f64,
}

impl PiecewiseLinear {
    /// A validated piecewise-linear NDF: `x` alone is isotropic; with `y`, the blend of eq 1.
    pub fn new(x: AngularProfile, y: Option<AngularProfile>) -> Result<Self, ParamError> {
        let c_iso_x = validate("x", &x)?;
        let c_iso_y = match &y {
            Some(p) => validate("y", p)?,
            None => c_iso_x,
        };
        let yp = y.as_ref().unwrap_or(&x);
        let mut grid: Vec<f64> = x.theta.iter().chain(yp.theta.iter()).copied().collect();
        // Validation pinned the ends: 0 and (within 1e-15) π/2; store π/2 exactly.
        for t in grid.iter_mut() {
            if *t > FRAC_PI_2 - 1e-15 {
                *t = FRAC_PI_2;
            }
        }
        grid.sort_by(f64::total_cmp);
        grid.dedup();
        let gx: Vec<f64> = grid.iter().map(|&t| interp(&x, t) / c_iso_x).collect();
        let gy: Vec<f64> = grid.iter().map(|&t| interp(yp, t) / c_iso_y).collect();
        let (dx0, dy0) = (gx[0], gy[0]);
        let (c, kx, ky) = if y.is_none() || (dx0 == 0.0 && dy0 == 0.0) {
            (None, 1.0, 1.0)
        } else {
            let c = 0.5 * (dx0 + dy0);
            (Some(c), dy0 / c, dx0 / c)
        };
        let cumulative = |g: &[f64], seg: fn(f64, f64, f64, f64) -> f64| {
            let mut out = vec![0.0; grid.len()];
            for i in 1..grid.len() {
                out[i] = out[i - 1] + seg(grid[i - 1], grid[i], g[i - 1], g[i]);
            }
            out
        };
        let tx = cumulative(&gx, segment_cos_sin);
        let ty = cumulative(&gy, segment_cos_sin);
        let ax = cumulative(&gx, segment_sin2);
        let ay = cumulative(&gy, segment_sin2);
        Ok(Self {
            x,
            y,
            c_iso_x,
            c_iso_y,
            c,
            kx,
            ky,
            grid,
            gx,
            gy,
            tx,
            ty,
            ax,
            ay,
            tolerance: DEFAULT_TOLERANCE,
        })
    }

    /// The same NDF with sampler inversion tolerance `tolerance` (the largest accepted
    /// |cdf(x) − ξ|; ≥ 0 and finite; 0 iterates until the bracket collapses).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self, ParamError> {
        if !(tolerance >= 0.0) || !tolerance.is_finite() {
            return Err(ParamError::OutOfRange {
                name: "tolerance",
                requirement: "finite and ≥ 0",
                value: tolerance,
            });
        }
        self.tolerance = tolerance;
        Ok(self)
    }

    /// The sampler inversion tolerance.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The normalization constants (c_iso of x, c_iso of y, c of eq 3); c is `None` for one
    /// profile and in the zero case D_x(0) = D_y(0) = 0 (§1.1). With one profile both c_iso are
    /// that of x.
    pub fn normalization_constants(&self) -> (f64, f64, Option<f64>) {
        (self.c_iso_x, self.c_iso_y, self.c)
    }

    /// The weights (k_x, k_y) of D(m) = k_x cos²φ D_x(θ) + k_y sin²φ D_y(θ).
    pub fn weights(&self) -> (f64, f64) {
        (self.kx, self.ky)
    }

    /// The merged breakpoints.
    pub fn breakpoints(&self) -> &[f64] {
        &self.grid
    }

    /// The normalized profile D_x(θ) (eq 4 divided by c_iso), θ ∈ [0, π/2].
    pub fn d_x(&self, theta: f64) -> f64 {
        self.eval(&self.gx, theta)
    }

    /// The normalized profile D_y(θ) (D_x for one profile).
    pub fn d_y(&self, theta: f64) -> f64 {
        self.eval(&self.gy, theta)
    }

    /// D at polar angle `theta` and azimuth through cos 2φ = `cos2phi`.
    pub(super) fn d_theta(&self, theta: f64, cos2phi: f64) -> f64 {
        let (i, t) = self.locate(theta);
        let vx = lerp(self.gx[i], self.gx[i + 1], t);
        let vy = lerp(self.gy[i], self.gy[i + 1], t);
        0.5 * (self.kx * vx * (1.0 + cos2phi) + self.ky * vy * (1.0 - cos2phi))
    }

    /// (D_x, D_y) (normalized profiles, document 000 eq 4) at θ = π/2 − ε, given the co-angle
    /// ε ∈ [0, π/2]: the segment's fraction is taken from its upper end,
    /// (ε − (π/2 − θᵢ₊₁))/(θᵢ₊₁ − θᵢ), so the
    /// values keep their relative accuracy where a profile vanishes at the horizon (from θ,
    /// whose absolute resolution next to π/2 is ~2e-16, D(π/2 − 1e-6) carries a relative error
    /// ~1e-10 there, which the nested quadrature of the `slope_space` route cannot converge on).
    pub(super) fn d_xy_co(&self, eps: f64) -> (f64, f64) {
        if !(0.0..=FRAC_PI_2).contains(&eps) {
            return if eps.is_nan() {
                (f64::NAN, f64::NAN)
            } else {
                (0.0, 0.0)
            };
        }
        let (i, _) = self.locate(FRAC_PI_2 - eps);
        let (a, b) = (self.grid[i], self.grid[i + 1]);
        // π/2 − θᵢ₊₁ is exact (Sterbenz) for θᵢ₊₁ ≥ π/4, and 0 at the last breakpoint.
        let s = ((eps - (FRAC_PI_2 - b)) / (b - a)).clamp(0.0, 1.0);
        (
            lerp(self.gx[i + 1], self.gx[i], s),
            lerp(self.gy[i + 1], self.gy[i], s),
        )
    }

    /// The segment index i (θ ∈ [θᵢ, θᵢ₊₁]) and the fraction within it.
    pub(super) fn locate(&self, theta: f64) -> (usize, f64) {
        let n = self.grid.len();
        let i = self
            .grid
            .partition_point(|&t| t <= theta)
            .saturating_sub(1)
            .min(n - 2);
        let (a, b) = (self.grid[i], self.grid[i + 1]);
        (i, ((theta - a) / (b - a)).clamp(0.0, 1.0))
    }

    fn eval(&self, g: &[f64], theta: f64) -> f64 {
        if !(0.0..=FRAC_PI_2).contains(&theta) {
            return if theta.is_nan() { f64::NAN } else { 0.0 };
        }
        let (i, t) = self.locate(theta);
        lerp(g[i], g[i + 1], t)
    }

    /// The marginal cdf of φ (document 000, eq 7):
    ///
    /// ```text
    /// cdf(φ) = φ/2π + (D_y(0) − D_x(0)) / (4π (D_y(0) + D_x(0))) sin 2φ
    ///        = φ/2π + κ sin 2φ / 4π,   κ = (k_x − k_y)/2 ∈ [−1, 1]
    /// ```
    ///
    /// κ = 0 for one profile and in the zero case (then φ is uniform). φ ∈ [0, 2π].
    pub fn cdf_phi(&self, phi: f64) -> f64 {
        let kappa = 0.5 * (self.kx - self.ky);
        phi / TAU + kappa * (2.0 * phi).sin() / (2.0 * TAU)
    }

    /// The conditional cdf of θ given φ (document 000, eq 8–9 corrected, ERRATA-000 E1), normalized
    /// to 1 at θ = π/2:
    ///
    /// ```text
    /// cdf(θ | φ) = ∫₀^θ (k_x cos²φ D_x + k_y sin²φ D_y) cos t sin t dt
    ///            / ((k_x cos²φ + k_y sin²φ) / 2π)
    /// ```
    pub fn cdf_theta(&self, theta: f64, phi: f64) -> f64 {
        let (wx, wy) = self.azimuth_weights(phi);
        let total = (wx * self.tx[self.tx.len() - 1]) + (wy * self.ty[self.ty.len() - 1]);
        let (i, _) = self.locate(theta);
        let gl = wx * self.gx[i] + wy * self.gy[i];
        let gt = wx * self.d_x(theta) + wy * self.d_y(theta);
        let partial = segment_cos_sin(self.grid[i], theta, gl, gt);
        (wx * self.tx[i] + wy * self.ty[i] + partial) / total
    }

    /// (k_x cos²φ, k_y sin²φ).
    fn azimuth_weights(&self, phi: f64) -> (f64, f64) {
        let (s, c) = phi.sin_cos();
        (self.kx * c * c, self.ky * s * s)
    }

    /// Document 000 Algorithm 1: φ with cdf(φ) = ξ, by Newton's method safeguarded by the quadrant
    /// bracket [kπ/2, (k+1)π/2] (cdf(kπ/2) = k/4); a Newton step that leaves the bracket, or
    /// a vanishing derivative (κ = ±1 at the quadrant ends), falls back to bisection. Stops when
    /// |cdf(φ) − ξ| ≤ tolerance or the bracket has collapsed.
    pub fn sample_phi(&self, xi: f64) -> f64 {
        let kappa = 0.5 * (self.kx - self.ky);
        let quadrant = (4.0 * xi).floor().clamp(0.0, 3.0);
        let mut a = quadrant * FRAC_PI_2;
        let mut c = a + FRAC_PI_2;
        let value = |phi: f64| (phi - TAU * xi) / TAU + kappa * (2.0 * phi).sin() / (2.0 * TAU);
        let derivative = |phi: f64| (1.0 + kappa * (2.0 * phi).cos()) / TAU;
        newton_bracketed(value, derivative, TAU * xi, &mut a, &mut c, self.tolerance)
    }

    /// Document 000 Algorithm 2 (eq 9, corrected per ERRATA-000 E1–E3): θ with cdf(θ | φ) = ξ. The
    /// segment is found in the cumulative tables (skipping segments without mass), then
    /// ∫_{θᵢ}^θ g(t) cos t sin t dt = ξ·total − Tᵢ is solved by Newton's method safeguarded by
    /// the segment bracket (bisection where the derivative g(θ) cos θ sin θ vanishes).
    pub fn sample_theta(&self, xi: f64, phi: f64) -> f64 {
        let (wx, wy) = self.azimuth_weights(phi);
        let n = self.grid.len();
        let w = |i: usize| wx * self.tx[i] + wy * self.ty[i];
        let total = w(n - 1);
        if !(total > 0.0) {
            // φ has zero density here (k_x cos²φ + k_y sin²φ = 0): any θ will do.
            return 0.0;
        }
        let target = xi * total;
        // The first breakpoint with cumulative mass > target; its segment has positive mass.
        let (mut lo, mut hi) = (0usize, n);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if w(mid) <= target {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let i = lo.clamp(1, n - 1) - 1;
        let (t0, t1) = (self.grid[i], self.grid[i + 1]);
        let g0 = wx * self.gx[i] + wy * self.gy[i];
        let g1 = wx * self.gx[i + 1] + wy * self.gy[i + 1];
        let residual = target - w(i);
        let g = |t: f64| lerp(g0, g1, ((t - t0) / (t1 - t0)).clamp(0.0, 1.0));
        let value = |t: f64| (segment_cos_sin(t0, t, g0, g(t)) - residual) / total;
        let derivative = |t: f64| g(t) * t.sin() * t.cos() / total;
        // Algorithm 2's starting point: the chord of the cdf over the segment.
        let mass = segment_cos_sin(t0, t1, g0, g1);
        let start = t0 + (t1 - t0) * (residual / mass);
        let (mut a, mut b) = (t0, t1);
        newton_bracketed(value, derivative, start, &mut a, &mut b, self.tolerance)
    }

    /// Document 000 eq 33 as printed: G(i, o, m) = 1 / (1 + Λ(i) + Λ(o)), without the χ⁺(i·m)
    /// χ⁺(o·m) factors of the general height-correlated form (ERRATA-000 E9): it does not
    /// vanish for back-facing microfacets. Equal to `g2(.., HeightCorrelated)` wherever both
    /// directions see m and are above the horizon.
    pub fn g2_eq33(&self, wi: Vec3, wo: Vec3) -> f64 {
        1.0 / (1.0 + self.lambda(wi) + self.lambda(wo))
    }
}

/// c_iso by document 000 eq 5 exactly as printed (a difference of end-point terms per segment;
/// correct, but it cancels for short segments). `profile` is raw (unnormalized).
pub fn c_iso_eq5_printed(profile: &AngularProfile) -> f64 {
    let (t, v) = (&profile.theta, &profile.value);
    let mut sum = 0.0;
    for i in 1..t.len() {
        let a = (v[i] - v[i - 1]) / (t[i] - t[i - 1]);
        let b = v[i - 1] - a * t[i - 1];
        sum += 2.0 * (a * t[i - 1] + b) * (2.0 * t[i - 1]).cos()
            - 2.0 * (a * t[i] + b) * (2.0 * t[i]).cos()
            + a * ((2.0 * t[i]).sin() - (2.0 * t[i - 1]).sin());
    }
    PI / 4.0 * sum
}

/// Validates a profile (document 000 eq 4 domain) and returns its c_iso (eq 5).
fn validate(axis: &'static str, p: &AngularProfile) -> Result<f64, ParamError> {
    let bad = |index: usize, requirement: &'static str, value: f64| ParamError::InvalidProfile {
        axis,
        index,
        requirement,
        value,
    };
    let n = p.theta.len();
    if n < 2 {
        return Err(bad(0, "at least 2 breakpoints", n as f64));
    }
    if p.value.len() != n {
        return Err(bad(
            n.min(p.value.len()),
            "as many values as breakpoints",
            p.value.len() as f64,
        ));
    }
    if p.theta[0] != 0.0 {
        return Err(bad(0, "the first breakpoint must be 0", p.theta[0]));
    }
    if !((p.theta[n - 1] - FRAC_PI_2).abs() <= 1e-15) {
        return Err(bad(
            n - 1,
            "the last breakpoint must be π/2",
            p.theta[n - 1],
        ));
    }
    for i in 1..n {
        if !(p.theta[i] > p.theta[i - 1]) {
            return Err(bad(i, "breakpoints strictly increasing", p.theta[i]));
        }
    }
    for (i, &v) in p.value.iter().enumerate() {
        if !(v >= 0.0) || !v.is_finite() {
            return Err(bad(i, "values finite and ≥ 0", v));
        }
    }
    let mut c_iso = 0.0;
    for i in 1..n {
        let t1 = p.theta[i].min(FRAC_PI_2);
        c_iso += segment_cos_sin(p.theta[i - 1], t1, p.value[i - 1], p.value[i]);
    }
    c_iso *= TAU;
    if !(c_iso > 0.0) || !c_iso.is_finite() {
        return Err(bad(
            0,
            "values not all zero, and ∫ D cos θ dω finite",
            c_iso,
        ));
    }
    Ok(c_iso)
}

/// Linear interpolation of a raw profile at θ.
fn interp(p: &AngularProfile, theta: f64) -> f64 {
    let n = p.theta.len();
    let i = p
        .theta
        .partition_point(|&t| t <= theta)
        .saturating_sub(1)
        .min(n - 2);
    let (a, b) = (p.theta[i], p.theta[i + 1]);
    lerp(
        p.value[i],
        p.value[i + 1],
        ((theta - a) / (b - a)).clamp(0.0, 1.0),
    )
}

#[inline]
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// sin 2h / 2 − h cos 2h = Σ_{k≥1} (−1)^{k+1} k (2h)^{2k+1} / (2k+1)!  (≈ 4h³/3).
fn s3(h: f64) -> f64 {
    if h.abs() >= 0.25 {
        return 0.5 * (2.0 * h).sin() - h * (2.0 * h).cos();
    }
    let x = 2.0 * h;
    let x2 = x * x;
    let mut term = x; // x^{2k+1}/(2k+1)! at k = 0
    let mut sum = 0.0;
    for k in 1..20 {
        term *= x2 / ((2 * k) as f64 * (2 * k + 1) as f64);
        let t = if k % 2 == 1 { 1.0 } else { -1.0 } * k as f64 * term;
        sum += t;
        if t.abs() <= 1e-18 * sum.abs() {
            break;
        }
    }
    sum
}

/// 2h − sin 2h = Σ_{k≥1} (−1)^{k+1} (2h)^{2k+1} / (2k+1)!  (≈ 4h³/3).
fn s1(h: f64) -> f64 {
    let x = 2.0 * h;
    if x.abs() >= 0.5 {
        return x - x.sin();
    }
    let x2 = x * x;
    let mut term = x;
    let mut sum = 0.0;
    for k in 1..20 {
        term *= x2 / ((2 * k) as f64 * (2 * k + 1) as f64);
        let t = if k % 2 == 1 { term } else { -term };
        sum += t;
        if t.abs() <= 1e-18 * sum.abs() {
            break;
        }
    }
    sum
}

/// The midpoint form [h, m, ḡ, δ] of the segment from (t0, g0) to (t1, g1): half-width
/// h = (t1−t0)/2, midpoint m = (t0+t1)/2, mean ḡ = (g0+g1)/2, half-rise δ = (g1−g0)/2; None for
/// an empty segment (h = 0, whose integrals are 0).
fn midpoint_form(t0: f64, t1: f64, g0: f64, g1: f64) -> Option<[f64; 4]> {
    let h = 0.5 * (t1 - t0);
    (h != 0.0).then_some([h, 0.5 * (t0 + t1), 0.5 * (g0 + g1), 0.5 * (g1 - g0)])
}

/// ∫_{t0}^{t1} g(θ) cos θ sin θ dθ for g linear from g0 at t0 to g1 at t1 (document 000 eq 5 per
/// segment, in midpoint form: m = (t0+t1)/2, h = (t1−t0)/2, ḡ = (g0+g1)/2, δ = (g1−g0)/2):
///
/// ```text
/// ∫ = ½ [ḡ sin 2m sin 2h + (δ/h) cos 2m (sin 2h / 2 − h cos 2h)]
/// ```
pub(super) fn segment_cos_sin(t0: f64, t1: f64, g0: f64, g1: f64) -> f64 {
    let Some([h, m, gm, d]) = midpoint_form(t0, t1, g0, g1) else {
        return 0.0;
    };
    0.5 * (gm * (2.0 * m).sin() * (2.0 * h).sin() + d / h * (2.0 * m).cos() * s3(h))
}

/// ∫_{t0}^{t1} g(θ) sin²θ dθ for g linear (document 000 eq 15 per segment, midpoint form):
///
/// ```text
/// ∫ = ½ [ḡ (2h − sin 2h + 2 sin²m sin 2h) + (δ/h) sin 2m (sin 2h / 2 − h cos 2h)]
/// ```
pub(super) fn segment_sin2(t0: f64, t1: f64, g0: f64, g1: f64) -> f64 {
    let Some([h, m, gm, d]) = midpoint_form(t0, t1, g0, g1) else {
        return 0.0;
    };
    let sm = m.sin();
    0.5 * (gm * (s1(h) + 2.0 * sm * sm * (2.0 * h).sin()) + d / h * (2.0 * m).sin() * s3(h))
}

/// Newton's method on `value` (increasing) safeguarded by the bracket [a, b] (value(a) ≤ 0 ≤
/// value(b)): a step out of the bracket bisects. Stops at |value| ≤ tol, when the bracket has
/// collapsed to adjacent floats, or after 200 iterations.
fn newton_bracketed(
    value: impl Fn(f64) -> f64,
    derivative: impl Fn(f64) -> f64,
    start: f64,
    a: &mut f64,
    b: &mut f64,
    tol: f64,
) -> f64 {
    let mut x = start;
    for _ in 0..200 {
        if !(x >= *a && x <= *b) {
            x = 0.5 * (*a + *b);
        }
        let v = value(x);
        if v.abs() <= tol {
            return x;
        }
        if v > 0.0 {
            *b = x;
        } else {
            *a = x;
        }
        let mid = 0.5 * (*a + *b);
        if !(mid > *a && mid < *b) {
            return x;
        }
        x -= v / derivative(x);
    }
    x
}

impl Ndf for PiecewiseLinear {
    fn d(&self, m: Vec3) -> f64 {
        if m[2] <= 0.0 {
            return 0.0;
        }
        let r2 = m[0] * m[0] + m[1] * m[1];
        let cos2phi = if r2 > 0.0 {
            (m[0] * m[0] - m[1] * m[1]) / r2
        } else {
            1.0 // at the pole both terms of eq 1 equal D_x(0) D_y(0) / c
        };
        let r = r2.sqrt();
        if m[2] < r {
            // Below 45° elevation, from the co-angle ε = π/2 − θ (relatively accurate from
            // m_z): θ itself resolves π/2 − ε only to ~2e-16 absolute, which made D relatively
            // inaccurate by ~1e-16/ε where a profile vanishes at the horizon.
            let (vx, vy) = self.d_xy_co(m[2].atan2(r));
            return 0.5 * (self.kx * vx * (1.0 + cos2phi) + self.ky * vy * (1.0 - cos2phi));
        }
        self.d_theta(r.atan2(m[2]), cos2phi)
    }

    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        Some(self)
    }
}

impl NormalSampler for PiecewiseLinear {
    /// φ by Algorithm 1 from `u[0]`, θ given φ by Algorithm 2 from `u[1]` (document 000 §2).
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let phi = self.sample_phi(u[0]);
        let theta = self.sample_theta(u[1], phi);
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        [st * cp, st * sp, ct]
    }
}

impl FamilySpec for PiecewiseSpec {
    fn build(&self) -> Result<Box<dyn Model>, crate::ParamError> {
        Ok(Box::new(PiecewiseLinear::new(
            self.x.clone(),
            self.y.clone(),
        )?))
    }

    /// The interior breakpoints of the profiles (both of the anisotropic blend, whose weights
    /// depend on φ only): D has kinks there for every azimuth.
    fn theta_kinks(&self) -> Vec<f64> {
        let mut out: Vec<f64> = self
            .x
            .theta
            .iter()
            .chain(self.y.iter().flat_map(|p| p.theta.iter()))
            .copied()
            .filter(|t| *t > 0.0 && *t < FRAC_PI_2)
            .collect();
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }
}

impl Model for PiecewiseLinear {
    fn spec(&self) -> ModelSpec {
        ModelSpec::PiecewiseLinear(PiecewiseSpec {
            x: self.x.clone(),
            y: self.y.clone(),
        })
    }

    fn family(&self) -> &'static str {
        PiecewiseSpec::INFO.name
    }
}

impl PiecewiseSpec {
    /// The registry entry of the piecewise-linear NDF ([`crate::registry`], which finds it through the spec type).
    pub const INFO: FamilyInfo = FamilyInfo {
        name: "piecewise_linear",
        documents: &["000"],
        source: "seed 000 eq 1–5",
        domain: "profiles: θ strictly increasing from 0 to π/2, values ≥ 0 and finite, not all 0",
        examples: &[
            r#"{"family": "piecewise_linear", "x": {"theta": [0.0, 0.3, 0.8, 1.2, 1.5707963267948966], "value": [3.0, 2.0, 0.6, 0.1, 0.0]}}"#,
            r#"{"family": "piecewise_linear", "x": {"theta": [0.0, 0.3, 0.8, 1.2, 1.5707963267948966], "value": [3.0, 2.0, 0.6, 0.1, 0.0]}, "y": {"theta": [0.0, 0.5, 1.0, 1.5707963267948966], "value": [1.5, 1.2, 0.3, 0.05]}}"#,
        ],
        stress_alpha: &[],
        stress_gamma: &[],
        stress_specs: &[],
        lambda_numerical: true,
        slow_sampler: true,
        beckmann_limit: false,
        intrinsic_moments: false,
        sampler_cost: SamplerCost {
            normal_ns: 568.0,
            visible_ns: 0.0,
        },
    };
}

#[cfg(test)]
#[path = "piecewise_tests.rs"]
pub(crate) mod tests;
