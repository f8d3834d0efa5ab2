//! Isotropic spherical Gaussians (document 003, §1–§2, after Wang et al. 2009): evaluation,
//! integral, inner and vector products, ε-support, the clamped-cosine fit, the lobe warp from
//! half vectors to light directions, and the spherical-cap integral.

use super::quadrature::{integrate_directions, Lobe};
use super::{add, frame_around, normalize, scale, sub, unit_axis};
use crate::error::{ParamError, QueryError};
use crate::geometry::{dot, Vec3};
use std::f64::consts::{FRAC_PI_2, LN_10, PI};

/// Relative accuracy asked of the `_exact` (quadrature) routes.
const EXACT_REL: f64 = 1e-12;

/// A spherical Gaussian (document 003, §1):
///
/// ```text
/// G(v; p, λ, μ) = μ e^{λ (v·p − 1)}
/// ```
///
/// with lobe axis p (unit), sharpness λ and amplitude μ. Domain: p a unit vector (within 1e-9;
/// it is normalized), λ finite and ≥ 0 (the document asks λ > 0; λ = 0 is the constant μ), μ
/// finite (any sign). The evaluation direction v should be a unit vector.
///
/// Sections 3.1 and 3.2.3 of the document write the same lobe as
/// `G_iso(v; p, ν) = e^{2ν(v·p − 1)}`, i.e. λ = 2ν.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sg {
    axis: Vec3,
    sharpness: f64,
    amplitude: f64,
}

/// The sharpness of the clamped-cosine fit C*(v; n) = G(v; n, 2.133, 1.170) (document 003, §2.4).
pub const CLAMPED_COSINE_SHARPNESS: f64 = 2.133;
/// The amplitude of the clamped-cosine fit (document 003, §2.4).
pub const CLAMPED_COSINE_AMPLITUDE: f64 = 1.170;

/// The measured maximum relative error of [`Sg::clamped_cosine_inner`] against the exact
/// ∫ G(v) max(v·n, 0) dv, for lights of any sharpness 1e-3 … 1e4 within 60° of n: 0.1944, for a
/// sharp light at 60° (test `clamped_cosine_fit_error_measured`).
pub const CLAMPED_COSINE_MAX_REL_ERROR_60: f64 = 0.195;

/// `f_h(θ_d, λ)`, the integral of the unit-amplitude SG over the spherical cap of half-angle
/// θ_d around its axis (document 003, §2.2):
///
/// ```text
/// f_h(θ_d, λ) = ∫₀^{θ_d} ∫₀^{2π} e^{λ(cos θ − 1)} sin θ dφ dθ = 2π (1 − e^{−λ (1 − cos θ_d)}) / λ
/// ```
///
/// Exact closed form (the document only says Wang et al. tabulate it and fit a sigmoid times a
/// polynomial, whose coefficients it does not give). Evaluated with expm1 and
/// 1 − cos θ_d = 2 sin²(θ_d/2), so it is accurate for λ → 0 (→ 2π (1 − cos θ_d)) and for small
/// caps. Domain: λ ≥ 0, θ_d ∈ [0, π].
pub fn f_h(theta_d: f64, lambda: f64) -> f64 {
    let s = (0.5 * theta_d).sin();
    let one_minus_cos = 2.0 * s * s;
    let x = lambda * one_minus_cos;
    let factor = if x == 0.0 { 1.0 } else { -(-x).exp_m1() / x };
    2.0 * PI * one_minus_cos * factor
}

/// `f_a(λ)`: the solid angle where a unit SG of sharpness λ is ≥ 0.1, the lobe's "mass" in Wang
/// et al. (document 003, §1):
///
/// ```text
/// f_a(λ) = −2π ln 0.1 / λ = 2π ln 10 / λ      λ ≥ ln(10)/2;   4π below
/// ```
///
/// Exact (see [`Sg::epsilon_support_area`]).
pub fn f_a(lambda: f64) -> f64 {
    support_area(lambda, 0.1)
}

/// The exact solid angle of {v : e^{λ(v·p − 1)} ≥ ε}, ε ∈ (0, 1].
fn support_area(lambda: f64, eps: f64) -> f64 {
    let t = -eps.ln();
    if t >= 2.0 * lambda {
        4.0 * PI
    } else {
        2.0 * PI * t / lambda
    }
}

impl Sg {
    /// A validated SG with axis `axis` (normalized), sharpness λ and amplitude μ.
    pub fn new(axis: Vec3, sharpness: f64, amplitude: f64) -> Result<Self, ParamError> {
        let axis = unit_axis("axis", axis)?;
        if !(sharpness >= 0.0 && sharpness.is_finite()) {
            return Err(ParamError::OutOfRange {
                name: "sharpness",
                requirement: "finite and ≥ 0",
                value: sharpness,
            });
        }
        if !amplitude.is_finite() {
            return Err(ParamError::OutOfRange {
                name: "amplitude",
                requirement: "finite",
                value: amplitude,
            });
        }
        Ok(Self {
            axis,
            sharpness,
            amplitude,
        })
    }

    /// The lobe axis p.
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// The sharpness λ.
    pub fn sharpness(&self) -> f64 {
        self.sharpness
    }

    /// The amplitude μ.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// G(v; p, λ, μ) = μ e^{λ(v·p − 1)} (document 003, §1).
    ///
    /// The SG is a function on the sphere: v is normalized, and the exponent is evaluated as
    /// −λ‖v̂ − p‖²/2 (= λ(v̂·p − 1) for unit vectors), which keeps its relative accuracy near the
    /// peak; λ(v·p − 1) as printed carries an absolute error λ·1e-16, i.e. a relative error
    /// 1e-12 in the value at λ = 1e4.
    pub fn eval(&self, v: Vec3) -> f64 {
        let d = sub(normalize(v), self.axis);
        self.amplitude * (-0.5 * self.sharpness * dot(d, d)).exp()
    }

    /// The integral over the sphere:
    ///
    /// ```text
    /// ∫_{S²} G(v) dv = 2π μ (1 − e^{−2λ}) / λ        (4π μ at λ = 0)
    /// ```
    ///
    /// Exact closed form (the inner-product formula of document 003 §1 with a constant 1), evaluated
    /// with expm1: accurate for every λ ≥ 0.
    pub fn integral(&self) -> f64 {
        let l = self.sharpness;
        if l == 0.0 {
            return 4.0 * PI * self.amplitude;
        }
        2.0 * PI * self.amplitude * -(-2.0 * l).exp_m1() / l
    }

    /// [`Sg::integral`] by adaptive quadrature over the sphere (relative accuracy ≈ 1e-12).
    pub fn integral_exact(&self) -> f64 {
        integrate_directions(
            &|v| self.eval(v),
            &frame_around(self.axis),
            PI,
            &[Lobe::of_sharpness(self.axis, self.sharpness)],
            EXACT_REL,
        )
    }

    /// The exponent d_m − λ₁ − λ₂ ≤ 0 of the inner and vector products, with
    /// d_m = ‖λ₁p₁ + λ₂p₂‖, computed without cancellation:
    /// `d_m − λ₁ − λ₂ = −λ₁λ₂ ‖p₁ − p₂‖² / (d_m + λ₁ + λ₂)`.
    fn product_exponent(&self, other: &Sg) -> (Vec3, f64, f64) {
        let (l1, l2) = (self.sharpness, other.sharpness);
        let w = add(scale(self.axis, l1), scale(other.axis, l2));
        let d = dot(w, w).sqrt();
        let diff = sub(self.axis, other.axis);
        let sum = d + l1 + l2;
        let exponent = if sum == 0.0 {
            0.0
        } else {
            -l1 * l2 * dot(diff, diff) / sum
        };
        (w, d, exponent)
    }

    /// The inner product (document 003, §1):
    ///
    /// ```text
    /// G₁ · G₂ = ∫_{S²} G₁ G₂ dv = 4π μ₁μ₂ e^{−(λ₁+λ₂)} sinh(d_m)/d_m,   d_m = ‖λ₁p₁ + λ₂p₂‖
    ///         = 4π μ₁μ₂ e^{d_m − λ₁ − λ₂} (1 − e^{−2 d_m}) / (2 d_m)      (as evaluated)
    /// ```
    ///
    /// Exact closed form; evaluated in the second form (exponent by
    /// `−λ₁λ₂‖p₁ − p₂‖²/(d_m + λ₁ + λ₂)`, expm1), so it neither overflows nor loses precision
    /// for sharpness up to 1e4 and beyond, parallel or anti-parallel axes.
    pub fn inner(&self, other: &Sg) -> f64 {
        let (_, d, exponent) = self.product_exponent(other);
        let shape = if d == 0.0 {
            1.0
        } else {
            -(-2.0 * d).exp_m1() / (2.0 * d)
        };
        4.0 * PI * self.amplitude * other.amplitude * exponent.exp() * shape
    }

    /// The inner product exactly as printed, `4π μ₁μ₂ / e^{λ₁+λ₂} · sinh(d_m)/d_m`. Correct
    /// mathematically, but e^{λ₁+λ₂} and sinh overflow once λ₁ + λ₂ > 709 (kept to show why
    /// [`Sg::inner`] evaluates it otherwise).
    pub fn inner_printed(&self, other: &Sg) -> f64 {
        let (_, d, _) = self.product_exponent(other);
        let shape = if d == 0.0 { 1.0 } else { d.sinh() / d };
        4.0 * PI * self.amplitude * other.amplitude / (self.sharpness + other.sharpness).exp()
            * shape
    }

    /// [`Sg::inner`] by adaptive quadrature over the sphere (relative accuracy ≈ 1e-12).
    pub fn inner_exact(&self, other: &Sg) -> f64 {
        let (w, d, _) = self.product_exponent(other);
        let mut lobes = vec![
            Lobe::of_sharpness(self.axis, self.sharpness),
            Lobe::of_sharpness(other.axis, other.sharpness),
        ];
        if d > 0.0 {
            lobes.push(Lobe::of_sharpness(scale(w, 1.0 / d), d));
        }
        integrate_directions(
            &|v| self.eval(v) * other.eval(v),
            &frame_around(self.axis),
            PI,
            &lobes,
            EXACT_REL,
        )
    }

    /// The vector product G₁ ⊗ G₂, the pointwise product, which is an SG (document 003, §1):
    ///
    /// ```text
    /// G₁(v) G₂(v) = G(v; p_m/‖p_m‖, λ_m ‖p_m‖, μ₁μ₂ e^{λ_m (‖p_m‖ − 1)})
    /// p_m = (λ₁p₁ + λ₂p₂)/(λ₁ + λ₂),   λ_m = λ₁ + λ₂
    /// ```
    ///
    /// Exact. λ_m‖p_m‖ = d_m and λ_m(‖p_m‖ − 1) = d_m − λ₁ − λ₂ are evaluated as in
    /// [`Sg::inner`]. Where λ₁p₁ + λ₂p₂ = 0 the product is the constant μ₁μ₂e^{−λ₁−λ₂}: an SG of
    /// sharpness 0 (axis p₁).
    pub fn product(&self, other: &Sg) -> Sg {
        let (w, d, exponent) = self.product_exponent(other);
        let axis = if d > 0.0 { normalize(w) } else { self.axis };
        Sg {
            axis,
            sharpness: d,
            amplitude: self.amplitude * other.amplitude * exponent.exp(),
        }
    }

    /// The solid angle of the ε-support, the region where the lobe is at least ε times its
    /// peak (document 003, §1, where it is defined for μ = 1):
    ///
    /// ```text
    /// ∫_{G(v; p, λ, 1) ≥ ε} dv = −2π ln ε / λ        λ ≥ −ln(ε)/2;   4π below
    /// ```
    ///
    /// Exact: the region is the cap cos θ ≥ 1 + ln ε / λ. The document states the formula for
    /// λ > −ln ε, a sufficient condition; it holds down to λ = −ln(ε)/2, where the cap becomes
    /// the sphere (ERRATA.md, note N1). Domain: ε ∈ (0, 1].
    pub fn epsilon_support_area(&self, eps: f64) -> Result<f64, QueryError> {
        check_epsilon(eps)?;
        Ok(support_area(self.sharpness, eps))
    }

    /// The cosine of the ε-support's half-angle around the axis, `max(1 + ln ε / λ, −1)`
    /// (document 003, §1). Domain: ε ∈ (0, 1].
    pub fn epsilon_support_cos(&self, eps: f64) -> Result<f64, QueryError> {
        check_epsilon(eps)?;
        if self.sharpness == 0.0 {
            return Ok(-1.0);
        }
        Ok((1.0 + eps.ln() / self.sharpness).max(-1.0))
    }

    /// The clamped-cosine fit of Wang et al. (document 003, §2.4):
    ///
    /// ```text
    /// max(v·n, 0) ≈ C*(v; n) = G(v; n, 2.133, 1.170)
    /// ```
    ///
    /// An approximation; the document states no error. Measured (test
    /// `clamped_cosine_fit_error_measured`): max pointwise error 0.170 (at v = n, where
    /// C* = 1.170), and 0.1386 at the horizon where the cosine is 0; ∫C* = 3.398 against
    /// ∫max(cos, 0) = π (+8.2 %); in use, as the inner product G · C* for an SG light G,
    /// relative error ≤ 0.1944 ([`CLAMPED_COSINE_MAX_REL_ERROR_60`]) for lights of sharpness
    /// 1e-3 … 1e4 within 60° of n: +17 % for a sharp light at n, −19.4 % for one at 60°, and
    /// worse towards the horizon. `n` must be a unit vector.
    pub fn clamped_cosine(n: Vec3) -> Result<Sg, ParamError> {
        Sg::new(n, CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE)
    }

    /// The document's route to ∫ G(v) max(v·n, 0) dv: the inner product G · C*(·; n) with the
    /// clamped-cosine fit (document 003, §2.4). Error: see [`Sg::clamped_cosine`].
    pub fn clamped_cosine_inner(&self, n: Vec3) -> Result<f64, ParamError> {
        Ok(self.inner(&Sg::clamped_cosine(n)?))
    }

    /// ∫ G(v) max(v·n, 0) dv by adaptive quadrature over the hemisphere around n (relative
    /// accuracy ≈ 1e-12): the exact counterpart of [`Sg::clamped_cosine_inner`]. `n` must be a
    /// unit vector.
    pub fn clamped_cosine_inner_exact(&self, n: Vec3) -> Result<f64, ParamError> {
        let n = unit_axis("n", n)?;
        Ok(integrate_directions(
            &|v| self.eval(v) * dot(v, n).max(0.0),
            &frame_around(n),
            FRAC_PI_2,
            &[Lobe::of_sharpness(self.axis, self.sharpness)],
            EXACT_REL,
        ))
    }

    /// The lobe warp of Wang et al. from a lobe in half vectors h to one in light directions i
    /// for the view direction o (document 003, §2.1):
    ///
    /// ```text
    /// i = ψ(h) = 2 (o·h) h − o,   di = 4 |h·o| dh
    /// p_W = ψ(p_D),   λ_W = λ_D / (4 |p_D·o|),   μ_W = μ_D
    /// ```
    ///
    /// An approximation: λ_W makes f_a(λ_W) (the 0.1-support of the new lobe) equal to the
    /// area of ψ(A), A the 0.1-support of the old one, with the Jacobian frozen at the axis. The
    /// document states no error; measured ([`Sg::warp_support_area_exact`], test
    /// `warp_mass_error_measured`): f_a(λ_W) exceeds the true area of ψ(A) by the factor
    /// 2/(1 + cos θ₀), θ₀ the support's half-angle, i.e. by ln(10)/(2λ_D) to first order —
    /// 1.2 % at λ_D = 100 — whatever o is (while A stays on o's side). `o` must be a unit vector;
    /// an error where p_D ⊥ o (λ_W infinite).
    pub fn warp(&self, o: Vec3) -> Result<Sg, QueryError> {
        let o = unit_axis("o", o).map_err(|e| QueryError::Argument(e.to_string()))?;
        let c = dot(o, self.axis);
        if c == 0.0 {
            return Err(QueryError::Argument(
                "the lobe axis is perpendicular to o: the warped sharpness is infinite".into(),
            ));
        }
        let axis = sub(scale(self.axis, 2.0 * c), o);
        Sg::new(axis, self.sharpness / (4.0 * c.abs()), self.amplitude)
            .map_err(|e| QueryError::Argument(e.to_string()))
    }

    /// The true solid angle of ψ(A), A = {h : G(h; p, λ, 1) ≥ 0.1}, ψ(h) = 2(o·h)h − o: the
    /// quantity that f_a(λ_W) of [`Sg::warp`] approximates, by adaptive quadrature of
    /// ∫_A 4|h·o| dh (ψ is one-to-one on A). Domain: λ > ln 10 (so that A is smaller than a
    /// hemisphere); `o` a unit vector.
    pub fn warp_support_area_exact(&self, o: Vec3) -> Result<f64, QueryError> {
        let o = unit_axis("o", o).map_err(|e| QueryError::Argument(e.to_string()))?;
        if !(self.sharpness > LN_10) {
            return Err(QueryError::Argument(format!(
                "the 0.1-support is a hemisphere or more for λ ≤ ln 10 (got λ = {})",
                self.sharpness
            )));
        }
        let theta0 = (1.0 - LN_10 / self.sharpness).acos();
        let frame = frame_around(self.axis);
        // The kink of |h·o| is at the great circle h·o = 0: put a lobe where it crosses A.
        let mut lobes = vec![Lobe {
            peak: self.axis,
            width: theta0 * 0.25,
        }];
        let across = sub(o, scale(self.axis, dot(o, self.axis)));
        if dot(across, across) > 0.0 {
            lobes.push(Lobe {
                peak: normalize(across),
                width: theta0 * 0.25,
            });
        }
        Ok(integrate_directions(
            &|h| 4.0 * dot(h, o).abs(),
            &frame,
            theta0,
            &lobes,
            EXACT_REL,
        ))
    }

    /// The integral over the spherical cap of half-angle θ_d around the axis (document 003, §2.2,
    /// the "dot product" G · V' with the cap visibility V'):
    ///
    /// ```text
    /// ∫_{p·i ≥ cos θ_d} G(i; p, λ, μ) di = μ f_h(θ_d, λ) = 2π μ (1 − e^{−λ(1 − cos θ_d)}) / λ
    /// ```
    ///
    /// Exact closed form (see [`f_h`]). Domain: θ_d ∈ [0, π].
    pub fn cap_integral(&self, theta_d: f64) -> Result<f64, QueryError> {
        check_cap(theta_d)?;
        Ok(self.amplitude * f_h(theta_d, self.sharpness))
    }

    /// [`Sg::cap_integral`] by adaptive quadrature over the cap (relative accuracy ≈ 1e-12).
    pub fn cap_integral_exact(&self, theta_d: f64) -> Result<f64, QueryError> {
        check_cap(theta_d)?;
        Ok(integrate_directions(
            &|v| self.eval(v),
            &frame_around(self.axis),
            theta_d,
            &[Lobe::of_sharpness(self.axis, self.sharpness)],
            EXACT_REL,
        ))
    }

    /// The document's vector product of the lobe with the cap visibility V' (document 003, §2.2):
    /// the same lobe, with its amplitude scaled
    ///
    /// ```text
    /// G(i; p, λ, μ) ⊗ V'(i) ≈ G(i; p, λ, μ f_h(θ_d, λ) / f_h(π/2, λ))        (as printed)
    /// ```
    ///
    /// An approximation "with amplitude scaled to give the same integral value as the
    /// product"; as printed it does not: its integral over the sphere is
    /// μ f_h(θ_d, λ) (1 + e^{−λ}), too large by the factor 1 + e^{−λ} (37 % at λ = 1, 4.5e-5 at
    /// λ = 10). Dividing by f_h(π, λ) instead matches it exactly (ERRATA.md, E2;
    /// [`Sg::cap_product_matched`]). Domain: θ_d ∈ [0, π].
    pub fn cap_product(&self, theta_d: f64) -> Result<Sg, QueryError> {
        check_cap(theta_d)?;
        let ratio = f_h(theta_d, self.sharpness) / f_h(FRAC_PI_2, self.sharpness);
        Ok(Sg {
            amplitude: self.amplitude * ratio,
            ..*self
        })
    }

    /// The cap product with the amplitude the document's stated purpose calls for:
    /// `μ f_h(θ_d, λ) / f_h(π, λ)`, so that its integral over the sphere is exactly the cap
    /// integral μ f_h(θ_d, λ) (ERRATA.md, E2). Domain: θ_d ∈ [0, π].
    pub fn cap_product_matched(&self, theta_d: f64) -> Result<Sg, QueryError> {
        check_cap(theta_d)?;
        let ratio = f_h(theta_d, self.sharpness) / f_h(PI, self.sharpness);
        Ok(Sg {
            amplitude: self.amplitude * ratio,
            ..*self
        })
    }
}

fn check_epsilon(eps: f64) -> Result<(), QueryError> {
    if !(eps > 0.0 && eps <= 1.0) {
        return Err(QueryError::Argument(format!(
            "ε must lie in (0, 1] (got {eps})"
        )));
    }
    Ok(())
}

fn check_cap(theta_d: f64) -> Result<(), QueryError> {
    if !(0.0..=PI).contains(&theta_d) {
        return Err(QueryError::Argument(format!(
            "the cap's half-angle must lie in [0, π] (got {theta_d})"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::from_spherical;
    use crate::sg::oracle::{cuts, directions, integrate_cut};
    use crate::test_support::rel_err;

    /// The independent oracle (double-exponential quadrature, `sg::oracle`) of ∫ f over the
    /// directions within θmax of +z, cut around a peak at polar angle θp (azimuth 0); f must be
    /// even in φ.
    fn sphere_oracle(
        f: &dyn Fn(Vec3) -> f64,
        theta_max: f64,
        theta_peak: f64,
        w: f64,
        rel: f64,
    ) -> f64 {
        directions(
            &|t, p| f(from_spherical(t, p)),
            theta_max,
            (theta_peak, 0.0),
            w,
            rel,
            true,
        )
    }

    #[test]
    fn validation() {
        assert!(Sg::new([0.0, 0.0, 1.0], 1.0, 1.0).is_ok());
        assert!(Sg::new([0.0, 0.0, 1.0], 0.0, -2.0).is_ok());
        let nearly = Sg::new([0.0, 0.0, 1.0 + 5e-10], 1.0, 1.0).unwrap();
        assert_eq!(nearly.axis(), [0.0, 0.0, 1.0]);
        assert!(Sg::new([0.0, 0.0, 1.0 + 1e-8], 1.0, 1.0).is_err());
        assert!(Sg::new([0.0, 0.0, f64::NAN], 1.0, 1.0).is_err());
        assert!(Sg::new([0.0, 0.0, 1.0], -1e-300, 1.0).is_err());
        assert!(Sg::new([0.0, 0.0, 1.0], f64::NAN, 1.0).is_err());
        assert!(Sg::new([0.0, 0.0, 1.0], f64::INFINITY, 1.0).is_err());
        assert!(Sg::new([0.0, 0.0, 1.0], 1.0, f64::NAN).is_err());
        assert!(Sg::new([0.0, 0.0, 1.0], 1.0, f64::INFINITY).is_err());
        let g = Sg::new([0.0, 0.0, 1.0], 1.0, 1.0).unwrap();
        assert!(g.epsilon_support_area(0.0).is_err());
        assert!(g.epsilon_support_area(1.5).is_err());
        assert!(g.epsilon_support_area(f64::NAN).is_err());
        assert!(g.cap_integral(-0.1).is_err());
        assert!(g.cap_integral(f64::NAN).is_err());
        assert!(g.cap_integral(3.2).is_err());
        assert!(g.warp([1.0, 0.0, 0.0]).is_err());
        assert!(g.warp([0.0, 0.0, 2.0]).is_err());
        assert!(g.warp_support_area_exact([0.0, 0.0, 1.0]).is_err());
    }

    #[test]
    fn integral_matches_quadrature() {
        let axis = normalize([0.3, -0.2, 0.9]);
        for l in [0.0, 1e-3, 1.0, 100.0, 1e4] {
            let g = Sg::new(axis, l, 1.7).unwrap();
            let cut = cuts(0.0, 1.0 / (1.0 + l).sqrt(), 0.0, PI);
            let q = 2.0
                * PI
                * 1.7
                * integrate_cut(&|t: f64| (l * (t.cos() - 1.0)).exp() * t.sin(), &cut, 1e-13);
            assert!(
                rel_err(g.integral(), q) < 1e-12,
                "λ = {l}: {} vs {q}",
                g.integral()
            );
            assert!(rel_err(g.integral_exact(), q) < 1e-10, "λ = {l}");
        }
    }

    #[test]
    fn inner_product_matches_quadrature_parallel_to_antiparallel() {
        let z = [0.0, 0.0, 1.0];
        let pairs = [
            (1e-3, 1e-3),
            (1.0, 1.0),
            (100.0, 1.0),
            (100.0, 100.0),
            (1e4, 1.0),
            (1e4, 1e4),
        ];
        for (l1, l2) in pairs {
            for beta in [0.0, 0.3, 1.5, PI] {
                if beta == 1.5 && l1 == l2 && l1 > 1.0 {
                    // e^{−2λ(1 − cos 0.75)}: covered by β = 0.3 at this sharpness.
                    continue;
                }
                let g1 = Sg::new(z, l1, 1.3).unwrap();
                let g2 = Sg::new(from_spherical(beta, 0.0), l2, -0.7).unwrap();
                let got = g1.inner(&g2);
                assert!(got.is_finite(), "{l1} {l2} {beta}");
                let prod = g1.product(&g2);
                let theta_peak = dot(prod.axis(), z).clamp(-1.0, 1.0).acos();
                let w = 1.0 / (1.0 + prod.sharpness()).sqrt();
                let q = if beta == 0.0 || beta == PI {
                    // Parallel or anti-parallel: symmetric about z, a 1-D integral.
                    let h = |t: f64| {
                        let v = from_spherical(t, 0.0);
                        2.0 * PI * g1.eval(v) * g2.eval(v) * t.sin()
                    };
                    integrate_cut(&h, &cuts(theta_peak, w, 0.0, PI), 1e-13)
                } else {
                    sphere_oracle(&|v| g1.eval(v) * g2.eval(v), PI, theta_peak, w, 1e-11)
                };
                if q == 0.0 {
                    // e^{−2·10⁴}: below the smallest double; the closed form agrees.
                    assert_eq!(got, 0.0, "{l1} {l2} {beta}");
                    continue;
                }
                assert!(
                    rel_err(got, q) < 1e-10,
                    "λ = {l1}, {l2}, β = {beta}: {got} vs {q}"
                );
                let mine = g1.inner_exact(&g2);
                assert!(
                    rel_err(mine, q) < 1e-10,
                    "exact route {l1} {l2} {beta}: {mine} vs {q}"
                );
                if l1 + l2 < 700.0 {
                    assert!(rel_err(g1.inner_printed(&g2), q) < 1e-10);
                }
            }
        }
        // The printed form overflows where the stable one does not.
        let g1 = Sg::new(z, 1e4, 1.0).unwrap();
        let printed = g1.inner_printed(&g1);
        assert!(!printed.is_finite() || printed == 0.0);
        let stable = g1.inner(&g1);
        assert!(rel_err(stable, 4.0 * PI * -(-4e4f64).exp_m1() / 4e4) < 1e-14);
    }

    #[test]
    fn vector_product_is_the_pointwise_product() {
        for (l1, l2, beta) in [
            (1.0, 2.0, 0.7),
            (1e4, 3.0, 0.01),
            (5.0, 5.0, PI),
            (0.0, 0.0, 1.0),
        ] {
            let g1 = Sg::new([0.0, 0.0, 1.0], l1, 2.0).unwrap();
            let g2 = Sg::new(from_spherical(beta, 0.4), l2, 0.5).unwrap();
            let p = g1.product(&g2);
            assert!(crate::geometry::is_unit(p.axis(), 1e-14));
            for i in 0..40 {
                let v = from_spherical(0.08 * i as f64, 0.37 * i as f64);
                let want = g1.eval(v) * g2.eval(v);
                assert!(
                    (p.eval(v) - want).abs() <= 1e-12 * want.abs().max(1e-300),
                    "{l1} {l2} {beta}: {} vs {want}",
                    p.eval(v)
                );
            }
            // The inner product is the product's integral.
            assert!(rel_err(p.integral(), g1.inner(&g2)) < 1e-13);
        }
    }

    #[test]
    fn epsilon_support() {
        let g = Sg::new([0.0, 0.0, 1.0], 7.0, 3.0).unwrap();
        let eps = 0.1;
        // The boundary by bisection on the lobe itself.
        let (mut lo, mut hi) = (0.0, PI);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if g.eval(from_spherical(m, 0.0)) >= eps * 3.0 {
                lo = m
            } else {
                hi = m
            }
        }
        let area = 2.0 * PI * (1.0 - lo.cos());
        assert!(rel_err(g.epsilon_support_area(eps).unwrap(), area) < 1e-12);
        assert!(
            rel_err(
                g.epsilon_support_area(eps).unwrap(),
                -2.0 * PI * eps.ln() / 7.0
            ) < 1e-15
        );
        assert!(rel_err(g.epsilon_support_cos(eps).unwrap(), lo.cos()) < 1e-12);
        assert!(rel_err(f_a(7.0), area) < 1e-12);
        // Note N1: the printed formula holds below the printed bound λ > −ln ε, down to
        // −ln(ε)/2 ...
        let g = Sg::new([0.0, 0.0, 1.0], 0.6 * LN_10, 1.0).unwrap();
        let printed = -2.0 * PI * eps.ln() / g.sharpness();
        assert!(rel_err(g.epsilon_support_area(eps).unwrap(), printed) < 1e-15);
        assert!(printed < 4.0 * PI);
        // ... and beyond it exceeds the sphere.
        let g = Sg::new([0.0, 0.0, 1.0], 0.4 * LN_10, 1.0).unwrap();
        assert!(-2.0 * PI * eps.ln() / g.sharpness() > 4.0 * PI);
        assert_eq!(g.epsilon_support_area(eps).unwrap(), 4.0 * PI);
        assert_eq!(g.epsilon_support_cos(eps).unwrap(), -1.0);
    }

    #[test]
    fn cap_integral_matches_quadrature() {
        for l in [0.0, 1e-3, 1.0, 100.0, 1e4] {
            for theta_d in [0.0, 1e-3, 0.3, FRAC_PI_2, 2.5, PI] {
                let g = Sg::new(normalize([1.0, 1.0, 1.0]), l, 0.8).unwrap();
                let cut = cuts(0.0, 1.0 / (1.0 + l).sqrt(), 0.0, theta_d);
                let q = 2.0
                    * PI
                    * 0.8
                    * integrate_cut(&|t: f64| (l * (t.cos() - 1.0)).exp() * t.sin(), &cut, 1e-13);
                let got = g.cap_integral(theta_d).unwrap();
                if theta_d == 0.0 {
                    assert_eq!(got, 0.0);
                    continue;
                }
                assert!(
                    rel_err(got, q) < 1e-12,
                    "λ = {l}, θd = {theta_d}: {got} vs {q}"
                );
                let mine = g.cap_integral_exact(theta_d).unwrap();
                assert!(rel_err(mine, q) < 1e-10, "λ = {l}, θd = {theta_d}");
            }
        }
        // f_h(π, λ) is the whole integral.
        let g = Sg::new([0.0, 0.0, 1.0], 3.0, 2.0).unwrap();
        assert!(rel_err(g.cap_integral(PI).unwrap(), g.integral()) < 1e-15);
    }

    #[test]
    fn printed_cap_product_misses_the_cap_integral() {
        // ERRATA.md, E2: document 003 §2.2 scales the amplitude by f_h(θd, λ)/f_h(π/2, λ) "to
        // give the same integral value as the product"; the scaled lobe's integral is
        // μ f_h(θd, λ)(1 + e^{−λ}).
        let mut report = Vec::new();
        for l in [1.0, 3.0, 10.0, 30.0] {
            let g = Sg::new([0.0, 0.6, 0.8], l, 1.0).unwrap();
            for theta_d in [0.2, 1.0, 2.0] {
                let want = g.cap_integral(theta_d).unwrap();
                let printed = g.cap_product(theta_d).unwrap().integral();
                let err = rel_err(printed, want);
                assert!((err - (-l).exp()).abs() < 1e-12, "λ = {l}: {err}");
                let matched = g.cap_product_matched(theta_d).unwrap().integral();
                assert!(rel_err(matched, want) < 1e-14);
            }
            report.push(format!("λ = {l}: {:.2e}", (-l).exp()));
        }
        assert!(
            rel_err(
                Sg::new([0.0, 0.0, 1.0], 1.0, 1.0)
                    .unwrap()
                    .cap_product(1.0)
                    .unwrap()
                    .integral(),
                Sg::new([0.0, 0.0, 1.0], 1.0, 1.0)
                    .unwrap()
                    .cap_integral(1.0)
                    .unwrap()
            ) > 0.3
        );
        eprintln!("cap product as printed, rel err of its integral: {report:?}");
    }

    #[test]
    fn clamped_cosine_fit_error_measured() {
        let n = [0.0, 0.0, 1.0];
        let c = Sg::clamped_cosine(n).unwrap();
        // Pointwise.
        let mut worst = 0.0f64;
        for i in 0..=3000 {
            let theta = PI * i as f64 / 3000.0;
            let v = from_spherical(theta, 0.0);
            worst = worst.max((c.eval(v) - theta.cos().max(0.0)).abs());
        }
        let at_horizon = c.eval(from_spherical(FRAC_PI_2, 0.0));
        assert!((worst - 0.17).abs() < 1e-12, "{worst}");
        assert!((at_horizon - 0.13862).abs() < 1e-5, "{at_horizon}");
        // Integral against ∫ max(cos, 0) = π.
        let integral_err = c.integral() / PI - 1.0;
        assert!((integral_err - 0.0817).abs() < 1e-3, "{integral_err}");
        assert!((c.integral() - 3.398).abs() < 1e-3);
        // In use: G · C* against ∫ G max(v·n, 0) dv, lights within 60° of n.
        let mut worst_use = 0.0f64;
        let mut worst_at = (0.0, 0.0);
        for l in [1e-3, 0.1, 1.0, 3.0, 10.0, 100.0, 1e4] {
            for deg in [0.0f64, 15.0, 30.0, 45.0, 60.0] {
                let g = Sg::new(from_spherical(deg.to_radians(), 0.0), l, 1.0).unwrap();
                let exact = g.clamped_cosine_inner_exact(n).unwrap();
                let err = rel_err(g.clamped_cosine_inner(n).unwrap(), exact);
                if err > worst_use {
                    worst_use = err;
                    worst_at = (l, deg);
                }
            }
        }
        eprintln!(
            "clamped-cosine fit (seed 003 §2.4): max |C* − max(cos,0)| = {worst:.4}, \
             ∫C*/π − 1 = {integral_err:.4}, max rel err of G·C* (≤ 60°) = {worst_use:.4} \
             at (λ, deg) = {worst_at:?}"
        );
        assert!(worst_use <= CLAMPED_COSINE_MAX_REL_ERROR_60, "{worst_use}");
        assert!(worst_use > 0.194, "{worst_use}");
    }

    #[test]
    fn clamped_cosine_exact_route_matches_quadrature() {
        let n = [0.0, 0.0, 1.0];
        for l in [1e-3, 1.0, 100.0, 1e4] {
            for beta in [0.7, 2.0] {
                let g = Sg::new(from_spherical(beta, 0.0), l, 1.0).unwrap();
                let q = sphere_oracle(
                    &|v| g.eval(v) * v[2].max(0.0),
                    FRAC_PI_2,
                    beta,
                    1.0 / (1.0 + l).sqrt(),
                    1e-11,
                );
                let got = g.clamped_cosine_inner_exact(n).unwrap();
                assert!(rel_err(got, q) < 1e-10, "λ = {l}, β = {beta}: {got} vs {q}");
            }
            // The lobe at n: 2π (1/λ − (1 − e^{−λ})/λ²).
            let g = Sg::new(n, l, 1.0).unwrap();
            let closed = 2.0 * PI * (1.0 / l + (-l).exp_m1() / (l * l));
            if l > 0.01 {
                assert!(rel_err(g.clamped_cosine_inner_exact(n).unwrap(), closed) < 1e-10);
            }
        }
    }

    #[test]
    fn warp_mass_error_measured() {
        let o = normalize([0.3, 0.1, 0.95]);
        let mut report = Vec::new();
        for l in [10.0, 100.0, 1e3, 1e4] {
            for p in [[0.0, 0.0, 1.0], normalize([0.4, -0.2, 0.9])] {
                let g = Sg::new(p, l, 1.0).unwrap();
                let w = g.warp(o).unwrap();
                // The axis is the mirror direction of o about p.
                let mirror = sub(scale(p, 2.0 * dot(o, p)), o);
                assert!(dot(w.axis(), mirror) > 1.0 - 1e-15);
                assert!(rel_err(w.sharpness(), l / (4.0 * dot(o, p))) < 1e-15);
                let true_area = g.warp_support_area_exact(o).unwrap();
                // Closed form while A stays on o's side: 4 (o·p) π sin²θ₀.
                let c0 = 1.0 - LN_10 / l;
                let closed = 4.0 * dot(o, p) * PI * (1.0 - c0 * c0);
                assert!(
                    rel_err(true_area, closed) < 1e-10,
                    "{true_area} vs {closed}"
                );
                let err = f_a(w.sharpness()) / true_area - 1.0;
                assert!((err - (1.0 - c0) / (1.0 + c0)).abs() < 1e-11, "{err}");
                if p[2] == 1.0 {
                    report.push(format!("λ_D = {l}: {err:.3e}"));
                }
            }
        }
        eprintln!("lobe warp (seed 003 §2.1): f_a(λ_W)/area(ψ(A)) − 1: {report:?}");
    }

    #[test]
    fn printed_visibility_lookup_mixes_sharpness_conventions() {
        // ERRATA.md, E6: §3.3.3 writes ∫ G_iso(i; p, ν) V(i) di ≈ f_h(θd, ν), with
        // G_iso = e^{2ν(i·p − 1)}; but f_h(θd, λ) (§2.2) integrates e^{λ(cos θ − 1)}. For a cap
        // visibility (where the lookup is exact) the right argument is 2ν.
        for nu in [0.5, 5.0, 50.0] {
            let g_iso = Sg::new([0.0, 0.0, 1.0], 2.0 * nu, 1.0).unwrap();
            for theta_d in [1.0, 2.0] {
                let cut = cuts(0.0, 1.0 / (1.0 + 2.0 * nu).sqrt(), 0.0, theta_d);
                let q = 2.0
                    * PI
                    * integrate_cut(
                        &|t: f64| (2.0 * nu * (t.cos() - 1.0)).exp() * t.sin(),
                        &cut,
                        1e-13,
                    );
                assert!(rel_err(f_h(theta_d, 2.0 * nu), q) < 1e-12);
                assert!(rel_err(g_iso.cap_integral(theta_d).unwrap(), q) < 1e-12);
                assert!(
                    rel_err(f_h(theta_d, nu), q) > 0.05,
                    "ν = {nu}, θd = {theta_d}"
                );
            }
        }
    }

    #[test]
    fn printed_sphere_light_sharpness_doubles_its_solid_angle() {
        // ERRATA.md, S1 (suspected): §2.3 gives the light's SG the sharpness
        // f_a⁻¹(2π r²/d²); the solid angle of a sphere of radius r at distance d is
        // 2π(1 − √(1 − r²/d²)) → π r²/d², so that lobe's 0.1-support is twice the light's
        // solid angle.
        for ratio in [0.01f64, 0.05, 0.1] {
            let solid_angle = 2.0 * PI * (1.0 - (1.0 - ratio * ratio).sqrt());
            let printed_support = 2.0 * PI * ratio * ratio;
            assert!((printed_support / solid_angle - 2.0).abs() < 0.01);
            let lambda = 2.0 * PI * LN_10 / printed_support; // f_a⁻¹
            assert!(rel_err(f_a(lambda), printed_support) < 1e-14);
        }
    }
}
