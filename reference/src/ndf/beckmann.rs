//! The Beckmann NDF, isotropic and anisotropic: the γ → ∞ limit of STD (document 001, §2, Table 1).

use crate::error::{ParamError, QueryError};
use crate::family::{resolve_roughness, roughness_fields, FamilyInfo, FamilySpec, SamplerCost};
use crate::geometry::{normal_from_slopes, Vec3};
use crate::model::{
    check_alpha, elliptic_direction, lambda_both_hemispheres, scale_along, standardized_cotangent,
    visible_domain, Model, Ndf, NormalSampler, SlopeDistribution, Smith, VisibleNormalSampler,
};
/// The family's spec type (declared with every family's in `crate::spec`).
pub use crate::spec::BeckmannSpec;
use crate::spec::ModelSpec;
use std::f64::consts::PI;

/// Beckmann NDF with roughness `alpha_x`, `alpha_y` (document 001, Table 1, row γ → ∞):
///
/// ```text
/// D(m)   = exp(−tan²θ (cos²φ/αx² + sin²φ/αy²)) / (π αx αy cos⁴θ)
/// P22    = exp(−p²/αx² − q²/αy²) / (π αx αy)
/// Λ(θ,φ) = ½ (e^{−a²}/(a √π) − erfc(a)),  a = cot θ / α(φ),  α(φ)² = αx² cos²φ + αy² sin²φ
/// ```
///
/// Domain: αx, αy finite and > 0 (tested 1e-4 … 10); any direction (Λ below the horizon by
/// Λ(−w) = −1 − Λ(w)).
#[derive(Debug, Clone, PartialEq)]
pub struct Beckmann {
    alpha_x: f64,
    alpha_y: f64,
    described_as: Option<ModelSpec>,
}

impl Beckmann {
    /// A validated Beckmann NDF.
    pub fn new(alpha_x: f64, alpha_y: f64) -> Result<Self, ParamError> {
        Ok(Self {
            alpha_x: check_alpha("alpha_x", alpha_x)?,
            alpha_y: check_alpha("alpha_y", alpha_y)?,
            described_as: None,
        })
    }

    /// The same model presented under another spec (STD with `gamma: "inf"` is Beckmann
    /// exactly).
    pub fn described_as(mut self, spec: ModelSpec) -> Self {
        self.described_as = Some(spec);
        self
    }

    /// The roughness (αx, αy).
    pub fn alpha(&self) -> (f64, f64) {
        (self.alpha_x, self.alpha_y)
    }

    /// Λ as a function of the standardized cotangent a = cot θ / α(φ) ≥ 0, by the
    /// cancellation-free evaluation of `special::student_tail::beckmann_lambda`.
    pub fn lambda_of(a: f64) -> f64 {
        crate::special::student_tail::beckmann_lambda(a)
    }

    /// Document 001, Table 1, row γ → ∞, evaluated as printed:
    /// `½ (σ e^{−μ²/σ²}/(μ √π) + erf(μ/σ) − 1)` with a = μ/σ. Correct, but it subtracts
    /// nearly equal numbers near normal incidence (kept to measure that loss).
    pub fn lambda_table1(a: f64) -> f64 {
        // libm (musl) erf: statrs erf is off by up to 2e-10 relative near a ≈ 1.
        0.5 * ((-a * a).exp() / (a * PI.sqrt()) + libm::erf(a) - 1.0)
    }
}

impl Ndf for Beckmann {
    fn d(&self, m: Vec3) -> f64 {
        let mz = m[2];
        if mz <= 0.0 {
            return 0.0;
        }
        let z2 = mz * mz;
        let u = (m[0] / self.alpha_x).powi(2) + (m[1] / self.alpha_y).powi(2);
        let e = (-u / z2).exp();
        if e == 0.0 {
            return 0.0;
        }
        e / (PI * self.alpha_x * self.alpha_y * z2 * z2)
    }

    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        Some(self)
    }
    fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
        Some(self)
    }
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        Some(self)
    }
}

impl Smith for Beckmann {
    fn lambda(&self, w: Vec3) -> f64 {
        let a = standardized_cotangent(self.alpha_x, self.alpha_y, w);
        lambda_both_hemispheres(a, Self::lambda_of)
    }

    fn lambda_routes(&self) -> Vec<&'static str> {
        vec!["default", "table1"]
    }

    fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        let a = standardized_cotangent(self.alpha_x, self.alpha_y, w);
        match route {
            "default" => Ok(self.lambda(w)),
            "table1" => Ok(lambda_both_hemispheres(a, Self::lambda_table1)),
            _ => Err(QueryError::Route {
                route: route.to_string(),
                reason: format!("Beckmann Λ routes: {}", self.lambda_routes().join(", ")),
            }),
        }
    }
}

impl NormalSampler for Beckmann {
    /// Slope-space inversion (document 001, eq 40 with the quadrant fixed, and eq 42 in the limit
    /// γ → ∞): φ from u1 and tan²θ A(φ) = −ln(1 − u2).
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let (dx, dy) = elliptic_direction(self.alpha_x, self.alpha_y, u[0]);
        let r = (-(-u[1]).ln_1p()).sqrt();
        normal_from_slopes(r * dx, r * dy)
    }

    /// `sample_wm` over a batch: the azimuth, √ and normal vectorized, −ln(1 − u₂) by `ln_1p`
    /// per element; bit for bit the scalar result (`ndf::batch`).
    fn sample_wm_batch(&self, u: &[[f64; 2]], out: &mut [Vec3]) {
        super::batch::sample_elliptic_batch(
            self.alpha_x,
            self.alpha_y,
            u,
            out,
            |u1, r2| {
                for (r2, &u1) in r2.iter_mut().zip(u1) {
                    *r2 = -(-u1).ln_1p();
                }
            },
            |u| self.sample_wm(u),
        );
    }
}

impl VisibleNormalSampler for Beckmann {
    /// Heitz & d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs using the Distribution of
    /// Visible Normals", CGF 33(4), §4 and supplement (not one of the five source documents;
    /// document 001 §7 cites it as \[9\]), with the visible-slope cdf inverted numerically as in Jakob
    /// 2014, "An Improved Visible Normal Sampling Routine for the Beckmann Distribution":
    /// stretch `wi` to unit roughness, at polar angle θ and azimuth φ; draw the slope x̃ along
    /// the incidence plane from the visible-slope density and ỹ across it from the Gaussian
    /// slope density; rotate by φ, unstretch and return the normal of the slope:
    ///
    /// ```text
    /// P(x̃) ∝ (cos θ − x̃ sin θ)⁺ e^{−x̃²}/√π,   F(x̃) = ½ (cos θ erfc(−x̃) + sin θ e^{−x̃²}/√π),  x̃ < cot θ
    /// P(ỹ) = e^{−ỹ²}/√π,                        F(ỹ) = ½ erfc(−ỹ)
    /// (s_x, s_y) = (αx (cos φ x̃ − sin φ ỹ), αy (sin φ x̃ + cos φ ỹ)),   m = normalize(−s_x, −s_y, 1)
    /// ```
    ///
    /// F(x̃) = u·F(cot θ) and F(ỹ) = u2 are solved by Newton's method safeguarded by bisection
    /// on [−9, min(cot θ, 9)] (outside, the mass is below e^{−81}) to ~1e-15 in x̃, with libm's
    /// erfc; ỹ starts from −erfc⁻¹(2u₂) (about 7 Newton steps for x̃, 1 for ỹ). Exact up to
    /// that root-finding error for every α and wi_z > 0; NaN outside the domain.
    fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
        if !visible_domain(wi) {
            return [f64::NAN; 3];
        }
        let (sx, sy, sz) = (self.alpha_x * wi[0], self.alpha_y * wi[1], wi[2]);
        let horizontal = sx.hypot(sy);
        let len = horizontal.hypot(sz);
        let (cos_t, sin_t) = (sz / len, horizontal / len);
        let (cos_p, sin_p) = if horizontal > 0.0 {
            (sx / horizontal, sy / horizontal)
        } else {
            (1.0, 0.0)
        };
        let x = visible_slope(cos_t, sin_t, u[0]);
        let y = visible_slope(1.0, 0.0, u[1]);
        let px = self.alpha_x * (cos_p * x - sin_p * y);
        let py = self.alpha_y * (sin_p * x + cos_p * y);
        normal_from_slopes(-px, -py)
    }
}

/// The slope x̃ < cot θ with F(x̃) = u·F(cot θ), for the unit-roughness Beckmann visible-slope
/// cdf F(x̃) = ½ (cos θ erfc(−x̃) + sin θ e^{−x̃²}/√π) seen at polar angle θ (given as
/// `(cos θ, sin θ)`, sin θ ≥ 0): Newton's method safeguarded by bisection. At sin θ = 0 this
/// is the quantile of the density e^{−x²}/√π.
fn visible_slope(cos_t: f64, sin_t: f64, u: f64) -> f64 {
    let inv_sqrt_pi = 1.0 / PI.sqrt();
    let cdf = |x: f64| 0.5 * (cos_t * libm::erfc(-x) + sin_t * (-x * x).exp() * inv_sqrt_pi);
    let density = |x: f64| (cos_t - x * sin_t).max(0.0) * (-x * x).exp() * inv_sqrt_pi;
    const BOUND: f64 = 9.0;
    let x_max = if sin_t > 0.0 {
        cos_t / sin_t
    } else {
        f64::INFINITY
    };
    let total = if x_max.is_finite() { cdf(x_max) } else { cos_t };
    let target = u * total;
    let (mut lo, mut hi) = (-BOUND, x_max.min(BOUND));
    if !(target > cdf(lo)) {
        return lo;
    }
    if !(target < cdf(hi)) {
        return hi;
    }
    // At normal incidence the quantile is −erfc⁻¹(2u) (statrs), which Newton's first step
    // confirms; elsewhere the bracket's midpoint.
    let start = if sin_t == 0.0 {
        -statrs::function::erf::erfc_inv(2.0 * u)
    } else {
        f64::NAN
    };
    let mut x = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..200 {
        let f = cdf(x) - target;
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let d = density(x);
        let mut next = if d > 0.0 { x - f / d } else { f64::NAN };
        // Converged before the bracket test: a step below the tolerance may land on the
        // bracket's end (f = 0 makes x its end), which is no reason to bisect away from the
        // root (that cost ~20 evaluations a slope where ~7 suffice).
        if (next - x).abs() <= 1e-15 * (1.0 + x.abs()) {
            return next.clamp(lo, hi);
        }
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if hi - lo <= 1e-15 * (1.0 + x.abs()) {
            return next;
        }
        x = next;
    }
    x
}

impl SlopeDistribution for Beckmann {
    fn p22(&self, p: f64, q: f64) -> f64 {
        (-(p / self.alpha_x).powi(2) - (q / self.alpha_y).powi(2)).exp()
            / (PI * self.alpha_x * self.alpha_y)
    }

    fn p2(&self, q: f64, phi: f64) -> f64 {
        let s = scale_along(self.alpha_x, self.alpha_y, phi);
        (-(q / s).powi(2)).exp() / (s * PI.sqrt())
    }

    /// ν₂ₖ = α(φ)^{2k} Γ(k + ½)/√π = α(φ)^{2k} (2k−1)!!/2^k (the γ → ∞ limit of document 001 eq 7).
    fn slope_moment(&self, k: u32, phi: f64) -> Option<f64> {
        let s2 = scale_along(self.alpha_x, self.alpha_y, phi).powi(2);
        Some((1..=k).fold(1.0, |acc, j| acc * s2 * (2 * j - 1) as f64 / 2.0))
    }
}

impl FamilySpec for BeckmannSpec {
    fn build(&self) -> Result<Box<dyn Model>, crate::ParamError> {
        let (ax, ay) = resolve_roughness(self.alpha, self.alpha_x, self.alpha_y)?;
        Ok(Box::new(Beckmann::new(ax, ay)?))
    }
}

impl Model for Beckmann {
    fn spec(&self) -> ModelSpec {
        self.described_as.clone().unwrap_or_else(|| {
            let (alpha, alpha_x, alpha_y) = roughness_fields(self.alpha_x, self.alpha_y);
            ModelSpec::Beckmann(BeckmannSpec {
                alpha,
                alpha_x,
                alpha_y,
            })
        })
    }

    fn family(&self) -> &'static str {
        self.described_as
            .as_ref()
            .map(ModelSpec::family)
            .unwrap_or(BeckmannSpec::INFO.name)
    }
}

impl BeckmannSpec {
    /// The registry entry of beckmann ([`crate::registry`], which finds it through the spec type).
    pub const INFO: FamilyInfo = FamilyInfo {
        name: "beckmann",
        documents: &["001"],
        source: "seed 001 Table 1 (γ → ∞)",
        domain: "α (or α_x, α_y) finite and > 0",
        examples: &[
            r#"{"family": "beckmann", "alpha": 0.3}"#,
            r#"{"family": "beckmann", "alpha_x": 0.1, "alpha_y": 0.4}"#,
        ],
        stress_alpha: &[1e-4, 10.0],
        stress_gamma: &[],
        stress_specs: &[],
        lambda_numerical: false,
        slow_sampler: false,
        beckmann_limit: false,
        intrinsic_moments: false,
        sampler_cost: SamplerCost {
            normal_ns: 23.0,
            visible_ns: 634.0,
        },
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::from_spherical;
    use crate::ndf::conformance::{assert_elliptic_model, assert_visible_sampler};
    use crate::test_support::rel_err;

    #[test]
    fn conforms_to_its_definitions() {
        for &alpha in &[
            (0.3, 0.3),
            (0.05, 0.05),
            (1.0, 1.0),
            (0.1, 0.4),
            (0.02, 0.8),
        ] {
            let m = Beckmann::new(alpha.0, alpha.1).unwrap();
            assert_elliptic_model(&m, alpha, 0.7, &format!("beckmann α={alpha:?}"));
        }
    }

    #[test]
    fn moments_are_gaussian() {
        // ν2 = α²/2, ν4 = 3α⁴/4: excess kurtosis 0.
        let m = Beckmann::new(0.3, 0.3).unwrap();
        assert!(rel_err(m.variance(0.0).unwrap(), 0.045) < 1e-15);
        assert!(m.excess_kurtosis().unwrap().abs() < 1e-14);
    }

    #[test]
    fn table1_route_cancels_near_normal_incidence_only() {
        let m = Beckmann::new(0.3, 0.3).unwrap();
        // a = cot θ/α ≤ 1.3: Λ ≥ 0.01, no harmful cancellation.
        for &theta in &[1.2, 1.5] {
            let w = from_spherical(theta, 0.0);
            let e = rel_err(m.lambda_route(w, "table1").unwrap(), m.lambda(w));
            assert!(e < 1e-13, "θ = {theta}: {e:e}");
        }
        // At a = cot θ/α ≈ 6 the printed row keeps no correct digit.
        let w = from_spherical((1.0f64 / 1.8).atan(), 0.0);
        let (t, d) = (m.lambda_route(w, "table1").unwrap(), m.lambda(w));
        assert!(rel_err(t, d) > 1e-3, "table1 {t:e} vs {d:e}");
        assert!(m.lambda_route(w, "2f1").is_err());
    }

    #[test]
    fn visible_normals_conform_to_their_density() {
        for &alpha in &[(0.3, 0.3), (0.05, 0.05), (1.0, 1.0), (0.1, 0.4)] {
            let m = Beckmann::new(alpha.0, alpha.1).unwrap();
            assert_visible_sampler(&m, alpha.0.min(alpha.1), &format!("beckmann α={alpha:?}"));
        }
    }

    #[test]
    fn visible_slope_quantiles() {
        // At normal incidence the slope is Gaussian with variance ½: F(x) = ½ erfc(−x).
        for &u in &[1e-12, 0.01, 0.3, 0.5, 0.9, 1.0 - 1e-12] {
            let x = visible_slope(1.0, 0.0, u);
            assert!(rel_err(0.5 * libm::erfc(-x), u) < 1e-13, "u = {u}: x = {x}");
        }
        assert!(visible_slope(1.0, 0.0, 0.5).abs() < 1e-14);
        // Oblique: F(x̃) = u·F(cot θ), F(x̃) = ½ (cos θ erfc(−x̃) + sin θ e^{−x̃²}/√π).
        for theta in [0.1f64, 0.5, 1.3, 1.55] {
            let (c, s) = (theta.cos(), theta.sin());
            let cdf = |x: f64| 0.5 * (c * libm::erfc(-x) + s * (-x * x).exp() / PI.sqrt());
            let total = cdf(c / s);
            for &u in &[1e-9, 0.01, 0.3, 0.5, 0.9, 0.999] {
                let x = visible_slope(c, s, u);
                assert!(x <= c / s, "θ = {theta}, u = {u}: x = {x}");
                assert!(
                    rel_err(cdf(x), u * total) < 1e-12,
                    "θ = {theta}, u = {u}: x = {x}"
                );
            }
        }
        // Grazing: the support ends at cot θ = 0.
        let x = visible_slope(0.0, 1.0, 0.999_999);
        assert!(x <= 0.0 && x > -1e-2, "{x}");
    }

    #[test]
    fn parameters_are_validated() {
        assert!(Beckmann::new(0.0, 0.3).is_err());
        assert!(Beckmann::new(f64::NAN, 0.3).is_err());
        assert!(Beckmann::new(0.3, f64::INFINITY).is_err());
    }
}
