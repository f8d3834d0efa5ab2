//! The reference `mfh audit-external --against` compares with: an NDF spec
//! (`{"family":"ggx","alpha":0.3}`) for a child that offers an NDF, or a BSDF spec
//! (`{"bsdf":"dielectric","eta":1.5,"ndf":{…}}`, told apart by its `"bsdf"` field) for one that
//! offers a BSDF. Parsed and validated before the child starts, so that a typo costs no audit.

use mfh_reference::bsdf::BsdfSpec;
use mfh_reference::ModelSpec;
use serde_json::Value;

/// A validated `--against` reference.
#[derive(Debug, Clone)]
pub enum Against {
    /// A reference NDF (compared with the child's NDF capabilities).
    Ndf(ModelSpec),
    /// A reference BSDF (compared with the child's BSDF).
    Bsdf(BsdfSpec),
}

impl Against {
    /// The reference of `text` (JSON): a BSDF spec if it is an object with a `"bsdf"` field,
    /// else an NDF spec; or why it is neither (a typed message quoting the text).
    pub fn parse(text: &str) -> Result<Self, String> {
        let value: Value = serde_json::from_str(text)
            .map_err(|e| format!("{text:?} is not a reference spec (JSON): {e}"))?;
        if value.get("bsdf").is_some() {
            let spec: BsdfSpec = serde_json::from_value(value)
                .map_err(|e| format!("{text:?} is not a reference BSDF spec: {e}"))?;
            spec.validate()
                .map_err(|e| format!("the reference BSDF spec {text} is invalid: {e}"))?;
            return Ok(Against::Bsdf(spec));
        }
        let spec: ModelSpec = serde_json::from_value(value)
            .map_err(|e| format!("{text:?} is not a reference model spec (JSON): {e}"))?;
        spec.build()
            .map_err(|e| format!("the reference spec {text} is invalid: {e}"))?;
        Ok(Against::Ndf(spec))
    }

    /// What the reference is of, for messages (`an NDF`, `a BSDF`).
    pub fn kind(&self) -> &'static str {
        match self {
            Against::Ndf(_) => "an NDF",
            Against::Bsdf(_) => "a BSDF",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bsdf_and_ndf_specs_are_told_apart_and_bad_ones_named() {
        let a =
            Against::parse(r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#);
        assert!(matches!(a, Ok(Against::Bsdf(_))), "{a:?}");
        let a = Against::parse(r#"{"family":"ggx","alpha":0.3}"#);
        assert!(matches!(a, Ok(Against::Ndf(_))), "{a:?}");
        let e =
            Against::parse(r#"{"bsdf":"dielectric","eta":1.0,"ndf":{"family":"ggx","alpha":0.3}}"#)
                .unwrap_err();
        assert!(e.contains("eta") && e.contains("invalid"), "{e}");
        let e = Against::parse(r#"{"bsdf":"glass"}"#).unwrap_err();
        assert!(e.contains("BSDF spec"), "{e}");
        let e = Against::parse("{nope").unwrap_err();
        assert!(e.contains("JSON"), "{e}");
    }
}
