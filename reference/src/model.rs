//! The model boundary: capability traits every NDF implements as far as it has a meaning for
//! them (ARCHITECTURE.md, "The model boundary").

use crate::error::QueryError;
use crate::geometry::dot;
pub use crate::geometry::Vec3;
use crate::spec::ModelSpec;

/// A normal distribution function, normalized so that ∫ D(m) (m·n) dm = 1.
///
/// `d` is the one required method. The `as_*` methods say which other capabilities the model
/// has: an implementation of [`Smith`], [`NormalSampler`], … is audited only where the model
/// returns `Some(self)` from the matching method (Rust cannot discover a trait impl at run
/// time). A renderer's own model writes, for example:
///
/// ```
/// use mfh_reference::{Ndf, Smith, Vec3};
/// struct MyGgx { alpha: f64 }
/// impl Ndf for MyGgx {
///     fn d(&self, m: Vec3) -> f64 {
///         if m[2] <= 0.0 { return 0.0; }
///         let a2 = self.alpha * self.alpha;
///         let t = m[2] * m[2] * (a2 - 1.0) + 1.0;
///         a2 / (std::f64::consts::PI * t * t)
///     }
///     fn as_smith(&self) -> Option<&dyn Smith> { Some(self) }
/// }
/// impl Smith for MyGgx {
///     fn lambda(&self, w: Vec3) -> f64 {
///         let t2 = (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2]);
///         ((1.0 + self.alpha * self.alpha * t2).sqrt() - 1.0) / 2.0
///     }
/// }
/// # assert!(MyGgx { alpha: 0.3 }.as_smith().is_some());
/// ```
pub trait Ndf: Send + Sync {
    /// D(m) for a unit microfacet normal `m`; 0 below the horizon (m_z ≤ 0).
    fn d(&self, m: Vec3) -> f64;

    /// The Smith capability, if the model has one.
    fn as_smith(&self) -> Option<&dyn Smith> {
        None
    }
    /// The normal-sampling capability, if the model has one.
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        None
    }
    /// The visible-normal sampling capability (Heitz & d'Eon 2014), if the model has one.
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        None
    }
    /// The slope-space capability, if the model has one.
    fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
        None
    }
    /// The visible-slope-moments capability (document 002, D_s), if the model has one.
    fn as_visible_moments(&self) -> Option<&dyn VisibleSlopeMoments> {
        None
    }

    /// `out[i] = self.d(m[i])` for every i: a batch capability for throughput (the default
    /// loops over [`Ndf::d`]; models may override it with a vectorized form that agrees with
    /// `d` to the number of ulps they document).
    ///
    /// # Panics
    /// If `m` and `out` differ in length.
    fn d_batch(&self, m: &[Vec3], out: &mut [f64]) {
        assert_eq!(m.len(), out.len(), "d_batch: m and out differ in length");
        for (o, &m) in out.iter_mut().zip(m) {
            *o = self.d(m);
        }
    }
}

/// A reference to a model is the model (so that `Arc<&M>` and `Box<dyn Model>` audit as `M`).
macro_rules! delegate_ndf {
    ($($ptr:ty),*) => {$(
        impl<T: Ndf + ?Sized> Ndf for $ptr {
            fn d(&self, m: Vec3) -> f64 {
                (**self).d(m)
            }
            fn d_batch(&self, m: &[Vec3], out: &mut [f64]) {
                (**self).d_batch(m, out)
            }
            fn as_smith(&self) -> Option<&dyn Smith> {
                (**self).as_smith()
            }
            fn as_sampler(&self) -> Option<&dyn NormalSampler> {
                (**self).as_sampler()
            }
            fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
                (**self).as_visible_sampler()
            }
            fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
                (**self).as_slopes()
            }
            fn as_visible_moments(&self) -> Option<&dyn VisibleSlopeMoments> {
                (**self).as_visible_moments()
            }
        }
    )*};
}
delegate_ndf!(&T, Box<T>, std::sync::Arc<T>);

/// Which two-direction masking-shadowing form to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Masking {
    /// G2 = G1(wo, m) G1(wi, m) (document 001, eq 22).
    Uncorrelated,
    /// G2 = χ⁺(wo·m) χ⁺(wi·m) / (1 + Λ(wo) + Λ(wi)) (document 001, eq 23).
    HeightCorrelated,
}

/// Smith masking: Λ, G1 and G2.
pub trait Smith: Ndf {
    /// Smith Λ(w) by the model's default (most accurate) route. For w below the horizon,
    /// Λ(−w) = −1 − Λ(w) (Heitz 2014, §5.2): the value follows from the upper hemisphere.
    fn lambda(&self, w: Vec3) -> f64;

    /// The names of the routes `lambda_route` accepts (the first is the default).
    fn lambda_routes(&self) -> Vec<&'static str> {
        vec!["default"]
    }

    /// Λ(w) by a named route; routes other than the default may be restricted in γ.
    fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        match route {
            "default" => Ok(self.lambda(w)),
            _ => Err(QueryError::Route {
                route: route.to_string(),
                reason: format!("known routes: {}", self.lambda_routes().join(", ")),
            }),
        }
    }

    /// G1(w, m) = χ⁺(w·m / w·n) / (1 + Λ(w)) (document 001, eq 16). Zero at grazing incidence and
    /// for back-facing microfacets.
    fn g1(&self, w: Vec3, m: Vec3) -> f64 {
        if w[2] <= 0.0 || dot(w, m) <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(w))
    }

    /// G2(wo, wi, m) in the uncorrelated (eq 22) or height-correlated (eq 23) form of document 001.
    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3, masking: Masking) -> f64 {
        smith_g2(self, wo, wi, m, masking)
    }

    /// `out[i] = self.lambda(w[i])` for every i (the default loops over [`Smith::lambda`]).
    ///
    /// # Panics
    /// If `w` and `out` differ in length.
    fn lambda_batch(&self, w: &[Vec3], out: &mut [f64]) {
        assert_eq!(
            w.len(),
            out.len(),
            "lambda_batch: w and out differ in length"
        );
        for (o, &w) in out.iter_mut().zip(w) {
            *o = self.lambda(w);
        }
    }
}

/// G2(wo, wi, m) of document 001 from `s`'s G1 and Λ: uncorrelated (eq 22), G1(wo)·G1(wi), or
/// height-correlated (eq 23), χ⁺ / (1 + Λ(wo) + Λ(wi)). [`Smith::g2`]'s default, and what a
/// wrapper that overrides `g2` (the self-test's mutants) calls after changing the masking.
pub fn smith_g2<S: Smith + ?Sized>(s: &S, wo: Vec3, wi: Vec3, m: Vec3, masking: Masking) -> f64 {
    match masking {
        Masking::Uncorrelated => s.g1(wo, m) * s.g1(wi, m),
        Masking::HeightCorrelated => {
            if wo[2] <= 0.0 || wi[2] <= 0.0 || dot(wo, m) <= 0.0 || dot(wi, m) <= 0.0 {
                0.0
            } else {
                1.0 / (1.0 + s.lambda(wo) + s.lambda(wi))
            }
        }
    }
}

/// Importance sampling of microfacet normals with pdf D(m)(m·n).
pub trait NormalSampler: Ndf {
    /// Maps `u ∈ [0, 1)²` to a microfacet normal distributed as D(m)(m·n).
    fn sample_wm(&self, u: [f64; 2]) -> Vec3;

    /// The density of `sample_wm` with respect to solid angle: D(m)(m·n).
    fn pdf_wm(&self, m: Vec3) -> f64 {
        if m[2] <= 0.0 {
            0.0
        } else {
            self.d(m) * m[2]
        }
    }

    /// `out[i] = self.sample_wm(u[i])` for every i: the batch capability the chi-square oracle
    /// draws through (the default loops over [`NormalSampler::sample_wm`], so a model that
    /// implements only the scalar method needs nothing more). A vectorized override must agree
    /// with `sample_wm` to the number of ulps it documents (the reference models: bit for
    /// bit).
    ///
    /// # Panics
    /// If `u` and `out` differ in length.
    fn sample_wm_batch(&self, u: &[[f64; 2]], out: &mut [Vec3]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wm_batch: u and out differ in length"
        );
        for (o, &u) in out.iter_mut().zip(u) {
            *o = self.sample_wm(u);
        }
    }

    /// `out[i] = self.pdf_wm(m[i])` for every i (the default loops over
    /// [`NormalSampler::pdf_wm`]).
    ///
    /// # Panics
    /// If `m` and `out` differ in length.
    fn pdf_wm_batch(&self, m: &[Vec3], out: &mut [f64]) {
        assert_eq!(
            m.len(),
            out.len(),
            "pdf_wm_batch: m and out differ in length"
        );
        for (o, &m) in out.iter_mut().zip(m) {
            *o = self.pdf_wm(m);
        }
    }
}

/// Importance sampling of the normals visible from a direction `wi`: the distribution of
/// visible normals of Heitz & d'Eon 2014 ("Importance Sampling Microfacet-Based BSDFs using the
/// Distribution of Visible Normals", CGF 33(4), eq 2; document 001 §7 cites it as \[9\]):
///
/// ```text
/// D_wi(m) = G1(wi) ⟨wi·m⟩⁺ D(m) / cos θi,   G1(wi) = 1/(1 + Λ(wi)),   ∫ D_wi(m) dm = 1
/// ```
///
/// (the normalization is the projected-area identity cos θi (1 + Λ(wi)) = ∫⟨wi·m⟩⁺ D(m) dm).
/// None of the five source documents gives a visible-normal sampler; the implementations cite
/// their papers. Domain: `wi` a finite unit vector with wi_z > 0 (at grazing incidence
/// Λ(wi) = ∞ and the formula above is 0·∞); elsewhere `sample_wm_visible` returns NaN
/// components and `pdf_wm_visible` returns 0.
pub trait VisibleNormalSampler: Smith {
    /// Maps `u ∈ [0, 1)²` to a microfacet normal distributed as D_wi(m).
    fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3;

    /// The density of `sample_wm_visible` with respect to solid angle:
    /// G1(wi) ⟨wi·m⟩⁺ D(m) / cos θi (0 for m below the horizon or facing away from `wi`, and for
    /// `wi` outside the domain).
    fn pdf_wm_visible(&self, wi: Vec3, m: Vec3) -> f64 {
        if !visible_domain(wi) || !(m[2] > 0.0) {
            return 0.0;
        }
        let c = dot(wi, m);
        if !(c > 0.0) {
            return 0.0;
        }
        let d = self.d(m);
        if d == 0.0 {
            return 0.0;
        }
        c * d / (wi[2] * (1.0 + self.lambda(wi)))
    }

    /// `out[i] = self.sample_wm_visible(wi, u[i])` for every i, at one incidence (the default
    /// loops over [`VisibleNormalSampler::sample_wm_visible`]; an override must agree with it
    /// to the number of ulps it documents).
    ///
    /// # Panics
    /// If `u` and `out` differ in length.
    fn sample_wm_visible_batch(&self, wi: Vec3, u: &[[f64; 2]], out: &mut [Vec3]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wm_visible_batch: u and out differ in length"
        );
        for (o, &u) in out.iter_mut().zip(u) {
            *o = self.sample_wm_visible(wi, u);
        }
    }

    /// `out[i] = self.pdf_wm_visible(wi, m[i])` for every i, at one incidence (the default
    /// loops over [`VisibleNormalSampler::pdf_wm_visible`]).
    ///
    /// # Panics
    /// If `m` and `out` differ in length.
    fn pdf_wm_visible_batch(&self, wi: Vec3, m: &[Vec3], out: &mut [f64]) {
        assert_eq!(
            m.len(),
            out.len(),
            "pdf_wm_visible_batch: m and out differ in length"
        );
        for (o, &m) in out.iter_mut().zip(m) {
            *o = self.pdf_wm_visible(wi, m);
        }
    }
}

/// Whether `wi` is in the domain of the visible-normal samplers: finite, unit length to 1e-9,
/// and strictly above the horizon.
pub fn visible_domain(wi: Vec3) -> bool {
    crate::geometry::is_unit(wi, 1e-9) && wi[2] > 0.0
}

/// A model defined in slope space (P22, P2) with slope moments.
pub trait SlopeDistribution {
    /// P22(p, q): the density of microfacet slopes (D(m) cos⁴θ_m).
    fn p22(&self, p: f64, q: f64) -> f64;

    /// P2(q): the 1-D density of the slope component along azimuth `phi` (the incidence plane).
    fn p2(&self, q: f64, phi: f64) -> f64;

    /// ν₂ₖ = ∫ q^{2k} P2(q) dq along azimuth `phi`; `None` where the moment diverges.
    fn slope_moment(&self, k: u32, phi: f64) -> Option<f64>;

    /// The slope variance ν₂ along `phi`; `None` where undefined.
    fn variance(&self, phi: f64) -> Option<f64> {
        self.slope_moment(1, phi)
    }

    /// The excess kurtosis ν₄/ν₂² − 3 (independent of `phi` for elliptic models); `None` where
    /// undefined.
    fn excess_kurtosis(&self) -> Option<f64> {
        let v2 = self.slope_moment(1, 0.0)?;
        let v4 = self.slope_moment(2, 0.0)?;
        Some(v4 / (v2 * v2) - 3.0)
    }
}

/// A reference model: a model of a known family, describable as data (its spec). Capabilities
/// are discovered through [`Ndf`]'s `as_*` methods, as for any model.
pub trait Model: Ndf {
    /// The model described as data.
    fn spec(&self) -> ModelSpec;
    /// The family name as in model specs (`ggx`, `std`, …).
    fn family(&self) -> &'static str;
}

/// The roughness along an azimuth for an elliptic slope distribution with scales `(sx, sy)`,
/// expressed for a direction `w`: √((sx w_x)² + (sy w_y)²) = s(φ) sin θ.
#[inline]
pub(crate) fn projected_scale(sx: f64, sy: f64, w: Vec3) -> f64 {
    ((sx * w[0]).powi(2) + (sy * w[1]).powi(2)).sqrt()
}

/// The standardized cotangent a = cot θ / s(φ) of direction `w` for scales `(sx, sy)`:
/// +∞ at normal incidence, 0 at grazing, negative below the horizon.
#[inline]
pub(crate) fn standardized_cotangent(sx: f64, sy: f64, w: Vec3) -> f64 {
    let s = projected_scale(sx, sy, w);
    if s == 0.0 {
        if w[2] >= 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        }
    } else {
        w[2] / s
    }
}

/// Applies Λ(−w) = −1 − Λ(w) to an upper-hemisphere Λ given as a function of the
/// standardized cotangent.
#[inline]
pub(crate) fn lambda_both_hemispheres(a: f64, upper: impl Fn(f64) -> f64) -> f64 {
    if a >= 0.0 {
        upper(a)
    } else {
        -1.0 - upper(-a)
    }
}

/// The scale along azimuth `phi`: s(φ) = √(sx² cos²φ + sy² sin²φ).
#[inline]
pub(crate) fn scale_along(sx: f64, sy: f64, phi: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    ((sx * c).powi(2) + (sy * s).powi(2)).sqrt()
}

/// The supported roughness range [`ALPHA_MIN`, `ALPHA_MAX`]. Outside it the closed forms lose
/// their meaning in f64: at α = 1e308 the slope scale overflows (Λ = inf, `sample_wm` gives
/// [0, 0, 0]), and below 1e-7 D(n) = 1/(πα²) exceeds 3e13 and every sampled normal rounds to n.
/// Renderers use α in about [1e-4, 10]; the range leaves three orders of magnitude either side.
pub const ALPHA_MIN: f64 = 1e-7;

/// The largest supported roughness; see [`ALPHA_MIN`].
pub const ALPHA_MAX: f64 = 1e4;

/// Validates a roughness parameter: finite and > 0 ([`crate::ParamError::AlphaNotPositive`]),
/// and within [`ALPHA_MIN`, `ALPHA_MAX`] ([`crate::ParamError::AlphaOutOfRange`]).
pub(crate) fn check_alpha(name: &'static str, value: f64) -> Result<f64, crate::ParamError> {
    if !(value > 0.0 && value.is_finite()) {
        Err(crate::ParamError::AlphaNotPositive { name, value })
    } else if !(ALPHA_MIN..=ALPHA_MAX).contains(&value) {
        Err(crate::ParamError::AlphaOutOfRange {
            name,
            value,
            min: ALPHA_MIN,
            max: ALPHA_MAX,
        })
    } else {
        Ok(value)
    }
}

/// The azimuthal part shared by every elliptic sampler: (cos 2πu, sin 2πu) scaled by the
/// per-axis slope scales. Multiplying by the sampled slope radius gives the slope (p, q).
/// This is the quadrant-correct form of document 001 eq 11 / 40.
#[inline]
pub(crate) fn elliptic_direction(sx: f64, sy: f64, u1: f64) -> (f64, f64) {
    let (s, c) = crate::geometry::sin_cos_turns(u1);
    (sx * c, sy * s)
}

/// The mean and covariance of a two-dimensional slope distribution, e.g. of the visible slopes
/// D_s (document 002, eq 19–23, 39–46).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VisibleMoments {
    /// The mean slope `[s̄x, s̄y]`.
    pub mean: [f64; 2],
    /// The covariance `[[σx², cxy], [cxy, σy²]]`.
    pub cov: [[f64; 2]; 2],
}

/// Moments of the distribution of visible slopes D_s(s) ∝ p_s(s) ⟨w·m(s)⟩⁺ / m_z(s) (document 002,
/// eq 12–13) for a view direction `w`.
pub trait VisibleSlopeMoments {
    /// The mean and covariance of D_s seen from `w` by the model's default (most accurate)
    /// route; `w` must be finite, non-zero and in the upper hemisphere (w_z ≥ 0), otherwise
    /// `QueryError::Argument`.
    fn visible_moments(&self, w: Vec3) -> Result<VisibleMoments, QueryError>;

    /// The names of the routes `visible_moments_route` accepts (the first is the default).
    fn visible_moments_routes(&self) -> Vec<&'static str> {
        vec!["default"]
    }

    /// The moments of D_s by a named route (e.g. a source's formulas as printed).
    fn visible_moments_route(&self, w: Vec3, route: &str) -> Result<VisibleMoments, QueryError> {
        match route {
            "default" => self.visible_moments(w),
            _ => Err(QueryError::Route {
                route: route.to_string(),
                reason: format!("known routes: {}", self.visible_moments_routes().join(", ")),
            }),
        }
    }
}
