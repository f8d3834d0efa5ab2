//! Stress cases for the Λ routes of the Student family: every route at γ ∈ {20, 50,
//! 90, 171.8, 10³, 10⁶} and θ near normal incidence, at the two incidences of the issue's
//! defects (0.5, 1.2) and near grazing (π/2 − 10⁻⁶), against the oracle the Smith checks use
//! (`oracle::smith_lambda::lambda_oracle`: quadrature of (q − μ)P2, or the Student-t partial expectation).
//!
//! A case is planned where the route applies (it answers; the planner asks it): it passes, or
//! it is an expected failure of the table (`tolerance::EXPECTED_FAILURES`) within its bound and
//! domain. Where the route refuses with a typed `route` error naming its domain (never the
//! default route, which must answer and pass), the case is planned only where the route's own
//! a-priori rounding bound predicts a loss of at least 1e-6 relative: its record
//! (`smith.lambda_route_loss`) evaluates the route's formula outside its domain and
//! demonstrates the loss as an expected failure bounded by that prediction. The other refusals
//! are stated, once per family and route, by `route_domain` (`smith.lambda_route_domain`).

use super::{apply_expected, compare, covers, need, Check, Planned};
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

/// The shapes of the stress cases.
pub const STRESS_GAMMAS: [f64; 6] = [20.0, 50.0, 90.0, 171.8, 1e3, 1e6];

/// The incidences: near normal, the two defects, near grazing.
pub const STRESS_THETAS: [f64; 4] = [1e-6, 0.5, 1.2, FRAC_PI_2 - 1e-6];

/// Below this predicted relative error the loss of a refused route is not demonstrated (its
/// actual error may then fall below the closed-form tolerance: no expected failure).
pub const LOSS_DEMONSTRATED_FROM: f64 = 1e-6;

const SOURCE: &str = "seed 001 eq 5 (Λ = (1/μ)∫_μ^∞ (q − μ) P2(q) dq), eq 21, 29–30, 36–37, \
                      Table 1, §8 Algorithm 2; stress cases (γ ∈ {20, 50, 90})";

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

/// A stressed variant of a material: its spec with the shape replaced by one of
/// `STRESS_GAMMAS`, built.
#[derive(Clone)]
pub struct StressModel {
    /// The variant.
    pub model: Arc<dyn Model>,
    /// Its spec (as records carry it).
    pub spec: Value,
    /// Its shape γ (or C).
    pub shape: f64,
}

/// The stressed variants of a Student-family material (none for another family).
pub fn stress_models(spec: &ModelSpec) -> Vec<StressModel> {
    let spec = serde_json::to_value(spec).unwrap_or(Value::Null);
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
        out.push(StressModel {
            model: Arc::from(built),
            spec: stress,
            shape: gamma,
        });
    }
    out
}

/// Whether a stress case is checked, from the route's answer: where the route answers, where
/// it refuses but its loss is demonstrated (`loss_prediction`), and always for the default
/// route (whose refusal is a failure). Elsewhere the route does not apply: the case is not
/// planned, and `route_domain` states it.
pub fn is_checked(
    m: &dyn Model,
    route: &str,
    theta: f64,
    answer: &Result<f64, QueryError>,
) -> bool {
    match answer {
        Ok(_) => true,
        Err(_) if matches!(route, "default" | "stable") => true,
        Err(QueryError::Route { .. }) => loss_prediction(m, route, theta).is_some(),
        Err(_) => false,
    }
}

/// Plans the stress cases for a Student-family material with masking: its spec with the shape
/// replaced by each of `STRESS_GAMMAS`, every route, every `STRESS_THETAS`, where the route
/// applies or its loss is demonstrated ([`is_checked`]). The route is asked at plan time; its
/// answer is what the check judges.
pub fn plan(model: &dyn Model, why: &str) -> Vec<Planned> {
    let mut out = Vec::new();
    for StressModel {
        model: m,
        spec: stress,
        shape: gamma,
    } in stress_models(&model.spec())
    {
        let family = m.family();
        let Some(smith) = m.as_smith() else {
            continue;
        };
        // One oracle per incidence, shared by the routes (computed by the first to run).
        let oracles: Vec<Arc<OnceLock<Estimate>>> = STRESS_THETAS
            .iter()
            .map(|_| Arc::new(OnceLock::new()))
            .collect();
        for (route, _) in ROUTES {
            let route: &'static str = route;
            for (theta, memo) in STRESS_THETAS.into_iter().zip(oracles.iter().cloned()) {
                let answer = smith.lambda_route(from_spherical(theta, 0.0), route);
                if !is_checked(m.as_ref(), route, theta, &answer) {
                    continue;
                }
                let case = json!({"route": route, "theta": theta, "phi": 0.0, "stress": true});
                let m = m.clone();
                out.push(
                    Check::new("smith.lambda_route", stress.clone(), case, SOURCE)
                        .why(format!(
                            "{why}: Λ by route `{route}` stressed at γ = {gamma}"
                        ))
                        .covers(vec![covers(family, "lambda", route)])
                        .run(move |r, _| {
                            need(m.as_smith(), "Smith masking")?;
                            run_case(r, m.as_ref(), route, theta, answer.clone(), &memo);
                            Ok(())
                        }),
                );
            }
        }
    }
    out
}

/// A refused route's predicted loss at a stress case: the shape C, the standardized cotangent
/// x = cot θ/s, the STD-equivalent σ and the relative error the route's a-priori rounding
/// bound predicts.
struct Loss {
    c: f64,
    x: f64,
    sigma: f64,
    predicted: f64,
}

/// The loss a refused route's a-priori rounding bound predicts at θ (φ = 0), where it is at
/// least `LOSS_DEMONSTRATED_FROM` for a route whose shape domain holds and that is not printed
/// with an erratum (printed routes are wrong for another cause than rounding): the refused
/// routes whose loss the stress cases demonstrate. None otherwise.
fn loss_prediction(m: &dyn Model, route: &str, theta: f64) -> Option<Loss> {
    let spec = serde_json::to_value(m.spec()).ok()?;
    let c = spec
        .get("gamma")
        .or_else(|| spec.get("c"))
        .and_then(Value::as_f64)?;
    if matches!(route, "default" | "stable") || student_lambda::route(route, c).is_err() {
        return None;
    }
    let printed = matches!(
        route,
        "2f1_algorithm2" | "half_integer_printed" | "table1_printed"
    );
    let (x, sigma) = standardized(m, c, theta, 0.0)?;
    let lambda = student_lambda::lambda_stable(c, x);
    let predicted = term_magnitude(route, c, x)
        .map(|mag| 32.0 * f64::EPSILON / 2.0 * mag / lambda)
        .unwrap_or(f64::NAN);
    (predicted.is_finite() && predicted >= LOSS_DEMONSTRATED_FROM && !printed).then_some(Loss {
        c,
        x,
        sigma,
        predicted,
    })
}

/// One stress case from the route's `answer`: an answer against the oracle; a refusal whose
/// loss is predicted ([`loss_prediction`]) becomes `smith.lambda_route_loss`, the route's
/// formula evaluated outside the domain against the oracle; a refusal of the default route
/// fails.
fn run_case(
    r: &mut CheckRecord,
    m: &dyn Model,
    route: &'static str,
    theta: f64,
    answer: Result<f64, QueryError>,
    oracle: &OnceLock<Estimate>,
) {
    let family = m.family();
    let w = from_spherical(theta, 0.0);
    let error = match answer {
        Ok(v) => {
            let oracle = *oracle.get_or_init(|| lambda_oracle(&Subject::borrowed(m), w));
            compare(r, v, oracle, &CLOSED_FORM);
            apply_expected(r, family, route);
            return;
        }
        Err(e) => e,
    };
    if let (QueryError::Route { reason, .. }, Some(loss)) =
        (&error, loss_prediction(m, route, theta))
    {
        if let Some(obj) = r.case.as_object_mut() {
            obj.insert("x".into(), json!(loss.x));
            obj.insert("predicted_relative_error".into(), json!(loss.predicted));
        }
        // The formula outside its domain: the loss, demonstrated.
        let value = student_lambda::route(route, loss.c)
            .map(|f| f(loss.c, loss.x, loss.sigma))
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
        return;
    }
    // Planned with an error only for the default route, which must answer.
    r.verdict = Verdict::Fail;
    if let Some(obj) = r.case.as_object_mut() {
        obj.insert("error".into(), json!(error.to_string()));
    }
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

    /// Every planned STD stress case passes or is an expected failure within its bound and
    /// domain (never skipped); the default route is always planned; a case is planned exactly
    /// where `is_checked` says; the defects are refused or pass.
    #[test]
    fn std_stress_cases_pass_or_demonstrate_a_loss() {
        let spec = json!({"family": "std", "gamma": 2.5, "alpha": 0.3});
        let records = run(spec.clone());
        let m: Box<dyn Model> = serde_json::from_value::<ModelSpec>(spec)
            .unwrap()
            .build()
            .unwrap();
        let mut checked = 0;
        for s in stress_models(&m.spec()) {
            let smith = s.model.as_smith().unwrap();
            for (route, _) in ROUTES {
                for theta in STRESS_THETAS {
                    let answer = smith.lambda_route(from_spherical(theta, 0.0), route);
                    checked += usize::from(is_checked(s.model.as_ref(), route, theta, &answer));
                }
            }
        }
        assert_eq!(records.len(), checked);
        assert!(checked < STRESS_GAMMAS.len() * ROUTES.len() * STRESS_THETAS.len());
        let mut counts = std::collections::BTreeMap::new();
        for r in &records {
            *counts.entry(r.verdict.name()).or_insert(0) += 1;
            assert!(
                matches!(r.verdict, Verdict::Pass | Verdict::ExpectedFailure { .. }),
                "{r:?}"
            );
            let route = r.case["route"].as_str().unwrap();
            if route == "stable" {
                assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
            }
            if route == "2f1_algorithm2_corrected" {
                assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
            }
        }
        eprintln!("STD stress verdicts: {counts:?}");
        let stable = records
            .iter()
            .filter(|r| r.case["route"] == "stable")
            .count();
        assert_eq!(stable, STRESS_GAMMAS.len() * STRESS_THETAS.len());
        // γ = 90, θ = 1.2: the integer route refuses (it returned 1.78e8 for 0.0075): no
        // record, or the demonstration of its loss.
        let integer = records.iter().find(|r| {
            r.case["route"] == "integer" && r.model["gamma"] == 90.0 && r.case["theta"] == 1.2
        });
        assert!(
            integer.is_none_or(|r| r.check == "smith.lambda_route_loss"
                && matches!(r.verdict, Verdict::ExpectedFailure { .. })),
            "{integer:?}"
        );
    }
}
