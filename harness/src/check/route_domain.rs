//! Where a Λ route does not apply: one record per family and route,
//! `smith.lambda_route_domain`. The Λ checks plan a reference route only where it answers
//! (`smith.lambda_route` at the profile's directions, and the stress cases of `route_stress`,
//! which also keep the refusals whose loss they demonstrate); this record states the other
//! cases of the audit — the models and directions where the route refuses — and checks the
//! domain at its edge:
//!
//! - every one of those cases is refused with the typed `route` error that names the domain
//!   (not an answer, not another error);
//! - at the edge, the route refuses just outside and answers just inside. Where one model
//!   refuses at some incidences and answers at others along one azimuth (an accuracy domain),
//!   the edge is narrowed by bisection in θ to 1e-9 relative; otherwise (a domain in the shape
//!   parameter) it lies between a model that refuses and one of the same family that answers,
//!   at the same direction where there is one;
//! - the answer just inside is finite and agrees with the oracle to the closed-form tolerance
//!   (the domain a route states is where it is accurate, and its edge is where that is
//!   hardest), unless the route has entries of its own in the expected-failure table (a
//!   printed formula with an erratum, a known limit): its value is then judged by
//!   `smith.lambda_route` against those entries, and here it must only answer.
//!
//! The planner asks no route: the cases where a route refuses are those of the audit that the
//! Λ checks did not plan (they ask it); the record asks them again when it runs.

use super::route_stress::{stress_models, STRESS_THETAS};
use super::smith::{directions, lambda_routes, route_answer};
use super::{compare, covers, Check, Planned, Profile};
use crate::oracle::smith_lambda::lambda_oracle;
use crate::record::{CheckRecord, Verdict};
use crate::subject::Subject;
use crate::tolerance::{expected_failures, CLOSED_FORM, NUMERICAL_ROUTE};
use mfh_reference::geometry::from_spherical;
use mfh_reference::ndf::student_lambda::ROUTES;
use mfh_reference::{Model, QueryError};
use serde_json::{json, Value};
use std::collections::HashSet;
use std::sync::Arc;

/// The check id of the records this module writes.
pub const CHECK: &str = "smith.lambda_route_domain";

/// The check id of the cases whose refusals this module states.
const ROUTE_CHECK: &str = "smith.lambda_route";

const SOURCE: &str = "seed 001 eq 5 (Λ = (1/μ)∫_μ^∞ (q − μ) P2(q) dq); the domain each route \
                      states by its typed `route` error (reference crate, `Smith::lambda_route`)";

/// The relative width in θ to which the bisection narrows an accuracy edge.
const EDGE_WIDTH: f64 = 1e-9;

/// A case of the audit at which a route is asked: a model (as a subject, for the oracle's
/// hints, with the label its records carry) and a direction.
#[derive(Clone)]
struct Point {
    subject: Arc<Subject<'static>>,
    label: Value,
    /// Index of the model among those of the plan (the points of one model share it).
    model: usize,
    theta: f64,
    phi: f64,
}

impl Point {
    /// The route's answer here.
    fn ask(&self, route: &str) -> Result<Option<f64>, QueryError> {
        let smith = self
            .subject
            .model
            .as_smith()
            .ok_or_else(|| QueryError::Unsupported {
                family: self.subject.family().to_string(),
                quantity: "lambda".to_string(),
            })?;
        route_answer(smith, route, self.theta, self.phi)
    }

    /// The same model at another incidence.
    fn at(&self, theta: f64) -> Point {
        Point {
            theta,
            ..self.clone()
        }
    }

    fn json(&self) -> Value {
        json!({"model": self.label, "theta": self.theta, "phi": self.phi})
    }
}

/// One route of one family over the audit's cases, in plan order: the cases no Λ check was
/// planned for, and those checked.
struct Group {
    family: &'static str,
    route: &'static str,
    materials: Vec<String>,
    refused: Vec<Point>,
    checked: Vec<Point>,
}

/// The key of a planned Λ case: model label, route, θ and φ (bits).
type Key = (String, String, u64, u64);

fn key(label: &Value, route: &str, theta: f64, phi: f64) -> Key {
    (
        label.to_string(),
        route.to_string(),
        theta.to_bits(),
        phi.to_bits(),
    )
}

/// Plans one `smith.lambda_route_domain` record per family and route that the Λ checks left
/// unplanned somewhere, over the scene's masked reference materials `(subject, material
/// name)`: the cases `smith::plan_lambda_routes` and `route_stress::plan` consider, minus those
/// in `planned`.
pub fn plan(
    materials: &[(Arc<Subject<'static>>, String)],
    planned: &[Planned],
    profile: Profile,
    theta_max: f64,
) -> Vec<Planned> {
    let planned: HashSet<Key> = planned
        .iter()
        .filter(|p| p.check == ROUTE_CHECK)
        .filter_map(|p| {
            let route = p.case.get("route")?.as_str()?;
            let theta = p.case.get("theta")?.as_f64()?;
            let phi = p.case.get("phi")?.as_f64()?;
            Some(key(&p.model, route, theta, phi))
        })
        .collect();
    let mut groups: Vec<Group> = Vec::new();
    let mut models = 0;
    for (subject, name) in materials {
        let family = subject.family();
        // The material at the profile's directions, then its stressed variants.
        let mut cases = vec![(
            subject.clone(),
            subject.label.clone(),
            lambda_routes(subject),
            directions(subject.anisotropic(), profile, theta_max),
        )];
        for s in subject.spec().map(stress_models).unwrap_or_default() {
            let model: Arc<dyn Model> = s.model;
            cases.push((
                Subject::from_model(model),
                s.spec,
                ROUTES.iter().map(|r| r.0).collect(),
                STRESS_THETAS.iter().map(|t| (*t, 0.0)).collect(),
            ));
        }
        for (s, label, routes, dirs) in cases {
            for route in routes.into_iter().filter(|r| *r != "default") {
                let g = group(&mut groups, family, route);
                if !g.materials.contains(name) {
                    g.materials.push(name.clone());
                }
                for &(theta, phi) in &dirs {
                    let p = Point {
                        subject: s.clone(),
                        label: label.clone(),
                        model: models,
                        theta,
                        phi,
                    };
                    if planned.contains(&key(&label, route, theta, phi)) {
                        g.checked.push(p);
                    } else {
                        g.refused.push(p);
                    }
                }
            }
            models += 1;
        }
    }
    groups
        .into_iter()
        .filter(|g| !g.refused.is_empty())
        .map(plan_one)
        .collect()
}

/// The group of (family, route), created empty where there is none yet.
fn group<'g>(
    groups: &'g mut Vec<Group>,
    family: &'static str,
    route: &'static str,
) -> &'g mut Group {
    let at = match groups
        .iter()
        .position(|g| g.family == family && g.route == route)
    {
        Some(i) => i,
        None => {
            groups.push(Group {
                family,
                route,
                materials: Vec::new(),
                refused: Vec::new(),
                checked: Vec::new(),
            });
            groups.len() - 1
        }
    };
    &mut groups[at]
}

/// The record of one family and route.
fn plan_one(g: Group) -> Planned {
    let (family, route) = (g.family, g.route);
    // Where it does not apply: the directions, model by model.
    let mut does_not_apply: Vec<(usize, Value, Vec<[f64; 2]>)> = Vec::new();
    for p in &g.refused {
        match does_not_apply.iter_mut().find(|(m, _, _)| *m == p.model) {
            Some((_, _, dirs)) => dirs.push([p.theta, p.phi]),
            None => does_not_apply.push((p.model, p.label.clone(), vec![[p.theta, p.phi]])),
        }
    }
    let case = json!({
        "route": route,
        "does_not_apply": does_not_apply
            .iter()
            .map(|(_, model, dirs)| json!({"model": model, "directions": dirs}))
            .collect::<Vec<_>>(),
        "checked_cases": g.checked.len(),
    });
    let why = format!(
        "material(s) {} ({family}) mask: where route `{route}` does not apply",
        g.materials
            .iter()
            .map(|m| format!("`{m}`"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let label = g.refused[0].label.clone();
    let (refused, checked) = (g.refused, g.checked);
    Check::new(CHECK, label, case, SOURCE)
        .why(why)
        .covers(vec![covers(family, "lambda", route)])
        .run(move |r, _| {
            judge(r, family, route, &refused, &checked);
            Ok(())
        })
}

/// Fills the record of one family and route: the refusals still typed, the edge refused just
/// outside and answered just inside, the answer inside accurate (see the module).
fn judge(r: &mut CheckRecord, family: &str, route: &str, refused: &[Point], checked: &[Point]) {
    let mut problems: Vec<String> = refused
        .iter()
        .filter_map(|p| not_a_refusal(p, route))
        .collect();
    let Some((outside, inside, value)) = edge(refused, checked, route) else {
        // It answers at no case of the audit: the refusals are all there is to check.
        r.verdict = verdict(r, problems);
        return;
    };
    problems.extend(not_a_refusal(&outside, route));
    let reason = outside.ask(route).err().map(|e| e.to_string());
    note(r, "outside", outside.json());
    note(r, "inside", inside.json());
    note(r, "reason", json!(reason));
    let w = from_spherical(inside.theta, inside.phi);
    let value = value.unwrap_or_else(|| {
        inside
            .subject
            .model
            .as_smith()
            .map_or(f64::NAN, |s| s.lambda(w))
    });
    let judged = expected_failures(ROUTE_CHECK, family, route)
        .next()
        .is_none();
    if judged {
        if !value.is_finite() {
            problems.push(format!("answers {value} just inside its domain"));
        }
        let tol = if inside.subject.lambda_numerical() && matches!(route, "default" | "exact") {
            &NUMERICAL_ROUTE
        } else {
            &CLOSED_FORM
        };
        compare(r, value, lambda_oracle(inside.subject.as_ref(), w), tol);
        if r.verdict == Verdict::Fail && value.is_finite() {
            problems.push("inaccurate just inside its domain".into());
        }
    } else {
        r.value = Some(value);
    }
    r.verdict = verdict(r, problems);
}

/// The edge of the domain, as (a case where the route refuses, one where it answers, its
/// answer there): along the first model and azimuth where it both refuses and answers, the
/// adjacent pair narrowed by bisection in θ; else the first refusal and an answer of another
/// model at the same direction (or the first answer). None where it answers at no checked case.
fn edge(refused: &[Point], checked: &[Point], route: &str) -> Option<(Point, Point, Option<f64>)> {
    let answer = |p: &Point| p.ask(route).ok();
    for r in refused {
        let mut along: Vec<&Point> = checked
            .iter()
            .filter(|c| c.model == r.model && c.phi == r.phi)
            .collect();
        along.sort_by(|a, b| {
            (a.theta - r.theta)
                .abs()
                .total_cmp(&(b.theta - r.theta).abs())
        });
        let Some((inside, _)) = along.into_iter().find_map(|c| answer(c).map(|v| (c, v))) else {
            continue;
        };
        // The refusal nearest to that answer: between them, every case answers.
        let outside = refused
            .iter()
            .filter(|x| x.model == r.model && x.phi == r.phi)
            .min_by(|x, y| {
                (x.theta - inside.theta)
                    .abs()
                    .total_cmp(&(y.theta - inside.theta).abs())
            })
            .unwrap_or(r);
        let (outside, inside) = bisect(outside, inside, route);
        let value = answer(&inside).flatten();
        return Some((outside, inside, value));
    }
    let outside = refused.first()?;
    let same = |c: &&Point| c.theta == outside.theta && c.phi == outside.phi;
    let (inside, value) = checked
        .iter()
        .filter(same)
        .chain(checked.iter())
        .find_map(|c| answer(c).map(|v| (c, v)))?;
    Some((outside.clone(), inside.clone(), value))
}

/// None when the route refuses at `p` with its typed `route` error; otherwise what it does.
fn not_a_refusal(p: &Point, route: &str) -> Option<String> {
    let at = format!("θ = {}, φ = {} of {}", p.theta, p.phi, p.label);
    match p.ask(route) {
        Err(QueryError::Route { .. }) => None,
        Err(e) => Some(format!("at {at}: refuses with an untyped error: {e}")),
        Ok(v) => Some(format!(
            "at {at}: answers {v:?} where no Λ check was planned"
        )),
    }
}

/// Narrows an edge along θ (one model, one azimuth) to `EDGE_WIDTH` relative: the last case
/// where the route refuses and the first where it answers.
fn bisect(outside: &Point, inside: &Point, route: &str) -> (Point, Point) {
    let (mut out, mut inn) = (outside.clone(), inside.clone());
    loop {
        let mid = 0.5 * (out.theta + inn.theta);
        let width = (out.theta - inn.theta).abs();
        if width <= EDGE_WIDTH * out.theta.abs().max(inn.theta.abs())
            || mid == out.theta
            || mid == inn.theta
        {
            return (out, inn);
        }
        let p = out.at(mid);
        if p.ask(route).is_err() {
            out = p;
        } else {
            inn = p;
        }
    }
}

/// Pass without problems (an error where the oracle could not resolve the answer inside);
/// otherwise fail, the problems in the case.
fn verdict(r: &mut CheckRecord, problems: Vec<String>) -> Verdict {
    if problems.is_empty() {
        // An oracle that could not resolve the answer inside (`compare`'s error) passes
        // nothing.
        return match &r.verdict {
            Verdict::Error { message } if message.starts_with(crate::check::UNRESOLVED) => {
                r.verdict.clone()
            }
            _ => Verdict::Pass,
        };
    }
    note(r, "problems", json!(problems));
    Verdict::Fail
}

/// Adds `key` to the record's case.
fn note(r: &mut CheckRecord, key: &str, value: Value) {
    if let Some(obj) = r.case.as_object_mut() {
        obj.insert(key.into(), value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{route_stress, smith, RunContext};
    use mfh_reference::ndf::student_lambda::lambda_2f1;
    use mfh_reference::{ModelSpec, Ndf, SlopeDistribution, Smith, Vec3};
    use std::f64::consts::FRAC_PI_2;

    /// How a wrapped STD(γ = 3, α = 0.3) misstates the domain of its route `2f1`.
    #[derive(Clone, Copy, PartialEq)]
    enum Defect {
        None,
        /// It answers eq 21 wherever Λ ≥ 1e-9, not only where that is accurate (Λ ≥ 3.6e-4):
        /// just inside that edge its rounding error is ~1e-6 relative.
        Generous,
        /// It refuses with an argument error instead of its typed `route` error.
        Untyped,
    }

    struct Wrapped {
        inner: Box<dyn Model>,
        defect: Defect,
    }

    impl Ndf for Wrapped {
        fn d(&self, m: Vec3) -> f64 {
            self.inner.d(m)
        }
        fn as_smith(&self) -> Option<&dyn Smith> {
            Some(self)
        }
        fn as_slopes(&self) -> Option<&dyn SlopeDistribution> {
            self.inner.as_slopes()
        }
    }

    impl Smith for Wrapped {
        fn lambda(&self, w: Vec3) -> f64 {
            self.inner.as_smith().unwrap().lambda(w)
        }
        fn lambda_routes(&self) -> Vec<&'static str> {
            self.inner.as_smith().unwrap().lambda_routes()
        }
        fn lambda_route(&self, w: Vec3, route: &str) -> Result<f64, QueryError> {
            let answer = self.inner.as_smith().unwrap().lambda_route(w, route);
            match (answer, self.defect) {
                (Err(QueryError::Route { .. }), Defect::Generous)
                    if route == "2f1" && self.lambda(w) >= 1e-9 =>
                {
                    // x = cot θ / (α √(γ − 1)) for the isotropic STD.
                    let x = w[2] / w[0].hypot(w[1]) / (0.3 * 2f64.sqrt());
                    Ok(lambda_2f1(3.0, x))
                }
                (Err(QueryError::Route { reason, .. }), Defect::Untyped) if route == "2f1" => {
                    Err(QueryError::Argument(reason))
                }
                (answer, _) => answer,
            }
        }
    }

    impl Model for Wrapped {
        fn spec(&self) -> ModelSpec {
            self.inner.spec()
        }
        fn family(&self) -> &'static str {
            self.inner.family()
        }
    }

    fn std3(defect: Defect) -> Arc<dyn Model> {
        let spec: ModelSpec =
            serde_json::from_value(json!({"family": "std", "gamma": 3.0, "alpha": 0.3})).unwrap();
        Arc::new(Wrapped {
            inner: spec.build().unwrap(),
            defect,
        })
    }

    /// The Λ checks of one masked material as the scene planner plans them.
    fn route_checks(model: &Arc<dyn Model>) -> (Arc<Subject<'static>>, Vec<Planned>) {
        let subject = Subject::from_model(model.clone());
        let mut planned = smith::plan_lambda_routes(&subject, Profile::Quick, FRAC_PI_2, "t");
        planned.extend(route_stress::plan(model.as_ref(), "t"));
        (subject, planned)
    }

    fn run(plan: &[Planned]) -> Vec<CheckRecord> {
        let ctx = RunContext { seed: 1 };
        plan.iter().map(|p| (p.run)(&ctx)).collect()
    }

    /// A correct model: one record per route that refuses somewhere, each passing; together
    /// they list every case no Λ check was planned for, once; each has its edge (a refusal
    /// outside with the route's reason, an answer inside) or says it answers nowhere.
    #[test]
    fn a_correct_model_gets_one_passing_record_per_route_that_refuses() {
        let model = std3(Defect::None);
        let (subject, planned) = route_checks(&model);
        let domains = plan(
            &[(subject.clone(), "m".into())],
            &planned,
            Profile::Quick,
            FRAC_PI_2,
        );
        let routes: Vec<&str> = domains
            .iter()
            .map(|d| d.case["route"].as_str().unwrap())
            .collect();
        for route in ["2f1", "half_integer", "integer", "table1"] {
            assert!(routes.contains(&route), "{routes:?}");
        }
        assert!(!routes.contains(&"stable"), "{routes:?}");
        let listed: usize = domains
            .iter()
            .flat_map(|d| d.case["does_not_apply"].as_array().unwrap().iter())
            .map(|m| m["directions"].as_array().unwrap().len())
            .sum();
        let plain = directions(subject.anisotropic(), Profile::Quick, FRAC_PI_2).len()
            * lambda_routes(&subject).len();
        let stress = stress_models(&model.spec()).len() * ROUTES.len() * STRESS_THETAS.len();
        assert_eq!(listed + planned.len(), plain + stress);
        for r in run(&domains) {
            assert_eq!(r.check, CHECK);
            assert_eq!(r.verdict, Verdict::Pass, "{r:?}");
            if r.case.get("inside").is_some() {
                assert!(r.case["reason"]
                    .as_str()
                    .unwrap()
                    .contains("is not available"));
            }
        }
        let r = run(&domains)
            .into_iter()
            .find(|r| r.case["route"] == "2f1")
            .unwrap();
        let (out, inn) = (&r.case["outside"], &r.case["inside"]);
        assert_eq!(out["model"], inn["model"]);
        let (a, b) = (
            out["theta"].as_f64().unwrap(),
            inn["theta"].as_f64().unwrap(),
        );
        assert!((a - b).abs() <= 2.0 * EDGE_WIDTH * a.max(b), "{a} {b}");
    }

    /// A route that states a domain wider than where it is accurate fails its record at the
    /// edge; one that refuses with another error than its typed `route` error fails too.
    #[test]
    fn a_misstated_domain_fails() {
        for (defect, problem) in [
            (Defect::Generous, "inaccurate just inside its domain"),
            (Defect::Untyped, "untyped error"),
        ] {
            let model = std3(defect);
            let (subject, planned) = route_checks(&model);
            let domains = plan(
                &[(subject, "m".into())],
                &planned,
                Profile::Quick,
                FRAC_PI_2,
            );
            for r in run(&domains) {
                let expected = if r.case["route"] == "2f1" {
                    Verdict::Fail
                } else {
                    Verdict::Pass
                };
                assert_eq!(r.verdict, expected, "{r:?}");
                if r.verdict == Verdict::Fail {
                    assert!(r.case["problems"].to_string().contains(problem), "{r:?}");
                }
            }
        }
    }

    /// The cases a record lists are those no Λ check was planned for: listed as refusals
    /// while the route answers there, they fail the record.
    #[test]
    fn answers_listed_as_refusals_fail() {
        let model = std3(Defect::None);
        let subject = Subject::from_model(model.clone());
        let domains = plan(&[(subject, "m".into())], &[], Profile::Quick, FRAC_PI_2);
        let stable = domains
            .iter()
            .find(|d| d.case["route"] == "stable")
            .expect("every case unplanned: the stable route listed");
        let r = (stable.run)(&RunContext { seed: 1 });
        assert_eq!(r.verdict, Verdict::Fail);
        assert!(r.case["problems"]
            .to_string()
            .contains("where no Λ check was planned"));
    }
}
