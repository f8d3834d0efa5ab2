//! Visible-normal sampling: the chi-square of `sample_wm_visible` against `pdf_wm_visible` at
//! fixed incidences and the normalization of `pdf_wm_visible` (Heitz & d'Eon 2014, Heitz 2018).

use super::{chi2_kinked, skipped};
use crate::check::{compare_at, covers, PlannedCheck, Profile};
use crate::check::{need, Check};
use crate::oracle::quadrature::{integrate_hemisphere_batch, Accuracy, Cuts};
use crate::subject::Subject;
use crate::tolerance::NORMALIZATION;
use mfh_reference::geometry::{from_spherical, Vec3};
use serde_json::json;
use std::sync::Arc;

/// The incidences (θ, φ) at which visible-normal sampling is checked: a moderate and a
/// near-grazing one, off the x axis so that anisotropic stretching is exercised.
pub const VISIBLE_INCIDENCES: [(f64, f64); 2] = [(0.5, 0.3), (1.3, 0.3)];

const VISIBLE_SOURCE: &str = "Heitz & d'Eon 2014 (CGF 33(4)) eq 2 and §4 (Beckmann, with Jakob      2014's inversion); Heitz 2018 (JCGT 7(4)) (GGX); cited by seed 001 §7 as [9]";

/// The polar angles (inside (0, π/2)) of the kinks of ⟨wi·m⟩⁺ (the terminator) and of the
/// reflected direction's horizon (2(wi·m)m_z = wi_z) along azimuth φ of m, for wi_z > 0.
pub fn visible_kinks(wi: Vec3, phi: f64) -> Vec<f64> {
    let k = wi[0] * phi.cos() + wi[1] * phi.sin();
    let psi = k.atan2(wi[2]);
    let mut out = vec![std::f64::consts::FRAC_PI_4 + 0.5 * psi];
    if k < 0.0 {
        out.push(std::f64::consts::FRAC_PI_2 + psi);
    }
    out
}

/// The azimuths of m in [0, 2π) where the terminator of ⟨wi·m⟩⁺ meets the normal, for wi at
/// azimuth `phi_i`: φi ± π/2 (the polar kinks of [`visible_kinks`] start there).
pub fn terminator_azimuths(phi_i: f64) -> [f64; 2] {
    let tau = std::f64::consts::TAU;
    let q = std::f64::consts::FRAC_PI_2;
    [(phi_i + q).rem_euclid(tau), (phi_i - q).rem_euclid(tau)]
}

/// Plans the visible-normal sampling checks of one model (scene `sampling: visible_normals`):
/// `sampling.chi2_visible` at each of [`VISIBLE_INCIDENCES`] and
/// `sampling.pdf_visible_normalization` (∫ pdf_wm_visible dm = 1 by quadrature), and
/// `sampling.batch_agrees` of its batch against its scalar visible sampler. A model without
/// a visible-normal sampler gets one skipped `sampling.chi2_visible` record that says so: the
/// scene is valid (the renderer may sample visible normals its own way), but there is no
/// reference sampler to check it against.
pub fn plan_visible<'a>(
    subject: &Arc<Subject<'a>>,
    profile: Profile,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let spec = subject.label.clone();
    let family = subject.family();
    if subject.model.as_visible_sampler().is_none() {
        return vec![skipped(
            "sampling.chi2_visible",
            &spec,
            json!({}),
            why,
            format!(
                "{family} has no visible-normal sampler in the reference crate (only GGX and \
                 Beckmann do; STD has none in closed form, seed 001 §7.1): nothing to check \
                 the renderer's against"
            ),
        )];
    }
    let samples = profile.chi2_samples();
    let resolution = 16;
    let mut out = Vec::new();
    for &(theta, phi) in &VISIBLE_INCIDENCES {
        let m = subject.clone();
        let case = json!({"theta_i": theta, "phi_i": phi, "samples": samples,
                          "resolution": resolution});
        let ids = vec![
            covers(family, "sample_wm_visible", "default"),
            covers(family, "pdf_wm_visible", "default"),
        ];
        out.push(
            Check::new("sampling.chi2_visible", spec.clone(), case, VISIBLE_SOURCE)
                .why(format!("{why}: importance sampling of visible normals"))
                .covers(ids)
                .statistical()
                .run(move |r, ctx| {
                    let v = need(m.model.as_visible_sampler(), "visible-normal sampler")?;
                    let wi = from_spherical(theta, phi);
                    chi2_kinked(
                        r,
                        ctx,
                        (resolution, samples),
                        &|u: &[[f64; 2]], out: &mut [Vec3]| v.sample_wm_visible_batch(wi, u, out),
                        &|mm: &[Vec3], out: &mut [f64]| v.pdf_wm_visible_batch(wi, mm, out),
                        (m.remote, m.precision),
                    );
                    Ok(())
                }),
        );
        let m = subject.clone();
        let case = json!({"theta_i": theta, "phi_i": phi});
        out.push(
            Check::new(
                "sampling.pdf_visible_normalization",
                spec.clone(),
                case,
                VISIBLE_SOURCE,
            )
            .why(format!(
                "{why}: the visible-normal density must integrate to 1"
            ))
            .covers(vec![covers(family, "pdf_wm_visible", "default")])
            .run(move |r, _| {
                let v = need(m.model.as_visible_sampler(), "visible-normal sampler")?;
                let wi = from_spherical(theta, phi);
                let kinks = |p: f64| visible_kinks(wi, p);
                let e = integrate_hemisphere_batch(
                    &|mm: &[Vec3], out: &mut [f64]| v.pdf_wm_visible_batch(wi, mm, out),
                    m.lobe().width(),
                    Some(Cuts {
                        theta: &kinks,
                        phi: &terminator_azimuths(phi),
                    }),
                    Accuracy::relative(1e-11).at(m.precision),
                );
                compare_at(
                    r,
                    1.0,
                    e,
                    &NORMALIZATION.at(m.precision),
                    Accuracy::relative(1e-11).at(m.precision).noise_floor(),
                );
                Ok(())
            }),
        );
    }
    out.push(super::visible_jacobian::plan(subject, why));
    out.extend(super::batch_agrees::plan_visible(
        subject,
        &VISIBLE_INCIDENCES,
        why,
    ));
    out
}
