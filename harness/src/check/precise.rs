//! Closed forms against the high-precision reference: the default Λ and D of isotropic
//! Beckmann, GGX and STD materials against double-double tanh–sinh values
//! (`oracle::precise`, certified to ~1e-24), at the 1e-14 the closed forms are built for —
//! a hundred times tighter than the quadrature checks of `smith` and `normalization` can see.

use super::{compare, covers, Planned, Profile};
use crate::check::{need, Check};
use crate::oracle::precise::{PreciseError, PreciseModel};
use crate::record::Verdict;
use crate::tolerance::{Tolerance, PRECISE};
use mfh_reference::geometry::from_spherical;
use mfh_reference::Model;
use serde_json::{json, Value};
use std::sync::Arc;

const SOURCE: &str = "seed 001 eq 5 (Λ = (1/μ)∫_μ^∞ (q − μ) P2 dq), eq 2, 10, 15; Table 1";

/// The incidences (Λ) and normal directions (D) checked.
fn thetas(profile: Profile, theta_max: f64) -> Vec<f64> {
    let all: &[f64] = match profile {
        Profile::Ci | Profile::Quick => &[1e-3, 0.7, 1.3],
        Profile::Standard => &[1e-6, 1e-3, 0.3, 0.7, 1.0, 1.3, 1.5],
        Profile::Thorough => &[
            1e-8, 1e-6, 1e-3, 0.1, 0.3, 0.5, 0.7, 0.9, 1.1, 1.3, 1.5, 1.565,
        ],
    };
    all.iter().copied().filter(|t| *t <= theta_max).collect()
}

/// `PRECISE` widened by the f64 evaluation's input rounding, 8 ε κ (κ: the quantity's condition
/// number with respect to cot θ or tan²θ). The rounding is the value's allowance, not the
/// reference's uncertainty, so it widens the tolerance and leaves the certified bound (~1e-24)
/// as the oracle's: put into the bound it would exceed `ORACLE_BOUND_FRACTION` of 1e-14 for
/// κ > 6 and leave the record unresolved.
fn widened(condition: f64) -> Tolerance {
    Tolerance {
        value: PRECISE.value + 8.0 * f64::EPSILON * condition,
        ..PRECISE
    }
}

/// Plans the high-precision checks of a material, if its model has a high-precision
/// reference (isotropic Beckmann, GGX, STD); nothing otherwise.
pub fn plan(model: Arc<dyn Model>, profile: Profile, theta_max: f64, why: &str) -> Vec<Planned> {
    let Ok(precise) = PreciseModel::from_spec(&model.spec()) else {
        return Vec::new();
    };
    let spec = serde_json::to_value(model.spec()).unwrap_or(Value::Null);
    let family = model.family();
    let mut out = Vec::new();
    for quantity in ["lambda", "d"] {
        if quantity == "lambda" && model.as_smith().is_none() {
            continue;
        }
        for theta in thetas(profile, theta_max) {
            let case = json!({"quantity": quantity, "theta": theta, "phi": 0.7});
            let m = model.clone();
            let covered = vec![covers(family, quantity, "default")];
            out.push(
                Check::new("precise.closed_form", spec.clone(), case, SOURCE)
                    .why(format!(
                        "{why}: {quantity} against the double-double reference"
                    ))
                    .covers(covered)
                    .run(move |r, _| {
                        let w = from_spherical(theta, 0.7);
                        let (value, reference) = if quantity == "lambda" {
                            let smith = need(m.as_smith(), "Smith masking")?;
                            let c = precise
                                .lambda(w)
                                .and_then(|c| Ok((c, precise.lambda_condition(w)?)));
                            (smith.lambda(w), c)
                        } else {
                            (m.d(w), precise.d(w).map(|c| (c, precise.d_condition(w))))
                        };
                        match reference {
                            Ok((c, condition)) => {
                                compare(r, value, c.estimate(), &widened(condition));
                                r.cost.evaluations += c.evaluations;
                            }
                            Err(PreciseError::Underflow { value: v }) => {
                                r.verdict = Verdict::Skipped {
                                    reason: format!(
                                        "the value ({v:e}) is below the certified range"
                                    ),
                                };
                            }
                            Err(e) => {
                                r.verdict = Verdict::Error {
                                    message: format!("no high-precision reference: {e}"),
                                };
                            }
                        }
                        Ok(())
                    }),
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::CheckRecord;
    use mfh_reference::ModelSpec;

    fn model(json: &str) -> Arc<dyn Model> {
        let spec: ModelSpec = serde_json::from_str(json).unwrap();
        Arc::from(spec.build().unwrap())
    }

    #[test]
    fn closed_forms_pass_and_a_defect_of_1e_12_fails() {
        let ctx = crate::check::RunContext { seed: 1 };
        for json in [
            r#"{"family":"ggx","alpha":0.3}"#,
            r#"{"family":"beckmann","alpha":0.3}"#,
            r#"{"family":"std","gamma":2.5,"alpha":0.3}"#,
        ] {
            for p in plan(model(json), Profile::Quick, 1.5, "test") {
                let r = (p.run)(&ctx);
                assert!(
                    matches!(r.verdict, Verdict::Pass | Verdict::Skipped { .. }),
                    "{json} {}: {:?} {:?} {:?}",
                    r.case,
                    r.verdict,
                    r.value,
                    r.oracle
                );
            }
        }
        // The same comparison rejects a value 1e-12 off (a hundred times the tolerance).
        let precise =
            PreciseModel::from_spec(&model(r#"{"family":"ggx","alpha":0.3}"#).spec()).unwrap();
        let w = from_spherical(0.7, 0.7);
        let c = precise.lambda(w).unwrap();
        let mut r = CheckRecord::new("precise.closed_form", Value::Null, Value::Null, "");
        compare(&mut r, c.value * (1.0 + 1e-12), c.estimate(), &widened(1.0));
        assert_eq!(r.verdict, Verdict::Fail);
    }

    #[test]
    fn unsupported_models_plan_nothing() {
        let m = model(r#"{"family":"gtr","gamma":2.0,"alpha":0.3}"#);
        assert!(plan(m, Profile::Quick, 1.5, "").is_empty());
        let m = model(r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.4}"#);
        assert!(plan(m, Profile::Quick, 1.5, "").is_empty());
    }
}
