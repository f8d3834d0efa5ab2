//! A material's BSDF in mfh's JSON scenes: `"bsdf": {"type": "conductor" |
//! "dielectric", …}` with the fields of a reference BSDF spec
//! ([`mfh_reference::bsdf::BsdfSpec`], whose own tag is `"bsdf"`; in a scene the tag is `"type"`
//! so that the material's key can be `"bsdf"`).

use mfh_reference::bsdf::{BsdfSpec, ConductorSpec, DielectricSpec};
use serde::{Deserialize, Serialize};

/// The reference BSDF a material names, tagged by `type`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum MaterialBsdf {
    /// `{"type": "conductor", "n", "k", "fresnel", "ndf", "masking", "sampling"}`.
    Conductor(ConductorSpec),
    /// `{"type": "dielectric", "eta", "ndf", "masking", "sampling", "transport"}`.
    Dielectric(DielectricSpec),
}

impl MaterialBsdf {
    /// The reference BSDF spec.
    pub fn spec(&self) -> BsdfSpec {
        match self {
            MaterialBsdf::Conductor(s) => BsdfSpec::Conductor(s.clone()),
            MaterialBsdf::Dielectric(s) => BsdfSpec::Dielectric(s.clone()),
        }
    }

    /// The BSDF's NDF.
    pub fn ndf(&self) -> &mfh_reference::ModelSpec {
        match self {
            MaterialBsdf::Conductor(s) => &s.ndf,
            MaterialBsdf::Dielectric(s) => &s.ndf,
        }
    }

    /// The material's BSDF of a reference spec.
    pub fn of(spec: BsdfSpec) -> Self {
        match spec {
            BsdfSpec::Conductor(s) => MaterialBsdf::Conductor(s),
            BsdfSpec::Dielectric(s) => MaterialBsdf::Dielectric(s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_type_tag_reads_the_reference_spec_fields() {
        let m: MaterialBsdf = serde_json::from_str(
            r#"{"type": "dielectric", "eta": 1.5, "ndf": {"family": "ggx", "alpha": 0.3}}"#,
        )
        .unwrap();
        assert_eq!(m.spec().kind(), "dielectric");
        assert_eq!(m.spec().eta(), Some(1.5));
        assert_eq!(MaterialBsdf::of(m.spec()), m);
        let e = serde_json::from_str::<MaterialBsdf>(
            r#"{"type": "conductor", "n": 0.2, "k": 3, "ndf": {"family": "ggx", "alpha": 0.3}, "eta": 2}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("eta"), "{e}");
    }
}
