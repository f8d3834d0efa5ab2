//! Scenes: what a renderer uses (materials with their masking and sampling, filtering, lighting,
//! incidence range), read from JSON with typed errors that carry the line and column, and the
//! embedded default scene that covers every model of the source documents (DESIGN.md, "Scenes").

use mfh_reference::{Masking, ModelSpec};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;
use std::path::Path;

/// The embedded default scene: every model of the five source documents, every effect on.
pub const DEFAULT_SCENE: &str = include_str!("../scenes/default.json");

/// How a material samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Normals from D(m)(m·n): `sample_wm`.
    Normals,
    /// Visible normals D_wi(m).
    VisibleNormals,
    /// The pseudo-VNIS of seed 001 §7.2 (normals, weighted by G/G1).
    PseudoVnis,
}

/// One material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Its name in the scene.
    pub name: String,
    /// The NDF.
    pub model: ModelSpec,
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
    /// Gaussian slope distributions (LEAN-style filtering, seed 002 visible-slope moments).
    #[serde(default)]
    pub gaussian_slopes: bool,
}

/// Lighting effects.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lighting {
    /// Spherical Gaussians (seed 003).
    #[serde(default)]
    pub spherical_gaussians: bool,
    /// Anisotropic spherical Gaussians (seed 003).
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
    /// θ_max outside (0, π/2].
    #[error("{origin}: incidence.theta_max = {value} is not in (0, π/2]")]
    ThetaMax {
        /// The file.
        origin: String,
        /// The value.
        value: f64,
    },
}

impl Scene {
    /// Parses and validates a scene from JSON text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Scene, SceneError> {
        let scene: Scene = serde_json::from_str(text).map_err(|e| SceneError::Syntax {
            origin: origin.to_string(),
            line: e.line(),
            column: e.column(),
            message: e.to_string(),
        })?;
        scene.validate(origin)
    }

    /// Checks what serde cannot: at least one material, unique names, valid model parameters,
    /// θ_max in (0, π/2].
    pub fn validate(self, origin: &str) -> Result<Scene, SceneError> {
        let scene = self;
        let origin = origin.to_string();
        if scene.materials.is_empty() && !scene.not_audited.is_empty() {
            let list: Vec<String> = scene.not_audited.iter().map(|n| n.to_string()).collect();
            return Err(SceneError::NothingToAudit {
                origin,
                not_audited: list.join("; "),
            });
        }
        if scene.materials.is_empty() {
            return Err(SceneError::NoMaterials { origin });
        }
        for (i, m) in scene.materials.iter().enumerate() {
            if scene.materials[..i].iter().any(|o| o.name == m.name) {
                return Err(SceneError::DuplicateMaterial {
                    origin,
                    name: m.name.clone(),
                });
            }
            if let Err(e) = m.model.build() {
                return Err(SceneError::InvalidModel {
                    origin,
                    name: m.name.clone(),
                    message: e.to_string(),
                });
            }
        }
        let t = scene.incidence.theta_max;
        if !(t > 0.0 && t <= FRAC_PI_2 + 1e-12) {
            return Err(SceneError::ThetaMax { origin, value: t });
        }
        Ok(scene)
    }

    /// Reads a scene file: `.xml` is a Mitsuba 3 scene ([`crate::mitsuba`]), anything else
    /// mfh's JSON.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::Unreadable {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let is_xml = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
        if is_xml {
            return crate::mitsuba::parse(&text, &path.display().to_string());
        }
        Scene::parse(&text, &path.display().to_string())
    }

    /// The embedded default scene.
    pub fn default_scene() -> Scene {
        Scene::parse(DEFAULT_SCENE, "<default scene>").expect("the embedded default scene is valid")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_scene_parses_and_covers_every_family() {
        let s = Scene::default_scene();
        let families: std::collections::BTreeSet<_> =
            s.materials.iter().map(|m| m.model.family()).collect();
        for f in [
            "beckmann",
            "ggx",
            "std",
            "hyper_cauchy",
            "student_fixed_variance",
            "student_general",
            "gtr",
            "piecewise_linear",
            "blend",
            "gaussian_slopes",
        ] {
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
}
