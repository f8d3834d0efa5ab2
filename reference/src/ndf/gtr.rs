//! The Generalized-Trowbridge-Reitz (GTR) NDF of Burley 2012, with the Smith Λ / G1 of document 004
//! (Dimov 2015) for every γ ≥ 0: isotropic, shape `gamma`, roughness `alpha`.

use crate::error::{ParamError, QueryError};
use crate::family::{FamilyInfo, FamilySpec, SamplerCost};
use crate::geometry::Vec3;
use crate::model::{
    check_alpha, lambda_both_hemispheres, standardized_cotangent, Model, Ndf, NormalSampler,
    SlopeDistribution, Smith,
};
use crate::ndf::gtr_lambda as routes;
/// The family's spec type (declared with every family's in `crate::spec`).
pub use crate::spec::GtrSpec;
use crate::spec::ModelSpec;
use crate::special::gauss_kronrod;
use std::f64::consts::{FRAC_PI_2, PI};

/// The largest γ accepted (document 004 §6: "values greater than 10 are impractical").
pub const GAMMA_MAX: f64 = 10.0;
/// The smallest α accepted; every quantity is tested down to here.
pub const ALPHA_MIN: f64 = 1e-4;

/// The GTR NDF (document 004 eq 1** and 4**, after Burley 2012), normalized so that
/// ∫ D(m) cos θ_m dω = 1:
///
/// ```text
/// D(θ)     = c / (1 + (α² − 1) cos²θ)^γ = c / (sin²θ + α² cos²θ)^γ
/// c        = (γ − 1)(α² − 1) / (π (1 − (α²)^{1−γ}))        γ ≠ 1          (1**)
///          = (α² − 1) / (π log α²)                          γ = 1          (4**)
///          = expm1(L) / (π expm1((1 − γ)L)/(1 − γ)),  L = log α²   (evaluated form)
/// P22(p,q) = D cos⁴θ = c (1 + r²)^{γ−2} / (r² + α²)^γ,  r² = p² + q²     (42*, §3)
/// P2(q)    = ∫ P22 dp = (c π/2) A^{1/2−γ} B^{γ−2} ₂F₁(2−γ, ½; 2; 1 − A/B),
///            A = q² + α², B = q² + 1                                      (43*)
/// ```
///
/// The printed constant (1**) is 0/0 at γ = 1 and at α = 1; the evaluated form is continuous
/// through both (its limits are (4**) and 1/π). γ = 0 is admissible: D ≡ 1/π for every α (the
/// cosine-weighted uniform NDF, document 004 §3.1), and so is α = 1: D ≡ 1/π for every γ.
///
/// Domain: 0 ≤ γ ≤ 10, 1e-4 ≤ α ≤ 1. Tails: P22 ~ c r⁻⁴ for every γ, so the slope mean is finite
/// (Λ exists for every γ ≥ 0) and the slope variance diverges (logarithmically).
#[derive(Debug, Clone, PartialEq)]
pub struct Gtr {
    gamma: f64,
    alpha: f64,
    /// α².
    a2: f64,
    /// The normalization constant c.
    c: f64,
    /// The u-independent parts of the sampler's inversion (`cos2_sin2`).
    inversion: Inversion,
}

/// The constants of the Burley inversion: L = log α², s = 1 − γ, expm1(sL), expm1(−sL),
/// expm1(L).
#[derive(Debug, Clone, PartialEq)]
struct Inversion {
    l: f64,
    s: f64,
    expm1_sl: f64,
    expm1_minus_sl: f64,
    expm1_l: f64,
}

impl Inversion {
    fn new(gamma: f64, alpha: f64) -> Self {
        let l = 2.0 * alpha.ln();
        let s = 1.0 - gamma;
        Self {
            l,
            s,
            expm1_sl: (s * l).exp_m1(),
            expm1_minus_sl: (-s * l).exp_m1(),
            expm1_l: l.exp_m1(),
        }
    }
}

impl Gtr {
    /// A validated GTR NDF: 0 ≤ γ ≤ 10 and 1e-4 ≤ α ≤ 1 (NaN fails).
    pub fn new(gamma: f64, alpha: f64) -> Result<Self, ParamError> {
        if !(0.0..=GAMMA_MAX).contains(&gamma) {
            return Err(ParamError::GammaOutOfRange {
                family: "gtr",
                requirement: "≥ 0 and ≤ 10",
                value: gamma,
            });
        }
        let alpha = check_alpha("alpha", alpha)?;
        if !(ALPHA_MIN..=1.0).contains(&alpha) {
            return Err(ParamError::OutOfRange {
                name: "alpha",
                requirement: "in [1e-4, 1] for gtr",
                value: alpha,
            });
        }
        Ok(Self {
            gamma,
            alpha,
            a2: alpha * alpha,
            c: routes::normalization_constant(gamma, alpha),
            inversion: Inversion::new(gamma, alpha),
        })
    }

    /// The shape γ.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// The roughness α.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// The normalization constant c of D (`gtr_lambda::normalization_constant`).
    pub fn normalization(&self) -> f64 {
        self.c
    }

    /// μ = cot θ of a direction (document 004 eq 44*, signed: negative below the horizon).
    pub fn mu(w: Vec3) -> f64 {
        standardized_cotangent(1.0, 1.0, w)
    }

    /// Λ(μ) for μ = cot θ ≥ 0 by the default ("exact") route.
    pub fn lambda_mu(&self, mu: f64) -> f64 {
        routes::lambda_exact_with(self.gamma, self.alpha, self.c, mu)
    }

    /// G1 of a direction by a named route (G1 = 1/(1 + Λ), 0 at and below the horizon). The
    /// routes `implementation` and `spline` compute G1 directly: this returns their G1 without
    /// the round trip through Λ.
    pub fn g1_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        let mu = Self::mu(w);
        let lambda = self.lambda_route(w, route)?; // validates the route
        if !(mu > 0.0) {
            return Ok(0.0);
        }
        Ok(match route {
            "implementation" => routes::g1_implementation(
                routes::integer_gamma(self.gamma).unwrap_or(u8::MAX),
                self.alpha,
                mu,
            ),
            "spline" => routes::g1_spline(self.gamma, self.alpha, mu),
            _ => 1.0 / (1.0 + lambda),
        })
    }

    /// (cos²θ, sin²θ) of the Burley 2012 inversion at u, each without cancellation:
    ///
    /// ```text
    /// cos²θ = (1 − ((α²)^{1−γ}(1 − u) + u)^{1/(1−γ)}) / (1 − α²)          (Burley 2012)
    ///       = expm1(ℓ)/expm1(L),   sin²θ = e^ℓ expm1(L − ℓ)/expm1(L),
    /// ℓ     = log(1 + (α²−1)cos²θ) = log1p((1 − u) expm1(sL))/s      (→ (1 − u)L at s = 0)
    /// L − ℓ = −log1p(u expm1(−sL))/s                                 (→ uL at s = 0)
    /// ```
    ///
    /// with s = 1 − γ, L = log α²; at α = 1, cos²θ = 1 − u. The u-independent expm1 values
    /// are computed once (`Inversion`); e^ℓ stays `exp` (1 + expm1(ℓ) cancels for small α).
    fn cos2_sin2(&self, u: f64) -> (f64, f64) {
        let Inversion {
            l,
            s,
            expm1_sl,
            expm1_minus_sl,
            expm1_l,
        } = self.inversion;
        if l == 0.0 {
            return (1.0 - u, u);
        }
        let (ell, delta) = if s == 0.0 {
            ((1.0 - u) * l, u * l)
        } else {
            (
                ((1.0 - u) * expm1_sl).ln_1p() / s,
                -(u * expm1_minus_sl).ln_1p() / s,
            )
        };
        (ell.exp_m1() / expm1_l, ell.exp() * delta.exp_m1() / expm1_l)
    }
}

impl Ndf for Gtr {
    fn d(&self, m: Vec3) -> f64 {
        let mz = m[2];
        if mz <= 0.0 {
            return 0.0;
        }
        // 1 + (α² − 1) cos²θ = sin²θ + α² cos²θ: no cancellation near θ = 0.
        let t = m[0] * m[0] + m[1] * m[1] + self.a2 * mz * mz;
        self.c * t.powf(-self.gamma)
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
}

impl Smith for Gtr {
    fn lambda(&self, w: Vec3) -> f64 {
        lambda_both_hemispheres(Self::mu(w), |mu| self.lambda_mu(mu))
    }

    fn lambda_routes(&self) -> Vec<&'static str> {
        routes::ROUTES.iter().map(|r| r.0).collect()
    }

    fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        if route == "default" || route == "exact" {
            return Ok(self.lambda(w));
        }
        // Validate once, at a μ where every route is defined.
        routes::lambda(route, self.gamma, self.alpha, 1.0)?;
        Ok(lambda_both_hemispheres(Self::mu(w), |mu| {
            routes::lambda(route, self.gamma, self.alpha, mu).unwrap_or(f64::NAN)
        }))
    }
}

impl NormalSampler for Gtr {
    /// Burley 2012 (Disney BRDF notes, appendix B.2) inversion of the GTR CDF: φ = 2π u₁ and
    /// cos θ from u₂ (`cos2_sin2`), so that the density is D(m) cos θ_m.
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let (cos2, sin2) = self.cos2_sin2(u[1]);
        let (sp, cp) = crate::geometry::sin_cos_turns(u[0]);
        let (st, ct) = (sin2.max(0.0).sqrt(), cos2.max(0.0).sqrt());
        let n = (sin2 + cos2).sqrt();
        [st * cp / n, st * sp / n, ct / n]
    }
}

impl SlopeDistribution for Gtr {
    fn p22(&self, p: f64, q: f64) -> f64 {
        let r2 = p * p + q * q;
        if !r2.is_finite() {
            return if r2.is_nan() { f64::NAN } else { 0.0 };
        }
        // c (1 + r²)^{γ−2} / (r² + α²)^γ = c ((1 + r²)/(r² + α²))^γ / (1 + r²)²: no overflow.
        let b = 1.0 + r2;
        self.c * (b / (r2 + self.a2)).powf(self.gamma) / (b * b)
    }

    /// P2(q) (isotropic: the same along every azimuth) from the Euler integral of its ₂F₁
    /// closed form (the crate has no ₂F₁ over z ∈ [0, 1)): with p = √A tan t,
    ///
    /// ```text
    /// P2(q) = 2c √A κ^{−γ} B⁻² J,  κ = A/B,
    /// J     = ∫_0^{π/2} sin²u (sin²u + κ cos²u)^{γ−2} du = (π/4) ₂F₁(2−γ, ½; 2; 1 − κ)
    /// ```
    ///
    /// J by the adaptive G7/K15 rule of `special::gauss_kronrod` (estimated relative error
    /// ≤ 1e-14), J = π/4 at γ = 2 or
    /// α = 1; P2 = cπ/(2|q|³) beyond |q| = 1e100.
    fn p2(&self, q: f64, _phi: f64) -> f64 {
        let q = q.abs();
        if q.is_nan() {
            return f64::NAN;
        }
        if q > 1e100 {
            return self.c * PI / 2.0 / q / q / q;
        }
        let q2 = q * q;
        let a = q2 + self.a2;
        let b = 1.0 + q2;
        let kappa = a / b;
        let j = if kappa == 1.0 || self.gamma == 2.0 {
            PI / 4.0
        } else {
            let g = self.gamma - 2.0;
            let f = |u: f64| {
                let (s, c) = u.sin_cos();
                let s2 = s * s;
                s2 * (s2 + kappa * c * c).powf(g)
            };
            // The integrand changes over u ≈ atan √κ: resolve that scale from the start.
            let root = kappa.sqrt();
            let mut points = vec![0.0];
            points.extend(
                [0.125, 0.5, 2.0, 8.0]
                    .iter()
                    .map(|k| (k * root).atan())
                    .filter(|&u| u < 1.4),
            );
            points.push(FRAC_PI_2);
            gauss_kronrod::integrate(&f, &points, 1e-14, 0.0).value
        };
        2.0 * self.c * a.sqrt() * kappa.powf(-self.gamma) * j / b / b
    }

    /// ν₀ = 1; ν₂ₖ for k ≥ 1 diverge for every γ and α (P2 ~ cπ/(2|q|³)).
    fn slope_moment(&self, k: u32, _phi: f64) -> Option<f64> {
        (k == 0).then_some(1.0)
    }
}

impl FamilySpec for GtrSpec {
    fn build(&self) -> Result<Box<dyn Model>, crate::ParamError> {
        Ok(Box::new(Gtr::new(self.gamma, self.alpha)?))
    }
}

impl Model for Gtr {
    fn spec(&self) -> ModelSpec {
        ModelSpec::Gtr(GtrSpec {
            gamma: self.gamma,
            alpha: self.alpha,
        })
    }

    fn family(&self) -> &'static str {
        GtrSpec::INFO.name
    }
}

impl GtrSpec {
    /// The registry entry of gtr ([`crate::registry`], which finds it through the spec type).
    pub const INFO: FamilyInfo = FamilyInfo {
        name: "gtr",
        documents: &["004"],
        source: "seed 004 §2 (Burley 2012 GTR), Smith G1 of seed 004",
        domain: "0 ≤ γ ≤ 10, 1e-4 ≤ α ≤ 1",
        examples: &[r#"{"family": "gtr", "gamma": 1.5, "alpha": 0.3}"#],
        stress_alpha: &[1e-4, 0.999],
        stress_gamma: &[1e-6, 10.0],
        stress_specs: &[],
        lambda_numerical: true,
        slow_sampler: false,
        beckmann_limit: false,
        intrinsic_moments: false,
        sampler_cost: SamplerCost {
            normal_ns: 84.0,
            visible_ns: 0.0,
        },
    };
}

#[cfg(test)]
#[path = "gtr_tests.rs"]
mod tests;
