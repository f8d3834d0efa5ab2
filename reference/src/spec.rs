//! Models described as data: [`ModelSpec`], e.g. `{"family": "std", "gamma": 2.5, "alpha": 0.3}`
//! (ARCHITECTURE.md, "Evaluating closed forms"), the spec type of every family, and the family
//! registry's list (`families!`: one entry per family, from which [`ModelSpec`] here and the
//! registry's lists in [`crate::registry`] are written). A spec is parameters only: each
//! family's file builds its model from its spec type, describes its model as one
//! ([`crate::family::FamilySpec`], [`crate::model::Model::spec`]) and attaches the family's
//! facts to its spec type (`SpecType::INFO`). This file names no model, so the models and the
//! registry may name it (the reference crate's files import one another without a cycle:
//! `reference/tests/layers.rs`).

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::ndf::angular_profile::AngularProfile;

/// Declares [`ModelSpec`] from the registry's list (`families!`). Writes the enum
/// (serde-tagged by `family`), [`ModelSpec::family`] and `From<SpecType> for ModelSpec`.
macro_rules! model_spec {
    ($($(#[$doc:meta])* $variant:ident($spec:ty) = $name:literal),+ $(,)?) => {
        /// A model described as data, e.g. `{"family": "std", "gamma": 2.5, "alpha": 0.3}`.
        /// Unknown keys are errors. Each variant holds its family's spec type (below), one
        /// per entry of the registry's list (`families!`).
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "family")]
        pub enum ModelSpec {
            $($(#[$doc])* #[serde(rename = $name)] $variant($spec),)+
        }

        impl ModelSpec {
            /// The family name, as written in the spec's `family` key.
            pub fn family(&self) -> &'static str {
                match self {
                    $(ModelSpec::$variant(_) => $name,)+
                }
            }
        }

        $(impl From<$spec> for ModelSpec {
            fn from(s: $spec) -> ModelSpec {
                ModelSpec::$variant(s)
            }
        })+
    };
}

/// The family registry's list: one entry per family, `Variant(SpecType) = "name"` — the
/// [`ModelSpec`] variant, the family's spec type (declared below; the family's file implements
/// [`crate::family::FamilySpec`] for it, its constructor, and declares `SpecType::INFO`, the
/// family's [`crate::family::FamilyInfo`]: sources, examples, stress values, flags, measured
/// sampler cost) and the `family` key of its specs. Every other list of families is written
/// from this one: `families!(m)` hands the list to the macro `m`, here [`ModelSpec`]'s and in
/// [`crate::registry`] the registry's ([`crate::registry::FAMILIES`], `info`, `by_name`, the
/// dispatch of [`crate::family::FamilySpec`]). Adding a family: its file, its spec type and one
/// entry here (ARCHITECTURE.md, "A new NDF family").
macro_rules! families {
    ($then:ident) => {
        $then! {
            /// Beckmann (document 001, Table 1, γ → ∞).
            Beckmann(BeckmannSpec) = "beckmann",
            /// GGX / Trowbridge–Reitz (document 001, Table 1, γ = 2).
            Ggx(GgxSpec) = "ggx",
            /// Student's t NDF, STD (document 001, f = 1/(γ−1)); `gamma: "inf"` is Beckmann.
            Std(StdSpec) = "std",
            /// Hyper-Cauchy (document 001, eq 8, f = 1).
            HyperCauchy(HyperCauchySpec) = "hyper_cauchy",
            /// The fixed-variance Student member (document 001, eq 9, f = 1/(γ−2)); `gamma: "inf"` is
            /// Beckmann.
            StudentFixedVariance(FixedVarianceSpec) = "student_fixed_variance",
            /// The general isotropic family D^G(B, C) (document 001, eq 1–2).
            StudentGeneral(GeneralSpec) = "student_general",
            /// The piecewise-linear NDF (document 000, eq 1–5).
            PiecewiseLinear(PiecewiseSpec) = "piecewise_linear",
            /// Two isotropic models combined by eq 1 of document 000.
            Blend(BlendSpec) = "blend",
            /// Generalized-Trowbridge-Reitz (Burley 2012; Smith G1 of document 004), isotropic.
            Gtr(GtrSpec) = "gtr",
            /// A Gaussian distribution of slopes N(s̄, Σ) (document 002, eq 1; slope sign of eq 11).
            GaussianSlopes(GaussianSlopesSpec) = "gaussian_slopes",
        }
    };
}
pub(crate) use families;

families!(model_spec);

/// Declares the spec type of a family parameterized by roughness only: `alpha`, or `alpha_x`
/// and `alpha_y` (validated when the model is built).
macro_rules! roughness_spec {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            /// Isotropic roughness.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha: Option<f64>,
            /// Roughness along x.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha_x: Option<f64>,
            /// Roughness along y.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha_y: Option<f64>,
        }
    };
}

/// Declares the spec type of a Student member parameterized by γ and roughness (STD,
/// Hyper-Cauchy, fixed variance: the same fields, a different member).
macro_rules! student_spec {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            /// Shape γ (a number, or the string `"inf"`).
            #[serde(with = "gamma_serde")]
            pub gamma: f64,
            /// Isotropic roughness.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha: Option<f64>,
            /// Roughness along x.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha_x: Option<f64>,
            /// Roughness along y.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub alpha_y: Option<f64>,
        }
    };
}

roughness_spec!(
    /// The spec of a Beckmann model: `{"family": "beckmann", "alpha": 0.3}`, or `alpha_x` and
    /// `alpha_y`.
    BeckmannSpec
);
roughness_spec!(
    /// The spec of a GGX model: `{"family": "ggx", "alpha": 0.3}`, or `alpha_x` and `alpha_y`.
    GgxSpec
);
student_spec!(
    /// The spec of an STD model (document 001, f = 1/(γ−1)): `{"family": "std", "gamma": 2.5,
    /// "alpha": 0.3}`; `gamma: "inf"` is Beckmann.
    StdSpec
);
student_spec!(
    /// The spec of a Hyper-Cauchy model (document 001 eq 8, f = 1), γ > 1.
    HyperCauchySpec
);
student_spec!(
    /// The spec of the fixed-variance Student member (document 001 eq 9, f = 1/(γ−2)), γ > 2;
    /// `gamma: "inf"` is Beckmann.
    FixedVarianceSpec
);

/// The spec of the general isotropic family D^G(B, C) (document 001 eq 1–2):
/// `{"family": "student_general", "b": 4, "c": 2.5}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeneralSpec {
    /// B > 0.
    pub b: f64,
    /// C > 1.
    pub c: f64,
}

/// The spec of a piecewise-linear NDF: `{"family": "piecewise_linear", "x": {"theta": […],
/// "value": […]}}`, with an optional profile `y` for the anisotropic blend.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PiecewiseSpec {
    /// The profile D_x (alone: the isotropic D_iso).
    pub x: AngularProfile,
    /// The profile D_y of the anisotropic blend (eq 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<AngularProfile>,
}

/// The spec of a blend: `{"family": "blend", "x": {…}, "y": {…}}`, two isotropic model specs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendSpec {
    /// The model along x.
    pub x: Box<ModelSpec>,
    /// The model along y.
    pub y: Box<ModelSpec>,
}

/// The spec of a GTR model: `{"family": "gtr", "gamma": 1.5, "alpha": 0.3}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GtrSpec {
    /// Shape 0 ≤ γ ≤ 10.
    pub gamma: f64,
    /// Roughness 1e-4 ≤ α ≤ 1.
    pub alpha: f64,
}

/// The spec of a Gaussian distribution of slopes:
/// `{"family": "gaussian_slopes", "mean": [0, 0], "cov": [[0.1, 0], [0, 0.2]]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussianSlopesSpec {
    /// The mean slope s̄ = `[s̄x, s̄y]`.
    pub mean: [f64; 2],
    /// The covariance Σ = `[[σx², cxy], [cxy, σy²]]`, symmetric positive definite.
    pub cov: [[f64; 2]; 2],
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
    use crate::error::ParamError;

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
            ModelSpec::Gtr(GtrSpec {
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
