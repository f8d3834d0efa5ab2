//! The planner: a scene's effects → the checks they call for, each with the reason it was
//! planned; nothing the scene does not use is simulated (ARCHITECTURE.md, "Scenes").

use crate::check::{
    claims, ds, errata, limits, moments, normalization, precise, route_domain, sampling, sg, smith,
    stability, Planned, PlannedCheck, Profile,
};
use crate::scene::{Sampling, Scene};
use crate::subject::bsdf::BsdfSubject;
use crate::subject::Subject;
use mfh_reference::registry;
use mfh_reference::{Masking, Model};
use serde_json::Value;
use std::collections::BTreeSet;
use std::sync::Arc;

/// The effects a renderer declares for one model: what it evaluates of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effects {
    /// The G2 form, if the renderer masks.
    pub masking: Option<Masking>,
    /// How it samples, if it does.
    pub sampling: Option<Sampling>,
    /// Whether it filters with slope moments (Gaussian-slope filtering, document 002).
    pub slope_moments: bool,
    /// The largest incidence it evaluates (radians).
    pub theta_max: f64,
}

/// The checks any model gets from its capabilities and the declared effects: normalization and
/// hard inputs always; Smith checks when it masks; sampling checks when it samples (visible
/// normals too when declared); slope moments when it filters with them. The same function
/// plans a scene's reference materials and a user's own model.
pub fn plan_model<'a>(
    subject: &Arc<Subject<'a>>,
    effects: &Effects,
    profile: Profile,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let mut out = Vec::new();
    out.extend(normalization::plan(subject, &format!("{why} evaluates D")));
    out.push(stability::plan_incidence(subject, why));
    if let Some(masking) = effects.masking {
        out.extend(smith::plan(
            subject,
            profile,
            effects.theta_max,
            &format!("{why} masks ({masking:?})"),
        ));
    }
    if let Some(s) = effects.sampling {
        let samples = format!("{why} samples ({s:?})");
        out.extend(sampling::plan(subject, profile, &samples));
        if s == Sampling::VisibleNormals {
            out.extend(sampling::plan_visible(subject, profile, &samples));
        }
    }
    if effects.slope_moments {
        out.extend(moments::plan(
            subject,
            &format!("{why}: slope moments feed Gaussian-slope filtering"),
        ));
    }
    out
}

/// The plan of a scene under a profile.
pub fn plan(scene: &Scene, profile: Profile) -> Vec<Planned> {
    let theta_max = scene.incidence.theta_max;
    let mut out = Vec::new();
    let mut documents = BTreeSet::new();
    let mut std_alphas: Vec<f64> = Vec::new();
    let mut masked = Vec::new();
    for material in &scene.materials {
        // A material's BSDF plans the BSDF checks of that reference BSDF, and a BSDF-only
        // material plans nothing else: the BSDF checks (chi-square over the whole sphere,
        // sample consistency, albedo, reciprocity) exercise its NDF's D, G2 and sampler through
        // the BSDF, while the NDF checks audit the NDF's closed forms against their documents,
        // which a scene asks for by naming the NDF as `model` (with the masking and sampling
        // the renderer evaluates), as the Mitsuba reader does for its rough BSDFs. Planning
        // them implicitly would bill every BSDF material ≈ 60–190 NDF checks it did not ask for.
        if let Some(bsdf) = &material.bsdf {
            if let Ok(subject) = BsdfSubject::reference(&bsdf.spec()) {
                let why = format!("material `{}` ({} BSDF)", material.name, subject.family());
                out.extend(crate::check::bsdf::plan(&subject, profile, &why));
            } // else: Scene::parse has rejected invalid BSDFs already.
        }
        let Some(spec) = &material.model else {
            continue;
        };
        let Ok(model) = spec.build() else {
            continue; // Scene::parse has rejected invalid models already.
        };
        let model: Arc<dyn Model> = Arc::from(model);
        let subject = Subject::from_model(model.clone());
        let info = registry::info(spec);
        let family = info.name;
        documents.extend(info.documents.iter().copied());
        let why = format!("material `{}` ({family})", material.name);
        let effects = Effects {
            masking: material.masking,
            sampling: material.sampling,
            slope_moments: scene.filtering.gaussian_slopes || info.intrinsic_moments,
            theta_max,
        };
        out.extend(plan_model(&subject, &effects, profile, &why));
        out.extend(precise::plan(
            model.clone(),
            profile,
            theta_max,
            &format!("{why} evaluates D and Λ"),
        ));
        out.extend(stability::plan(
            spec,
            &format!("{why}: its parameters pushed to the ends of their domains"),
        ));
        if material.sampling == Some(Sampling::PseudoVnis) {
            documents.insert("001");
            out.extend(sampling::plan_pseudo_vnis(
                spec,
                material.masking,
                profile,
                &format!("{why} samples (PseudoVnis)"),
            ));
        }
        if material.masking.is_some() {
            out.extend(crate::check::route_stress::plan(
                model.as_ref(),
                &format!("{why} masks"),
            ));
            masked.push((subject.clone(), material.name.clone()));
        }
        if scene.filtering.gaussian_slopes {
            out.extend(ds::plan(
                model.clone(),
                profile,
                theta_max,
                &format!("{why}: Gaussian-slope filtering uses the visible-slope moments"),
            ));
        }
        if info.beckmann_limit {
            let spec = serde_json::to_value(spec).unwrap_or(Value::Null);
            if let Some(a) = spec.get("alpha").and_then(Value::as_f64) {
                if !std_alphas.contains(&a) {
                    std_alphas.push(a);
                    out.extend(limits::plan(a, &format!("{why}: STD generalizes Beckmann")));
                }
            }
        }
    }
    let domains = route_domain::plan(&masked, &out, profile, theta_max);
    out.extend(domains);
    if scene.filtering.gaussian_slopes {
        documents.insert("002");
    }
    if scene.lighting.spherical_gaussians || scene.lighting.anisotropic_spherical_gaussians {
        documents.insert("003");
        out.extend(sg::plan(
            profile,
            scene.lighting.spherical_gaussians,
            scene.lighting.anisotropic_spherical_gaussians,
            "the scene lights with spherical Gaussians",
        ));
    }
    let documents: Vec<&str> = documents.into_iter().collect();
    let used = format!("the scene uses seed(s) {}", documents.join(", "));
    let scope = errata_scope(scene);
    out.extend(errata::plan(&scope, &used));
    out.extend(claims::plan(&scope, &used));
    out
}

/// The errata scope of a scene: its materials' families and what they and the scene do (the
/// errata and claims planned are those that concern it).
pub fn errata_scope(scene: &Scene) -> errata::Scope {
    let mut s = errata::Scope::default();
    for material in &scene.materials {
        if let Some(Ok(model)) = material.model.as_ref().map(|m| m.build()) {
            s.families.insert(model.family());
        }
        if material.masking.is_some() {
            s.effects.insert(errata::Effect::Masking);
        }
        match material.sampling {
            Some(Sampling::Normals) => {
                s.effects.insert(errata::Effect::SampleNormals);
            }
            Some(Sampling::VisibleNormals) => {
                s.effects.insert(errata::Effect::SampleVisible);
            }
            Some(Sampling::PseudoVnis) => {
                // Algorithm 1 of §7.2 samples normals (§6) on some branches.
                s.effects.insert(errata::Effect::PseudoVnis);
                s.effects.insert(errata::Effect::SampleNormals);
            }
            None => {}
        }
    }
    if scene.filtering.gaussian_slopes {
        s.effects.insert(errata::Effect::GaussianSlopes);
    }
    if scene.lighting.spherical_gaussians {
        s.effects.insert(errata::Effect::SphericalGaussians);
    }
    if scene.lighting.anisotropic_spherical_gaussians {
        s.effects
            .insert(errata::Effect::AnisotropicSphericalGaussians);
    }
    s
}

/// One line per planned check: id, model, case and why (for `mfh plan`).
pub fn describe(plan: &[PlannedCheck<'_>]) -> Vec<Value> {
    plan.iter()
        .map(|p| {
            serde_json::json!({
                "check": p.check,
                "model": p.model,
                "case": p.case,
                "why": p.why,
                "covers": p.covers,
                "statistical": p.statistical,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Profile;

    /// A BSDF material plans the BSDF checks of its reference BSDF and no NDF check; a
    /// material with a `model` beside its `bsdf` plans both.
    #[test]
    fn a_bsdf_material_plans_the_bsdf_checks() {
        let glass = r#"{"type": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}"#;
        let scene = Scene::parse(
            &format!(r#"{{"name": "b", "materials": [{{"name": "glass", "bsdf": {glass}}}]}}"#),
            "s",
        )
        .unwrap();
        let planned = plan(&scene, Profile::Quick);
        let ids: BTreeSet<&str> = planned.iter().map(|p| p.check.as_str()).collect();
        for id in [
            "bsdf.chi2",
            "bsdf.sample_consistency",
            "bsdf.albedo",
            "bsdf.reciprocity",
        ] {
            assert!(ids.contains(id), "{id} not in {ids:?}");
        }
        let material: Vec<_> = planned
            .iter()
            .filter(|p| p.why.contains("material `glass`"))
            .collect();
        assert!(material.iter().all(|p| p.check.starts_with("bsdf.")));
        assert!(
            material[0].why.contains("dielectric BSDF"),
            "{}",
            material[0].why
        );
        // Both: the NDF checks of the model too.
        let both = Scene::parse(
            &format!(
                r#"{{"name": "b", "materials": [{{"name": "glass", "bsdf": {glass},
                   "model": {{"family": "ggx", "alpha": 0.3}}, "masking": "uncorrelated"}}]}}"#
            ),
            "s",
        )
        .unwrap();
        let ids: BTreeSet<String> = plan(&both, Profile::Quick)
            .into_iter()
            .map(|p| p.check)
            .collect();
        assert!(
            ids.contains("bsdf.chi2") && ids.contains("smith.g1_g2"),
            "{ids:?}"
        );
    }
}
