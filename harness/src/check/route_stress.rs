//! Stress cases for the Λ routes of the Student family (issue 12): every route at γ ∈ {20, 50,
//! 90, 171.8, 10³, 10⁶} and θ near normal incidence, at the two incidences of the issue's
//! defects (0.5, 1.2) and near grazing (π/2 − 10⁻⁶), against the oracle the Smith checks use
//! (`oracle::smith_lambda::lambda_oracle`: quadrature of (q − μ)P2, or the Student-t partial expectation).
//!
//! Each case passes; or the route answers a typed `route` error naming its domain (never the
//! default route, which must answer and pass) — and then, where the route's own a-priori
//! rounding bound predicts a loss of at least 1e-6 relative, a second record
//! (`smith.lambda_route_loss`) evaluates the route's formula outside its domain and
//! demonstrates the loss as an expected failure bounded by that prediction; or it is an
//! expected failure of the table (`tolerance::EXPECTED_FAILURES`) within its bound and domain.

use super::{apply_expected, compare, covers, need, Check, Outcome, Planned};
use crate::oracle::smith_lambda::lambda_oracle;
use crate::oracle::Estimate;
use crate::record::{CheckRecord, Verdict};
use crate::subject::Subject;
use crate::tolerance::CLOSED_FORM;
use mfh_reference::geometry::from_spherical;
use mfh_reference::ndf::student_lambda::{self, p2_norm, term_magnitude, ROUTES};
use mfh_reference::{Model, ModelSpec, QueryError};
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;
use std::sync::{Arc, OnceLock};

/// The shapes of issue 12's stress cases.
pub const STRESS_GAMMAS: [f64; 6] = [20.0, 50.0, 90.0, 171.8, 1e3, 1e6];

/// The incidences: near normal, the two defects, near grazing.
pub const STRESS_THETAS: [f64; 4] = [1e-6, 0.5, 1.2, FRAC_PI_2 - 1e-6];

/// Below this predicted relative error the loss of a refused route is not demonstrated (its
/// actual error may then fall below the closed-form tolerance: no expected failure).
pub const LOSS_DEMONSTRATED_FROM: f64 = 1e-6;

const SOURCE: &str = "seed 001 eq 5 (Λ = (1/μ)∫_μ^∞ (q − μ) P2(q) dq), eq 21, 29–30, 36–37, \
                      Table 1, §8 Algorithm 2; issue 12 (stress cases)";

/// The shape key of a Student-family spec (`c` for the general member, else `gamma`).
fn shape_key(spec: &Value) -> Option<&'static str> {
    match spec.get("family")?.as_str()? {
        "std" | "hyper_cauchy" | "student_fixed_variance" => Some("gamma"),
        "student_general" => Some("c"),
        _ => None,
    }
}

/// The standardized cotangent x = cot θ/s(φ) and the STD-equivalent σ = s/√(C − 1) of a
/// Student model, s(φ) = N_C/P2(0, φ).
fn standardized(model: &dyn Model, c: f64, theta: f64, phi: f64) -> Option<(f64, f64)> {
    let s = p2_norm(c) / model.as_slopes()?.p2(0.0, phi);
    Some((1.0 / (theta.tan() * s), s / (c - 1.0).sqrt()))
}

/// Plans the stress cases for a Student-family material with masking: its spec with the shape
/// replaced by each of `STRESS_GAMMAS`, every route, every `STRESS_THETAS`.
pub fn plan(model: &dyn Model, why: &str) -> Vec<Planned> {
    let spec = serde_json::to_value(model.spec()).unwrap_or(Value::Null);
    let Some(key) = shape_key(&spec) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for gamma in STRESS_GAMMAS {
        let mut stress = spec.clone();
        stress[key] = json!(gamma);
        let Ok(parsed) = serde_json::from_value::<ModelSpec>(stress.clone()) else {
            continue;
        };
        let Ok(built) = parsed.build() else {
            continue;
        };
        let m: Arc<dyn Model> = Arc::from(built);
        let family = m.family();
        // One oracle per incidence, shared by the routes (computed by the first to run).
        let oracles: Vec<Arc<OnceLock<Estimate>>> = STRESS_THETAS
            .iter()
            .map(|_| Arc::new(OnceLock::new()))
            .collect();
        for (route, _) in ROUTES {
            let route: &'static str = route;
            for (theta, memo) in STRESS_THETAS.into_iter().zip(oracles.iter().cloned()) {
                let case = json!({"route": route, "theta": theta, "phi": 0.0, "stress": true});
                let (m, spec_run) = (m.clone(), stress.clone());
                out.push(
                    Check::new("smith.lambda_route", stress.clone(), case, SOURCE)
                        .why(format!(
                            "{why}: Λ by route `{route}` stressed at γ = {gamma}"
                        ))
                        .covers(vec![covers(family, "lambda", route)])
                        .run(move |r, _| run_case(r, m.as_ref(), &spec_run, route, theta, &memo)),
                );
            }
        }
    }
    out
}

/// One stress case: the route against the oracle; where the route refuses and predicts a loss
/// ≥ `LOSS_DEMONSTRATED_FROM`, the record becomes `smith.lambda_route_loss`, its formula
/// evaluated outside the domain against the oracle.
fn run_case(
    r: &mut CheckRecord,
    m: &dyn Model,
    spec: &Value,
    route: &'static str,
    theta: f64,
    oracle: &OnceLock<Estimate>,
) -> Outcome {
    let family = m.family();
    let w = from_spherical(theta, 0.0);
    let smith = need(m.as_smith(), "Smith masking")?;
    let c = spec
        .get("gamma")
        .or_else(|| spec.get("c"))
        .and_then(Value::as_f64)
        .unwrap_or(f64::NAN);
    match smith.lambda_route(w, route) {
        Ok(v) => {
            let oracle = *oracle.get_or_init(|| lambda_oracle(&Subject::borrowed(m), w));
            compare(r, v, oracle, &CLOSED_FORM);
            apply_expected(r, family, route);
        }
        Err(QueryError::Route { reason, .. })
            if !matches!(route, "default" | "stable")
                && student_lambda::route(route, c).is_ok() =>
        {
            let (x, sigma) = need(standardized(m, c, theta, 0.0), "slope distribution")?;
            let lambda = student_lambda::lambda_stable(c, x);
            let predicted = term_magnitude(route, c, x)
                .map(|mag| 32.0 * f64::EPSILON / 2.0 * mag / lambda)
                .unwrap_or(f64::NAN);
            if let Some(obj) = r.case.as_object_mut() {
                obj.insert("x".into(), json!(x));
                obj.insert("predicted_relative_error".into(), json!(predicted));
            }
            // Printed routes with an erratum are wrong for another cause than rounding: their
            // loss is not this demonstration's.
            let printed = matches!(
                route,
                "2f1_algorithm2" | "half_integer_printed" | "table1_printed"
            );
            if predicted.is_finite() && predicted >= LOSS_DEMONSTRATED_FROM && !printed {
                // The formula outside its domain: the loss, demonstrated.
                let value = student_lambda::route(route, c)
                    .map(|f| f(c, x, sigma))
                    .unwrap_or(f64::NAN);
                let oracle = *oracle.get_or_init(|| lambda_oracle(&Subject::borrowed(m), w));
                r.check = "smith.lambda_route_loss".into();
                compare(r, value, oracle, &CLOSED_FORM);
                apply_expected(r, family, route);
                if let Verdict::ExpectedFailure { reason: why } = &r.verdict {
                    r.verdict = Verdict::ExpectedFailure {
                        reason: format!("{why}; route refused in the audit: {reason}"),
                    };
                }
            } else {
                r.verdict = Verdict::Skipped {
                    reason: format!("route outside its domain: {reason}"),
                };
            }
        }
        Err(e) => {
            r.verdict = if matches!(route, "default" | "stable") {
                Verdict::Fail
            } else {
                Verdict::Skipped {
                    reason: format!("route does not apply: {e}"),
                }
            };
            if let Some(obj) = r.case.as_object_mut() {
                obj.insert("error".into(), json!(e.to_string()));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::RunContext;

    fn run(spec: Value) -> Vec<CheckRecord> {
        let m: Box<dyn Model> = serde_json::from_value::<ModelSpec>(spec)
            .unwrap()
            .build()
            .unwrap();
        let ctx = RunContext { seed: 1 };
        plan(m.as_ref(), "test")
            .iter()
            .map(|p| (p.run)(&ctx))
            .collect()
    }

    /// Every STD stress case passes, is a refused route (never the default), or an expected
    /// failure within its bound and domain; the defects are refused or pass.
    #[test]
    fn std_stress_cases_pass_or_are_typed_errors() {
        let records = run(json!({"family": "std", "gamma": 2.5, "alpha": 0.3}));
        assert_eq!(
            records.len(),
            STRESS_GAMMAS.len() * ROUTES.len() * STRESS_THETAS.len()
        );
        let mut counts = std::collections::BTreeMap::new();
        for r in &records {
            *counts.entry(r.verdict.name()).or_insert(0) += 1;
            assert!(!r.verdict.is_failure(), "{r:?}");
            let route = r.case["route"].as_str().unwrap();
            if route == "stable" {
                assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
            }
            if route == "2f1_algorithm2_corrected" {
                let lambda = r.oracle.map(|o| o.value).unwrap_or(0.0);
                if lambda >= 1e-300 && r.check == "smith.lambda_route" {
                    assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
                }
            }
        }
        eprintln!("STD stress verdicts: {counts:?}");
        // γ = 90, θ = 1.2: the integer route refuses (it returned 1.78e8 for 0.0075).
        let integer = records
            .iter()
            .find(|r| {
                r.case["route"] == "integer" && r.model["gamma"] == 90.0 && r.case["theta"] == 1.2
            })
            .unwrap();
        assert!(
            matches!(
                integer.verdict,
                Verdict::Skipped { .. } | Verdict::ExpectedFailure { .. }
            ),
            "{integer:?}"
        );
    }
}
