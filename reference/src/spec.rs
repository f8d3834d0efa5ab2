//! Models described as data (`ModelSpec`, serde) and built into validated models.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::ParamError;
use crate::model::Model;
use crate::ndf::{Beckmann, Blend, Ggx, PiecewiseLinear, Profile, Student};

/// A model described as data, e.g. `{"family": "std", "gamma": 2.5, "alpha": 0.3}`
/// (ARCHITECTURE.md, "Evaluating closed forms"). Unknown keys are errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case", deny_unknown_fields)]
pub enum ModelSpec {
    /// Beckmann (seed 001, Table 1, γ → ∞).
    Beckmann {
        /// Isotropic roughness.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<f64>,
        /// Roughness along x.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_x: Option<f64>,
        /// Roughness along y.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_y: Option<f64>,
    },
    /// GGX / Trowbridge–Reitz (seed 001, Table 1, γ = 2).
    Ggx {
        /// Isotropic roughness.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<f64>,
        /// Roughness along x.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_x: Option<f64>,
        /// Roughness along y.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_y: Option<f64>,
    },
    /// Student's t NDF, STD (seed 001, f = 1/(γ−1)); `gamma: "inf"` is Beckmann.
    Std {
        /// Shape γ > 1, or +∞.
        #[serde(with = "gamma_serde")]
        gamma: f64,
        /// Isotropic roughness.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<f64>,
        /// Roughness along x.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_x: Option<f64>,
        /// Roughness along y.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_y: Option<f64>,
    },
    /// Hyper-Cauchy (seed 001, eq 8, f = 1).
    HyperCauchy {
        /// Shape γ > 1.
        #[serde(with = "gamma_serde")]
        gamma: f64,
        /// Isotropic roughness.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<f64>,
        /// Roughness along x.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_x: Option<f64>,
        /// Roughness along y.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_y: Option<f64>,
    },
    /// The fixed-variance Student member (seed 001, eq 9, f = 1/(γ−2)); `gamma: "inf"` is
    /// Beckmann.
    StudentFixedVariance {
        /// Shape γ > 2, or +∞.
        #[serde(with = "gamma_serde")]
        gamma: f64,
        /// Isotropic roughness.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha: Option<f64>,
        /// Roughness along x.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_x: Option<f64>,
        /// Roughness along y.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        alpha_y: Option<f64>,
    },
    /// The general isotropic family D^G(B, C) (seed 001, eq 1–2).
    StudentGeneral {
        /// B > 0.
        b: f64,
        /// C > 1.
        c: f64,
    },
    /// The piecewise-linear NDF (seed 000, eq 1–5).
    PiecewiseLinear {
        /// The profile D_x (alone: the isotropic D_iso).
        x: Profile,
        /// The profile D_y of the anisotropic blend (eq 1).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        y: Option<Profile>,
    },
    /// Two isotropic models combined by eq 1 of seed 000.
    Blend {
        /// The model along x.
        x: Box<ModelSpec>,
        /// The model along y.
        y: Box<ModelSpec>,
    },
    /// A Gaussian distribution of slopes N(s̄, Σ) (seed 002, eq 1; slope sign of eq 11).
    GaussianSlopes {
        /// The mean slope s̄ = `[s̄x, s̄y]`.
        mean: [f64; 2],
        /// The covariance Σ = `[[σx², cxy], [cxy, σy²]]`, symmetric positive definite.
        cov: [[f64; 2]; 2],
    },
    /// Generalized-Trowbridge-Reitz (Burley 2012; Smith G1 of seed 004), isotropic.
    Gtr {
        /// Shape 0 ≤ γ ≤ 10.
        gamma: f64,
        /// Roughness 1e-4 ≤ α ≤ 1.
        alpha: f64,
    },
}

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

impl ModelSpec {
    /// The family name, as written in the spec's `family` key.
    pub fn family(&self) -> &'static str {
        match self {
            ModelSpec::Beckmann { .. } => "beckmann",
            ModelSpec::Ggx { .. } => "ggx",
            ModelSpec::Std { .. } => "std",
            ModelSpec::HyperCauchy { .. } => "hyper_cauchy",
            ModelSpec::StudentFixedVariance { .. } => "student_fixed_variance",
            ModelSpec::StudentGeneral { .. } => "student_general",
            ModelSpec::PiecewiseLinear { .. } => "piecewise_linear",
            ModelSpec::Blend { .. } => "blend",
            ModelSpec::GaussianSlopes { .. } => "gaussian_slopes",
            ModelSpec::Gtr { .. } => "gtr",
        }
    }

    /// Why the model has no Smith Λ (and so no G1 or G2), if that follows from its parameters:
    /// for the Student-t members with γ ≤ 3/2 (and D^G(B, C) with C ≤ 3/2) the mean slope
    /// diverges and Λ = ∞ at every incidence (seed 001 eq 18: the slope integral behind Λ,
    /// ((γ−1)σ² + μ²)^{3/2−γ}/(3−2γ), diverges for γ ≤ 3/2).
    /// The message names the field and the limit.
    pub fn smith_limit(&self) -> Option<String> {
        let (field, value) = match *self {
            ModelSpec::Std { gamma, .. } | ModelSpec::HyperCauchy { gamma, .. } => ("gamma", gamma),
            ModelSpec::StudentGeneral { c, .. } => ("c", c),
            _ => return None,
        };
        (value <= 1.5).then(|| {
            format!(
                "{} {field} = {value} has no Smith Λ: Λ diverges for {field} ≤ 3/2 (the mean \
                 slope is infinite); masking needs {field} > 3/2",
                self.family()
            )
        })
    }

    /// Validates the parameters and builds the model.
    pub fn build(&self) -> Result<Box<dyn Model>, ParamError> {
        use crate::ndf::student::Member;
        Ok(match *self {
            ModelSpec::Beckmann {
                alpha,
                alpha_x,
                alpha_y,
            } => {
                let (ax, ay) = resolve_roughness(alpha, alpha_x, alpha_y)?;
                Box::new(Beckmann::new(ax, ay)?)
            }
            ModelSpec::Ggx {
                alpha,
                alpha_x,
                alpha_y,
            } => {
                let (ax, ay) = resolve_roughness(alpha, alpha_x, alpha_y)?;
                Box::new(Ggx::new(ax, ay)?)
            }
            ModelSpec::Std {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            } => {
                let (ax, ay) = resolve_roughness(alpha, alpha_x, alpha_y)?;
                if gamma == f64::INFINITY {
                    Box::new(Beckmann::new(ax, ay)?.described_as(self.clone()))
                } else {
                    Box::new(Student::new(Member::Std, gamma, ax, ay)?)
                }
            }
            ModelSpec::HyperCauchy {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            } => {
                let (ax, ay) = resolve_roughness(alpha, alpha_x, alpha_y)?;
                Box::new(Student::new(Member::HyperCauchy, gamma, ax, ay)?)
            }
            ModelSpec::StudentFixedVariance {
                gamma,
                alpha,
                alpha_x,
                alpha_y,
            } => {
                let (ax, ay) = resolve_roughness(alpha, alpha_x, alpha_y)?;
                if gamma == f64::INFINITY {
                    Box::new(Beckmann::new(ax, ay)?.described_as(self.clone()))
                } else {
                    Box::new(Student::new(Member::FixedVariance, gamma, ax, ay)?)
                }
            }
            ModelSpec::StudentGeneral { b, c } => Box::new(Student::general(b, c)?),
            ModelSpec::PiecewiseLinear { ref x, ref y } => {
                Box::new(PiecewiseLinear::new(x.clone(), y.clone())?)
            }
            ModelSpec::Blend { ref x, ref y } => Box::new(Blend::new(x.build()?, y.build()?)?),
            ModelSpec::GaussianSlopes { mean, cov } => {
                Box::new(crate::slopes::GaussianSlopes::new(mean, cov)?)
            }
            ModelSpec::Gtr { gamma, alpha } => Box::new(crate::ndf::Gtr::new(gamma, alpha)?),
        })
    }
}

/// γ as a JSON number, or the string `"inf"` for +∞.
mod gamma_serde {
    use super::*;

    pub fn serialize<S: Serializer>(gamma: &f64, s: S) -> Result<S::Ok, S::Error> {
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

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
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
        assert!(matches!(s, ModelSpec::Std { gamma, .. } if gamma == f64::INFINITY));
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
            ModelSpec::Gtr {
                gamma: 1.5,
                alpha: 0.3
            }
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
