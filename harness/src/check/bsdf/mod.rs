//! The checks of a whole BSDF (reflection and refraction, Fresnel, Jacobians, sample weights),
//! planned from the [`Bsdf`] capability alone, for mfh's reference BSDFs and a renderer's own:
//!
//! | check | file | oracle |
//! |---|---|---|
//! | `bsdf.chi2` | `chi2.rs` | sampled wo against `pdf` over the whole sphere ([`crate::oracle::chi2::sphere`]) |
//! | `bsdf.sample_consistency` | `consistency.rs` | the sample's pdf and weight against `pdf` and `eval/pdf` at its wo |
//! | `bsdf.failure_rate` | `consistency.rs` | the rate of failed samples against 1 − ∫ pdf (cubature) |
//! | `bsdf.albedo` | `albedo.rs` | ∫ eval by cubature against the mean sampled weight (Monte Carlo) |
//! | `bsdf.energy` | `albedo.rs` | ∫ eval ≤ 1 in the importance transport (radiance converted), at every incidence |
//! | `bsdf.reciprocity` | `reciprocity.rs` | f(wi, wo) against f(wo, wi) with the transport's η² |
//! | `bsdf.stability` | `stability.rs` | finite, non-negative, sampled where valued, at the hard cases |
//! | `bsdf.against` | `against.rs` | eval and pdf against a reference BSDF on a grid and in its lobes, the samples' pdf and weight at their wo, the wo for the same u where the BSDF declares the reference map |
//! | `bsdf.jacobian` | `jacobian.rs` | `pdf` against the density of `sample`'s map (u₁, u₂) ↦ wo, lobe by lobe, at a sweep of incidences (`check/regime.rs`) |
//! | `bsdf.ndf_consistency` | `ndf.rs` | eval (and a visible-normal pdf) against Walter's eq 20/21 from the BSDF's own D and Λ |
//!
//! Incidences ([`incidences`]): normal, oblique and grazing (cos θi = 0.05) from outside; for a
//! transmitting BSDF also from inside and beyond the critical angle on the denser side (total
//! internal reflection). Conventions (which direction is which, the cosine in `eval`, the
//! transport) are those of [`mfh_reference::bsdf`].

mod against;
#[cfg(test)]
mod against_tests;
mod albedo;
mod chi2;
mod consistency;
pub mod jacobian;
mod ndf;
mod reciprocity;
mod stability;

pub use against::plan_against;
pub use chi2::{table as chi2_table, RESOLUTION as CHI2_RESOLUTION};

use super::{PlannedCheck, Profile};
use crate::oracle::chi2::sphere::{
    chi2_masses_about, draw_chunks, expected_sphere_about, SphereMasses,
};
use crate::oracle::chi2::Expected;
use crate::oracle::hemisphere_grid::HemisphereGrid;
use crate::oracle::lobe_centres::lobe_centres;
use crate::oracle::Estimate;
use crate::subject::bsdf::BsdfSubject;
use mfh_reference::bsdf::{Bsdf, BsdfSample};
use mfh_reference::geometry::Vec3;
use serde_json::{json, Value};
use std::sync::{Arc, OnceLock};

/// The source every BSDF check cites.
pub const SOURCE: &str = "Walter et al. 2007 (seed 001 [13]) eq 13–23; Walter §5.3 (sampling)";

/// An incidence at which the direction-dependent checks run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Incidence {
    /// What it is (`normal`, `oblique`, `grazing`, `inside`, `total_internal_reflection`,
    /// `back_oblique`, `back_grazing`).
    pub name: &'static str,
    /// The direction (unit; z < 0 from inside).
    pub wi: Vec3,
}

impl Incidence {
    fn at(name: &'static str, cos_theta: f64, inside: bool) -> Self {
        // An azimuth off the grid's column edges and off the axes of an anisotropic lobe.
        let phi: f64 = 0.3;
        let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let z = if inside { -cos_theta } else { cos_theta };
        Self {
            name,
            wi: [s * phi.cos(), s * phi.sin(), z],
        }
    }

    /// The record's case fields.
    pub fn case(&self) -> Value {
        json!({
            "incidence": self.name,
            "cos_theta_i": self.wi[2],
            "wi": self.wi,
        })
    }
}

/// The incidences of a BSDF: normal (cos θ = 1 − 5e-7), oblique (θ = 0.9) and grazing (cos θ =
/// 0.05) from outside; for a two-sided reflector, oblique and grazing from below; for a
/// transmitting BSDF of relative index η, from inside at θ = 0.5 and,
/// on the denser side, beyond the critical angle θc = asin(η_thin/η_dense) by a third of what is
/// left to grazing (total internal reflection for every microfacet near the macro-normal).
pub fn incidences(bsdf: &dyn Bsdf) -> Vec<Incidence> {
    let mut out = vec![
        Incidence::at("normal", 1.0 - 5e-7, false),
        Incidence::at("oblique", 0.9f64.cos(), false),
        Incidence::at("grazing", 0.05, false),
    ];
    if let Some(eta) = bsdf.eta() {
        out.push(Incidence::at("inside", 0.5f64.cos(), true));
        let ratio = eta.min(1.0 / eta);
        let critical = ratio.asin();
        let theta = critical + (std::f64::consts::FRAC_PI_2 - critical) / 3.0;
        out.push(Incidence::at(
            "total_internal_reflection",
            theta.cos(),
            eta > 1.0,
        ));
    } else if bsdf.two_sided() {
        // A two-sided reflector is audited from its back side too.
        out.push(Incidence::at("back_oblique", 0.9f64.cos(), true));
        out.push(Incidence::at("back_grazing", 0.05, true));
    }
    out
}

/// Plans every BSDF check of `subject` at `profile`; `why` says what called for them.
pub fn plan<'a>(
    subject: &Arc<BsdfSubject<'a>>,
    profile: Profile,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let incidences = incidences(subject.bsdf.as_ref());
    let mut out = Vec::new();
    for inc in &incidences {
        let shared = Integrals::new(inc.wi, profile.chi2_samples());
        out.push(chi2::plan(subject, *inc, &shared, profile, why));
        out.extend(consistency::plan(subject, *inc, &shared, profile, why));
        out.extend(albedo::plan(subject, *inc, &shared, profile, why));
    }
    out.extend(jacobian::plan(subject, profile, why));
    out.push(reciprocity::plan(subject, why));
    out.extend(ndf::plan(subject, why));
    out.extend(stability::plan(subject, why));
    out
}

/// The samples of one incidence from the record's streams, chunk by chunk in parallel, each
/// chunk folded into an accumulator by `push(acc, index, u, sample)`; the accumulators in chunk
/// order (so a result folded from them is the same whatever the thread count).
pub fn fold_samples<A: Send>(
    bsdf: &dyn Bsdf,
    wi: Vec3,
    samples: u64,
    seed: u64,
    init: impl Fn() -> A + Sync,
    push: impl Fn(&mut A, u64, [f64; 3], Option<BsdfSample>) + Sync,
) -> Vec<A> {
    draw_chunks(samples, seed, init, Vec::new, |acc, out, index, u| {
        out.clear();
        out.resize(u.len(), None);
        bsdf.sample_batch(wi, u, out);
        for (k, (&u, &s)) in u.iter().zip(out.iter()).enumerate() {
            push(acc, index + k as u64, u, s);
        }
    })
}

/// The integrals over the sphere that the checks of one incidence share, each computed once by
/// whichever check needs it first (the others wait for it): the pdf's cell masses (the
/// chi-square's expected counts and the failure rate's 1 − ∫ pdf) and ∫ eval (the albedo and
/// the energy). Each is an adaptive cubature of a BSDF with kinks, seconds of work.
///
/// Their evaluations are reported whoever computed them, and each is billed to one designated
/// record: the pdf masses to `bsdf.chi2`, ∫ eval to `bsdf.albedo` (`bsdf.failure_rate` and
/// `bsdf.energy` add none). Billing the first caller made a record's cost depend on the order
/// the checks ran in, so a sharded audit's records differed from the unsharded ones.
pub struct Integrals {
    wi: Vec3,
    samples: u64,
    pdf: OnceLock<(SphereMasses, u64)>,
    eval: OnceLock<(Estimate, Estimate)>,
}

impl Integrals {
    /// The integrals at `wi`, to the accuracy a chi-square of `samples` samples needs.
    pub fn new(wi: Vec3, samples: u64) -> Arc<Self> {
        Arc::new(Self {
            wi,
            samples,
            pdf: OnceLock::new(),
            eval: OnceLock::new(),
        })
    }

    /// The chi-square's cells of both hemispheres (following each hemisphere's lobe) and the
    /// pdf's masses over them, to the accuracy its `samples` need ([`chi2_masses_about`]), and the
    /// evaluations they cost.
    pub fn pdf_masses(&self, bsdf: &dyn Bsdf) -> (&SphereMasses, u64) {
        let masses = self.pdf.get_or_init(|| {
            let e = chi2_masses_about(
                &pdf_at(bsdf, self.wi),
                chi2::RESOLUTION,
                self.samples,
                &lobe_centres(self.wi, bsdf.eta()),
            );
            let spent = e.upper.evaluations + e.lower.evaluations;
            (e, spent)
        });
        (&masses.0, masses.1)
    }

    /// ∫ pdf dωo with its error bound.
    pub fn pdf_mass(&self, bsdf: &dyn Bsdf) -> Estimate {
        let (masses, spent) = self.pdf_masses(bsdf);
        Estimate {
            value: masses.upper.total + masses.lower.total,
            error_bound: masses.upper.error_bound + masses.lower.error_bound,
            evaluations: spent,
        }
    }

    /// ∫ eval dωo (the albedo) with its error bound and the evaluations it cost, on the same
    /// grid, to [`albedo_target`].
    pub fn albedo(&self, bsdf: &dyn Bsdf) -> Estimate {
        let (u, l) = self.albedo_hemispheres(bsdf);
        Estimate {
            value: u.value + l.value,
            error_bound: u.error_bound + l.error_bound,
            evaluations: u.evaluations + l.evaluations,
        }
    }

    /// ∫ eval dωo over each hemisphere (upper z > 0, lower z < 0), each with its error bound
    /// and evaluations: the reflected and transmitted parts of [`Self::albedo`].
    pub fn albedo_hemispheres(&self, bsdf: &dyn Bsdf) -> (Estimate, Estimate) {
        *self.eval.get_or_init(|| {
            let grid = HemisphereGrid::new(chi2::RESOLUTION).expect("R ≥ 1");
            let target = albedo_target(self.samples);
            let centres = lobe_centres(self.wi, bsdf.eta());
            let (u, l) = expected_sphere_about(&eval_at(bsdf, self.wi), grid, target, &centres);
            let side = |e: &Expected| Estimate {
                value: e.total,
                error_bound: e.error_bound,
                evaluations: e.evaluations,
            };
            (side(&u), side(&l))
        })
    }
}

/// The summed error bound ∫ eval aims at in each hemisphere for `samples` sampled weights:
/// 10/N (1e-5 at the ci profile's 10⁶), with a floor of 1e-9.
///
/// Why not the chi-square's 1/N ([`crate::oracle::chi2::sphere::mass_target`]): `bsdf.albedo` compares the integral with
/// the mean sampled weight, whose standard error is σ_w/√N (σ_w, the weights' spread, is
/// 0.05–1 for the microfacet BSDFs we audit), and takes the bound off the deviation; a bound
/// of 2 × 10/N is then 20/(σ_w √N) ≤ 0.4 standard errors at 10⁶ samples for σ_w ≥ 0.05, a
/// small loss of power, where 1/N cost ≈ 5× the evaluations (the error of a cubature across
/// the steps of a BSDF falls as 1/evaluations): 2.5·10⁷ → 5·10⁶ for a GGX dielectric at the
/// ci profile, minutes for a BSDF in pure Python. `bsdf.energy` reads the same integral; an
/// energy gain a renderer ships (a lost Fresnel, η² misplaced) is percents, not 10⁻⁵.
pub fn albedo_target(samples: u64) -> f64 {
    (10.0 / samples.max(1) as f64).max(1e-9)
}

/// The largest summed error bound of ∫ eval dωo (both hemispheres) with which `bsdf.albedo`
/// and `bsdf.energy` give a verdict: past it (the evaluation budget spent on a lobe the
/// cubature cannot resolve) the record is an error, for a bound that large would hide an
/// energy gain or an eval error of that size. 100× the ci profile's target ([`albedo_target`]).
pub const ALBEDO_CERTIFIED_BOUND: f64 = 1e-3;

/// `bsdf.pdf_batch` at one incidence, as a batch density over wo.
pub fn pdf_at<'b>(bsdf: &'b dyn Bsdf, wi: Vec3) -> impl Fn(&[Vec3], &mut [f64]) + Sync + 'b {
    move |wo: &[Vec3], out: &mut [f64]| {
        let wis = vec![wi; wo.len()];
        bsdf.pdf_batch(&wis, wo, out);
    }
}

/// `bsdf.eval_batch` at one incidence, as a batch density over wo.
pub fn eval_at<'b>(bsdf: &'b dyn Bsdf, wi: Vec3) -> impl Fn(&[Vec3], &mut [f64]) + Sync + 'b {
    move |wo: &[Vec3], out: &mut [f64]| {
        let wis = vec![wi; wo.len()];
        bsdf.eval_batch(&wis, wo, out);
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod corner_tests;
