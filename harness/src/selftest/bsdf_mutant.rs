//! BSDF mutants: a reference BSDF behind a wrapper with one defect that renderer authors have
//! really shipped, for `mfh selftest` to prove the BSDF checks see it. Each defect is written
//! from Walter 2007's quantities (the half vectors of eq 13 and 16, the Jacobians of eq 14 and
//! 17, the Fresnel factor of eq 22, the visible-normal density's G1) recomputed at the arguments
//! the wrapper sees, and names the check that must catch it.

use mfh_reference::bsdf::fresnel;
use mfh_reference::bsdf::microfacet::reflection_half_vector;
use mfh_reference::bsdf::{Bsdf, BsdfSample, BsdfSpec, Transport};
use mfh_reference::geometry::{dot, Vec3};
use mfh_reference::Ndf;
use std::sync::Arc;

/// A defect of a BSDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BsdfDefect {
    /// `sample` returns a weight 1 % above eval/pdf.
    WeightOff,
    /// `pdf` of reflected directions without the reflection Jacobian 1/(4|wo·h|) (eq 14).
    ReflectionJacobianMissing,
    /// `pdf` of refracted directions without the refraction Jacobian (eq 17).
    RefractionJacobianMissing,
    /// `eval` of refraction with (η_o/η_i)² where the radiance convention has (η_i/η_o)².
    EtaSquaredInverted,
    /// `eval` of refraction without the radiance convention's (η_i/η_o)² (stated radiance).
    EtaSquaredMissing,
    /// `pdf` weighs the lobes by F at cos θo instead of at wi·h.
    FresnelWrongCosineInPdf,
    /// Under total internal reflection `sample` fails instead of reflecting.
    TotalInternalReflectionLost,
    /// `eval` answers below the surface for a conductor (the side condition wo·n > 0 lost).
    SideConditionLostInEval,
    /// `sample` drops 1 % of its samples (u₀ in the top 1 %) although `pdf` counts them.
    SamplesLost,
    /// The visible-normal pdf without G1(wi) (`pdf` and the sample's pdf too large by 1/G1).
    G1MissingInVisiblePdf,
    /// `eval(wi, wo)` answers f(wo, wi) (the arguments swapped).
    ArgumentsSwapped,
    /// `eval` is NaN at a degenerate half vector (wo = −wi).
    NanAtDegenerateHalfVector,
    /// `eval` 2 % too large for reflection (a Fresnel or G2 factor off), `sample` unchanged.
    ReflectionValueOff,
    /// `sample` decides total internal reflection 1e-3 rad before the critical angle (the
    /// angle between wi and m above θc − 1e-3 reflects), `pdf` at the true θc.
    TotalInternalReflectionEarly,
}

impl BsdfDefect {
    /// Every defect.
    pub const ALL: [BsdfDefect; 14] = [
        BsdfDefect::WeightOff,
        BsdfDefect::ReflectionJacobianMissing,
        BsdfDefect::RefractionJacobianMissing,
        BsdfDefect::EtaSquaredInverted,
        BsdfDefect::EtaSquaredMissing,
        BsdfDefect::FresnelWrongCosineInPdf,
        BsdfDefect::TotalInternalReflectionLost,
        BsdfDefect::SideConditionLostInEval,
        BsdfDefect::SamplesLost,
        BsdfDefect::G1MissingInVisiblePdf,
        BsdfDefect::ArgumentsSwapped,
        BsdfDefect::NanAtDegenerateHalfVector,
        BsdfDefect::ReflectionValueOff,
        BsdfDefect::TotalInternalReflectionEarly,
    ];

    /// The mutant's id.
    pub fn id(self) -> &'static str {
        match self {
            BsdfDefect::WeightOff => "bsdf_weight_off",
            BsdfDefect::ReflectionJacobianMissing => "bsdf_reflection_jacobian_missing",
            BsdfDefect::RefractionJacobianMissing => "bsdf_refraction_jacobian_missing",
            BsdfDefect::EtaSquaredInverted => "bsdf_eta_squared_inverted",
            BsdfDefect::EtaSquaredMissing => "bsdf_eta_squared_missing",
            BsdfDefect::FresnelWrongCosineInPdf => "bsdf_fresnel_wrong_cosine_in_pdf",
            BsdfDefect::TotalInternalReflectionLost => "bsdf_total_internal_reflection_lost",
            BsdfDefect::SideConditionLostInEval => "bsdf_side_condition_lost_in_eval",
            BsdfDefect::SamplesLost => "bsdf_samples_lost",
            BsdfDefect::G1MissingInVisiblePdf => "bsdf_g1_missing_in_visible_pdf",
            BsdfDefect::ArgumentsSwapped => "bsdf_arguments_swapped",
            BsdfDefect::NanAtDegenerateHalfVector => "bsdf_nan_at_degenerate_half_vector",
            BsdfDefect::ReflectionValueOff => "bsdf_reflection_value_off",
            BsdfDefect::TotalInternalReflectionEarly => "bsdf_total_internal_reflection_early",
        }
    }

    /// The reference BSDF the mutant wraps: the GGX dielectric (η = 1.5, α = 0.3, visible
    /// normals, radiance) for the defects of refraction and the lobe choice, the GGX conductor
    /// for those of reflection alone.
    pub fn base(self) -> BsdfSpec {
        let text = match self {
            BsdfDefect::SideConditionLostInEval | BsdfDefect::ReflectionValueOff => {
                r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"ggx","alpha":0.3}}"#
            }
            _ => r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#,
        };
        serde_json::from_str(text).expect("a valid spec")
    }

    /// The checks that must catch it (any one of them).
    pub fn killers(self) -> &'static [&'static str] {
        match self {
            BsdfDefect::WeightOff => &["bsdf.sample_consistency"],
            BsdfDefect::ReflectionJacobianMissing
            | BsdfDefect::RefractionJacobianMissing
            | BsdfDefect::FresnelWrongCosineInPdf
            | BsdfDefect::G1MissingInVisiblePdf => &["bsdf.chi2"],
            BsdfDefect::EtaSquaredInverted
            | BsdfDefect::EtaSquaredMissing
            | BsdfDefect::ArgumentsSwapped => &["bsdf.reciprocity"],
            BsdfDefect::TotalInternalReflectionLost | BsdfDefect::SamplesLost => {
                &["bsdf.failure_rate"]
            }
            BsdfDefect::SideConditionLostInEval => &["bsdf.stability", "bsdf.albedo"],
            BsdfDefect::NanAtDegenerateHalfVector => &["bsdf.stability"],
            BsdfDefect::ReflectionValueOff => &["bsdf.albedo", "bsdf.sample_consistency"],
            BsdfDefect::TotalInternalReflectionEarly => &["bsdf.jacobian"],
        }
    }
}

/// A reference BSDF with one defect.
pub struct MutatedBsdf {
    base: Arc<dyn Bsdf>,
    ndf: Box<dyn Ndf>,
    defect: BsdfDefect,
}

impl MutatedBsdf {
    /// The mutant of `defect` over its base.
    pub fn new(defect: BsdfDefect) -> Self {
        let spec = defect.base();
        Self {
            base: spec.build().expect("a valid spec"),
            ndf: Box::new(spec.ndf().build().expect("a valid NDF")),
            defect,
        }
    }

    fn eta(&self) -> f64 {
        self.base.eta().unwrap_or(1.0)
    }

    /// (η_i, η_o): the indices on wi's and wo's sides.
    fn indices(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        let index = |w: Vec3| if w[2] > 0.0 { 1.0 } else { self.eta() };
        (index(wi), index(wo))
    }

    /// The half vector of (wi, wo) with h_z > 0 (eq 13 or 16), if any.
    fn half(&self, wi: Vec3, wo: Vec3) -> Option<Vec3> {
        let h = if wi[2] * wo[2] > 0.0 {
            reflection_half_vector(wi, wo)?.0
        } else {
            let (ni, no) = self.indices(wi, wo);
            let v = [
                ni * wi[0] + no * wo[0],
                ni * wi[1] + no * wo[1],
                ni * wi[2] + no * wo[2],
            ];
            let len = dot(v, v).sqrt();
            if !(len > 0.0) {
                return None;
            }
            [-v[0] / len, -v[1] / len, -v[2] / len]
        };
        Some(if h[2] < 0.0 { [-h[0], -h[1], -h[2]] } else { h })
    }

    /// The Fresnel reflectance at cosine `c` from wi's side.
    fn fresnel(&self, wi: Vec3, c: f64) -> f64 {
        let eta = if wi[2] > 0.0 {
            self.eta()
        } else {
            1.0 / self.eta()
        };
        fresnel::dielectric(c.abs(), eta).reflectance
    }

    /// [`BsdfDefect::TotalInternalReflectionEarly`]: a refracted sample whose normal m makes
    /// an angle with wi above θc − 1e-3 (from the denser side) reflected about m instead.
    fn reflected_early(&self, wi: Vec3, s: BsdfSample) -> Option<BsdfSample> {
        let (ni, no) = self.indices(wi, s.wo);
        if wi[2] * s.wo[2] > 0.0 || ni <= no {
            return Some(s);
        }
        let h = self.half(wi, s.wo)?;
        let c = dot(wi, h);
        if c.abs().min(1.0).acos() <= (no / ni).asin() - 1e-3 {
            return Some(s);
        }
        let wo = [
            2.0 * c * h[0] - wi[0],
            2.0 * c * h[1] - wi[1],
            2.0 * c * h[2] - wi[2],
        ];
        if !(wo[2] * wi[2] > 0.0) {
            return None;
        }
        BsdfSample::at(wo, (self.eval(wi, wo), self.pdf(wi, wo)))
    }

    /// The factor by which the mutant's pdf differs from the base's at (wi, wo).
    fn pdf_factor(&self, wi: Vec3, wo: Vec3) -> f64 {
        let reflection = wi[2] * wo[2] > 0.0;
        let Some(h) = self.half(wi, wo) else {
            return 1.0;
        };
        match self.defect {
            BsdfDefect::ReflectionJacobianMissing if reflection => 4.0 * dot(wo, h).abs(),
            BsdfDefect::RefractionJacobianMissing if !reflection => {
                let (ni, no) = self.indices(wi, wo);
                let v = [
                    ni * wi[0] + no * wo[0],
                    ni * wi[1] + no * wo[1],
                    ni * wi[2] + no * wo[2],
                ];
                dot(v, v) / (no * no * dot(wo, h).abs())
            }
            BsdfDefect::FresnelWrongCosineInPdf => {
                let right = self.fresnel(wi, dot(wi, h));
                let wrong = self.fresnel(wi, wi[2]);
                if reflection {
                    wrong / right
                } else {
                    (1.0 - wrong) / (1.0 - right)
                }
            }
            BsdfDefect::G1MissingInVisiblePdf => {
                let up = if wi[2] < 0.0 {
                    [-wi[0], -wi[1], -wi[2]]
                } else {
                    wi
                };
                let lambda = self.ndf.as_smith().map_or(0.0, |s| s.lambda(up));
                1.0 + lambda
            }
            _ => 1.0,
        }
    }
}

impl Bsdf for MutatedBsdf {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        let reflection = wi[2] * wo[2] > 0.0;
        let (ni, no) = self.indices(wi, wo);
        match self.defect {
            BsdfDefect::EtaSquaredInverted if !reflection => {
                self.base.eval(wi, wo) * (no / ni).powi(4)
            }
            BsdfDefect::EtaSquaredMissing if !reflection => {
                self.base.eval(wi, wo) * (no / ni).powi(2)
            }
            BsdfDefect::SideConditionLostInEval if wo[2] < 0.0 => {
                self.base.eval(wi, [wo[0], wo[1], -wo[2]])
            }
            BsdfDefect::ArgumentsSwapped => {
                self.base.eval(wo, wi) / wi[2].abs().max(f64::MIN_POSITIVE) * wo[2].abs()
            }
            BsdfDefect::NanAtDegenerateHalfVector
                if wi[0] + wo[0] == 0.0 && wi[1] + wo[1] == 0.0 && wi[2] + wo[2] == 0.0 =>
            {
                f64::NAN
            }
            BsdfDefect::ReflectionValueOff if reflection => 1.02 * self.base.eval(wi, wo),
            _ => self.base.eval(wi, wo),
        }
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.base.pdf(wi, wo) * self.pdf_factor(wi, wo)
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        if self.defect == BsdfDefect::SamplesLost && u[0] >= 0.99 {
            return None;
        }
        let s = self.base.sample(wi, u)?;
        match self.defect {
            BsdfDefect::WeightOff => Some(BsdfSample {
                weight: 1.01 * s.weight,
                ..s
            }),
            BsdfDefect::TotalInternalReflectionLost => {
                // Reflected although the sampler drew refraction only where F = 1.
                let h = self.half(wi, s.wo)?;
                let f = self.fresnel(wi, dot(wi, h));
                (f < 1.0).then_some(s)
            }
            BsdfDefect::ReflectionValueOff => Some(s),
            BsdfDefect::TotalInternalReflectionEarly => self.reflected_early(wi, s),
            BsdfDefect::SideConditionLostInEval | BsdfDefect::NanAtDegenerateHalfVector => Some(s),
            _ => {
                // The sample's pdf and weight as this mutant's pdf and eval give them.
                let (value, pdf) = (self.eval(wi, s.wo), self.pdf(wi, s.wo));
                BsdfSample::at(s.wo, (value, pdf))
            }
        }
    }

    fn eta(&self) -> Option<f64> {
        self.base.eta()
    }

    fn transport(&self) -> Transport {
        self.base.transport()
    }
}
