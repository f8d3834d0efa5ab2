//! Scenes: what a renderer uses (materials with their masking and sampling, filtering, lighting,
//! incidence range), read from JSON with typed errors that carry the line and column, and the
//! embedded default scene that covers every model of the source documents (ARCHITECTURE.md, "Scenes").

mod bsdf;

pub use bsdf::MaterialBsdf;

use mfh_reference::{Masking, ModelSpec};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// The embedded default scene: every model of the five source documents, every effect on.
pub const DEFAULT_SCENE: &str = include_str!("../scenes/default.json");

/// The largest scene file read, 1 MiB: the default scene of 21 materials is 3.6 KB, and
/// [`MAX_MATERIALS`] materials of a few hundred bytes each fit with room to spare. The file is
/// read through a bounded reader, so `--scene /dev/zero` stops after 1 MiB.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The most materials a scene may have, 256 (the default scene has 21). Each material plans
/// ≈ 60 checks at the quick profile and ≈ 190 at the thorough one; see [`MAX_PLAN_CHECKS`].
pub const MAX_MATERIALS: usize = 256;

/// The largest plan an audit runs, 50 000 checks (the default scene plans 1 229 quick and
/// 3 972 thorough). Measured: 10 000 materials planned 250 015 checks in 1.5 GB (≈ 6 KB per
/// planned check), so this bounds planning to ≈ 300 MB.
pub const MAX_PLAN_CHECKS: usize = 50_000;

/// How a material samples: the reference crate's one definition (`normals`, `visible_normals`,
/// `pseudo_vnis`), which its BSDFs use too.
pub use mfh_reference::bsdf::Sampling;

/// One material: an NDF (`model`, with what the renderer evaluates of it: `masking`,
/// `sampling`), a reference BSDF (`bsdf`), or both (the Mitsuba reader's rough BSDFs). A
/// material with both names the same NDF in each.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Its name in the scene.
    pub name: String,
    /// The NDF, if the material plans NDF checks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelSpec>,
    /// The reference BSDF, if the material plans BSDF checks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bsdf: Option<MaterialBsdf>,
    /// The G2 form the renderer uses, if it masks.
    #[serde(default)]
    pub masking: Option<Masking>,
    /// How the renderer samples the material, if it does.
    #[serde(default)]
    pub sampling: Option<Sampling>,
}

/// Filtering effects.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Filtering {
    /// Gaussian slope distributions (LEAN-style filtering, document 002 visible-slope moments).
    #[serde(default)]
    pub gaussian_slopes: bool,
}

/// Lighting effects.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lighting {
    /// Spherical Gaussians (document 003).
    #[serde(default)]
    pub spherical_gaussians: bool,
    /// Anisotropic spherical Gaussians (document 003).
    #[serde(default)]
    pub anisotropic_spherical_gaussians: bool,
}

/// The incidence range the renderer evaluates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Incidence {
    /// The largest θ (radians), in (0, π/2].
    #[serde(default = "half_pi")]
    pub theta_max: f64,
}

fn half_pi() -> f64 {
    FRAC_PI_2
}

impl Default for Incidence {
    fn default() -> Self {
        Self {
            theta_max: FRAC_PI_2,
        }
    }
}

/// A scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Its name.
    pub name: String,
    /// The materials (at least one).
    pub materials: Vec<Material>,
    /// Filtering effects (off when absent).
    #[serde(default)]
    pub filtering: Filtering,
    /// Lighting effects (off when absent).
    #[serde(default)]
    pub lighting: Lighting,
    /// The incidence range (θ_max = π/2 when absent).
    #[serde(default)]
    pub incidence: Incidence,
    /// What the scene file holds that is not audited, and why (Mitsuba scenes: every plugin
    /// that is not a microfacet BSDF). Never dropped silently: `mfh plan` and the report list it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_audited: Vec<NotAudited>,
}

/// A part of a scene file that is not audited, with the reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NotAudited {
    /// The plugin (`diffuse`, `shape obj`, …).
    pub plugin: String,
    /// Its id in the file (or `type@line:column` when it has none; `outer/inner` when nested).
    pub id: String,
    /// Why it is not audited (`has no microfacet model`, …).
    pub reason: String,
}

impl std::fmt::Display for NotAudited {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "not audited: {} ({}) {}",
            self.plugin, self.id, self.reason
        )
    }
}

/// Why a scene was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene {path}: {message}")]
    Unreadable {
        /// The path.
        path: String,
        /// The I/O error.
        message: String,
    },
    /// The scene needs a cargo feature this build of the library was made without.
    #[error("cannot read scene {path}: this build of mfh-harness has no `{feature}` feature")]
    FeatureOff {
        /// The path.
        path: String,
        /// The feature (`mitsuba` for XML scenes).
        feature: &'static str,
    },
    /// The JSON is malformed or has unknown or missing keys.
    #[error("{origin}:{line}:{column}: {message}")]
    Syntax {
        /// The file (or `<default scene>`).
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// serde's message, which names the key.
        message: String,
    },
    /// The scene has no material.
    #[error("{origin}: the scene has no materials")]
    NoMaterials {
        /// The file.
        origin: String,
    },
    /// A scene file (Mitsuba) has no material mfh can audit.
    #[error("{origin}: no BSDF with a microfacet model to audit ({not_audited})")]
    NothingToAudit {
        /// The file.
        origin: String,
        /// What it holds instead, `; `-separated.
        not_audited: String,
    },
    /// Two materials share a name.
    #[error("{origin}: two materials are named `{name}`")]
    DuplicateMaterial {
        /// The file.
        origin: String,
        /// The name.
        name: String,
    },
    /// A material's model parameters are invalid.
    #[error("{origin}: material `{name}`: {message}")]
    InvalidModel {
        /// The file.
        origin: String,
        /// The material.
        name: String,
        /// The parameter error.
        message: String,
    },
    /// The scene file exceeds [`MAX_SCENE_BYTES`].
    #[error("scene {path} is larger than the limit of {limit} bytes (1 MiB)")]
    TooLarge {
        /// The path.
        path: String,
        /// The limit in bytes.
        limit: u64,
    },
    /// More materials than [`MAX_MATERIALS`].
    #[error("{origin}: materials: {count} materials exceed the limit of {limit}")]
    TooManyMaterials {
        /// The file.
        origin: String,
        /// The number of materials.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// The plan exceeds [`MAX_PLAN_CHECKS`].
    #[error(
        "{origin}: the {profile} plan has {checks} checks, more than the plan-size limit of \
         {limit}; audit fewer materials or a lighter profile"
    )]
    PlanTooLarge {
        /// The file.
        origin: String,
        /// The profile's name.
        profile: String,
        /// Checks planned.
        checks: usize,
        /// The limit.
        limit: usize,
    },
    /// A material asks for something its model cannot do (masking without a Smith Λ).
    #[error("{origin}: material `{name}`: {field}: {message}")]
    Unsupported {
        /// The file.
        origin: String,
        /// The material.
        name: String,
        /// The material's field that asks for it (`masking`, `sampling`).
        field: &'static str,
        /// Why the model cannot, naming the parameter and its limit.
        message: String,
    },
    /// A material's BSDF is invalid, or contradicts the material's other fields.
    #[error("{origin}: material `{name}`: {field}: {message}")]
    InvalidBsdf {
        /// The file.
        origin: String,
        /// The material.
        name: String,
        /// The field (`bsdf.eta`, `bsdf.ndf`, `model`, `masking`, …).
        field: String,
        /// What is wrong, naming the limit.
        message: String,
    },
    /// θ_max outside (0, π/2].
    #[error("{origin}: incidence.theta_max = {value} is not in (0, π/2]")]
    ThetaMax {
        /// The file.
        origin: String,
        /// The value.
        value: f64,
    },
}

impl Material {
    /// The material's NDF: its `model`, else its BSDF's NDF (a valid material has one).
    pub fn ndf(&self) -> Option<&ModelSpec> {
        self.model
            .as_ref()
            .or_else(|| self.bsdf.as_ref().map(MaterialBsdf::ndf))
    }

    /// What is wrong with the material's BSDF, as `(field, message)`: neither `model` nor
    /// `bsdf`; an invalid spec (the field and its limit); `masking` or `sampling` beside a
    /// `bsdf` without a `model` (a BSDF carries its own); a `model` that is not the BSDF's NDF.
    fn bsdf_error(&self) -> Option<(String, String)> {
        let Some(bsdf) = &self.bsdf else {
            return self.model.is_none().then(|| {
                (
                    "model".to_string(),
                    "a material needs a `model` (an NDF) or a `bsdf` (a reference BSDF)".into(),
                )
            });
        };
        let spec = bsdf.spec();
        if let Err(e) = spec.validate() {
            return Some((format!("bsdf.{}", e.field()), e.to_string()));
        }
        if self.model.is_none() {
            for (field, given) in [
                ("masking", self.masking.is_some()),
                ("sampling", self.sampling.is_some()),
            ] {
                if given {
                    return Some((
                        field.to_string(),
                        format!(
                            "a BSDF material gives its {field} inside `bsdf` (`bsdf.{field}`); \
                             `{field}` beside it belongs to a `model`"
                        ),
                    ));
                }
            }
        }
        match &self.model {
            Some(model) if model != spec.ndf() => Some((
                "bsdf.ndf".to_string(),
                "differs from the material's `model`: a material with both names one NDF".into(),
            )),
            _ => None,
        }
    }
}

impl Scene {
    /// Parses and validates a scene from JSON text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Scene, SceneError> {
        let scene: Scene = serde_json::from_str(text).map_err(|e| SceneError::Syntax {
            origin: origin.to_string(),
            line: e.line(),
            column: e.column(),
            message: crate::messages::json_error_message(&e),
        })?;
        scene.validate(origin)
    }

    /// Checks what serde cannot: at least one material, unique names, valid model parameters,
    /// θ_max in (0, π/2].
    pub fn validate(self, origin: &str) -> Result<Scene, SceneError> {
        let scene = self;
        let origin = origin.to_string();
        if scene.materials.is_empty() && !scene.not_audited.is_empty() {
            // The first few only: an error is one short line, whatever the scene holds.
            const SHOWN: usize = 10;
            let n = scene.not_audited.len();
            let mut list: Vec<String> = scene
                .not_audited
                .iter()
                .take(SHOWN)
                .map(|n| n.to_string())
                .collect();
            if n > SHOWN {
                list.push(format!("… and {} more, {n} in all", n - SHOWN));
            }
            return Err(SceneError::NothingToAudit {
                origin,
                not_audited: list.join("; "),
            });
        }
        if scene.materials.is_empty() {
            return Err(SceneError::NoMaterials { origin });
        }
        if scene.materials.len() > MAX_MATERIALS {
            return Err(SceneError::TooManyMaterials {
                origin,
                count: scene.materials.len(),
                limit: MAX_MATERIALS,
            });
        }
        for (i, m) in scene.materials.iter().enumerate() {
            if scene.materials[..i].iter().any(|o| o.name == m.name) {
                return Err(SceneError::DuplicateMaterial {
                    origin,
                    name: m.name.clone(),
                });
            }
            if let Some(e) = m.bsdf_error() {
                let (field, message) = e;
                return Err(SceneError::InvalidBsdf {
                    origin,
                    name: m.name.clone(),
                    field,
                    message: crate::messages::compact_numbers(&message),
                });
            }
            let Some(model) = &m.model else {
                continue; // a BSDF material: its spec is checked above
            };
            if let Err(e) = model.build() {
                return Err(SceneError::InvalidModel {
                    origin,
                    name: m.name.clone(),
                    message: crate::messages::compact_numbers(&e.to_string()),
                });
            }
            // Masking and the pseudo-VNIS weight G/G1 need Λ: a model without one would
            // silently lose its Smith checks.
            let needs_smith = [
                ("masking", m.masking.is_some()),
                ("sampling", m.sampling == Some(Sampling::PseudoVnis)),
            ];
            for (field, needed) in needs_smith {
                if let (true, Some(why)) = (needed, model.smith_limit()) {
                    return Err(SceneError::Unsupported {
                        origin,
                        name: m.name.clone(),
                        field,
                        message: why,
                    });
                }
            }
        }
        let t = scene.incidence.theta_max;
        if !(t > 0.0 && t <= FRAC_PI_2 + 1e-12) {
            return Err(SceneError::ThetaMax { origin, value: t });
        }
        Ok(scene)
    }

    /// Checks the size of a plan of this scene against [`MAX_PLAN_CHECKS`]; `origin` names the
    /// scene and `profile` the profile in the message.
    pub fn check_plan_size(checks: usize, origin: &str, profile: &str) -> Result<(), SceneError> {
        if checks > MAX_PLAN_CHECKS {
            return Err(SceneError::PlanTooLarge {
                origin: origin.to_string(),
                profile: profile.to_string(),
                checks,
                limit: MAX_PLAN_CHECKS,
            });
        }
        Ok(())
    }

    /// The embedded default scene: `scenes/default.json`, plus one material for every family of
    /// the registry that the file does not name (its first registry example, with every effect
    /// the model supports: masking height-correlated where it has Λ, normal sampling where it
    /// has a sampler), so that a family added to the registry is audited by the main job
    /// without editing the scene.
    pub fn default_scene() -> Scene {
        let mut scene = Scene::parse(DEFAULT_SCENE, "<default scene>")
            .expect("the embedded default scene is valid");
        for family in mfh_reference::registry::FAMILIES {
            if scene
                .materials
                .iter()
                .any(|m| m.model.as_ref().is_some_and(|s| s.family() == family.name))
            {
                continue;
            }
            let model: ModelSpec = serde_json::from_str(family.examples[0])
                .expect("registry examples parse (the registry test)");
            let built = model.build().expect("registry examples build");
            let has_smith = built.as_smith().is_some() && model.smith_limit().is_none();
            scene.materials.push(Material {
                name: format!("{} (registry example)", family.name),
                masking: has_smith.then_some(Masking::HeightCorrelated),
                sampling: built.as_sampler().map(|_| Sampling::Normals),
                model: Some(model),
                bsdf: None,
            });
        }
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn the_default_scene_parses_and_covers_every_family() {
        let s = Scene::default_scene();
        let families: std::collections::BTreeSet<_> = s
            .materials
            .iter()
            .filter_map(|m| m.model.as_ref().map(|s| s.family()))
            .collect();
        for f in mfh_reference::registry::FAMILIES.iter().map(|f| f.name) {
            assert!(families.contains(f), "{f} missing from the default scene");
        }
        assert!(s.lighting.spherical_gaussians && s.filtering.gaussian_slopes);
    }

    #[test]
    fn bad_scenes_are_typed_errors_with_positions() {
        let e = Scene::parse(
            "{\"name\": \"x\",\n \"materials\": [], \"lightning\": {}}",
            "s.json",
        )
        .unwrap_err();
        match &e {
            SceneError::Syntax { line, message, .. } => {
                assert_eq!(*line, 2);
                assert!(message.contains("lightning"), "{message}");
            }
            other => panic!("{other:?}"),
        }
        let e = Scene::parse(r#"{"name": "x", "materials": []}"#, "s.json").unwrap_err();
        assert!(matches!(e, SceneError::NoMaterials { .. }));
        let bad = r#"{"name": "x", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": -1}}]}"#;
        assert!(matches!(
            Scene::parse(bad, "s").unwrap_err(),
            SceneError::InvalidModel { .. }
        ));
        let dup = r#"{"name": "x", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.1}},
                     {"name": "a", "model": {"family": "ggx", "alpha": 0.2}}]}"#;
        assert!(matches!(
            Scene::parse(dup, "s").unwrap_err(),
            SceneError::DuplicateMaterial { .. }
        ));
        let theta = r#"{"name": "x", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.1}}],
                       "incidence": {"theta_max": 2}}"#;
        assert!(matches!(
            Scene::parse(theta, "s").unwrap_err(),
            SceneError::ThetaMax { .. }
        ));
        let key = r#"{"name": "x", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.1}, "shading": 1}]}"#;
        assert!(Scene::parse(key, "s")
            .unwrap_err()
            .to_string()
            .contains("shading"));
    }

    fn materials(n: usize) -> String {
        let list: Vec<String> = (0..n)
            .map(|i| format!(r#"{{"name": "m{i}", "model": {{"family": "ggx", "alpha": 0.3}}}}"#))
            .collect();
        format!(r#"{{"name": "many", "materials": [{}]}}"#, list.join(","))
    }

    #[test]
    fn size_limits_name_the_field_and_the_limit() {
        assert!(Scene::parse(&materials(MAX_MATERIALS), "s").is_ok());
        let e = Scene::parse(&materials(10_000), "s.json").unwrap_err();
        assert!(matches!(
            e,
            SceneError::TooManyMaterials { count: 10_000, .. }
        ));
        let m = e.to_string();
        assert!(m.contains("materials") && m.contains("256"), "{m}");
        let e = Scene::check_plan_size(MAX_PLAN_CHECKS + 1, "s.json", "quick").unwrap_err();
        assert!(e.to_string().contains("50000"), "{e}");
        assert!(Scene::check_plan_size(MAX_PLAN_CHECKS, "s.json", "quick").is_ok());
        // An endless file is read only up to the limit.
        if Path::new("/dev/zero").exists() {
            let e = Scene::load(Path::new("/dev/zero")).unwrap_err();
            assert!(matches!(e, SceneError::TooLarge { .. }), "{e}");
            assert!(e.to_string().contains("1048576"), "{e}");
        }
    }

    #[test]
    fn masking_a_model_without_smith_is_a_scene_error() {
        let scene = |gamma: f64, extra: &str| {
            format!(
                r#"{{"name": "s", "materials": [{{"name": "rough", "model": {{"family": "std",
                   "gamma": {gamma}, "alpha": 0.3}}{extra}}}]}}"#
            )
        };
        let e = Scene::parse(&scene(1.5, r#", "masking": "height_correlated""#), "s").unwrap_err();
        let m = e.to_string();
        assert!(
            matches!(
                e,
                SceneError::Unsupported {
                    field: "masking",
                    ..
                }
            ),
            "{m}"
        );
        assert!(
            m.contains("`rough`") && m.contains("gamma") && m.contains("3/2"),
            "{m}"
        );
        let e = Scene::parse(&scene(1.2, r#", "sampling": "pseudo_vnis""#), "s").unwrap_err();
        assert!(
            matches!(
                e,
                SceneError::Unsupported {
                    field: "sampling",
                    ..
                }
            ),
            "{e}"
        );
        // Without masking the model is fine; above 3/2 masking is fine.
        assert!(Scene::parse(&scene(1.5, ""), "s").is_ok());
        assert!(Scene::parse(&scene(1.6, r#", "masking": "uncorrelated""#), "s").is_ok());
    }

    #[test]
    fn a_minimal_scene_turns_everything_else_off() {
        let s = Scene::parse(
            r#"{"name": "m", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.1}}]}"#,
            "s",
        )
        .unwrap();
        assert_eq!(s.materials[0].masking, None);
        assert!(!s.lighting.spherical_gaussians && !s.filtering.gaussian_slopes);
        assert_eq!(s.incidence.theta_max, FRAC_PI_2);
    }

    const GLASS: &str =
        r#"{"type": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}"#;

    fn bsdf_scene(material: &str) -> String {
        format!(r#"{{"name": "b", "materials": [{{"name": "glass", {material}}}]}}"#)
    }

    #[test]
    fn a_material_may_name_a_reference_bsdf() {
        let s = Scene::parse(&bsdf_scene(&format!(r#""bsdf": {GLASS}"#)), "s").unwrap();
        let m = &s.materials[0];
        assert_eq!(m.model, None);
        assert_eq!(m.bsdf.as_ref().map(|b| b.spec().kind()), Some("dielectric"));
        assert_eq!(m.ndf().map(ModelSpec::family), Some("ggx"));
        // With its NDF as `model` too, masking and sampling describe the NDF.
        let both = format!(
            r#""model": {{"family": "ggx", "alpha": 0.3}}, "masking": "uncorrelated", "bsdf": {GLASS}"#
        );
        assert!(Scene::parse(&bsdf_scene(&both), "s").is_ok());
    }

    #[test]
    fn bad_bsdf_materials_name_the_field() {
        for (material, field, needles) in [
            (
                r#""bsdf": {"type": "dielectric", "eta": 20, "ndf": {"family": "ggx", "alpha": 0.3}}"#.to_string(),
                "bsdf.eta",
                &["[0.1, 10]", "`glass`"][..],
            ),
            (
                r#""bsdf": {"type": "conductor", "n": 0.2, "k": 300, "ndf": {"family": "ggx", "alpha": 0.3}}"#.to_string(),
                "bsdf.k",
                &["100"],
            ),
            (
                r#""bsdf": {"type": "conductor", "n": 0.2, "k": 3, "ndf": {"family": "std", "gamma": 1.2, "alpha": 0.3}}"#.to_string(),
                "bsdf.ndf",
                &["Smith"],
            ),
            (format!(r#""bsdf": {GLASS}, "masking": "uncorrelated""#), "masking", &["bsdf.masking"]),
            (
                format!(r#""bsdf": {GLASS}, "model": {{"family": "ggx", "alpha": 0.4}}"#),
                "bsdf.ndf",
                &["model"],
            ),
            (String::new(), "model", &["`bsdf`"]),
        ] {
            let text = bsdf_scene(&material).replace(", }", "}");
            let e = Scene::parse(&text, "s.json").unwrap_err();
            match &e {
                SceneError::InvalidBsdf { field: f, .. } => assert_eq!(f, field, "{e}"),
                other => panic!("{material}: {other:?}"),
            }
            let m = e.to_string();
            assert!(m.contains(field), "{m}");
            for n in needles {
                assert!(m.contains(n), "{material}: {m} lacks {n}");
            }
        }
        // An unknown BSDF type or key is a syntax error naming it, with its position.
        let e = Scene::parse(&bsdf_scene(r#""bsdf": {"type": "plastic"}"#), "s.json").unwrap_err();
        assert!(
            matches!(e, SceneError::Syntax { .. }) && e.to_string().contains("plastic"),
            "{e}"
        );
    }
}
