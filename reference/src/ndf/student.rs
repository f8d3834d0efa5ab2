//! The Student-t family of NDFs (seed 001): the general D^G(B, C), STD, Hyper-Cauchy and the
//! fixed-variance member, isotropic and anisotropic.

use crate::error::{ParamError, QueryError};
use crate::geometry::{normal_from_slopes, Vec3};
use crate::model::{
    check_alpha, elliptic_direction, lambda_both_hemispheres, scale_along, standardized_cotangent,
    Model, Ndf, NormalSampler, SlopeDistribution, Smith,
};
use crate::ndf::student_lambda as routes;
use crate::spec::ModelSpec;
use std::f64::consts::PI;

/// The largest finite γ accepted: accuracy of every quantity is established up to here; use
/// `gamma: "inf"` (Beckmann, exactly) beyond.
pub const GAMMA_MAX: f64 = 1e8;

/// Which member of the family, i.e. how B depends on σ and γ (seed 001, §1.1: B = f/σ²).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Member {
    /// STD, f = 1/(γ − 1) (seed 001, §1.1, §2–6).
    Std,
    /// Hyper-Cauchy, f = 1 (seed 001, eq 8).
    HyperCauchy,
    /// Fixed variance σ²/2, f = 1/(γ − 2) (seed 001, eq 9); needs γ > 2.
    FixedVariance,
    /// The general isotropic D^G(B, C) (seed 001, eq 1–2), given by B and C directly.
    General,
}

/// A Student-t NDF: the bivariate Student's t-distribution of slopes (seed 001, eq 1–3, 10,
/// 13). With C = γ and per-axis Student scales s_x = σx/√f, s_y = σy/√f (s = 1/√B for the
/// general member):
///
/// ```text
/// P22(p, q) = (C − 1) / (π s_x s_y) · (1 + p²/s_x² + q²/s_y²)^(−C)          (eq 3, 10, 13)
/// D(m)      = P22(tan θ cos φ, tan θ sin φ) / cos⁴θ                          (eq 2, 8, 9, 10)
/// P2(q)     = N_C / s(φ) · (1 + q²/s(φ)²)^(1/2 − C),  N_C = Γ(C−½)/(√π Γ(C−1))  (eq 4, 15)
/// Λ(w)      = N_C / x · ∫_x^∞ (t − x)(1 + t²)^(1/2 − C) dt,  x = cot θ / s(φ)     (eq 5, 17, 21)
/// ν₂ₖ       = s(φ)^{2k} Γ(k+½) Γ(C−1−k) / (√π Γ(C−1)),  C > 1 + k              (eq 7)
/// ```
///
/// where s(φ)² = s_x² cos²φ + s_y² sin²φ. Domain of validity: 1 < γ ≤ 1e8 (D, P22, P2 and
/// sampling; γ ≤ 1 is not normalizable), Λ / G1 / G2 only for γ > 1.5 (below, the slope mean
/// diverges and Λ = ∞), γ > 2 for the fixed-variance member, σ finite and > 0 (tested 1e-4 …
/// 10), every direction (Λ below the horizon by Λ(−w) = −1 − Λ(w)). Everything is evaluated in
/// logarithms: no (γ − 1)^γ overflow.
#[derive(Debug, Clone, PartialEq)]
pub struct Student {
    member: Member,
    c: f64,
    alpha_x: f64,
    alpha_y: f64,
    sx: f64,
    sy: f64,
    /// (C − 1)/(π s_x s_y), the constant of P22.
    p22_norm: f64,
    /// N_C = Γ(C − ½)/(√π Γ(C − 1)), the constant of the standardized P2.
    p2_norm: f64,
}

impl Student {
    /// A validated member of the family with shape `gamma` and roughness (`alpha_x`,
    /// `alpha_y`).
    pub fn new(member: Member, gamma: f64, alpha_x: f64, alpha_y: f64) -> Result<Self, ParamError> {
        let family = member_family(member);
        let (lower, requirement) = match member {
            Member::FixedVariance => (2.0, "> 2 and ≤ 1e8 (or \"inf\")"),
            Member::HyperCauchy => (1.0, "> 1 and ≤ 1e8"),
            _ => (1.0, "> 1 and ≤ 1e8 (or \"inf\")"),
        };
        if !(gamma > lower && gamma <= GAMMA_MAX) {
            return Err(ParamError::GammaOutOfRange {
                family,
                requirement,
                value: gamma,
            });
        }
        let alpha_x = check_alpha("alpha_x", alpha_x)?;
        let alpha_y = check_alpha("alpha_y", alpha_y)?;
        let f_sqrt = match member {
            Member::Std | Member::General => (gamma - 1.0).sqrt(),
            Member::HyperCauchy => 1.0,
            Member::FixedVariance => (gamma - 2.0).sqrt(),
        };
        Ok(Self::from_scales(
            member,
            gamma,
            alpha_x,
            alpha_y,
            alpha_x * f_sqrt,
            alpha_y * f_sqrt,
        ))
    }

    /// The general isotropic D^G(B, C) of seed 001 eq 2 (B > 0, 1 < C ≤ 1e8).
    pub fn general(b: f64, c: f64) -> Result<Self, ParamError> {
        if !(b > 0.0 && b.is_finite()) {
            return Err(ParamError::OutOfRange {
                name: "b",
                requirement: "finite and > 0",
                value: b,
            });
        }
        if !(c > 1.0 && c <= GAMMA_MAX) {
            return Err(ParamError::OutOfRange {
                name: "c",
                requirement: "> 1 and ≤ 1e8",
                value: c,
            });
        }
        let s = 1.0 / b.sqrt();
        // σ is not a parameter of the general member; record the STD-equivalent roughness
        // s/√(C−1) so that `alpha()` stays meaningful.
        let alpha = s / (c - 1.0).sqrt();
        Ok(Self::from_scales(Member::General, c, alpha, alpha, s, s))
    }

    fn from_scales(member: Member, c: f64, alpha_x: f64, alpha_y: f64, sx: f64, sy: f64) -> Self {
        Self {
            member,
            c,
            alpha_x,
            alpha_y,
            sx,
            sy,
            p22_norm: (c - 1.0) / (PI * sx * sy),
            p2_norm: routes::p2_norm(c),
        }
    }

    /// The shape γ (= C).
    pub fn gamma(&self) -> f64 {
        self.c
    }

    /// The member of the family.
    pub fn member(&self) -> Member {
        self.member
    }

    /// The Student scales (s_x, s_y): slopes are standardized as p/s_x, q/s_y.
    pub fn scales(&self) -> (f64, f64) {
        (self.sx, self.sy)
    }

    /// The standardized cotangent x = cot θ / s(φ) of a direction.
    pub fn standardized_cotangent(&self, w: Vec3) -> f64 {
        standardized_cotangent(self.sx, self.sy, w)
    }

    /// The printed seed 001 eq 11 / 40 for φ: arctan((σy/σx) tan(2π u1)), without quadrant
    /// handling. Kept to demonstrate the erratum: its range is (−π/2, π/2), so every sampled
    /// normal has m_x ≥ 0 (see ERRATA.md).
    pub fn sample_wm_printed(&self, u: [f64; 2]) -> Vec3 {
        let phi = ((self.sy / self.sx) * (std::f64::consts::TAU * u[0]).tan()).atan();
        let (s, c) = phi.sin_cos();
        // Eq 12: tan²θ = ((1 − ξ2)^{1/(1−C)} − 1) / (f A(φ)), with f A(φ) = cos²φ/s_x² + sin²φ/s_y².
        let fa = (c / self.sx).powi(2) + (s / self.sy).powi(2);
        let t = (self.radius2(u[1]) / fa).sqrt();
        normal_from_slopes(t * c, t * s)
    }

    /// The squared standardized slope radius of eq 12 / 42: (1 − u)^{1/(1−C)} − 1, evaluated
    /// as expm1(−ln(1 − u)/(C − 1)) so that it keeps its relative accuracy for large C and
    /// small u.
    #[inline]
    fn radius2(&self, u: f64) -> f64 {
        (-(-u).ln_1p() / (self.c - 1.0)).exp_m1()
    }
}

fn member_family(member: Member) -> &'static str {
    match member {
        Member::Std => "std",
        Member::HyperCauchy => "hyper_cauchy",
        Member::FixedVariance => "student_fixed_variance",
        Member::General => "student_general",
    }
}

impl Ndf for Student {
    fn d(&self, m: Vec3) -> f64 {
        let mz = m[2];
        if mz <= 0.0 {
            return 0.0;
        }
        let z2 = mz * mz;
        // tan²θ (cos²φ/s_x² + sin²φ/s_y²) = (m_x²/s_x² + m_y²/s_y²)/m_z²
        let t = ((m[0] / self.sx).powi(2) + (m[1] / self.sy).powi(2)) / z2;
        // (1 + t)^(−C) / cos⁴θ in logarithms: exact for large C and t, no overflow of 1/m_z⁴.
        let ln = -self.c * t.ln_1p() - 2.0 * z2.ln();
        self.p22_norm * ln.exp()
    }
}

impl Smith for Student {
    fn lambda(&self, w: Vec3) -> f64 {
        let x = self.standardized_cotangent(w);
        lambda_both_hemispheres(x, |x| routes::lambda_stable(self.c, x))
    }

    fn lambda_routes(&self) -> Vec<&'static str> {
        routes::ROUTES.iter().map(|r| r.0).collect()
    }

    fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
        let x = self.standardized_cotangent(w);
        let f = routes::route(route, self.c)?;
        Ok(lambda_both_hemispheres(x, |x| f(self.c, x)))
    }
}

impl NormalSampler for Student {
    /// Seed 001 eq 11–12 / 40–42 in slope space, with the quadrant of φ fixed (ERRATA.md):
    /// the slope is √r (s_x cos 2πu₁, s_y sin 2πu₁) with r = (1 − u₂)^{1/(1−C)} − 1.
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let (dx, dy) = elliptic_direction(self.sx, self.sy, u[0]);
        let r = self.radius2(u[1]).sqrt();
        normal_from_slopes(r * dx, r * dy)
    }
}

impl SlopeDistribution for Student {
    fn p22(&self, p: f64, q: f64) -> f64 {
        let t = (p / self.sx).powi(2) + (q / self.sy).powi(2);
        self.p22_norm * (-self.c * t.ln_1p()).exp()
    }

    fn p2(&self, q: f64, phi: f64) -> f64 {
        let s = scale_along(self.sx, self.sy, phi);
        self.p2_norm / s * ((0.5 - self.c) * (q / s).powi(2).ln_1p()).exp()
    }

    /// Seed 001 eq 7 with Γ(C−1)/Γ(C−1−k) = ∏_{j=1..k} (C−1−j) and Γ(k+½)/√π = (2k−1)!!/2^k,
    /// exact for every C (no Γ of large arguments).
    fn slope_moment(&self, k: u32, phi: f64) -> Option<f64> {
        if !(self.c > 1.0 + k as f64) {
            return None;
        }
        let s2 = scale_along(self.sx, self.sy, phi).powi(2);
        Some((1..=k).fold(1.0, |acc, j| {
            acc * s2 * (2 * j - 1) as f64 / (2.0 * (self.c - 1.0 - j as f64))
        }))
    }
}

impl Model for Student {
    fn spec(&self) -> ModelSpec {
        let (alpha, alpha_x, alpha_y) = if self.alpha_x == self.alpha_y {
            (Some(self.alpha_x), None, None)
        } else {
            (None, Some(self.alpha_x), Some(self.alpha_y))
        };
        let gamma = self.c;
        match self.member {
            Member::Std => ModelSpec::Std {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            },
            Member::HyperCauchy => ModelSpec::HyperCauchy {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            },
            Member::FixedVariance => ModelSpec::StudentFixedVariance {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            },
            Member::General => ModelSpec::StudentGeneral {
                b: 1.0 / (self.sx * self.sx),
                c: self.c,
            },
        }
    }

    fn family(&self) -> &'static str {
        member_family(self.member)
    }

    fn as_smith(&self) -> Option<&dyn Smith> {
        (self.c > 1.5).then_some(self as &dyn Smith)
    }

    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        Some(self)
    }

    fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
        Some(self)
    }
}
