//! The planner: a scene's effects → the checks they call for, each with the reason it was
//! planned; nothing the scene does not use is simulated (DESIGN.md, "Scenes").

use crate::check::{
    claims, ds, errata, limits, moments, normalization, precise, sampling, sg, smith, stability,
    Planned, Profile,
};
use crate::scene::{Sampling, Scene};
use mfh_reference::Model;
use serde_json::Value;
use std::collections::BTreeSet;
use std::sync::Arc;

/// The source document (seed id) each family comes from.
pub fn document_of(family: &str) -> &'static [&'static str] {
    match family {
        "beckmann"
        | "ggx"
        | "std"
        | "hyper_cauchy"
        | "student_fixed_variance"
        | "student_general" => &["001"],
        "gtr" => &["004"],
        "piecewise_linear" | "blend" => &["000"],
        "gaussian_slopes" => &["002"],
        _ => &[],
    }
}

/// The plan of a scene under a profile.
pub fn plan(scene: &Scene, profile: Profile) -> Vec<Planned> {
    let theta_max = scene.incidence.theta_max;
    let mut out = Vec::new();
    let mut documents = BTreeSet::new();
    let mut std_alphas: Vec<f64> = Vec::new();
    for material in &scene.materials {
        let Ok(model) = material.model.build() else {
            continue; // Scene::parse has rejected invalid models already.
        };
        let model: Arc<dyn Model> = Arc::from(model);
        let family = model.family();
        documents.extend(document_of(family).iter().copied());
        let spec = serde_json::to_value(&material.model).unwrap_or(Value::Null);
        let why = format!("material `{}` ({family})", material.name);
        out.extend(normalization::plan(
            model.clone(),
            &format!("{why} evaluates D"),
        ));
        out.extend(precise::plan(
            model.clone(),
            profile,
            theta_max,
            &format!("{why} evaluates D and Λ"),
        ));
        out.extend(stability::plan(
            &spec,
            &format!("{why}: its parameters pushed to the ends of their domains"),
        ));
        if let Some(masking) = material.masking {
            out.extend(smith::plan(
                model.clone(),
                profile,
                theta_max,
                &format!("{why} masks ({masking:?})"),
            ));
            out.extend(crate::check::route_stress::plan(
                model.as_ref(),
                &format!("{why} masks"),
            ));
        }
        if let Some(s) = material.sampling {
            let samples = format!("{why} samples ({s:?})");
            out.extend(sampling::plan(model.clone(), profile, &samples));
            match s {
                Sampling::Normals => {}
                Sampling::VisibleNormals => {
                    out.extend(sampling::plan_visible(model.clone(), profile, &samples));
                }
                Sampling::PseudoVnis => {
                    documents.insert("001");
                    out.extend(sampling::plan_pseudo_vnis(
                        &material.model,
                        material.masking,
                        profile,
                        &samples,
                    ));
                }
            }
        }
        if scene.filtering.gaussian_slopes || family == "gaussian_slopes" {
            out.extend(moments::plan(
                model.clone(),
                &format!("{why}: slope moments feed Gaussian-slope filtering"),
            ));
        }
        if scene.filtering.gaussian_slopes {
            out.extend(ds::plan(
                model.clone(),
                profile,
                theta_max,
                &format!("{why}: Gaussian-slope filtering uses the visible-slope moments"),
            ));
        }
        if family == "std" {
            if let Some(a) = spec.get("alpha").and_then(Value::as_f64) {
                if !std_alphas.contains(&a) {
                    std_alphas.push(a);
                    out.extend(limits::plan(a, &format!("{why}: STD generalizes Beckmann")));
                }
            }
        }
    }
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
    out.extend(errata::plan(&documents, &used));
    out.extend(claims::plan(&documents, &used));
    out
}

/// One line per planned check: id, model, case and why (for `mfh plan`).
pub fn describe(plan: &[Planned]) -> Vec<Value> {
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
