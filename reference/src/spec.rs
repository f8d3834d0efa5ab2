//! Models described as data (`ModelSpec`, serde) and built into validated models. The
//! `ModelSpec` enum is written by the registry (`crate::registry`) from one line per family;
//! each family's spec type lives in its own file and implements [`FamilySpec`].

use serde::{Deserializer, Serializer};

use crate::error::ParamError;
use crate::model::Model;
pub use crate::registry::ModelSpec;

/// Resolves `alpha` or (`alpha_x`, `alpha_y`) into validated per-axis roughness.
pub fn resolve_roughness(
    alpha: Option<f64>,
    alpha_x: Option<f64>,
    alpha_y: Option<f64>,
) -> Result<(f64, f64), ParamError> {
    match (alpha, alpha_x, alpha_y) {
        (Some(a), None, None) => {
            let a = crate::model::check_alpha("alpha", a)?;
            Ok((a, a))
        }
        (None, Some(ax), Some(ay)) => Ok((
            crate::model::check_alpha("alpha_x", ax)?,
            crate::model::check_alpha("alpha_y", ay)?,
        )),
        _ => Err(ParamError::Combination(
            "give either alpha, or both alpha_x and alpha_y".to_string(),
        )),
    }
}

/// What every family's spec type does (each family's file implements it for its spec type; the
/// registry's line for the family makes it a [`ModelSpec`] variant).
pub trait FamilySpec {
    /// Validates the parameters and builds the model.
    fn build(&self) -> Result<Box<dyn Model>, ParamError>;

    /// The parameter (name, value) that puts the model outside the domain of its Smith Λ, if
    /// any: for the Student-t members with γ ≤ 3/2 (and D^G(B, C) with C ≤ 3/2) the mean slope
    /// diverges and Λ = ∞ at every incidence (seed 001 eq 18).
    fn smith_limit(&self) -> Option<(&'static str, f64)> {
        None
    }
}

/// Per-axis roughness written back as a spec's fields: `alpha` when isotropic, otherwise
/// `alpha_x` and `alpha_y` (the inverse of [`resolve_roughness`]).
pub fn roughness_fields(alpha_x: f64, alpha_y: f64) -> (Option<f64>, Option<f64>, Option<f64>) {
    if alpha_x == alpha_y {
        (Some(alpha_x), None, None)
    } else {
        (None, Some(alpha_x), Some(alpha_y))
    }
}

/// The Smith limit of a Student-t shape parameter: Λ exists for `value` > 3/2 only.
pub fn student_smith_limit(field: &'static str, value: f64) -> Option<(&'static str, f64)> {
    (value <= 1.5).then_some((field, value))
}

impl ModelSpec {
    /// The family name, as written in the spec's `family` key.
    pub fn family(&self) -> &'static str {
        crate::registry::info(self).name
    }

    /// Why the model has no Smith Λ (and so no G1 or G2), if that follows from its parameters
    /// ([`FamilySpec::smith_limit`]). The message names the field and the limit.
    pub fn smith_limit(&self) -> Option<String> {
        let (field, value) = self.family_spec().smith_limit()?;
        Some(format!(
            "{} {field} = {value} has no Smith Λ: Λ diverges for {field} ≤ 3/2 (the mean \
             slope is infinite); masking needs {field} > 3/2",
            self.family()
        ))
    }

    /// Validates the parameters and builds the model.
    pub fn build(&self) -> Result<Box<dyn Model>, ParamError> {
        self.family_spec().build()
    }
}

/// γ as a JSON number, or the string `"inf"` for +∞.
pub(crate) mod gamma_serde {
    use super::*;

    pub(crate) fn serialize<S: Serializer>(gamma: &f64, s: S) -> Result<S::Ok, S::Error> {
        if *gamma == f64::INFINITY {
            s.serialize_str("inf")
        } else {
            s.serialize_f64(*gamma)
        }
    }

    /// A visitor rather than an untagged enum, so that a bad γ is reported as such (serde's
    /// untagged enums report only "data did not match any variant of untagged enum …").
    struct GammaVisitor;

    impl serde::de::Visitor<'_> for GammaVisitor {
        type Value = f64;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("gamma as a number or the string \"inf\"")
        }

        fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<f64, E> {
            Ok(x)
        }

        fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<f64, E> {
            Ok(x as f64)
        }

        fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<f64, E> {
            Ok(x as f64)
        }

        fn visit_str<E: serde::de::Error>(self, t: &str) -> Result<f64, E> {
            if matches!(t, "inf" | "infinity" | "Infinity") {
                Ok(f64::INFINITY)
            } else {
                Err(E::custom(format!(
                    "gamma must be a number or \"inf\" (got {t:?})"
                )))
            }
        }
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        d.deserialize_any(GammaVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ModelSpec, serde_json::Error> {
        serde_json::from_str(text)
    }

    #[test]
    fn parse_build_and_round_trip() {
        let s = parse(r#"{"family":"std","gamma":"inf","alpha":0.3}"#).expect("parses");
        assert!(matches!(&s, ModelSpec::Std(std) if std.gamma == f64::INFINITY));
        let m = s.build().expect("builds");
        assert_eq!(m.family(), "std");
        assert_eq!(m.spec(), s);
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(text, r#"{"family":"std","gamma":"inf","alpha":0.3}"#);
        let s =
            parse(r#"{"family":"hyper_cauchy","gamma":3,"alpha_x":0.1,"alpha_y":0.2}"#).unwrap();
        assert_eq!(s.build().unwrap().spec(), s);
        let s = parse(r#"{"family":"student_general","b":4,"c":2.5}"#).unwrap();
        assert_eq!(s.build().unwrap().spec(), s);
    }

    #[test]
    fn piecewise_and_blend_specs_round_trip() {
        let text = r#"{"family":"piecewise_linear","x":{"theta":[0.0,0.5,1.5707963267948966],"value":[2.0,1.0,0.0]}}"#;
        let s = parse(text).unwrap();
        assert_eq!(s.family(), "piecewise_linear");
        let m = s.build().unwrap();
        assert_eq!(m.family(), "piecewise_linear");
        assert_eq!(m.spec(), s);
        assert_eq!(serde_json::to_string(&s).unwrap(), text);
        let text = r#"{"family":"piecewise_linear","x":{"theta":[0.0,1.5707963267948966],"value":[1.0,0.0]},"y":{"theta":[0.0,0.7,1.5707963267948966],"value":[0.0,3.0,1.0]}}"#;
        let s = parse(text).unwrap();
        assert_eq!(s.build().unwrap().spec(), s);
        assert_eq!(serde_json::to_string(&s).unwrap(), text);
        let text = r#"{"family":"blend","x":{"family":"ggx","alpha":0.2},"y":{"family":"beckmann","alpha":0.5}}"#;
        let s = parse(text).unwrap();
        assert_eq!(s.family(), "blend");
        assert_eq!(s.build().unwrap().spec(), s);
        assert_eq!(serde_json::to_string(&s).unwrap(), text);
        // Unknown keys (also inside a profile) and bad profiles are errors.
        assert!(parse(r#"{"family":"piecewise_linear","x":{"theta":[0,1.5707963267948966],"value":[1,1],"n":2}}"#).is_err());
        assert!(parse(r#"{"family":"piecewise_linear","x":{"theta":[0,1.5707963267948966],"value":[1,1]},"z":1}"#).is_err());
        let s =
            parse(r#"{"family":"piecewise_linear","x":{"theta":[0,1.5],"value":[1,1]}}"#).unwrap();
        assert!(matches!(
            s.build().map(|_| ()).unwrap_err(),
            ParamError::InvalidProfile { .. }
        ));
        let s = parse(r#"{"family":"blend","x":{"family":"ggx","alpha_x":0.1,"alpha_y":0.3},"y":{"family":"ggx","alpha":0.2}}"#).unwrap();
        assert!(matches!(
            s.build().map(|_| ()).unwrap_err(),
            ParamError::NotIsotropic { .. }
        ));
    }

    #[test]
    fn gtr_spec_round_trips() {
        let s = parse(r#"{"family":"gtr","gamma":1.5,"alpha":0.3}"#).unwrap();
        assert_eq!(
            s,
            ModelSpec::Gtr(crate::ndf::gtr::GtrSpec {
                gamma: 1.5,
                alpha: 0.3
            })
        );
        assert_eq!(s.family(), "gtr");
        let m = s.build().unwrap();
        assert_eq!(m.family(), "gtr");
        assert_eq!(m.spec(), s);
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(text, r#"{"family":"gtr","gamma":1.5,"alpha":0.3}"#);
        assert_eq!(parse(&text).unwrap(), s);
        assert!(parse(r#"{"family":"gtr","gamma":1.5}"#).is_err());
        assert!(parse(r#"{"family":"gtr","gamma":1.5,"alpha":0.3,"alpha_x":0.3}"#).is_err());
        let bad = parse(r#"{"family":"gtr","gamma":11,"alpha":0.3}"#).unwrap();
        assert!(matches!(
            bad.build().map(|_| ()).unwrap_err(),
            ParamError::GammaOutOfRange { .. }
        ));
    }

    #[test]
    fn unknown_keys_and_bad_gamma_are_errors() {
        let e = parse(r#"{"family":"ggx","alpha":0.3,"gamma":2}"#).unwrap_err();
        assert!(e.to_string().contains("gamma"), "{e}");
        assert!(parse(r#"{"family":"std","gamma":"many","alpha":0.3}"#).is_err());
        assert!(parse(r#"{"family":"nope","alpha":0.3}"#).is_err());
    }

    #[test]
    fn bad_parameters_are_typed_errors() {
        let e = resolve_roughness(Some(0.1), Some(0.2), None).unwrap_err();
        assert!(matches!(e, ParamError::Combination(_)));
        let e = resolve_roughness(Some(f64::NAN), None, None).unwrap_err();
        assert!(matches!(e, ParamError::AlphaNotPositive { .. }));
        let e = resolve_roughness(None, Some(0.1), Some(-1.0)).unwrap_err();
        assert!(matches!(
            e,
            ParamError::AlphaNotPositive {
                name: "alpha_y",
                ..
            }
        ));
        for gamma in [1.0, 0.5, f64::NAN, 2e8] {
            let e = parse(&format!(
                r#"{{"family":"std","gamma":{},"alpha":0.3}}"#,
                if gamma.is_nan() {
                    "\"nan\"".to_string()
                } else {
                    gamma.to_string()
                }
            ));
            match e {
                Ok(s) => assert!(matches!(
                    s.build().map(|_| ()).unwrap_err(),
                    ParamError::GammaOutOfRange { .. }
                )),
                Err(_) => assert!(gamma.is_nan()),
            }
        }
        let e = parse(r#"{"family":"student_fixed_variance","gamma":2,"alpha":0.3}"#).unwrap();
        assert!(e.build().is_err());
        let e = parse(r#"{"family":"student_general","b":0,"c":2.5}"#).unwrap();
        assert!(e.build().is_err());
    }
}
