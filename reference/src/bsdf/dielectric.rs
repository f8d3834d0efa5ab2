//! The rough dielectric of Walter 2007: microfacet reflection and refraction at an interface
//! of relative index η = η_inside/η_outside, lit from either side, with total internal
//! reflection.

use super::microfacet::{reflection_half_vector, Microfacet, SUB_BLOCK};
use super::{finite, finite_or_zero, Bsdf, BsdfError, BsdfSample, Directions, Transport};
use super::{fresnel, scatter_block};
use crate::geometry::{dot, Vec3};

/// The smallest and largest relative index accepted, and the least |η − 1|: at η = 1 the
/// refraction lobe is a delta (wo = −wi), and it narrows as |η − 1| (its width in wo is about
/// |η − 1| times the roughness), so that no density-based check can resolve it below 5e-5.
/// η = 1.0001 and its inverse 0.99990001 are accepted.
pub const ETA_MIN: f64 = 0.1;
/// See [`ETA_MIN`].
pub const ETA_MAX: f64 = 10.0;
/// See [`ETA_MIN`].
pub const ETA_MIN_GAP: f64 = 5e-5;

/// A rough dielectric after Walter 2007 (section and equation numbers are the paper's):
///
/// ```text
/// reflection (wi·n)(wo·n) > 0:
///   h_r = sign(wi·n)(wi + wo) / |wi + wo|                                      (eq 13)
///   f_r = F(wi, h_r) G(wi, wo, h_r) D(h_r) / (4 |wi·n| |wo·n|)                 (eq 20)
///   ∂ω_h/∂ω_o = 1/(4 |wo·h_r|)                                                  (eq 14)
/// refraction (wi·n)(wo·n) < 0, η_i, η_o the indices on wi's and wo's sides:
///   h_t = −(η_i wi + η_o wo) / |η_i wi + η_o wo|, taken with h_t·n > 0           (eq 16)
///   f_t = |wi·h||wo·h|/(|wi·n||wo·n|)
///         · η_o² (1 − F(wi, h)) G D(h) / (η_i(wi·h) + η_o(wo·h))²               (eq 21)
///   ∂ω_h/∂ω_o = η_o² |wo·h| / (η_i(wi·h) + η_o(wo·h))²                          (eq 17)
/// F: Walter eq 22 at c = |wi·h| and η_t/η_i (fresnel::dielectric); G: microfacet.rs.
/// side conditions (the χ⁺ of G, Walter §3 and eq 23): (wi·h)(wi·n) > 0 and (wo·h)(wo·n) > 0.
/// ```
///
/// The refraction denominator is evaluated as |η_i wi + η_o wo|², the same number
/// (η_i(wi·h) + η_o(wo·h) = −|η_i wi + η_o wo| for the unflipped h_t) without the cancellation
/// of the two dot products; the reflection cosines |wi·h_r| = |wo·h_r| as |wi + wo|/2; the
/// transmittance 1 − F(wi, h_t), which equals 1 − F(wo, h_t), from the side of the smaller
/// index (well conditioned near the critical angle of the other side). So f(wo, wi) is computed
/// from the same numbers as f(wi, wo), and the reciprocity relations hold to rounding. `eval`
/// is f · |wo·n| in the stated [`Transport`] (f_t as above for `Importance`, times (η_i/η_o)²
/// for `Radiance`).
///
/// Sampling (Walter §5.3): m from the [`Microfacet`]'s sampler at wi⁺; with F = F(wi, m),
/// reflect about m if u₀ < F, else refract through m (F = 1 under total internal reflection);
/// a direction on the wrong side of the surface fails. The density of wo is
///
/// ```text
/// pdf(wo) = F(wi, h_r) p_m(h_r) / (4|wo·h_r|)                               (reflection)
/// pdf(wo) = (1 − F(wi, h_t)) p_m(h_t) η_o²|wo·h_t| / |η_i wi + η_o wo|²      (refraction)
/// ```
///
/// with p_m the sampler's density of m, 0 where the side conditions fail. `sample` returns
/// pdf(wi, wo) and eval(wi, wo)/pdf(wi, wo) recomputed at the sampled wo (so the three agree to
/// the last bit).
#[derive(Debug, Clone)]
pub struct Dielectric {
    eta: f64,
    microfacet: Microfacet,
    transport: Transport,
}

impl Dielectric {
    /// A rough dielectric of relative index `eta` (η_inside/η_outside, in
    /// [[`ETA_MIN`], [`ETA_MAX`]] and |η − 1| ≥ [`ETA_MIN_GAP`]) on `microfacet`.
    pub fn new(eta: f64, microfacet: Microfacet, transport: Transport) -> Result<Self, BsdfError> {
        check_eta(eta)?;
        Ok(Self {
            eta,
            microfacet,
            transport,
        })
    }

    /// The microfacet part.
    pub fn microfacet(&self) -> &Microfacet {
        &self.microfacet
    }

    /// (index on `w`'s side): 1 above the surface, η below.
    #[inline]
    fn index(&self, w: Vec3) -> f64 {
        if w[2] > 0.0 {
            1.0
        } else {
            self.eta
        }
    }

    /// The direction `sample` scatters wi into through the sampled normal m, the lobe chosen
    /// by `u0` against the Fresnel reflectance at wi·m (§5.3): reflected (eq 39) or
    /// refracted (eq 40); `None` unless finite, off the surface and on the chosen lobe's side.
    #[inline]
    fn scattered(&self, wi: Vec3, m: Vec3, u0: f64) -> Option<Vec3> {
        let other = self.other(wi);
        let fr = fresnel::dielectric(dot(wi, m), other);
        let (wo, ok) = scatter_block::scatter_lane(wi, m, u0, other, (fr.reflectance, fr.cos_t));
        ok.then_some(wo)
    }

    /// The index of the far side over wi's: η from outside, 1/η from inside.
    #[inline]
    fn other(&self, wi: Vec3) -> f64 {
        if wi[2] > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        }
    }

    /// eval and pdf together: the half vector, D, G, F and the Jacobian once.
    fn evaluate(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        let (ci, co) = (wi[2], wo[2]);
        if !finite(wi) || !finite(wo) || ci == 0.0 || co == 0.0 {
            return (0.0, 0.0);
        }
        let mf = &self.microfacet;
        let eta_i = self.index(wi);
        let eta_o = self.index(wo);
        if ci * co > 0.0 {
            // Reflection, eq 13.
            let Some((m, len)) = reflection_half_vector(wi, wo) else {
                return (0.0, 0.0);
            };
            let (cim, com) = (dot(wi, m), dot(wo, m));
            if !(m[2] > 0.0) || !(cim * ci > 0.0) || !(com * co > 0.0) {
                return (0.0, 0.0);
            }
            // |wi·h| = |wo·h| = |wi + wo|/2: one number for both, symmetric in (wi, wo).
            let c = 0.5 * len;
            let other = if ci > 0.0 { self.eta } else { 1.0 / self.eta };
            let f = fresnel::dielectric(c, other).reflectance;
            let d = mf.d(m);
            let g = mf.g2(wi, wo, m);
            // eq 20 times |wo·n|; eq 14.
            let value = f * g * d / (4.0 * ci.abs());
            let pdf = f * mf.pdf_m(wi, m) / (4.0 * c);
            (finite_or_zero(value), finite_or_zero(pdf))
        } else {
            // Refraction, eq 16 (h flipped to the outside).
            let v = [
                eta_i * wi[0] + eta_o * wo[0],
                eta_i * wi[1] + eta_o * wo[1],
                eta_i * wi[2] + eta_o * wo[2],
            ];
            let len2 = dot(v, v);
            let len = len2.sqrt();
            if !(len > 0.0) {
                return (0.0, 0.0);
            }
            let s = if v[2] > 0.0 { 1.0 / len } else { -1.0 / len };
            let m = [s * v[0], s * v[1], s * v[2]];
            let (cim, com) = (dot(wi, m), dot(wo, m));
            if !(m[2] > 0.0) || !(cim * ci > 0.0) || !(com * co > 0.0) {
                return (0.0, 0.0);
            }
            // 1 − F(wi, h) = 1 − F(wo, h) (Fresnel transmittance is the same both ways);
            // evaluated from the side of the smaller index, where it is well conditioned (from
            // the denser side it is not near the critical angle), and so the same number for
            // (wi, wo) and (wo, wi).
            let t = if eta_i < eta_o {
                fresnel::dielectric(cim, eta_o / eta_i)
            } else {
                fresnel::dielectric(com, eta_i / eta_o)
            }
            .transmittance;
            if !(t > 0.0) {
                return (0.0, 0.0);
            }
            let d = mf.d(m);
            let g = mf.g2(wi, wo, m);
            // eq 17 with (η_i(wi·h) + η_o(wo·h))² = |v|².
            let jacobian = eta_o * eta_o * com.abs() / len2;
            // eq 21 times |wo·n|.
            let value =
                cim.abs() * t * g * d * jacobian / ci.abs() * self.transport.factor(eta_i, eta_o);
            let pdf = t * mf.pdf_m(wi, m) * jacobian;
            (finite_or_zero(value), finite_or_zero(pdf))
        }
    }
}

/// Validates a relative index (field `eta`).
pub(crate) fn check_eta(eta: f64) -> Result<f64, BsdfError> {
    if !(ETA_MIN..=ETA_MAX).contains(&eta) {
        return Err(BsdfError::OutOfRange {
            field: "eta",
            requirement: "finite and in [0.1, 10]",
            value: eta,
        });
    }
    if !((eta - 1.0).abs() >= ETA_MIN_GAP) {
        return Err(BsdfError::OutOfRange {
            field: "eta",
            requirement: "at least 5e-5 away from 1 (at η = 1 refraction is a delta, wo = −wi)",
            value: eta,
        });
    }
    Ok(eta)
}

impl Bsdf for Dielectric {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.evaluate(wi, wo).0
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.evaluate(wi, wo).1
    }

    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        self.evaluate(wi, wo)
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        if !finite(wi) || wi[2] == 0.0 {
            return None;
        }
        let m = self.microfacet.sample_m(wi, [u[1], u[2]])?;
        let wo = self.scattered(wi, m, u[0])?;
        BsdfSample::at(wo, self.evaluate(wi, wo))
    }

    /// The directions of [`Bsdf::sample`] without its eval and pdf: the normals by the
    /// model's batch sampler, then the Fresnel choice and the reflection or refraction.
    fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wo_batch: u and out differ in length"
        );
        if !finite(wi) || wi[2] == 0.0 {
            return out.fail_all();
        }
        // Sub-blocks on the stack: the normals, then their tests and the scatter in one pass.
        let mut m = [[0.0; 3]; SUB_BLOCK];
        let other = self.other(wi);
        for (u, out) in u.chunks(SUB_BLOCK).zip(out.as_mut().chunks(SUB_BLOCK)) {
            let m = &mut m[..u.len()];
            match self.microfacet.sample_m_unchecked(wi, u, m) {
                Some(v) => scatter_block::scatter_block((wi, v), other, u, m, out),
                None => out.sampled.fill(false),
            }
        }
    }

    fn eta(&self) -> Option<f64> {
        Some(self.eta)
    }

    fn reference_map(&self) -> Option<super::Sampling> {
        Some(self.microfacet.sampling())
    }

    fn transport(&self) -> Transport {
        self.transport
    }
}
