//! Mutants: a reference model behind a wrapper that injects one defect into one quantity
//! (never a source edit of the reference). The wrapper has exactly the capabilities of the
//! model it wraps; every quantity the defect does not touch is delegated unchanged, except G1
//! and G2, which are the trait's own forms over the (possibly mutated) Λ — as a renderer
//! derives them.

use mfh_reference::model::{
    Model, NormalSampler, SlopeDistribution, VisibleMoments, VisibleNormalSampler,
    VisibleSlopeMoments,
};
use mfh_reference::sg::Sg;
use mfh_reference::{Masking, ModelSpec, Ndf, QueryError, Smith, Vec3};
use serde::Serialize;

/// One defect, in the quantity it corrupts. Relative sizes are fractions (0.01 = 1 %).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Defect {
    /// D multiplied by 1 + `e` everywhere (a normalization constant off).
    DScale {
        /// The relative error.
        e: f64,
    },
    /// D multiplied by 1 + `e` where θ_m > `theta` only (the tail).
    DScaleAbove {
        /// Where the error starts (radians).
        theta: f64,
        /// The relative error.
        e: f64,
    },
    /// D with α_x and α_y swapped (evaluated at (m_y, m_x, m_z)).
    DAxesSwapped,
    /// D is NaN at exactly m = n (a 0/0 at θ = 0).
    DNanAtNormal,
    /// Λ multiplied by 1 + `e` where θ > `theta` (wrong only towards grazing).
    LambdaScaleAbove {
        /// Where the error starts (radians).
        theta: f64,
        /// The relative error.
        e: f64,
    },
    /// Λ multiplied by 1 + `e` where 0 < θ < `theta` (wrong in the near-normal branch only).
    LambdaScaleBelow {
        /// Where the error stops (radians).
        theta: f64,
        /// The relative error.
        e: f64,
    },
    /// Below the horizon Λ(w) = Λ(−w) instead of −1 − Λ(−w) (the lower branch dropped).
    LambdaLowerBranch,
    /// Λ with α_x and α_y swapped.
    LambdaAxesSwapped,
    /// Λ is NaN at exactly θ = 0.
    LambdaNanAtNormal,
    /// Λ recovered from G1 as 1/G1 − 1: the absolute rounding of 1 + Λ (≈ 1e-16) swamps the
    /// small Λ near normal incidence (precision lost).
    LambdaViaG1,
    /// The height-correlated G2 replaced by the uncorrelated product G1·G1.
    G2Uncorrelated,
    /// The uncorrelated G2 replaced by the height-correlated form.
    G2CorrelatedForUncorrelated,
    /// The sampled tan²θ raised to the power 1 + `e` about the roughness `scale`:
    /// tan²θ' = scale² (tan²θ / scale²)^{1+e} (a sampler's radius exponent off).
    SamplerExponent {
        /// The roughness the exponent is taken about.
        scale: f64,
        /// The relative error of the exponent.
        e: f64,
    },
    /// The sampled azimuth halved: φ covers half the circle.
    SamplerHalfPhi,
    /// The sampled normal with x and y swapped.
    SamplerAxesSwapped,
    /// The sampled normal mirrored below the horizon when u₁ = 0 exactly.
    SamplerBelowHorizonAtU0,
    /// pdf_wm multiplied by 1 + `e` (a pdf that disagrees with its sampler).
    PdfScale {
        /// The relative error.
        e: f64,
    },
    /// pdf_wm = D(m) without the cosine m·n.
    PdfMissingCosine,
    /// The visible-normal sampler ignores the incidence: it samples D(m)(m·n).
    VisibleIgnoresIncidence,
    /// The visible-normal sampler uses θi scaled by 1 + `e`.
    VisibleWrongIncidence {
        /// The relative error of θi.
        e: f64,
    },
    /// Heitz's GGX visible-normal sampler with its tangent frame switched to the fixed axis
    /// T1 = (1, 0, 0) where the stretched incidence is within `within` of the normal
    /// (V_h,z ≥ 1 − `within`, as a renderer shipped it: that axis is not orthogonal to V_h, so
    /// the map's density departs from the stated pdf by ≈ V_h's tilt).
    VisibleFrameSwitch {
        /// How near the normal (1 − V_h,z) the frame switches.
        within: f64,
    },
    /// Heitz's GGX visible-normal sampler with the stretched normal's height clamped at
    /// `floor` (max(`floor`, N_h,z) where the listing has max(0, N_h,z)): the normals near the
    /// stretched horizon are moved up, the pdf is not.
    VisibleHeightClamp {
        /// The clamp.
        floor: f64,
    },
    /// pdf_wm_visible multiplied by 1 + `e`.
    VisiblePdfScale {
        /// The relative error.
        e: f64,
    },
    /// The slope moments ν₂ₖ multiplied by 1 + `e`.
    SlopeMomentScale {
        /// The relative error.
        e: f64,
    },
    /// D_s: the cross covariance dropped (cov_xy = 0).
    DsCrossDropped,
    /// D_s: E₁ with its sign flipped (document 002 eq 59 as printed, through eq 61–69).
    DsE1Flipped,
    /// D_s: the mean multiplied by 1 + `e`.
    DsMeanScale {
        /// The relative error.
        e: f64,
    },
    /// The SG vector product's amplitude multiplied by 1 + `e` (not a model defect: applied
    /// by [`sg_product`]).
    SgProductAmplitude {
        /// The relative error.
        e: f64,
    },
}

/// The SG vector product G₁ ⊗ G₂ (document 003 §1) with `defect` applied.
pub fn sg_product(a: &Sg, b: &Sg, defect: Defect) -> Sg {
    let p = a.product(b);
    match defect {
        Defect::SgProductAmplitude { e } => {
            Sg::new(p.axis(), p.sharpness(), p.amplitude() * (1.0 + e)).unwrap_or(p)
        }
        _ => p,
    }
}

/// A reference model with one [`Defect`].
pub struct Mutated {
    base: Box<dyn Model>,
    defect: Defect,
}

impl std::fmt::Debug for Mutated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mutated")
            .field("base", &self.base.spec())
            .field("defect", &self.defect)
            .finish()
    }
}

/// Heitz's GGX visible-normal sampler (Heitz 2018, JCGT 7(4), Listing 1; u₀ the radius, u₁
/// the angle, as mfh's reference) written out with two regime defects: the tangent frame
/// T1 = (1, 0, 0) where 1 − V_h,z ≤ `within` (0: only at exactly normal incidence, the
/// listing's `lensq > 0` test), and the stretched normal's height clamped at `floor` (0: the
/// listing's max(0, ·)).
fn heitz_visible((ax, ay): (f64, f64), wi: Vec3, u: [f64; 2], within: f64, floor: f64) -> Vec3 {
    let norm = |v: Vec3| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    };
    let vh = norm([ax * wi[0], ay * wi[1], wi[2]]);
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if lensq > 0.0 && 1.0 - vh[2] > within {
        [-vh[1] / lensq.sqrt(), vh[0] / lensq.sqrt(), 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t2 = [
        vh[1] * t1[2] - vh[2] * t1[1],
        vh[2] * t1[0] - vh[0] * t1[2],
        vh[0] * t1[1] - vh[1] * t1[0],
    ];
    let r = u[0].sqrt();
    let (sp, cp) = (std::f64::consts::TAU * u[1]).sin_cos();
    let p1 = r * cp;
    let s = 0.5 * (1.0 + vh[2]);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sp;
    let lift = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh = [
        p1 * t1[0] + p2 * t2[0] + lift * vh[0],
        p1 * t1[1] + p2 * t2[1] + lift * vh[1],
        p1 * t1[2] + p2 * t2[2] + lift * vh[2],
    ];
    norm([ax * nh[0], ay * nh[1], nh[2].max(floor)])
}

/// θ of a direction (radians).
fn theta_of(w: Vec3) -> f64 {
    w[0].hypot(w[1]).atan2(w[2])
}

fn swap(m: Vec3) -> Vec3 {
    [m[1], m[0], m[2]]
}

impl Mutated {
    /// The model of `spec` with `defect`.
    pub fn new(spec: &ModelSpec, defect: Defect) -> Result<Self, mfh_reference::ParamError> {
        Ok(Self {
            base: spec.build()?,
            defect,
        })
    }

    /// The defect.
    pub fn defect(&self) -> Defect {
        self.defect
    }

    /// (αx, αy) of the base spec (1, 1 where it has none).
    fn alphas(&self) -> (f64, f64) {
        let spec = serde_json::to_value(self.base.spec()).unwrap_or_default();
        let get = |k: &str| spec.get(k).and_then(serde_json::Value::as_f64);
        let a = get("alpha").unwrap_or(1.0);
        (get("alpha_x").unwrap_or(a), get("alpha_y").unwrap_or(a))
    }

    fn base_smith(&self) -> Option<&dyn Smith> {
        self.base.as_smith()
    }

    fn base_sampler(&self) -> Option<&dyn NormalSampler> {
        self.base.as_sampler()
    }
}

impl Ndf for Mutated {
    fn d(&self, m: Vec3) -> f64 {
        match self.defect {
            Defect::DScale { e } => self.base.d(m) * (1.0 + e),
            Defect::DScaleAbove { theta, e } if theta_of(m) > theta => self.base.d(m) * (1.0 + e),
            Defect::DAxesSwapped => self.base.d(swap(m)),
            Defect::DNanAtNormal if m[0] == 0.0 && m[1] == 0.0 => f64::NAN,
            _ => self.base.d(m),
        }
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        self.base.as_smith().map(|_| self as &dyn Smith)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        self.base.as_sampler().map(|_| self as &dyn NormalSampler)
    }
    fn as_visible_sampler(&self) -> Option<&dyn VisibleNormalSampler> {
        self.base
            .as_visible_sampler()
            .map(|_| self as &dyn VisibleNormalSampler)
    }
    fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
        self.base
            .as_slopes()
            .map(|_| self as &dyn SlopeDistribution)
    }
    fn as_visible_moments(&self) -> Option<&dyn VisibleSlopeMoments> {
        self.base
            .as_visible_moments()
            .map(|_| self as &dyn VisibleSlopeMoments)
    }
}

impl Smith for Mutated {
    fn lambda(&self, w: Vec3) -> f64 {
        let Some(s) = self.base_smith() else {
            return f64::NAN;
        };
        match self.defect {
            Defect::LambdaScaleAbove { theta, e } if w[2] > 0.0 && theta_of(w) > theta => {
                s.lambda(w) * (1.0 + e)
            }
            Defect::LambdaScaleBelow { theta, e }
                if w[2] > 0.0 && theta_of(w) < theta && theta_of(w) > 0.0 =>
            {
                s.lambda(w) * (1.0 + e)
            }
            Defect::LambdaLowerBranch if w[2] < 0.0 => s.lambda([-w[0], -w[1], -w[2]]),
            Defect::LambdaAxesSwapped => s.lambda(swap(w)),
            Defect::LambdaNanAtNormal if w[0] == 0.0 && w[1] == 0.0 => f64::NAN,
            Defect::LambdaViaG1 => {
                let g1 = 1.0 / (1.0 + s.lambda(w));
                1.0 / g1 - 1.0
            }
            _ => s.lambda(w),
        }
    }

    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3, masking: Masking) -> f64 {
        let masking = match (self.defect, masking) {
            (Defect::G2Uncorrelated, Masking::HeightCorrelated) => Masking::Uncorrelated,
            (Defect::G2CorrelatedForUncorrelated, Masking::Uncorrelated) => {
                Masking::HeightCorrelated
            }
            (_, m) => m,
        };
        mfh_reference::model::smith_g2(self, wo, wi, m, masking)
    }
}

impl NormalSampler for Mutated {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        let Some(s) = self.base_sampler() else {
            return [f64::NAN; 3];
        };
        let m = s.sample_wm(u);
        match self.defect {
            Defect::SamplerExponent { scale, e } => {
                let r = m[0].hypot(m[1]);
                if !(r > 0.0 && m[2] > 0.0) {
                    return m;
                }
                let t2 = (r / m[2]).powi(2);
                let t2 = scale * scale * (t2 / (scale * scale)).powf(1.0 + e);
                let t = t2.sqrt();
                let n = (1.0 + t2).sqrt();
                [m[0] / r * t / n, m[1] / r * t / n, 1.0 / n]
            }
            Defect::SamplerHalfPhi => {
                let r = m[0].hypot(m[1]);
                let phi = m[1].atan2(m[0]).rem_euclid(std::f64::consts::TAU) / 2.0;
                [r * phi.cos(), r * phi.sin(), m[2]]
            }
            Defect::SamplerAxesSwapped => swap(m),
            Defect::SamplerBelowHorizonAtU0 if u[0] == 0.0 => [m[0], m[1], -m[2]],
            _ => m,
        }
    }

    fn pdf_wm(&self, m: Vec3) -> f64 {
        let Some(s) = self.base_sampler() else {
            return f64::NAN;
        };
        match self.defect {
            Defect::PdfScale { e } => s.pdf_wm(m) * (1.0 + e),
            Defect::PdfMissingCosine if m[2] > 0.0 => self.base.d(m),
            _ => s.pdf_wm(m),
        }
    }
}

impl VisibleNormalSampler for Mutated {
    fn sample_wm_visible(&self, wi: Vec3, u: [f64; 2]) -> Vec3 {
        let Some(v) = self.base.as_visible_sampler() else {
            return [f64::NAN; 3];
        };
        match self.defect {
            Defect::VisibleIgnoresIncidence => self.sample_wm(u),
            Defect::VisibleWrongIncidence { e } => {
                let (theta, phi) = (theta_of(wi) * (1.0 + e), wi[1].atan2(wi[0]));
                let w = mfh_reference::geometry::from_spherical(theta, phi);
                v.sample_wm_visible(w, u)
            }
            Defect::VisibleFrameSwitch { within } => {
                heitz_visible(self.alphas(), wi, u, within, 0.0)
            }
            Defect::VisibleHeightClamp { floor } => heitz_visible(self.alphas(), wi, u, 0.0, floor),
            _ => v.sample_wm_visible(wi, u),
        }
    }

    fn pdf_wm_visible(&self, wi: Vec3, m: Vec3) -> f64 {
        let Some(v) = self.base.as_visible_sampler() else {
            return f64::NAN;
        };
        match self.defect {
            Defect::VisiblePdfScale { e } => v.pdf_wm_visible(wi, m) * (1.0 + e),
            _ => v.pdf_wm_visible(wi, m),
        }
    }
}

impl SlopeDistribution for Mutated {
    fn p22(&self, p: f64, q: f64) -> f64 {
        self.base.as_slopes().map_or(f64::NAN, |s| s.p22(p, q))
    }
    fn p2(&self, q: f64, phi: f64) -> f64 {
        self.base.as_slopes().map_or(f64::NAN, |s| s.p2(q, phi))
    }
    fn slope_moment(&self, k: u32, phi: f64) -> Option<f64> {
        let m = self.base.as_slopes()?.slope_moment(k, phi)?;
        Some(match self.defect {
            Defect::SlopeMomentScale { e } => m * (1.0 + e),
            _ => m,
        })
    }
}

impl VisibleSlopeMoments for Mutated {
    fn visible_moments(&self, w: Vec3) -> Result<VisibleMoments, QueryError> {
        let v = self.base.as_visible_moments().ok_or(QueryError::Route {
            route: "default".into(),
            reason: "the base model has no visible moments".into(),
        })?;
        let mut m = match self.defect {
            Defect::DsE1Flipped => v.visible_moments_route(w, "equations_printed")?,
            _ => v.visible_moments(w)?,
        };
        match self.defect {
            Defect::DsCrossDropped => {
                m.cov[0][1] = 0.0;
                m.cov[1][0] = 0.0;
            }
            Defect::DsMeanScale { e } => {
                m.mean = [m.mean[0] * (1.0 + e), m.mean[1] * (1.0 + e)];
            }
            _ => {}
        }
        Ok(m)
    }
    // One route, the mutant's own: `default`.
}

/// The D_s mutants are audited through the D_s check, which plans reference models: the
/// mutant is a [`Model`] with the spec and family of its base (the check's oracle integrates
/// the spec, so it owes nothing to the mutant).
impl Model for Mutated {
    fn spec(&self) -> ModelSpec {
        self.base.spec()
    }
    fn family(&self) -> &'static str {
        self.base.family()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ggx() -> ModelSpec {
        serde_json::from_str(r#"{"family":"ggx","alpha":0.3}"#).unwrap()
    }

    #[test]
    fn a_mutant_changes_only_its_quantity() {
        let base = ggx().build().unwrap();
        let m = Mutated::new(&ggx(), Defect::DScale { e: 0.01 }).unwrap();
        let n = [0.1, 0.2, (1.0f64 - 0.05).sqrt()];
        assert!((m.d(n) / base.d(n) - 1.01).abs() < 1e-15);
        let s = base.as_smith().unwrap();
        assert_eq!(m.lambda(n), s.lambda(n));
        let u = [0.3, 0.7];
        assert_eq!(m.sample_wm(u), base.as_sampler().unwrap().sample_wm(u));
    }

    #[test]
    fn the_exponent_mutant_is_the_identity_at_zero_error() {
        let base = ggx().build().unwrap();
        let m = Mutated::new(&ggx(), Defect::SamplerExponent { scale: 0.3, e: 0.0 }).unwrap();
        for u in [[0.1, 0.2], [0.7, 0.9], [0.4, 0.5]] {
            let (a, b) = (m.sample_wm(u), base.as_sampler().unwrap().sample_wm(u));
            for i in 0..3 {
                assert!((a[i] - b[i]).abs() < 1e-14, "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn a_mutant_has_the_capabilities_of_its_base() {
        let gs: ModelSpec = serde_json::from_str(
            r#"{"family":"gaussian_slopes","mean":[0.1,-0.05],"cov":[[0.04,0.01],[0.01,0.09]]}"#,
        )
        .unwrap();
        let m = Mutated::new(&gs, Defect::DsCrossDropped).unwrap();
        assert!(m.as_visible_moments().is_some());
        assert!(m.as_sampler().is_none());
        let g = Mutated::new(&ggx(), Defect::DsCrossDropped).unwrap();
        assert!(g.as_visible_moments().is_none());
        assert!(g.as_sampler().is_some());
    }
}
