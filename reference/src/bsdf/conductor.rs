//! The rough conductor: Walter 2007's microfacet reflection with the Fresnel term of a complex
//! index n + ik (exact, or Schlick's approximation), one-sided (lit from outside only).

use super::fresnel::{self, FresnelModel};
use super::microfacet::{reflection_half_vector, Microfacet, SUB_BLOCK};
use super::scatter_block;
use super::{finite, finite_or_zero, Bsdf, BsdfError, BsdfSample, Directions};
use crate::geometry::{dot, Vec3};

/// The largest n and k accepted (measured metals have n, k < 15 in the visible; the bound only
/// keeps (n² + k²)² finite and far from overflow).
pub const NK_MAX: f64 = 100.0;
/// The smallest n accepted.
pub const N_MIN: f64 = 1e-3;

/// A rough conductor (Walter 2007, reflection only):
///
/// ```text
/// h = (wi + wo)/|wi + wo|                                      (eq 13, wi·n > 0)
/// f = F(|wi·h|) G(wi, wo, h) D(h) / (4 (wi·n)(wo·n))          (eq 20)
/// pdf(wo) = p_m(h) / (4 |wo·h|)                                (eq 14)
/// ```
///
/// F is [`fresnel::conductor`] (exact) or [`fresnel::schlick`]; G and p_m are the
/// [`Microfacet`]'s. Zero unless wi·n > 0, wo·n > 0 and both see h from its front. `sample`
/// ignores u₀ (one lobe), reflects wi about the sampled m and fails when wo·n ≤ 0.
#[derive(Debug, Clone)]
pub struct Conductor {
    n: f64,
    k: f64,
    fresnel: FresnelModel,
    microfacet: Microfacet,
}

impl Conductor {
    /// A rough conductor of complex index `n` + i`k` relative to the outside medium
    /// (n ∈ [[`N_MIN`], [`NK_MAX`]], k ∈ [0, [`NK_MAX`]]) on `microfacet`.
    pub fn new(
        n: f64,
        k: f64,
        fresnel: FresnelModel,
        microfacet: Microfacet,
    ) -> Result<Self, BsdfError> {
        check_nk(n, k)?;
        Ok(Self {
            n,
            k,
            fresnel,
            microfacet,
        })
    }

    /// The microfacet part.
    pub fn microfacet(&self) -> &Microfacet {
        &self.microfacet
    }

    /// F at incidence cosine `c` on the microfacet.
    pub fn fresnel(&self, c: f64) -> f64 {
        match self.fresnel {
            FresnelModel::Exact => fresnel::conductor(c, self.n, self.k),
            FresnelModel::Schlick => fresnel::schlick(c, self.n, self.k),
        }
    }

    fn evaluate(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        if !finite(wi) || !finite(wo) || !(wi[2] > 0.0) || !(wo[2] > 0.0) {
            return (0.0, 0.0);
        }
        let Some((m, len)) = reflection_half_vector(wi, wo) else {
            return (0.0, 0.0);
        };
        let (cim, com) = (dot(wi, m), dot(wo, m));
        if !(cim > 0.0) || !(com > 0.0) {
            return (0.0, 0.0);
        }
        let mf = &self.microfacet;
        // |wi·h| = |wo·h| = |wi + wo|/2, symmetric in (wi, wo).
        let c = 0.5 * len;
        let value = self.fresnel(c) * mf.g2(wi, wo, m) * mf.d(m) / (4.0 * wi[2]);
        let pdf = mf.pdf_m(wi, m) / (4.0 * c);
        (finite_or_zero(value), finite_or_zero(pdf))
    }
}

/// Validates a complex index (fields `n` and `k`).
pub(crate) fn check_nk(n: f64, k: f64) -> Result<(), BsdfError> {
    if !(N_MIN..=NK_MAX).contains(&n) {
        return Err(BsdfError::OutOfRange {
            field: "n",
            requirement: "finite and in [1e-3, 100]",
            value: n,
        });
    }
    if !(0.0..=NK_MAX).contains(&k) {
        return Err(BsdfError::OutOfRange {
            field: "k",
            requirement: "finite and in [0, 100]",
            value: k,
        });
    }
    Ok(())
}

impl Bsdf for Conductor {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.evaluate(wi, wo).0
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.evaluate(wi, wo).1
    }

    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        self.evaluate(wi, wo)
    }

    fn reference_map(&self) -> Option<super::Sampling> {
        Some(self.microfacet.sampling())
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        if !finite(wi) || !(wi[2] > 0.0) {
            return None;
        }
        let m = self.microfacet.sample_m(wi, [u[1], u[2]])?;
        let wo = reflected(wi, m)?;
        BsdfSample::at(wo, self.evaluate(wi, wo))
    }

    /// The directions of [`Bsdf::sample`] without its eval and pdf: the normals by the
    /// model's batch sampler, then the reflection.
    fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wo_batch: u and out differ in length"
        );
        if !finite(wi) || !(wi[2] > 0.0) {
            return out.fail_all();
        }
        // Sub-blocks on the stack: the normals, then their tests and the reflection in one
        // vectorized pass.
        let mut m = [[0.0; 3]; SUB_BLOCK];
        for (u, out) in u.chunks(SUB_BLOCK).zip(out.as_mut().chunks(SUB_BLOCK)) {
            let m = &mut m[..u.len()];
            match self.microfacet.sample_m_unchecked(wi, u, m) {
                Some(v) => scatter_block::reflect_block((wi, v), m, out),
                None => out.sampled.fill(false),
            }
        }
    }
}

/// wi reflected about the sampled normal m, `None` unless finite and above the surface.
#[inline]
fn reflected(wi: Vec3, m: Vec3) -> Option<Vec3> {
    let (wo, ok) = scatter_block::reflect_lane(wi, m);
    ok.then_some(wo)
}
