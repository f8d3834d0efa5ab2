//! What a scene uses, for planning only the errata and claims that concern it ("a
//! scene plans only what its materials call for"): the model families of its materials and
//! the effects it exercises (built from a scene by the planner, `plan::errata_scope`: checks
//! know nothing of scenes). Each erratum and claim declares a [`Concern`]; it is planned when
//! the scene uses one of its families (or it names none) and one of its effects (or it names
//! none), and its reason says which.

use std::collections::BTreeSet;

/// An effect a scene exercises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Effect {
    /// A material masks (Smith Λ, G1, G2).
    Masking,
    /// A material samples normals (`sample_wm`).
    SampleNormals,
    /// A material samples visible normals.
    SampleVisible,
    /// A material samples by the pseudo-VNIS of document 001 §7.2.
    PseudoVnis,
    /// Gaussian-slope filtering (document 002's visible-slope moments).
    GaussianSlopes,
    /// Spherical-Gaussian lighting (document 003 §1–2, §4).
    SphericalGaussians,
    /// Anisotropic-spherical-Gaussian lighting (document 003 §3).
    AnisotropicSphericalGaussians,
}

impl Effect {
    /// The name used in reasons.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Masking => "masking",
            Effect::SampleNormals => "normal sampling",
            Effect::SampleVisible => "visible-normal sampling",
            Effect::PseudoVnis => "pseudo-VNIS",
            Effect::GaussianSlopes => "Gaussian-slope filtering",
            Effect::SphericalGaussians => "SG lighting",
            Effect::AnisotropicSphericalGaussians => "ASG lighting",
        }
    }
}

/// The Student-t members of document 001, which share its Λ, sampling and §7 derivations.
pub const STUDENT: &[&str] = &[
    "std",
    "hyper_cauchy",
    "student_fixed_variance",
    "student_general",
];

/// What an erratum or claim is about: families (empty: any) and effects (empty: any).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Concern {
    /// Model families it concerns.
    pub families: &'static [&'static str],
    /// Effects it concerns.
    pub effects: &'static [Effect],
}

impl Concern {
    /// A concern with the given families and effects.
    pub const fn new(families: &'static [&'static str], effects: &'static [Effect]) -> Self {
        Self { families, effects }
    }
}

/// The families and effects a scene uses.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scope {
    /// Families of the scene's materials.
    pub families: BTreeSet<&'static str>,
    /// Effects the scene exercises.
    pub effects: BTreeSet<Effect>,
}

impl Scope {
    /// Every family and effect (the scope of the whole catalogue, for tests and tools).
    pub fn everything() -> Self {
        let families = [
            "beckmann",
            "ggx",
            "gtr",
            "piecewise_linear",
            "blend",
            "gaussian_slopes",
        ]
        .into_iter()
        .chain(STUDENT.iter().copied())
        .collect();
        let effects = [
            Effect::Masking,
            Effect::SampleNormals,
            Effect::SampleVisible,
            Effect::PseudoVnis,
            Effect::GaussianSlopes,
            Effect::SphericalGaussians,
            Effect::AnisotropicSphericalGaussians,
        ]
        .into_iter()
        .collect();
        Self { families, effects }
    }

    /// Whether the scope uses what `concern` is about; if so, the reason (which families and
    /// effects matched).
    pub fn uses(&self, concern: &Concern) -> Option<String> {
        let families: Vec<&str> = concern
            .families
            .iter()
            .copied()
            .filter(|f| self.families.contains(f))
            .collect();
        let effects: Vec<&str> = concern
            .effects
            .iter()
            .filter(|e| self.effects.contains(e))
            .map(|e| e.name())
            .collect();
        if (!concern.families.is_empty() && families.is_empty())
            || (!concern.effects.is_empty() && effects.is_empty())
        {
            return None;
        }
        let mut parts = Vec::new();
        if !families.is_empty() {
            parts.push(format!("family {}", families.join(", ")));
        }
        if !effects.is_empty() {
            parts.push(effects.join(", "));
        }
        Some(if parts.is_empty() {
            "concerns every scene".into()
        } else {
            format!("the scene uses {}", parts.join(" with "))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_concern_needs_one_of_its_families_and_one_of_its_effects() {
        let scope = Scope {
            families: ["std"].into_iter().collect(),
            effects: [Effect::Masking].into_iter().collect(),
        };
        let lambda = Concern::new(STUDENT, &[Effect::Masking]);
        assert_eq!(
            scope.uses(&lambda).as_deref(),
            Some("the scene uses family std with masking")
        );
        assert!(scope
            .uses(&Concern::new(STUDENT, &[Effect::SampleNormals]))
            .is_none());
        assert!(scope.uses(&Concern::new(&["hyper_cauchy"], &[])).is_none());
        assert!(scope
            .uses(&Concern::new(&[], &[Effect::GaussianSlopes]))
            .is_none());
        assert!(Scope::everything()
            .uses(&Concern::new(
                &["gtr"],
                &[Effect::AnisotropicSphericalGaussians]
            ))
            .is_some());
    }

    #[test]
    fn a_one_std_material_scene_plans_only_its_errata_and_claims() {
        use crate::check::Profile;
        use crate::plan::plan;
        use crate::scene::Scene;
        let scene = Scene::parse(
            r#"{"name": "one std", "materials": [{"name": "s",
                "model": {"family": "std", "gamma": 3.0, "alpha": 0.3},
                "masking": "uncorrelated", "sampling": "normals"}]}"#,
            "test",
        )
        .expect("scene");
        let checks: Vec<String> = plan(&scene, Profile::Quick)
            .iter()
            .map(|p| p.check.clone())
            .collect();
        for absent in [
            "claims.hyper_cauchy_includes_ggx",
            "claims.student_fixed_variance",
            "claims.gtr_spline_mean",
            "claims.asg_integral",
        ] {
            assert!(!checks.iter().any(|c| c == absent), "{absent} planned");
        }
        for present in ["claims.std_includes_ggx", "claims.std_eq41_42_sampler"] {
            assert!(checks.iter().any(|c| c == present), "{present} not planned");
        }
        let all = plan(&Scene::default_scene(), Profile::Quick);
        let everything = super::super::plan(&Scope::everything(), "test").len()
            + crate::check::claims::plan(&Scope::everything(), "test").len();
        let planned = all
            .iter()
            .filter(|p| p.check.starts_with("claims.") || p.check == super::super::CHECK)
            .count();
        assert_eq!(
            planned, everything,
            "the default scene plans every erratum and claim"
        );
        let why = all
            .iter()
            .find(|p| p.check == "claims.hyper_cauchy_includes_ggx")
            .map(|p| p.why.clone())
            .unwrap_or_default();
        assert!(why.contains("family hyper_cauchy"), "{why}");
    }
}
