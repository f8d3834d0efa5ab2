//! Reference microfacet BSDFs: a rough conductor (reflection only) and a rough dielectric
//! (reflection and refraction) after Walter, Marschner, Li & Torrance 2007, "Microfacet models
//! for refraction through rough surfaces" (EGSR 2007; document 001 cites it as \[13\]; "Walter" below),
//! built on any NDF that has a Smith Λ, and the [`Bsdf`] capability a renderer's own BSDF
//! implements to be audited the same way.
//!
//! # Conventions
//!
//! - **Frame.** Local shading frame, macro-normal n = +z pointing to the *outside* medium;
//!   directions are unit vectors pointing *away* from the surface; monochrome (one channel).
//! - **Arguments.** `wi` is the direction the query comes from (the camera side of a path traced
//!   from the camera, Mitsuba's and Falcor's `wi`), `wo` the other one (toward the light for a
//!   camera path). Both may lie in either hemisphere; `wi_z = 0` or `wo_z = 0` (exactly grazing)
//!   evaluates to 0.
//! - **`eval(wi, wo)`** = f(wi, wo) · |cos θo|, the BSDF times the cosine at `wo` (Mitsuba's
//!   and Falcor's `eval`), so that ∫ eval dωo is the albedo and `weight = eval / pdf`.
//! - **`pdf(wi, wo)`** is the solid-angle density of the `wo` that `sample(wi, ·)` returns.
//!   Where `sample` fails (a reflected or refracted direction on the wrong side of the surface, a
//!   back-facing sampled normal, a non-finite input) no direction is returned, so
//!   ∫ pdf dωo = 1 − (probability of failure) ≤ 1.
//! - **Relative index.** `eta()` = η_inside / η_outside (`None`: reflection only). The index on
//!   `wi`'s side is η_i (1 if wi_z > 0, else η), the one on `wo`'s side η_o.
//! - **Sides of a reflector.** A reflection-only BSDF is one-sided by default: 0 for wi_z < 0
//!   (a conductor seen from below is black). A two-sided one ([`Bsdf::two_sided`], Mitsuba's
//!   `twosided` wrapper, a renderer's conductor that mirrors wi below the surface) evaluates
//!   (wi, wo) with wi_z < 0 as its front side evaluates (wi', wo') with z negated in both
//!   ([`TwoSided`]): it reflects into the hemisphere of wi, from either side.
//! - **Below the horizon: D and Λ.** D(m) = 0 for m_z ≤ 0 (microfacet normals face out). An
//!   NDF's Λ(w) is asked only for w_z > 0. A BSDF needs the masking of a direction below the
//!   surface too (transmission, incidence from inside): the reference BSDFs evaluate it as
//!   Λ(w⁺), w⁺ = −w for w_z < 0 (the microsurface seen from below; [`microfacet`]'s module
//!   documentation). Smith's Λ continued below the horizon obeys Λ(−w) = −1 − Λ(w) (the
//!   relation Heitz, Hanika, d'Eon & Dachsbacher 2016, "Multiple-scattering microfacet BSDFs
//!   with the Smith model", use for downward directions); mfh never asks for that
//!   continuation (an external child's `lambda` is asked only for w_z > 0), and the masking
//!   of a downward direction in a BSDF is Λ(w⁺), not the continued Λ(w).
//! - **The sample map and its u.** `sample(wi, u)`: `u[0]` chooses the lobe (a dielectric
//!   reflects when u\[0\] < F(wi·m), the Fresnel reflectance of the sampled normal m, and
//!   refracts otherwise); `u[1]`, `u[2]` draw the microfacet normal, by convention of the
//!   reference samplers: visible normals (Heitz 2018, polar disk map): `u[1]` is the *radial*
//!   coordinate (disk radius √u\[1\]) and `u[2]` the azimuth 2π u\[2\]; normals (Walter 2007 in
//!   slope space): `u[1]` the azimuth 2π u\[1\] and `u[2]` the *polar* coordinate (slope radius
//!   from u\[2\]). A renderer's map may differ (a concentric disk map, the other u order, its own
//!   tangent frame): only the distribution of `wo` is a property of the BSDF, so mfh compares
//!   sampled directions for the same u only with a BSDF that declares the reference map
//!   ([`Bsdf::reference_map`]).
//! - **A failed sample.** `sample` returns `None` (through the external protocol: pdf 0 and
//!   weight 0, wo ignored) where it produces no direction: a reflected or refracted direction on
//!   the wrong side, a back-facing normal, a non-finite input. A sample of pdf 0 is a failed
//!   sample too. The failure probability is 1 − ∫ pdf dωo.
//!
//! # Transport convention
//!
//! Walter's BTDF (eq 21), written with i = wi and o = wo,
//!
//! ```text
//! W(wi, wo) = |wi·h||wo·h| / (|wi·n||wo·n|)
//!             · η_o² (1 − F(wi, h)) G(wi, wo, h) D(h) / (η_i(wi·h) + η_o(wo·h))²
//! ```
//!
//! obeys W(wi, wo)/η_o² = W(wo, wi)/η_i² (the numerator other than η_o² and the denominator are
//! symmetric in (wi, η_i) ↔ (wo, η_o), and so is F's transmittance). Two conventions are in use:
//!
//! - [`Transport::Importance`]: f(wi, wo) = W(wi, wo), Walter's eq 21 exactly as printed. It
//!   transports importance from the camera side (or radiance in the direction wi → wo): no η²
//!   factor in the sampling weight, and ∫ eval dωo ≤ 1 from both sides.
//!   Reciprocity: f(wi, wo)/η_o² = f(wo, wi)/η_i².
//! - [`Transport::Radiance`]: f(wi, wo) = W(wi, wo) · (η_i/η_o)² = W(wo, wi): the BTDF that
//!   carries radiance arriving along `wo` to `wi` (light from the other medium is compressed
//!   into the smaller solid angle of the denser one), as pbrt-v4 and Mitsuba 3 evaluate in their
//!   radiance mode (Veach 1997, §5.2: radiance scales as η²). Reciprocity:
//!   f(wi, wo)/η_i² = f(wo, wi)/η_o². ∫ eval dωo may exceed 1 when η_i > η_o.
//!
//! Reflection (Walter eq 20) is the same in both conventions and reciprocal:
//! f(wi, wo) = f(wo, wi).
//!
//! # What is built where
//!
//! - [`fresnel`]: exact dielectric Fresnel (Walter eq 22), exact conductor Fresnel of a complex
//!   index, Schlick's approximation.
//! - [`microfacet`]: D, the Smith G1/G2 of both hemispheres, and the samplers of microfacet
//!   normals (by normals, by visible normals, document 001's pseudo-VNIS) with their densities.
//! - [`conductor`] and [`dielectric`]: the BSDFs.
//! - [`spec`]: the serde description `{"bsdf": "dielectric", "eta": 1.5, "ndf": {...}, …}`,
//!   validated with typed errors, built into `Arc<dyn Bsdf>`.
//! - [`error`]: `BsdfError`, naming the field and the limit.
//! - `directions.rs`: [`Directions`], the sampled directions of `Bsdf::sample_wo_batch` as
//!   separate x, y, z and flag arrays, so that the scatter and the chi-square's cell finder load
//!   whole vectors.
//! - `fresnel_block.rs` and `scatter_block.rs`: the batch forms of the dielectric's and
//!   conductor's sampled directions (Fresnel of a block of cosines; lobe choice and scatter),
//!   bit for bit the scalar ones on every dispatch path.

pub mod conductor;
pub mod dielectric;
pub mod directions;
pub mod error;
pub mod fresnel;
pub mod fresnel_block;
pub mod microfacet;
mod scatter_block;
pub mod spec;
mod two_sided;

#[cfg(test)]
mod direction_tests;
#[cfg(test)]
mod golden_tests;
#[cfg(test)]
mod tests;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use directions::{Directions, DirectionsMut};
pub use error::BsdfError;
pub use fresnel::FresnelModel;
pub use microfacet::{Microfacet, Sampling};
pub use spec::{BsdfSpec, ConductorSpec, DielectricSpec};
pub use two_sided::TwoSided;

use crate::geometry::Vec3;

/// A sampled direction: `wo`, its density `pdf` = [`Bsdf::pdf`]`(wi, wo)` (> 0) and
/// `weight` = [`Bsdf::eval`]`(wi, wo) / pdf`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction (unit, either hemisphere).
    pub wo: Vec3,
    /// The solid-angle density of `wo`.
    pub pdf: f64,
    /// eval(wi, wo) / pdf(wi, wo).
    pub weight: f64,
}

impl BsdfSample {
    /// The sample at `wo` from eval and pdf evaluated there (so the three agree to the last
    /// bit); `None` where the pdf is 0 (a direction the BSDF cannot sample is a failed sample).
    pub fn at(wo: Vec3, (value, pdf): (f64, f64)) -> Option<Self> {
        (pdf > 0.0).then(|| Self {
            wo,
            pdf,
            weight: value / pdf,
        })
    }
}

/// The transport convention of a transmitting BSDF (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Transport {
    /// f(wi, wo) = Walter's eq 21 with i = wi, o = wo: f(wi, wo)/η_o² = f(wo, wi)/η_i².
    Importance,
    /// Walter's eq 21 times (η_i/η_o)², η_i the index on wi's side (pbrt-v4, Mitsuba 3):
    /// f(wi, wo)/η_i² = f(wo, wi)/η_o².
    #[default]
    Radiance,
}

impl Transport {
    /// The name used in specs and in the external protocol (`radiance`, `importance`).
    pub fn name(self) -> &'static str {
        match self {
            Transport::Importance => "importance",
            Transport::Radiance => "radiance",
        }
    }

    /// The factor by which this convention multiplies Walter's eq 21 (W(wi, wo)) for the
    /// indices `eta_i` on wi's side and `eta_o` on wo's side: 1 or (η_i/η_o)².
    pub fn factor(self, eta_i: f64, eta_o: f64) -> f64 {
        match self {
            Transport::Importance => 1.0,
            Transport::Radiance => (eta_i / eta_o).powi(2),
        }
    }
}

/// A BSDF in the local shading frame (normal +z, pointing outside), monochrome: the capability
/// a renderer's BSDF implements to be audited, and what the reference BSDFs implement. See the
/// module documentation for the conventions (which direction is which, the cosine in `eval`,
/// the relative index, the transport convention).
///
/// ```
/// use mfh_reference::bsdf::{Bsdf, BsdfSpec};
/// let spec: BsdfSpec = serde_json::from_str(
///     r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},
///         "masking":"height_correlated","sampling":"visible_normals"}"#,
/// ).unwrap();
/// let b = spec.build().unwrap();
/// let wi = [0.6, 0.0, 0.8];
/// let s = b.sample(wi, [0.7, 0.3, 0.6]).unwrap();
/// assert!((s.pdf - b.pdf(wi, s.wo)).abs() <= 1e-12 * s.pdf);
/// assert!((s.weight - b.eval(wi, s.wo) / s.pdf).abs() <= 1e-12 * s.weight);
/// assert_eq!(b.eta(), Some(1.5));
/// ```
pub trait Bsdf: Send + Sync {
    /// f(wi, wo) · |cos θo| (0 where the BSDF is 0, for non-finite or exactly grazing
    /// directions; never NaN).
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64;

    /// The solid-angle density of the `wo` that [`Bsdf::sample`] returns for `wi` (0 where it
    /// never returns one).
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64;

    /// A direction `wo` for `wi` from `u ∈ [0, 1)³`: `u[0]` chooses the lobe, `u[1..]` the
    /// microfacet normal. `None` for a failed sample (no direction; its probability is
    /// 1 − ∫ pdf dωo).
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample>;

    /// `(eval(wi, wo), pdf(wi, wo))` in one call (the reference BSDFs share the half vector,
    /// D, Λ and Fresnel between the two).
    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        (self.eval(wi, wo), self.pdf(wi, wo))
    }

    /// The relative index η = η_inside / η_outside of a transmitting BSDF; `None` for a
    /// reflection-only one (the default).
    fn eta(&self) -> Option<f64> {
        None
    }

    /// The transport convention of the transmission lobe (default [`Transport::Radiance`];
    /// without transmission it changes nothing).
    fn transport(&self) -> Transport {
        Transport::Radiance
    }

    /// Whether a reflection-only BSDF reflects from both sides (default `false`: black from
    /// below). A two-sided one evaluates and samples (wi, wo) with wi_z < 0 as (wi', wo') with
    /// z negated in both ([`TwoSided`]); it is audited from below too. Meaningless for a
    /// transmitting BSDF (`eta()` is `Some`), which has both sides anyway.
    fn two_sided(&self) -> bool {
        false
    }

    /// The reference sampler whose map u ↦ wo [`Bsdf::sample`] reproduces, if any (default
    /// `None`: the BSDF's own map). A BSDF that declares `Some(s)` promises the reference
    /// BSDF's map with sampling `s` (see the module documentation, *The sample map and its
    /// u*), and `bsdf.against` then compares its sampled direction with the reference's for the
    /// same u; otherwise only what the map's distribution determines is compared (eval and pdf
    /// at the sampled directions, and the chi-square of `bsdf.chi2`).
    fn reference_map(&self) -> Option<Sampling> {
        None
    }

    /// `out[k] = self.eval(wi[k], wo[k])` (the default loops over [`Bsdf::eval`]).
    ///
    /// # Panics
    /// If `wi`, `wo` and `out` differ in length.
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        assert!(
            wi.len() == wo.len() && wo.len() == out.len(),
            "eval_batch: wi, wo and out differ in length"
        );
        for ((o, &a), &b) in out.iter_mut().zip(wi).zip(wo) {
            *o = self.eval(a, b);
        }
    }

    /// `out[k] = self.pdf(wi[k], wo[k])` (the default loops over [`Bsdf::pdf`]).
    ///
    /// # Panics
    /// If `wi`, `wo` and `out` differ in length.
    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        assert!(
            wi.len() == wo.len() && wo.len() == out.len(),
            "pdf_batch: wi, wo and out differ in length"
        );
        for ((o, &a), &b) in out.iter_mut().zip(wi).zip(wo) {
            *o = self.pdf(a, b);
        }
    }

    /// `out[k] = self.sample(wi, u[k])` at one incidence (the default loops over
    /// [`Bsdf::sample`]).
    ///
    /// # Panics
    /// If `u` and `out` differ in length.
    fn sample_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut [Option<BsdfSample>]) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_batch: u and out differ in length"
        );
        for (o, &u) in out.iter_mut().zip(u) {
            *o = self.sample(wi, u);
        }
    }

    /// The directions alone of [`Bsdf::sample_batch`]: element k of `out` = the `wo` of
    /// `self.sample(wi, u[k])`, a failed sample for a failed sample or one of pdf 0. A
    /// chi-square of the sampled directions needs nothing else, so an implementation may skip
    /// the pdf and weight of each sample here (the reference BSDFs do: their Fresnel, D, Λ and
    /// Jacobians are most of a sample's cost), provided it returns the same directions (the
    /// reference BSDFs do to the ulps their batch normal samplers document, within 1e-12 a
    /// component: `reference/src/bsdf/direction_tests.rs`). The default calls
    /// [`Bsdf::sample_batch`] (one request of an external BSDF) and keeps the `wo`.
    ///
    /// # Panics
    /// If `u` and `out` differ in length.
    fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
        assert_eq!(
            u.len(),
            out.len(),
            "sample_wo_batch: u and out differ in length"
        );
        let mut samples = vec![None; u.len()];
        self.sample_batch(wi, u, &mut samples);
        for (k, s) in samples.into_iter().enumerate() {
            out.set(k, s.filter(|s: &BsdfSample| s.pdf > 0.0).map(|s| s.wo));
        }
    }
}

/// A reference to a BSDF is the BSDF (so `Arc<dyn Bsdf>`, `Box<T>` and `&T` audit as `T`).
macro_rules! delegate_bsdf {
    ($($ptr:ty),*) => {$(
        impl<T: Bsdf + ?Sized> Bsdf for $ptr {
            fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
                (**self).eval(wi, wo)
            }
            fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
                (**self).pdf(wi, wo)
            }
            fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
                (**self).sample(wi, u)
            }
            fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
                (**self).eval_pdf(wi, wo)
            }
            fn eta(&self) -> Option<f64> {
                (**self).eta()
            }
            fn transport(&self) -> Transport {
                (**self).transport()
            }
            fn two_sided(&self) -> bool {
                (**self).two_sided()
            }
            fn reference_map(&self) -> Option<Sampling> {
                (**self).reference_map()
            }
            fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
                (**self).eval_batch(wi, wo, out)
            }
            fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
                (**self).pdf_batch(wi, wo, out)
            }
            fn sample_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut [Option<BsdfSample>]) {
                (**self).sample_batch(wi, u, out)
            }
            fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
                (**self).sample_wo_batch(wi, u, out)
            }
        }
    )*};
}
delegate_bsdf!(&T, Box<T>, std::sync::Arc<T>);

/// Whether every component is finite.
#[inline]
pub(crate) fn finite(w: Vec3) -> bool {
    w.iter().all(|c| c.is_finite())
}

/// `x` if finite, else 0 (an overflowing D at α = 1e-7 must not leak ∞).
#[inline]
pub(crate) fn finite_or_zero(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// `s · v`.
#[inline]
pub(crate) fn scale(s: f64, v: Vec3) -> Vec3 {
    [s * v[0], s * v[1], s * v[2]]
}
