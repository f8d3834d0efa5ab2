//! The Gaussian slope distribution N(s̄, Σ) of document 002 (eq 1, 11), its rotation into the view
//! frame (eq 2–10) and the closed-form mean and covariance of its visible slopes D_s
//! (eq 12–69), evaluated without cancellation from θ = 0 to π/2 and for near-singular Σ.

use crate::error::{ParamError, QueryError};
use crate::family::{FamilyInfo, FamilySpec, SamplerCost};
use crate::geometry::Vec3;
use crate::model::{Model, Ndf, SlopeDistribution, Smith, VisibleMoments, VisibleSlopeMoments};
use crate::slopes::pseudocode::{self, Transcription};
use crate::slopes::ramp::{normal_loss, ramp_moments};
/// The family's spec type (declared with every family's in `crate::spec`).
pub use crate::spec::GaussianSlopesSpec;
use crate::spec::ModelSpec;
use std::f64::consts::TAU;

/// A Gaussian distribution of microfacet slopes (document 002, §3, eq 1 and 11):
///
/// ```text
/// p_s(s)   = exp(−½ (s − s̄)ᵀ Σ⁻¹ (s − s̄)) / (2π √|Σ|)                          (eq 1)
/// m(s)     = (−s_x, −s_y, 1) / √(1 + s_x² + s_y²)                               (eq 11)
/// D(m)     = p_s(−m_x/m_z, −m_y/m_z) / m_z⁴         so that ∫ D(m) m_z dm = ∫ p_s ds = 1
/// P22(p,q) = p_s(p, q)
/// P2(q; φ) = exp(−(q − s̄_φ)²/(2σ_φ²)) / (√(2π) σ_φ),
///            s̄_φ = s̄_x cos φ + s̄_y sin φ,  σ_φ² = σx² cos²φ + σy² sin²φ + 2 cxy cos φ sin φ
///                                                                     (eq 6 and 8 at φ_o = φ)
/// Λ(w)     = (1/μ) ∫_μ^∞ (q − μ) P2(q; φ) dq = σ_φ L(z) / μ,   μ = cot θ,  z = (μ − s̄_φ)/σ_φ,
///            L(z) = φ(z) − z (1 − Φ(z))   (the normal loss function; φ, Φ standard normal)
/// ```
///
/// Slope sign: slopes are those of eq 11, a facet of slope s has normal ∝ (−s, 1) (the
/// convention of Heitz 2014, x̃_m = −x_m/z_m). `geometry::normal_from_slopes(p, q)` uses the
/// opposite sign, so the normal of slope (p, q) here is `normal_from_slopes(−p, −q)`. With a
/// zero mean the sign does not matter; with a non-zero mean it does: the mean facet
/// ∝ (−s̄, 1) faces the viewer at azimuth φ when s̄_φ < 0.
///
/// Slope moments (`slope_moment`) are raw moments about 0 along φ,
/// E[q^{2k}] = Σ_j C(2k, 2j) s̄_φ^{2k−2j} σ_φ^{2j} (2j−1)!!; `variance` is the central σ_φ²
/// and `excess_kurtosis` the central one, 0 (a Gaussian), which differ from ν₂ and ν₄/ν₂² − 3
/// when s̄ ≠ 0.
///
/// Smith Λ: the integral above (Smith's 1-D form, document 001 eq 17) in closed form; with s̄ = 0
/// it is Beckmann's Λ with α_φ = √2 σ_φ. With s̄ ≠ 0 the distribution describes a tilted
/// surface: ∫ (w·m) D(m) dm = cos θ − sin θ s̄_φ ≠ cos θ, so the premises of Smith's model
/// relative to n = +z fail. Λ is then the integral by definition only; G1 = 1/(1 + Λ) does not
/// satisfy ∫ G1(w, m) ⟨w·m⟩ D(m) dm = cos θ (that integral is
/// `visible_area(w) / (1 + Λ(w))`, with visible_area = cos θ (1 + Λ) − sin θ s̄_φ), and
/// below the horizon Λ(−w) = −1 − Λ(w) is the trait's convention (the literal integral there
/// differs by s̄_φ tan θ).
///
/// Domain: s̄ finite; Σ finite, symmetric and positive definite (|Σ| > 0 computed without
/// cancellation, so correlations up to 1 − 1e-15 and variance ratios down to ~1e-300 are
/// accepted). A singular Σ has no density D and is rejected here; its visible-slope moments
/// are available from [`visible_moments_psd`].
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianSlopes {
    mean: [f64; 2],
    cov: [[f64; 2]; 2],
    sigma: Cov2,
    /// 1 / (2π √|Σ|).
    norm: f64,
}

impl GaussianSlopes {
    /// A validated Gaussian slope distribution with mean `mean` = s̄ and covariance `cov` = Σ.
    ///
    /// Errors (`ParamError::OutOfRange`, named after the broken entry): a non-finite entry;
    /// `cov[1][0] ≠ cov[0][1]` (exactly); a variance that is not > 0; |Σ| not finite and > 0
    /// (`det(cov)`: singular or indefinite).
    pub fn new(mean: [f64; 2], cov: [[f64; 2]; 2]) -> Result<Self, ParamError> {
        let sigma = Cov2::validated(mean, cov, true)?;
        Ok(Self {
            mean,
            cov,
            norm: 1.0 / (TAU * sigma.det.sqrt()),
            sigma,
        })
    }

    /// The mean slope s̄.
    pub fn mean(&self) -> [f64; 2] {
        self.mean
    }

    /// The covariance Σ.
    pub fn cov(&self) -> [[f64; 2]; 2] {
        self.cov
    }

    /// The slope statistics rotated into the frame (o, ⊥) of azimuth `phi` (document 002,
    /// eq 6–10): `mean = [s̄_o, s̄_⊥]`, `cov = [[σ_o², c_o⊥], [c_o⊥, σ_⊥²]]`.
    ///
    /// ```text
    /// s̄_o = s̄x cos φ + s̄y sin φ                 s̄_⊥ = −s̄x sin φ + s̄y cos φ
    /// σ_o² = σx² cos²φ + σy² sin²φ + 2 cxy cos φ sin φ
    /// σ_⊥² = σx² sin²φ + σy² cos²φ − 2 cxy cos φ sin φ
    /// c_o⊥ = (σy² − σx²) cos φ sin φ + cxy (cos²φ − sin²φ)
    /// ```
    ///
    /// σ_o² and σ_⊥² are evaluated as ω̂ᵀΣω̂ through a pivoted Cholesky factor, so that they
    /// keep full relative accuracy when Σ is near-singular and φ is near its null direction.
    pub fn rotated(&self, phi: f64) -> VisibleMoments {
        let (s, c) = phi.sin_cos();
        let o = [c, s];
        let perp = [-s, c];
        let u = self.sigma.times(o);
        let cross = dot2(perp, u);
        VisibleMoments {
            mean: [dot2(self.mean, o), dot2(self.mean, perp)],
            cov: [[self.sigma.quad(o), cross], [cross, self.sigma.quad(perp)]],
        }
    }

    /// The density of slopes p_s(s) (eq 1), by a pivoted Cholesky factor of Σ.
    pub fn ps(&self, s: [f64; 2]) -> f64 {
        let q = self
            .sigma
            .mahalanobis2([s[0] - self.mean[0], s[1] - self.mean[1]]);
        self.norm * (-0.5 * q).exp()
    }

    /// The mean and covariance of the visible slopes D_s seen from `w` (document 002, eq 12–46),
    /// in the surface frame (x, y) and the slope sign of eq 11, i.e. in the same terms as
    /// [`GaussianSlopes::mean`] and [`GaussianSlopes::cov`] (so that the Gaussian
    /// approximation of D_s is `GaussianSlopes::new(m.mean, m.cov)`).
    ///
    /// ```text
    /// D_s(s) = p_s(s) ⟨w·m(s)⟩⁺ / (m_z(s) N) = p_s(s) (w_z − s·w_xy)⁺ / N        (eq 12–15)
    /// ```
    ///
    /// With ω̂ = w_xy/|w_xy| (the view azimuth), μ = cot θ, a = ω̂ᵀΣω̂ = σ_o², u = Σω̂,
    /// û = u/√a, ω̂⊥ = (−ω̂_y, ω̂_x), s̄_o = s̄·ω̂, s̄_⊥ = s̄·ω̂⊥, c = ω̂⊥·u = c_o⊥:
    ///
    /// ```text
    /// z₀ = (μ − s̄_o)/σ_o,   (τ, v, g) = E, Var of t and E[z₀ − t] under t ~ φ(t)(z₀ − t)⁺
    /// mean(D_s) = s̄ + τ û                                        (z₀ ≥ 0)
    ///           = (μ − σ_o g) ω̂ + (s̄_⊥ + τ c/σ_o) ω̂⊥             (z₀ < 0, same value)
    /// cov(D_s)  = (|Σ|/a) ω̂⊥ω̂⊥ᵀ + v û ûᵀ
    /// ```
    ///
    /// This is eq 24–46 (with E₁ as in pseudocode line 23 and eq 68 for lines 36–39)
    /// rearranged: writing s_⊥ = s̄_⊥ + (c/a)(s_o − s̄_o) + ε with ε ~ N(0, |Σ|/a) independent
    /// of s_o, and since the weight depends on s_o only, D_s changes the law of s_o alone; the
    /// ratios I_…/N of eq 25–29 reduce to (τ, v) (see `ramp::ramp_moments`, evaluated by
    /// continued fraction where the closed forms cancel). No term is divided by |Σ| and every
    /// term of the covariance is ≥ 0: no cancellation for near-singular Σ, at θ → 0 (z₀ → ∞)
    /// or at grazing incidence with the mean facet facing away (z₀ → −∞).
    ///
    /// Domain: θ ∈ [0, π/2], both ends included: θ = 0 gives (s̄, Σ) exactly; θ = π/2 is the
    /// limit μ = 0 (D_s ∝ p_s (−s_o)⁺). Only the direction of `w` matters. For w below the
    /// horizon the same formulas give the moments of the facets facing w (w = −z: none, NaN).
    ///
    /// Accuracy (unit tests, against 2-D quadrature of the definition with this model's D):
    /// ≤ 8e-13 for regular Σ with z₀ down to −16, ≤ 5e-13 for correlation ±(1 − 1e-9) and
    /// variance ratio 1e-8 except at z₀ ≈ −2000 (1.7e-10, where the quadrature's own rounding
    /// dominates); the mean in units of max(|s̄ᵢ|, σᵢ), variances relative, the covariance as a
    /// correlation.
    pub fn visible_moments(&self, w: Vec3) -> VisibleMoments {
        visible_core(self.mean, &self.sigma, w).unwrap_or(VisibleMoments {
            mean: [f64::NAN; 2],
            cov: [[f64::NAN; 2]; 2],
        })
    }

    /// The moments of D_s by the source's own formulas, as printed or corrected (document 002
    /// pseudocode; see `pseudocode::d_s` and reference/ERRATA.md). Defined for
    /// 0 < θ ≤ π/2 only (NaN at θ = 0).
    pub fn visible_moments_transcribed(
        &self,
        w: Vec3,
        transcription: Transcription,
    ) -> VisibleMoments {
        let theta = w[0].hypot(w[1]).atan2(w[2]);
        let phi = w[1].atan2(w[0]);
        pseudocode::d_s(
            self.mean[0],
            self.mean[1],
            self.cov[0][0],
            self.cov[1][1],
            self.cov[0][1],
            theta,
            phi,
            transcription,
        )
    }

    /// The pseudocode exactly as printed (lines 36–39 wrong; erratum 2 of ERRATA.md).
    pub fn visible_moments_printed(&self, w: Vec3) -> VisibleMoments {
        self.visible_moments_transcribed(w, Transcription::PseudocodePrinted)
    }

    /// The normalization N of D_s (document 002, eq 16, 24): the projected area of the facets that
    /// face `w` (unit),
    ///
    /// ```text
    /// N(w) = ∫ ⟨w·m⟩⁺ D(m) dm = ∫ p_s(s) (w_z − s·w_xy)⁺ ds = sin θ σ_o L(−z₀)
    ///      = cos θ (1 + Λ(w)) − sin θ s̄_o
    /// ```
    ///
    /// (N = w_z⁺ at normal incidence.) Domain: any unit `w`.
    pub fn visible_area(&self, w: Vec3) -> f64 {
        let qn = w[0].hypot(w[1]);
        if !(qn > 0.0) {
            return w[2].max(0.0);
        }
        let dir = [w[0] / qn, w[1] / qn];
        let sigma_o = self.sigma.quad(dir).sqrt();
        let z0 = (w[2] / qn - dot2(self.mean, dir)) / sigma_o;
        qn * sigma_o * normal_loss(-z0)
    }

    /// Λ for w in the upper hemisphere (w_z ≥ 0).
    fn lambda_upper(&self, w: Vec3) -> f64 {
        let qn = w[0].hypot(w[1]);
        if !(qn > 0.0) {
            return 0.0;
        }
        let dir = [w[0] / qn, w[1] / qn];
        let mu = if w[2] == 0.0 { 0.0 } else { w[2] / qn };
        let sigma = self.sigma.quad(dir).sqrt();
        let z = (mu - dot2(self.mean, dir)) / sigma;
        sigma * normal_loss(z) / mu
    }
}

impl Ndf for GaussianSlopes {
    fn d(&self, m: Vec3) -> f64 {
        let mz = m[2];
        if mz <= 0.0 {
            return 0.0;
        }
        let p = self.ps([-m[0] / mz, -m[1] / mz]);
        if p == 0.0 {
            return 0.0;
        }
        let z2 = mz * mz;
        p / (z2 * z2)
    }

    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
    fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
        Some(self)
    }
    fn as_visible_moments(&self) -> Option<&dyn VisibleSlopeMoments> {
        Some(self)
    }
}

impl Smith for GaussianSlopes {
    /// Λ(w) = σ_φ L((cot θ − s̄_φ)/σ_φ) / cot θ in the upper hemisphere (see the type's doc
    /// for its meaning when s̄ ≠ 0); 0 at normal incidence, +∞ at grazing; below the horizon
    /// by Λ(−w) = −1 − Λ(w).
    fn lambda(&self, w: Vec3) -> f64 {
        if w[2] < 0.0 {
            -1.0 - self.lambda_upper([-w[0], -w[1], -w[2]])
        } else {
            self.lambda_upper(w)
        }
    }
}

impl SlopeDistribution for GaussianSlopes {
    fn p22(&self, p: f64, q: f64) -> f64 {
        self.ps([p, q])
    }

    fn p2(&self, q: f64, phi: f64) -> f64 {
        let (s, c) = phi.sin_cos();
        let dir = [c, s];
        let var = self.sigma.quad(dir);
        let d = q - dot2(self.mean, dir);
        (-0.5 * d * d / var).exp() / (TAU * var).sqrt()
    }

    /// The raw moment E[q^{2k}] about 0 of the slope q along `phi` (q ~ N(s̄_φ, σ_φ²)):
    /// Σ_{j=0..k} C(2k, 2j) s̄_φ^{2k−2j} σ_φ^{2j} (2j − 1)!!. Always finite (or +∞ on overflow).
    fn slope_moment(&self, k: u32, phi: f64) -> Option<f64> {
        let (s, c) = phi.sin_cos();
        let dir = [c, s];
        let m = dot2(self.mean, dir);
        let var = self.sigma.quad(dir);
        let n = 2 * k;
        let mut sum = 0.0;
        let mut binom = 1.0; // C(2k, 2j)
        let mut gauss = 1.0; // σ^{2j} (2j − 1)!!
        for j in 0..=k {
            if j > 0 {
                let (a, b) = (2 * j - 1, 2 * j);
                binom *= ((n - a + 1) as f64 / a as f64) * ((n - b + 1) as f64 / b as f64);
                gauss *= var * a as f64;
            }
            sum += binom * m.powi((n - 2 * j) as i32) * gauss;
        }
        Some(sum)
    }

    /// The central variance σ_φ² (eq 8 at φ_o = φ); equals ν₂ only when s̄_φ = 0.
    fn variance(&self, phi: f64) -> Option<f64> {
        let (s, c) = phi.sin_cos();
        Some(self.sigma.quad([c, s]))
    }

    /// The central excess kurtosis of a Gaussian: 0 along every azimuth.
    fn excess_kurtosis(&self) -> Option<f64> {
        Some(0.0)
    }
}

impl VisibleSlopeMoments for GaussianSlopes {
    fn visible_moments(&self, w: Vec3) -> Result<VisibleMoments, QueryError> {
        check_view(w)?;
        Ok(GaussianSlopes::visible_moments(self, w))
    }

    fn visible_moments_routes(&self) -> Vec<&'static str> {
        vec![
            "default",
            "pseudocode",
            "pseudocode_printed",
            "equations_printed",
        ]
    }

    /// Routes: `default` (the stable form), `pseudocode` (document 002's pseudocode with its
    /// erratum fixed), `pseudocode_printed` (as printed), `equations_printed` (eq 59–69 as
    /// printed). The transcribed routes return NaN at θ = 0.
    fn visible_moments_route(&self, w: Vec3, route: &str) -> Result<VisibleMoments, QueryError> {
        let transcription = match route {
            "default" => return VisibleSlopeMoments::visible_moments(self, w),
            "pseudocode" => Transcription::PseudocodeCorrected,
            "pseudocode_printed" => Transcription::PseudocodePrinted,
            "equations_printed" => Transcription::EquationsPrinted,
            _ => {
                return Err(QueryError::Route {
                    route: route.to_string(),
                    reason: format!(
                        "gaussian_slopes visible_moments routes: {}",
                        self.visible_moments_routes().join(", ")
                    ),
                })
            }
        };
        check_view(w)?;
        Ok(self.visible_moments_transcribed(w, transcription))
    }
}

impl FamilySpec for GaussianSlopesSpec {
    fn build(&self) -> Result<Box<dyn Model>, crate::ParamError> {
        Ok(Box::new(GaussianSlopes::new(self.mean, self.cov)?))
    }

    fn mean_slope(&self) -> [f64; 2] {
        self.mean
    }
}

impl Model for GaussianSlopes {
    fn spec(&self) -> ModelSpec {
        ModelSpec::GaussianSlopes(GaussianSlopesSpec {
            mean: self.mean,
            cov: self.cov,
        })
    }

    fn family(&self) -> &'static str {
        GaussianSlopesSpec::INFO.name
    }
}

/// The mean and covariance of D_s for a positive *semi*-definite covariance (document 002,
/// eq 12–46, by the same closed form as [`GaussianSlopes::visible_moments`]).
///
/// A singular Σ (|Σ| = 0, including Σ = 0: a perfectly smooth surface) has no density D but
/// D_s is still a well-defined distribution, and its moments are the limits of the regular
/// case:
///
/// ```text
/// a = ω̂ᵀΣω̂ > 0:   the formulas of GaussianSlopes::visible_moments, with |Σ| = 0
/// a = 0, θ > 0:    the slope along ω̂ is s̄_o surely: (s̄, Σ) if w_z − s̄·w_xy > 0
/// θ = 0:           (s̄, Σ)
/// ```
///
/// Errors: `QueryError::Argument` for invalid parameters (non-finite, asymmetric, a negative
/// variance or |Σ| < 0; the message names the entry), for `w` not finite, zero or below the
/// horizon, and when no facet faces `w` (a = 0 and w_z − s̄·w_xy ≤ 0: D_s does not exist).
pub fn visible_moments_psd(
    mean: [f64; 2],
    cov: [[f64; 2]; 2],
    w: Vec3,
) -> Result<VisibleMoments, QueryError> {
    let sigma =
        Cov2::validated(mean, cov, false).map_err(|e| QueryError::Argument(e.to_string()))?;
    check_view(w)?;
    visible_core(mean, &sigma, w).ok_or_else(|| {
        QueryError::Argument(format!(
            "no microfacet faces w = {w:?}: the slope along the view azimuth is s̄_o surely \
             and w_z − s̄·w_xy ≤ 0, so D_s does not exist"
        ))
    })
}

/// A view direction for D_s: finite, non-zero, w_z ≥ 0.
fn check_view(w: Vec3) -> Result<(), QueryError> {
    if !w.iter().all(|c| c.is_finite()) || w == [0.0; 3] {
        return Err(QueryError::Argument(format!(
            "the view direction must be finite and non-zero (got {w:?})"
        )));
    }
    if !(w[2] >= 0.0) {
        return Err(QueryError::Argument(format!(
            "the view direction must lie in the upper hemisphere, w_z ≥ 0 (got {w:?})"
        )));
    }
    Ok(())
}

/// The stable closed form of D_s's moments (see `GaussianSlopes::visible_moments`); `None`
/// when no facet faces `w`.
fn visible_core(mean: [f64; 2], sigma: &Cov2, w: Vec3) -> Option<VisibleMoments> {
    let unchanged = VisibleMoments {
        mean,
        cov: sigma.matrix(),
    };
    let qn = w[0].hypot(w[1]);
    if !(qn > 0.0) {
        // Normal incidence: the weight w_z is the same for every facet.
        return (w[2] > 0.0).then_some(unchanged);
    }
    let dir = [w[0] / qn, w[1] / qn];
    let perp = [-dir[1], dir[0]];
    let mu = w[2] / qn;
    let a = sigma.quad(dir);
    let mean_o = dot2(mean, dir);
    if !(a > 0.0) {
        // The slope along the view azimuth is s̄_o surely: every facet has weight W(s̄).
        return (mu - mean_o > 0.0).then_some(unchanged);
    }
    let sigma_o = a.sqrt();
    let z0 = (mu - mean_o) / sigma_o;
    if z0.is_nan() || z0 == f64::NEG_INFINITY {
        return None;
    }
    let r = ramp_moments(z0);
    let u = sigma.times(dir);
    let u_hat = [u[0] / sigma_o, u[1] / sigma_o];
    let mean_s = if z0 >= 0.0 {
        [mean[0] + r.tau * u_hat[0], mean[1] + r.tau * u_hat[1]]
    } else {
        // Referenced to the cut s_o = μ, so that s̄_o + σ_o τ does not cancel when the mean
        // facet faces away (s̄_o ≫ μ).
        let along = mu - sigma_o * r.gap;
        let across = dot2(mean, perp) + r.tau * dot2(perp, u) / sigma_o;
        [
            along * dir[0] + across * perp[0],
            along * dir[1] + across * perp[1],
        ]
    };
    let conditional = sigma.det / a;
    let cov = |i: usize, j: usize| conditional * perp[i] * perp[j] + r.var * u_hat[i] * u_hat[j];
    let cxy = cov(0, 1);
    Some(VisibleMoments {
        mean: mean_s,
        cov: [[cov(0, 0), cxy], [cxy, cov(1, 1)]],
    })
}

#[inline]
fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// a·b − c·d with one rounding error (Kahan's algorithm with a fused multiply-add).
#[inline]
fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let cd = c * d;
    let err = (-c).mul_add(d, cd);
    a.mul_add(b, -cd) + err
}

/// A validated 2×2 covariance with its determinant and a pivoted Cholesky factor: the
/// quadratic forms it evaluates keep full relative accuracy when Σ is near-singular.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cov2 {
    xx: f64,
    xy: f64,
    yy: f64,
    /// |Σ| = σx² σy² − cxy², with one rounding error.
    det: f64,
}

impl Cov2 {
    /// Validates s̄ and Σ: finite, symmetric, and positive definite (`strict`) or
    /// semi-definite.
    fn validated(mean: [f64; 2], cov: [[f64; 2]; 2], strict: bool) -> Result<Self, ParamError> {
        const MEAN: [&str; 2] = ["mean[0]", "mean[1]"];
        const COV: [[&str; 2]; 2] = [["cov[0][0]", "cov[0][1]"], ["cov[1][0]", "cov[1][1]"]];
        for (i, &m) in mean.iter().enumerate() {
            if !m.is_finite() {
                return Err(ParamError::OutOfRange {
                    name: MEAN[i],
                    requirement: "finite",
                    value: m,
                });
            }
        }
        for i in 0..2 {
            for j in 0..2 {
                if !cov[i][j].is_finite() {
                    return Err(ParamError::OutOfRange {
                        name: COV[i][j],
                        requirement: "finite",
                        value: cov[i][j],
                    });
                }
            }
        }
        if cov[1][0] != cov[0][1] {
            return Err(ParamError::OutOfRange {
                name: "cov[1][0]",
                requirement: "equal to cov[0][1] (a covariance is symmetric)",
                value: cov[1][0],
            });
        }
        for i in 0..2 {
            let v = cov[i][i];
            let ok = if strict { v > 0.0 } else { v >= 0.0 };
            if !ok {
                return Err(ParamError::OutOfRange {
                    name: COV[i][i],
                    requirement: if strict {
                        "> 0 (a variance)"
                    } else {
                        "≥ 0 (a variance)"
                    },
                    value: v,
                });
            }
        }
        let (xx, xy, yy) = (cov[0][0], cov[0][1], cov[1][1]);
        let det = difference_of_products(xx, yy, xy, xy);
        let ok = det.is_finite() && if strict { det > 0.0 } else { det >= 0.0 };
        if !ok {
            return Err(ParamError::OutOfRange {
                name: "det(cov)",
                requirement: if strict {
                    "finite and > 0: cov[0][0]·cov[1][1] − cov[0][1]² (positive definite; a \
                     singular covariance has no density D, see visible_moments_psd)"
                } else {
                    "finite and ≥ 0: cov[0][0]·cov[1][1] − cov[0][1]² (positive semi-definite)"
                },
                value: det,
            });
        }
        Ok(Self { xx, xy, yy, det })
    }

    fn matrix(&self) -> [[f64; 2]; 2] {
        [[self.xx, self.xy], [self.xy, self.yy]]
    }

    /// (pivot, the other index, l = √Σ_pp, r = Σ_xy / l): Σ = L Lᵀ with
    /// L = [[l, 0], [r, √|Σ| / l]] in the order (pivot, other); `None` when Σ = 0.
    #[inline]
    fn pivot(&self) -> Option<(usize, usize, f64, f64)> {
        let (p, o, d) = if self.xx >= self.yy {
            (0, 1, self.xx)
        } else {
            (1, 0, self.yy)
        };
        if !(d > 0.0) {
            return None;
        }
        let l = d.sqrt();
        Some((p, o, l, self.xy / l))
    }

    /// qᵀΣq = (l q_p + r q_o)² + (|Σ|/Σ_pp) q_o².
    fn quad(&self, q: [f64; 2]) -> f64 {
        let Some((p, o, l, r)) = self.pivot() else {
            return 0.0;
        };
        let t = l * q[p] + r * q[o];
        t * t + self.det / (l * l) * q[o] * q[o]
    }

    /// Σq = L Lᵀ q.
    fn times(&self, q: [f64; 2]) -> [f64; 2] {
        let Some((p, o, l, r)) = self.pivot() else {
            return [0.0; 2];
        };
        let t = l * q[p] + r * q[o];
        let mut u = [0.0; 2];
        u[p] = l * t;
        u[o] = r * t + self.det / (l * l) * q[o];
        u
    }

    /// dᵀΣ⁻¹d = |L⁻¹d|² (Σ positive definite).
    fn mahalanobis2(&self, d: [f64; 2]) -> f64 {
        let Some((p, o, l, r)) = self.pivot() else {
            return f64::NAN;
        };
        let k = self.det.sqrt() / l;
        let y1 = d[p] / l;
        let y2 = (d[o] - r * y1) / k;
        y1 * y1 + y2 * y2
    }
}

#[cfg(test)]
#[path = "gaussian_tests.rs"]
mod tests;

impl GaussianSlopesSpec {
    /// The registry entry of Gaussian slopes ([`crate::registry`], which finds it through the spec type).
    pub const INFO: FamilyInfo = FamilyInfo {
        name: "gaussian_slopes",
        documents: &["002"],
        source: "seed 002 eq 1 (slope sign of eq 11)",
        domain: "mean finite; cov symmetric positive definite",
        examples: &[
            r#"{"family": "gaussian_slopes", "mean": [0.1, -0.05], "cov": [[0.04, 0.01], [0.01, 0.09]]}"#,
        ],
        stress_alpha: &[],
        stress_gamma: &[],
        stress_specs: &[(
            "cov correlation 1 − 1e-9",
            r#"{"family": "gaussian_slopes", "mean": [0.1, -0.05], "cov": [[0.04, 0.03999999996], [0.03999999996, 0.04]]}"#,
        )],
        lambda_numerical: false,
        slow_sampler: false,
        beckmann_limit: false,
        intrinsic_moments: true,
        sampler_cost: SamplerCost::NONE,
    };
}
