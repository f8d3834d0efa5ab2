//! The microfacet part shared by the reference BSDFs: D, the Smith G1 and G2 of directions in
//! either hemisphere, and the sampler of microfacet normals with its density.
//!
//! **Directions below the surface.** The NDF describes the normals m of the interface (m_z > 0,
//! pointing outside). A direction w with w_z < 0 sees the same microsurface from below: flipping
//! the height field (z → −z) turns it into a microsurface seen from above whose slopes are
//! negated, so that its Λ at the flipped direction is the original Λ at −w. So every Λ and every
//! visible-normal query here is made at
//!
//! ```text
//! w⁺ = w if w_z > 0, −w if w_z < 0
//! ```
//!
//! (the point reflection, which equals the mirror (w_x, w_y, −w_z) for the centrally symmetric
//! NDFs — all elliptic ones — and is the right one for those with a mean slope). With it
//! (Walter 2007 eq 23, and the Smith G1 and G2 of Heitz 2014, "Understanding the
//! masking-shadowing function in microfacet-based BRDFs", JCGT 3(2), §5 and §6, as document 001
//! eq 16, 22 and 23 print them for reflection):
//!
//! ```text
//! G1(w, m)         = χ⁺((w·m)/(w·n)) / (1 + Λ(w⁺))
//! G2 uncorrelated  = G1(wi, m) G1(wo, m)              (Walter eq 23; document 001 eq 22)
//! G2 height-corr.  = χ⁺((wi·m)/(wi·n)) χ⁺((wo·m)/(wo·n)) / (1 + Λ(wi⁺) + Λ(wo⁺))
//!                                                      (Heitz 2014 §6; document 001 eq 23)
//! ```
//!
//! The height-correlated form is used for refraction too, as pbrt-v4 does. Heitz 2014 §6.2
//! derives a different height-correlated G2 for transmission, B(1 + Λ(wi⁺), 1 + Λ(wo⁺)) (the
//! Beta function: one ray must escape above the facet's height, the other below); that form is
//! not implemented here.
//!
//! **Sampling** of m, for an incidence `wi` from either side (the density is that of m; the
//! BSDFs turn it into a density of wo by Walter's Jacobians):
//!
//! - [`Sampling::Normals`]: m ∼ D(m)(m·n) (the NDF's `sample_wm`; Walter §5.3); a sampled m with
//!   wi⁺·m ≤ 0 (back-facing, which no refraction or reflection of wi can use) fails.
//! - [`Sampling::VisibleNormals`]: m ∼ D_{wi⁺}(m) = G1(wi⁺, m)⟨wi⁺·m⟩ D(m)/(wi⁺·n) (Heitz &
//!   d'Eon 2014, eq 2; the NDF's `sample_wm_visible` at wi⁺).
//! - [`Sampling::PseudoVnis`]: document 001 §7.2's pseudo-VNIS for the STD (Algorithm 1 picks GGX's
//!   or Beckmann's visible normals, or the STD's own normals, with the STD's roughness;
//!   `ndf::student_vnis`), with the density of the proxy it picked in closed form, so that the
//!   BSDF's weight eval/pdf is unbiased (not eq 43's printed G2/G1, which assumes the STD's own
//!   visible normals).

use std::sync::Arc;

use super::{finite, scale, BsdfError};
use crate::geometry::{dot, Vec3};
use crate::model::{Masking, Ndf};
use crate::ndf::student_vnis::PseudoVnis;

/// How a BSDF samples microfacet normals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// m ∼ D(m)(m·n).
    Normals,
    /// m ∼ the distribution of normals visible from wi⁺ (Heitz & d'Eon 2014).
    #[default]
    VisibleNormals,
    /// Document 001 §7.2's pseudo-VNIS (STD only).
    PseudoVnis,
}

impl Sampling {
    /// The name used in specs (`normals`, `visible_normals`, `pseudo_vnis`).
    pub fn name(self) -> &'static str {
        match self {
            Sampling::Normals => "normals",
            Sampling::VisibleNormals => "visible_normals",
            Sampling::PseudoVnis => "pseudo_vnis",
        }
    }
}

/// An NDF with a Smith Λ, a masking form and a sampler of normals: the microfacet part of a
/// reference BSDF. See the module documentation for the formulas.
#[derive(Clone)]
pub struct Microfacet {
    ndf: Arc<dyn Ndf>,
    label: String,
    masking: Masking,
    sampling: Sampling,
    pseudo: Option<Arc<PseudoVnis>>,
}

impl std::fmt::Debug for Microfacet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Microfacet")
            .field("ndf", &self.label)
            .field("masking", &self.masking)
            .field("sampling", &self.sampling)
            .finish()
    }
}

/// w⁺: `w`, or −w below the horizon (see the module documentation).
#[inline]
pub fn upper(w: Vec3) -> Vec3 {
    if w[2] < 0.0 {
        scale(-1.0, w)
    } else {
        w
    }
}

impl Microfacet {
    /// The microfacet part of a BSDF on `ndf` (called `label` in errors, e.g. its family), with
    /// G2 in the form `masking`, sampling normals by `sampling`. Errors: the NDF has no Smith Λ
    /// ([`BsdfError::NoSmith`]), or not the sampler asked for ([`BsdfError::NoSampler`];
    /// [`Sampling::PseudoVnis`] is built by [`Microfacet::pseudo_vnis`] only).
    pub fn new(
        ndf: Arc<dyn Ndf>,
        label: &str,
        masking: Masking,
        sampling: Sampling,
    ) -> Result<Self, BsdfError> {
        if ndf.as_smith().is_none() {
            return Err(BsdfError::NoSmith {
                family: label.to_string(),
                reason: "the model has no Smith capability".to_string(),
            });
        }
        let missing = match sampling {
            Sampling::Normals => ndf
                .as_sampler()
                .is_none()
                .then_some("a normal sampler (sample_wm)"),
            Sampling::VisibleNormals => ndf
                .as_visible_sampler()
                .is_none()
                .then_some("a visible-normal sampler (sample_wm_visible)"),
            Sampling::PseudoVnis => {
                Some("to be the STD (seed 001 §7.2's pseudo-VNIS is for the STD)")
            }
        };
        if let Some(needs) = missing {
            return Err(BsdfError::NoSampler {
                sampling: sampling.name(),
                family: label.to_string(),
                needs,
            });
        }
        Ok(Self {
            ndf,
            label: label.to_string(),
            masking,
            sampling,
            pseudo: None,
        })
    }

    /// The microfacet part on the STD of the pseudo-VNIS `pv` (its target), sampling by the
    /// pseudo-VNIS.
    pub fn pseudo_vnis(pv: PseudoVnis, masking: Masking) -> Self {
        Self {
            ndf: Arc::new(pv.target().clone()),
            label: "std".to_string(),
            masking,
            sampling: Sampling::PseudoVnis,
            pseudo: Some(Arc::new(pv)),
        }
    }

    /// The NDF.
    pub fn ndf(&self) -> &dyn Ndf {
        &*self.ndf
    }

    /// The label given at construction (the family of a reference NDF).
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The masking form of G2.
    pub fn masking(&self) -> Masking {
        self.masking
    }

    /// How normals are sampled.
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// The pseudo-VNIS, when sampling by it.
    pub fn pseudo(&self) -> Option<&PseudoVnis> {
        self.pseudo.as_deref()
    }

    /// D(m) (0 for m_z ≤ 0).
    #[inline]
    pub fn d(&self, m: Vec3) -> f64 {
        self.ndf.d(m)
    }

    /// Λ(w⁺) (∞ for a grazing or non-finite w).
    pub fn lambda(&self, w: Vec3) -> f64 {
        if !(w[2] != 0.0) {
            return f64::INFINITY;
        }
        match self.ndf.as_smith() {
            Some(s) => s.lambda(upper(w)),
            None => f64::INFINITY,
        }
    }

    /// G1(w, m) = χ⁺((w·m)/(w·n)) / (1 + Λ(w⁺)), for w in either hemisphere.
    pub fn g1(&self, w: Vec3, m: Vec3) -> f64 {
        if !(dot(w, m) * w[2] > 0.0) {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(w))
    }

    /// G2(wi, wo, m) in this BSDF's masking form (module documentation).
    pub fn g2(&self, wi: Vec3, wo: Vec3, m: Vec3) -> f64 {
        match self.masking {
            Masking::Uncorrelated => self.g1(wi, m) * self.g1(wo, m),
            Masking::HeightCorrelated => {
                if !(dot(wi, m) * wi[2] > 0.0) || !(dot(wo, m) * wo[2] > 0.0) {
                    0.0
                } else {
                    1.0 / (1.0 + self.lambda(wi) + self.lambda(wo))
                }
            }
        }
    }

    /// The density (solid angle, over m) of [`Microfacet::sample_m`] for incidence `wi`:
    /// D(m)(m·n), D_{wi⁺}(m) or the pseudo-VNIS proxy's, and 0 where wi⁺·m ≤ 0 or m_z ≤ 0.
    pub fn pdf_m(&self, wi: Vec3, m: Vec3) -> f64 {
        let v = upper(wi);
        if !(v[2] > 0.0) || !(m[2] > 0.0) || !(dot(v, m) > 0.0) {
            return 0.0;
        }
        let p = match self.sampling {
            Sampling::Normals => self.ndf.as_sampler().map_or(0.0, |s| s.pdf_wm(m)),
            Sampling::VisibleNormals => self
                .ndf
                .as_visible_sampler()
                .map_or(0.0, |s| s.pdf_wm_visible(v, m)),
            Sampling::PseudoVnis => self.pseudo.as_ref().map_or(0.0, |p| p.pdf_wm(v, m)),
        };
        if p.is_finite() {
            p
        } else {
            0.0
        }
    }

    /// A microfacet normal for incidence `wi` (either side) from `u ∈ [0, 1)²`, or `None`
    /// where the sampler gives none usable: wi grazing or non-finite, a non-finite normal, or
    /// one with m_z ≤ 0 or wi⁺·m ≤ 0.
    pub fn sample_m(&self, wi: Vec3, u: [f64; 2]) -> Option<Vec3> {
        let v = upper(wi);
        if !(v[2] > 0.0) || !finite(v) {
            return None;
        }
        let m = match self.sampling {
            Sampling::Normals => self.ndf.as_sampler()?.sample_wm(u),
            Sampling::VisibleNormals => self.ndf.as_visible_sampler()?.sample_wm_visible(v, u),
            Sampling::PseudoVnis => self.pseudo.as_ref()?.sample_wm(v, u),
        };
        (finite(m) && m[2] > 0.0 && dot(v, m) > 0.0).then_some(m)
    }

    /// `out[k] = self.sample_m(wi, [u[k][1], u[k][2]])` for a block at one incidence (u's
    /// first component, the lobe choice, is not used), through the model's batch sampler
    /// ([`crate::model::NormalSampler::sample_wm_batch`],
    /// [`crate::model::VisibleNormalSampler::sample_wm_visible_batch`]: the scalar sampler's
    /// normals to the ulps each documents; the pseudo-VNIS one at a time).
    pub fn sample_m_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut [Option<Vec3>]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_m_batch: u and out differ in length"
        );
        // Sub-blocks on the stack: a heap buffer of a whole block (hundreds of kB) is mapped
        // and zeroed by the kernel at every call (measured: 39 % of a BSDF chi-square's time).
        let (mut m, mut ok) = ([[0.0; 3]; SUB_BLOCK], [false; SUB_BLOCK]);
        for (u, out) in u.chunks(SUB_BLOCK).zip(out.chunks_mut(SUB_BLOCK)) {
            let n = u.len();
            self.sample_m_sub_block(wi, u, &mut m[..n], &mut ok[..n]);
            for ((o, &m), &ok) in out.iter_mut().zip(&m[..n]).zip(&ok[..n]) {
                *o = ok.then_some(m);
            }
        }
    }

    /// [`Microfacet::sample_m_batch`] of at most [`SUB_BLOCK`] elements into `m[k]`, and
    /// whether it is a sample into `ok[k]`.
    ///
    /// # Panics
    /// If `u`, `m` and `ok` differ in length, or are longer than [`SUB_BLOCK`].
    fn sample_m_sub_block(&self, wi: Vec3, u: &[[f64; 3]], m: &mut [Vec3], ok: &mut [bool]) {
        assert_eq!(
            ok.len(),
            m.len(),
            "sample_m_sub_block: m and ok differ in length"
        );
        let Some(v) = self.sample_m_unchecked(wi, u, m) else {
            return ok.fill(false);
        };
        for (ok, m) in ok.iter_mut().zip(m.iter()) {
            *ok = normal_ok(v, *m);
        }
    }

    /// The sampler's normals of at most [`SUB_BLOCK`] elements into `m`, before the test of
    /// each ([`normal_ok`], which the caller makes): `Some(wi⁺)`, the incidence they are
    /// sampled at, or `None` if nothing is sampled (wi⁺ at or below the horizon or not
    /// finite, or no sampler of the kind asked), `m` then unspecified.
    ///
    /// # Panics
    /// If `u` and `m` differ in length, or are longer than [`SUB_BLOCK`].
    pub(crate) fn sample_m_unchecked(
        &self,
        wi: Vec3,
        u: &[[f64; 3]],
        m: &mut [Vec3],
    ) -> Option<Vec3> {
        let n = u.len();
        assert!(
            n <= SUB_BLOCK && m.len() == n,
            "sample_m_unchecked: u and m differ in length or exceed a sub-block"
        );
        let v = upper(wi);
        if !(v[2] > 0.0) || !finite(v) {
            return None;
        }
        let mut pairs = [[0.0; 2]; SUB_BLOCK];
        for (p, u) in pairs.iter_mut().zip(u) {
            *p = [u[1], u[2]];
        }
        let pairs = &pairs[..n];
        match self.sampling {
            Sampling::Normals => self.ndf.as_sampler()?.sample_wm_batch(pairs, m),
            Sampling::VisibleNormals => self
                .ndf
                .as_visible_sampler()?
                .sample_wm_visible_batch(v, pairs, m),
            Sampling::PseudoVnis => {
                let p = self.pseudo.as_ref()?;
                for (m, &u) in m.iter_mut().zip(pairs) {
                    *m = p.sample_wm(v, u);
                }
            }
        }
        Some(v)
    }
}

/// Whether the normal `m` sampled at incidence `v` (= wi⁺) is a sample, as `sample_m` decides:
/// finite, above the surface and facing v. Branch-free (`&`, not `&&`), for vector loops.
#[inline(always)]
pub(crate) fn normal_ok(v: Vec3, m: Vec3) -> bool {
    let finite = m[0].is_finite() & m[1].is_finite() & m[2].is_finite();
    finite & (m[2] > 0.0) & (dot(v, m) > 0.0)
}

/// The directions a batch method of the BSDFs handles at once on the stack.
pub(crate) const SUB_BLOCK: usize = 512;

/// The reflection half vector of Walter eq 13, h_r = sign(wi·n)(wi + wo)/|wi + wo| (on wi's
/// side of the surface), and |wi + wo|; `None` when wi + wo is 0 or not finite.
#[inline]
pub fn reflection_half_vector(wi: Vec3, wo: Vec3) -> Option<(Vec3, f64)> {
    let h = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    let len = dot(h, h).sqrt();
    if !(len > 0.0) || !len.is_finite() {
        return None;
    }
    let s = 1.0f64.copysign(wi[2]) / len;
    Some(([s * h[0], s * h[1], s * h[2]], len))
}

/// The mirror direction of `wi` about `m`: 2(wi·m)m − wi.
#[inline]
pub fn reflect(wi: Vec3, m: Vec3) -> Vec3 {
    let c = 2.0 * dot(wi, m);
    [c * m[0] - wi[0], c * m[1] - wi[1], c * m[2] - wi[2]]
}

/// The direction refracted from `wi` through the facet `m` into the far side, whose index over
/// wi's is `eta` (η_t/η_i), given the refracted cosine `cos_t` (from
/// [`super::fresnel::dielectric`]): with s = sign(wi·m) and e = 1/η,
///
/// ```text
/// t = −e wi + (e |wi·m| − cos_t) s m
/// ```
///
/// (tangential part −e times wi's, Snell's law; t·(s m) = −cos_t; |t| = 1).
#[inline]
pub fn refract(wi: Vec3, m: Vec3, eta: f64, cos_t: f64) -> Vec3 {
    let c = dot(wi, m);
    let e = 1.0 / eta;
    let k = (e * c.abs() - cos_t) * 1.0f64.copysign(c);
    [
        -e * wi[0] + k * m[0],
        -e * wi[1] + k * m[1],
        -e * wi[2] + k * m[2],
    ]
}
