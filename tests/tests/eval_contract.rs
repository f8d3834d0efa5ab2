//! End to end: the `mfh eval` contract (ARCHITECTURE.md, "Evaluating closed forms"), driven through
//! `mfh_harness::cli::run` exactly as the binary calls it. Every family × every quantity answers
//! `{"value": …}` equal bit for bit to the reference library called directly, or an error of
//! kind `unsupported`; malformed lines answer `parse`, `model`, `route` or `argument` errors;
//! answers keep the order of the queries, a bad line does not stop the others, and the exit
//! status is 2 exactly when some line failed.

// The quantities of the contract: every model quantity `mfh eval` answers.
use mfh_harness::eval::QUANTITIES;
use mfh_reference::geometry::{from_spherical, Vec3};
use mfh_reference::ndf::gtr_lambda::ROUTES as GTR_ROUTES;
use mfh_reference::ndf::student_lambda::ROUTES;
use mfh_reference::{Masking, Model, ModelSpec, QueryError};
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;

mod eval_support;

use eval_support::{answers, assert_answer, lines, mfh, num, Expect};

fn build(spec: &Value) -> Box<dyn Model> {
    serde_json::from_value::<ModelSpec>(spec.clone())
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
        .build()
        .unwrap_or_else(|e| panic!("{spec}: {e}"))
}

fn profile(theta: &[f64], value: &[f64]) -> Value {
    json!({ "theta": theta, "value": value })
}

/// One model spec per family of ARCHITECTURE.md (and the special cases: STD with γ = ∞, STD with
/// γ ≤ 3/2 where Λ diverges, anisotropic roughness, GTR at an integer and a fractional γ).
fn families() -> Vec<Value> {
    let px = profile(&[0.0, 0.4, 1.0, FRAC_PI_2], &[2.0, 1.5, 0.2, 0.0]);
    let py = profile(&[0.0, 0.7, FRAC_PI_2], &[1.0, 0.6, 0.1]);
    let mut listed = vec![
        json!({"family": "beckmann", "alpha": 0.3}),
        json!({"family": "beckmann", "alpha_x": 0.1, "alpha_y": 0.4}),
        json!({"family": "ggx", "alpha": 0.3}),
        json!({"family": "ggx", "alpha_x": 0.1, "alpha_y": 0.4}),
        json!({"family": "std", "gamma": 2.5, "alpha": 0.3}),
        json!({"family": "std", "gamma": 3.5, "alpha_x": 0.1, "alpha_y": 0.4}),
        json!({"family": "std", "gamma": "inf", "alpha": 0.3}),
        json!({"family": "std", "gamma": 1.2, "alpha": 0.3}),
        json!({"family": "hyper_cauchy", "gamma": 3, "alpha": 0.3}),
        json!({"family": "student_fixed_variance", "gamma": 4, "alpha_x": 0.2, "alpha_y": 0.5}),
        json!({"family": "student_fixed_variance", "gamma": "inf", "alpha": 0.3}),
        json!({"family": "student_general", "b": 4, "c": 5}),
        json!({"family": "piecewise_linear", "x": px}),
        json!({"family": "piecewise_linear", "x": px, "y": py}),
        json!({"family": "blend", "x": {"family": "ggx", "alpha": 0.2},
               "y": {"family": "beckmann", "alpha": 0.4}}),
        json!({"family": "gtr", "gamma": 1.5, "alpha": 0.3}),
        json!({"family": "gtr", "gamma": 3, "alpha": 0.5}),
        json!({"family": "gaussian_slopes", "mean": [0.1, -0.05],
               "cov": [[0.04, 0.01], [0.01, 0.09]]}),
    ];
    // Every registry example too, so that a new family is held to the contract without an
    // edit here.
    listed.extend(mfh_reference::registry::FAMILIES.iter().flat_map(|f| {
        f.examples
            .iter()
            .map(|e| serde_json::from_str::<Value>(e).expect("registry examples are JSON"))
    }));
    listed
}

/// The quantities a model has a meaning for (ARCHITECTURE.md and the source documents): everything
/// for the elliptic slope families (but Λ, G1, G2 only where γ > 3/2); D, Smith and sampling for
/// the piecewise-linear NDF; D and Smith for the blend (no closed-form sampler); D, Smith,
/// slopes and sampling (Burley's inversion) for GTR; D, Smith, slopes and the moments of the
/// visible slopes for Gaussian slopes (no sampler); visible-normal sampling for GGX and
/// Beckmann (also as STD with γ = ∞) only.
fn supported(spec: &Value) -> Vec<&'static str> {
    let smith = ["lambda", "g1", "g2"];
    let slopes = ["p22", "p2", "slope_moment", "variance", "excess_kurtosis"];
    let sampler = ["sample_wm", "pdf_wm"];
    let mut q = vec!["d"];
    let family = spec["family"].as_str().unwrap();
    if family == "ggx" || family == "beckmann" || spec["gamma"] == "inf" {
        q.extend(["sample_wm_visible", "pdf_wm_visible"]);
    }
    match family {
        "piecewise_linear" => q.extend(smith.iter().chain(&sampler)),
        "blend" => q.extend(smith),
        "gtr" => q.extend(smith.iter().chain(&slopes).chain(&sampler)),
        "gaussian_slopes" => q.extend(smith.iter().chain(&slopes).chain(&["visible_moments"])),
        _ => {
            let gamma = spec["gamma"].as_f64().unwrap_or(f64::INFINITY);
            if gamma > 1.5 {
                q.extend(smith);
            }
            q.extend(slopes.iter().chain(&sampler));
        }
    }
    q
}

fn vector(v: Vec3) -> Value {
    json!(v)
}

/// The queries of one quantity (its arguments) with what the library answers to each.
fn battery(quantity: &str, m: &dyn Model) -> Vec<(Value, Expect)> {
    let unsupported = Err("unsupported");
    let smith = m.as_smith();
    let slopes = m.as_slopes();
    let sampler = m.as_sampler();
    let wo = from_spherical(0.9, 0.0);
    let wi = from_spherical(1.2, 3.0);
    let z = [0.0, 0.0, 1.0];
    match quantity {
        "d" => vec![
            (
                json!({"theta": 0.7, "phi": 0.4}),
                Ok(num(m.d(from_spherical(0.7, 0.4)))),
            ),
            (json!({"theta": 0.0}), Ok(num(m.d(z)))),
            (
                json!({"m": vector(from_spherical(1.3, 2.0))}),
                Ok(num(m.d(from_spherical(1.3, 2.0)))),
            ),
        ],
        "lambda" => {
            let mut v = vec![
                (
                    json!({"theta": 1.2, "phi": 0.3}),
                    smith
                        .map(|s| num(s.lambda(from_spherical(1.2, 0.3))))
                        .ok_or("unsupported"),
                ),
                (
                    json!({"w": vector(from_spherical(0.2, 4.0))}),
                    smith
                        .map(|s| num(s.lambda(from_spherical(0.2, 4.0))))
                        .ok_or("unsupported"),
                ),
            ];
            // Every route the model lists, every Student route name, "default" and an unknown
            // one: the value of that route, or a "route" error where it does not apply.
            let mut routes: Vec<&str> = ROUTES.iter().map(|r| r.0).collect();
            routes.extend(GTR_ROUTES.iter().map(|r| r.0));
            routes.extend([
                "default",
                "exact",
                "table1",
                "domain_split",
                "no_such_route",
            ]);
            if let Some(s) = smith {
                routes.extend(s.lambda_routes());
            }
            routes.sort();
            routes.dedup();
            let w = from_spherical(1.1, 0.6);
            for route in routes {
                let expect = match smith {
                    None => unsupported.clone(),
                    Some(s) => match s.lambda_route(w, route) {
                        Ok(x) => Ok(num(x)),
                        Err(QueryError::Route { .. }) => Err("route"),
                        Err(e) => panic!("unexpected {e}"),
                    },
                };
                v.push((json!({"theta": 1.1, "phi": 0.6, "route": route}), expect));
            }
            v
        }
        "g1" => {
            let (w, mm) = (from_spherical(1.1, 0.2), from_spherical(0.3, 0.5));
            vec![
                (
                    json!({"w": vector(w), "m": vector(mm)}),
                    smith.map(|s| num(s.g1(w, mm))).ok_or("unsupported"),
                ),
                (
                    json!({"theta": 1.1, "phi": 0.2}),
                    smith.map(|s| num(s.g1(w, z))).ok_or("unsupported"),
                ),
            ]
        }
        "g2" => {
            let g2 = |mm: Vec3, masking: Masking| {
                smith
                    .map(|s| num(s.g2(wo, wi, mm, masking)))
                    .ok_or("unsupported")
            };
            let mm = from_spherical(0.1, 0.2);
            let angles = json!({"theta_o": 0.9, "theta_i": 1.2, "phi_i": 3.0});
            let with = |extra: Value| {
                let mut q = angles.clone();
                for (k, v) in extra.as_object().unwrap() {
                    q[k] = v.clone();
                }
                q
            };
            vec![
                (
                    with(json!({"masking": "uncorrelated"})),
                    g2(z, Masking::Uncorrelated),
                ),
                (
                    with(json!({"masking": "height_correlated"})),
                    g2(z, Masking::HeightCorrelated),
                ),
                (with(json!({})), g2(z, Masking::HeightCorrelated)),
                (
                    json!({"wo": vector(wo), "wi": vector(wi), "m": vector(mm),
                           "masking": "uncorrelated"}),
                    g2(mm, Masking::Uncorrelated),
                ),
            ]
        }
        "p22" => vec![(
            json!({"p": 0.2, "q": -0.1}),
            slopes.map(|s| num(s.p22(0.2, -0.1))).ok_or("unsupported"),
        )],
        "p2" => vec![
            (
                json!({"q": 0.3, "phi": 0.5}),
                slopes.map(|s| num(s.p2(0.3, 0.5))).ok_or("unsupported"),
            ),
            (
                json!({"q": -1.5}),
                slopes.map(|s| num(s.p2(-1.5, 0.0))).ok_or("unsupported"),
            ),
        ],
        "slope_moment" => (0..4)
            .map(|k| {
                (
                    json!({"k": k, "phi": 0.5}),
                    slopes
                        .map(|s| s.slope_moment(k, 0.5).map_or(Value::Null, num))
                        .ok_or("unsupported"),
                )
            })
            .collect(),
        "variance" => vec![(
            json!({"phi": 1.0}),
            slopes
                .map(|s| s.variance(1.0).map_or(Value::Null, num))
                .ok_or("unsupported"),
        )],
        "excess_kurtosis" => vec![(
            json!({}),
            slopes
                .map(|s| s.excess_kurtosis().map_or(Value::Null, num))
                .ok_or("unsupported"),
        )],
        "sample_wm" => [[0.3, 0.6], [0.0, 0.0], [0.95, 0.999]]
            .into_iter()
            .map(|u| {
                (
                    json!({ "u": u }),
                    sampler
                        .map(|s| json!(s.sample_wm(u).map(num)))
                        .ok_or("unsupported"),
                )
            })
            .collect(),
        "pdf_wm" => {
            let mm = from_spherical(0.4, 1.0);
            vec![
                (
                    json!({"m": vector(mm)}),
                    sampler.map(|s| num(s.pdf_wm(mm))).ok_or("unsupported"),
                ),
                (
                    json!({"theta": 0.4, "phi": 1.0}),
                    sampler.map(|s| num(s.pdf_wm(mm))).ok_or("unsupported"),
                ),
            ]
        }
        "sample_wm_visible" => {
            let wi = from_spherical(1.2, 0.7);
            let mut v: Vec<(Value, Expect)> = [[0.3, 0.6], [0.0, 0.0], [0.95, 0.999]]
                .into_iter()
                .map(|u| {
                    (
                        json!({"theta_i": 1.2, "phi_i": 0.7, "u": u}),
                        m.as_visible_sampler()
                            .map(|s| json!(s.sample_wm_visible(wi, u).map(num)))
                            .ok_or("unsupported"),
                    )
                })
                .collect();
            let wi = from_spherical(0.2, 3.0);
            v.push((
                json!({"wi": vector(wi), "u": [0.5, 0.25]}),
                m.as_visible_sampler()
                    .map(|s| json!(s.sample_wm_visible(wi, [0.5, 0.25]).map(num)))
                    .ok_or("unsupported"),
            ));
            v
        }
        "pdf_wm_visible" => {
            let (wi, mm) = (from_spherical(1.2, 0.7), from_spherical(0.4, 1.0));
            vec![
                (
                    json!({"theta_i": 1.2, "phi_i": 0.7, "m": vector(mm)}),
                    m.as_visible_sampler()
                        .map(|s| num(s.pdf_wm_visible(wi, mm)))
                        .ok_or("unsupported"),
                ),
                (
                    json!({"wi": vector(wi), "theta": 0.4, "phi": 1.0}),
                    m.as_visible_sampler()
                        .map(|s| num(s.pdf_wm_visible(wi, mm)))
                        .ok_or("unsupported"),
                ),
            ]
        }
        "visible_moments" => {
            let moments = |v: mfh_reference::model::VisibleMoments| {
                json!({
                    "mean": v.mean.map(num),
                    "cov": v.cov.map(|row| row.map(num)),
                })
            };
            let w = from_spherical(0.8, 0.5);
            let mut v = vec![(
                json!({"theta": 0.8, "phi": 0.5}),
                m.as_visible_moments()
                    .map(|s| moments(s.visible_moments(w).expect("upper hemisphere")))
                    .ok_or("unsupported"),
            )];
            let mut routes = vec!["default", "no_such_route"];
            if let Some(s) = m.as_visible_moments() {
                routes.extend(s.visible_moments_routes());
            }
            for route in routes {
                let expect = match m.as_visible_moments() {
                    None => Err("unsupported"),
                    Some(s) => match s.visible_moments_route(w, route) {
                        Ok(x) => Ok(moments(x)),
                        Err(QueryError::Route { .. }) => Err("route"),
                        Err(e) => panic!("unexpected {e}"),
                    },
                };
                v.push((json!({"w": vector(w), "route": route}), expect));
            }
            v
        }
        other => panic!("no battery for {other}"),
    }
}

#[test]
fn every_family_answers_every_quantity_as_the_library_does() {
    let mut queries = Vec::new();
    let mut expects = Vec::new();
    for spec in families() {
        let model = build(&spec);
        let supported = supported(&spec);
        for quantity in QUANTITIES {
            // The library and ARCHITECTURE.md agree on what the family supports.
            let has = match quantity {
                "d" => true,
                "lambda" | "g1" | "g2" => model.as_smith().is_some(),
                "sample_wm" | "pdf_wm" => model.as_sampler().is_some(),
                "sample_wm_visible" | "pdf_wm_visible" => model.as_visible_sampler().is_some(),
                "visible_moments" => model.as_visible_moments().is_some(),
                _ => model.as_slopes().is_some(),
            };
            assert_eq!(
                has,
                supported.contains(&quantity),
                "{spec}: {quantity} supported by the library: {has}"
            );
            for (args, expect) in battery(quantity, model.as_ref()) {
                if supported.contains(&quantity) && args.get("route").is_none() {
                    assert!(expect.is_ok(), "{spec} {quantity} {args}: {expect:?}");
                } else if !supported.contains(&quantity) {
                    assert_eq!(expect, Err("unsupported"));
                }
                let mut q = json!({"model": spec, "quantity": quantity});
                for (k, v) in args.as_object().unwrap() {
                    q[k] = v.clone();
                }
                queries.push(q);
                expects.push(expect);
            }
        }
    }
    let r = mfh(&["eval"], &lines(&queries));
    let got = answers(&r);
    assert_eq!(got.len(), queries.len(), "one answer per query");
    for ((q, a), e) in queries.iter().zip(&got).zip(&expects) {
        assert_answer(q, a, e);
    }
    let failed = expects.iter().filter(|e| e.is_err()).count();
    assert!(failed > 0 && failed < queries.len());
    assert_eq!(r.status, 2, "some lines failed, so the status is 2");
    assert_eq!(
        r.stderr.trim(),
        format!("mfh eval: {failed} of {} queries failed", queries.len())
    );
    // Every Λ route of the Student and GTR families answered a value somewhere.
    for &(route, _) in ROUTES.iter().chain(GTR_ROUTES) {
        assert!(
            queries
                .iter()
                .zip(&expects)
                .any(|(q, e)| q["route"] == route && e.is_ok()),
            "route {route} never answered a value"
        );
    }
}

#[test]
fn the_issue_example_answers_the_library_lambda() {
    let line =
        r#"{"model":{"family":"std","gamma":2.5,"alpha":0.3},"quantity":"lambda","theta":1.2}"#;
    let r = mfh(&["eval"], &format!("{line}\n"));
    assert_eq!(r.status, 0, "{}", r.stderr);
    assert_eq!(r.stderr, "");
    assert_eq!(r.stdout.lines().count(), 1, "{}", r.stdout);
    let model = build(&json!({"family": "std", "gamma": 2.5, "alpha": 0.3}));
    let lambda = model
        .as_smith()
        .expect("STD γ = 2.5 has Λ")
        .lambda(from_spherical(1.2, 0.0));
    assert!(lambda > 0.0 && lambda.is_finite());
    let answer = answers(&r).remove(0);
    assert_eq!(
        answer["value"].as_f64().map(f64::to_bits),
        Some(lambda.to_bits())
    );
    // The exact text: one compact JSON object and a newline.
    assert_eq!(r.stdout, format!("{}\n", json!({ "value": lambda })));
    // docs/eval.md shows this very example with its answer.
    let page = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/eval.md"))
        .expect("docs/eval.md");
    assert!(
        page.contains(&format!("echo '{line}' | mfh eval\n{}", r.stdout)),
        "docs/eval.md's `mfh eval` example does not show today's answer {}",
        r.stdout.trim()
    );
}

#[test]
fn error_kinds() {
    let ggx = json!({"family": "ggx", "alpha": 0.3});
    let std25 = json!({"family": "std", "gamma": 2.5, "alpha": 0.3});
    let cases: Vec<(String, &str)> = vec![
        // parse: not JSON, not an object
        ("not json".into(), "parse"),
        (r#"{"model": {"family": "ggx""#.into(), "parse"),
        ("[1, 2]".into(), "parse"),
        ("42".into(), "parse"),
        // model: bad parameters, unknown families and keys
        (json!({"model": {"family": "ggx", "alpha": -1}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "ggx", "alpha": 0}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "ggx", "alpha_x": 0.1}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "ggx", "alpha": 0.1, "gamma": 2}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "std", "gamma": 1, "alpha": 0.3}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "std", "gamma": "many", "alpha": 0.3}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "student_fixed_variance", "gamma": 2, "alpha": 0.3}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "student_general", "b": 0, "c": 3}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "no_such_family", "alpha": 0.3}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "piecewise_linear", "x": {"theta": [0, 1.5], "value": [1, 1]}}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": {"family": "blend", "x": {"family": "ggx", "alpha_x": 0.1, "alpha_y": 0.3}, "y": ggx}, "quantity": "d", "theta": 0}).to_string(), "model"),
        (json!({"model": "ggx", "quantity": "d", "theta": 0}).to_string(), "model"),
        // route: unknown, or not applicable to these parameters, or on a one-route quantity
        (json!({"model": std25, "quantity": "lambda", "theta": 1, "route": "no_such_route"}).to_string(), "route"),
        (json!({"model": std25, "quantity": "lambda", "theta": 1, "route": "integer"}).to_string(), "route"),
        (json!({"model": {"family": "std", "gamma": 7.5, "alpha": 0.3}, "quantity": "lambda", "theta": 1, "route": "table1"}).to_string(), "route"),
        (json!({"model": ggx, "quantity": "lambda", "theta": 1, "route": "stable"}).to_string(), "route"),
        (json!({"model": ggx, "quantity": "d", "theta": 1, "route": "table1"}).to_string(), "route"),
        // argument: missing or malformed arguments
        (json!({"quantity": "d", "theta": 0}).to_string(), "argument"),
        (json!({"model": ggx, "theta": 0}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "no_such_quantity"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "d"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "lambda"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "g2", "theta_o": 0.5}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "g2", "theta_o": 0.5, "theta_i": 0.5, "masking": "both"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "p22", "q": 0.1}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "slope_moment"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "slope_moment", "k": -1}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "sample_wm"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "sample_wm", "u": [0.5, 1.0]}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "sample_wm", "u": [0.5]}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "d", "theta": 4.0}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "d", "theta": "0.5"}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "d", "m": [0, 0, 2]}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "d", "m": [0, 1]}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "d", "m": [0, 0, 1], "theta": 0}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "lambda", "theta": 1, "route": 3}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "sample_wm_visible", "u": [0.5, 0.5]}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "sample_wm_visible", "theta_i": FRAC_PI_2, "u": [0.5, 0.5]}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "pdf_wm_visible", "theta_i": 2.0, "theta": 0.1}).to_string(), "argument"),
        (json!({"model": ggx, "quantity": "pdf_wm_visible", "theta_i": 0.5}).to_string(), "argument"),
        // unsupported: quantities the family has no meaning for
        (json!({"model": {"family": "std", "gamma": 1.2, "alpha": 0.3}, "quantity": "lambda", "theta": 1}).to_string(), "unsupported"),
        (json!({"model": {"family": "piecewise_linear", "x": {"theta": [0, FRAC_PI_2], "value": [1, 0]}}, "quantity": "p22", "p": 0, "q": 0}).to_string(), "unsupported"),
        (json!({"model": {"family": "blend", "x": ggx, "y": ggx}, "quantity": "sample_wm", "u": [0.1, 0.2]}).to_string(), "unsupported"),
        (json!({"model": std25, "quantity": "sample_wm_visible", "theta_i": 0.5, "u": [0.1, 0.2]}).to_string(), "unsupported"),
        (json!({"model": std25, "quantity": "pdf_wm_visible", "theta_i": 0.5, "theta": 0.1}).to_string(), "unsupported"),
    ];
    let input: String = cases.iter().map(|(l, _)| format!("{l}\n")).collect();
    let r = mfh(&["eval"], &input);
    let got = answers(&r);
    assert_eq!(got.len(), cases.len());
    for ((line, kind), answer) in cases.iter().zip(&got) {
        assert_answer(&json!(line), answer, &Err(*kind));
    }
    assert_eq!(r.status, 2);
    assert_eq!(
        r.stderr.trim(),
        format!("mfh eval: {n} of {n} queries failed", n = cases.len())
    );
}

#[test]
fn order_is_kept_and_a_bad_line_does_not_stop_the_others() {
    let q = |theta: f64| json!({"model": {"family": "ggx", "alpha": 0.3}, "quantity": "d", "theta": theta});
    let ggx = build(&json!({"family": "ggx", "alpha": 0.3}));
    let d = |theta: f64| num(ggx.d(from_spherical(theta, 0.0)));
    let input = format!(
        "{}\nnot json\n\n   \n{}\n{}\n{}\n",
        q(0.1),
        q(0.2),
        json!({"model": {"family": "ggx", "alpha": -0.3}, "quantity": "d", "theta": 0.3}),
        q(0.4)
    );
    let r = mfh(&["eval"], &input);
    let got = answers(&r);
    // Blank lines are skipped: five queries, five answers, in order.
    let expect = [
        Ok(d(0.1)),
        Err("parse"),
        Ok(d(0.2)),
        Err("model"),
        Ok(d(0.4)),
    ];
    assert_eq!(got.len(), expect.len(), "{}", r.stdout);
    for (a, e) in got.iter().zip(&expect) {
        assert_answer(&json!(input), a, e);
    }
    assert_eq!(r.status, 2);
    assert_eq!(r.stderr.trim(), "mfh eval: 2 of 5 queries failed");
    // The last line needs no newline.
    let r = mfh(&["eval"], &format!("{}\n{}", q(0.1), q(0.2)));
    assert_eq!(answers(&r).len(), 2);
    assert_eq!(r.status, 0);
}

#[test]
fn status_is_zero_when_every_line_is_answered() {
    let queries: Vec<Value> = (0..20)
        .map(|i| {
            json!({"model": {"family": "beckmann", "alpha": 0.5}, "quantity": "lambda",
                   "theta": 0.07 * i as f64})
        })
        .collect();
    let r = mfh(&["eval"], &lines(&queries));
    assert_eq!(r.status, 0);
    assert_eq!(r.stderr, "");
    assert_eq!(answers(&r).len(), 20);
    assert!(answers(&r).iter().all(|a| a.get("value").is_some()));
    // No queries at all: no answers, status 0.
    let r = mfh(&["eval"], "");
    assert_eq!(
        (r.status, r.stdout.as_str(), r.stderr.as_str()),
        (0, "", "")
    );
}

#[test]
fn non_finite_values_are_strings() {
    let ggx = json!({"family": "ggx", "alpha": 0.3});
    let queries = [
        // Λ at grazing incidence is +∞.
        json!({"model": ggx, "quantity": "lambda", "theta": FRAC_PI_2}),
        json!({"model": {"family": "std", "gamma": 2.5, "alpha": 0.3}, "quantity": "lambda",
               "w": [1.0, 0.0, 0.0]}),
        // Just below the horizon, Λ(−w) = −1 − Λ(w) overflows to −∞.
        json!({"model": ggx, "quantity": "lambda", "w": [1.0, 0.0, -1e-320]}),
    ];
    // (Algorithm 2 of document 001 as printed, which hits a pole of Γ at integer γ, now answers a
    // typed `route` error outside the domain where it is accurate, not NaN.)
    let r = mfh(&["eval"], &lines(&queries));
    let got: Vec<Value> = answers(&r)
        .into_iter()
        .map(|a| a["value"].clone())
        .collect();
    assert_eq!(got, [json!("inf"), json!("inf"), json!("-inf")]);
    // A value, not an error: status 0.
    assert_eq!(r.status, 0, "{}", r.stderr);
    // And the library agrees: the printed Algorithm 2 at integer γ is refused outside its
    // domain with a typed route error (it used to answer NaN there).
    let m = build(&json!({"family": "std", "gamma": 3, "alpha": 0.3}));
    let lambda = m
        .as_smith()
        .unwrap()
        .lambda_route(from_spherical(0.1, 0.0), "2f1_algorithm2");
    assert!(
        matches!(lambda, Err(mfh_reference::QueryError::Route { .. })),
        "{lambda:?}"
    );
}

#[test]
fn input_file_equals_stdin() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/queries.jsonl"
    ))
    .expect("examples/queries.jsonl");
    let from_stdin = mfh(&["eval"], &text);
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("eval_contract_input.jsonl");
    std::fs::write(&path, &text).unwrap();
    let from_file = mfh(&["eval", "--input", path.to_str().unwrap()], "ignored\n");
    assert_eq!(from_file.stdout, from_stdin.stdout);
    assert_eq!(from_file.stderr, from_stdin.stderr);
    assert_eq!(from_file.status, from_stdin.status);
    assert_eq!(
        from_stdin.stdout.lines().count(),
        text.lines().filter(|l| !l.trim().is_empty()).count()
    );
    // The status says whether some line failed.
    let failed = from_stdin
        .stdout
        .lines()
        .filter(|l| l.starts_with(r#"{"error""#))
        .count();
    assert_eq!(from_stdin.status, if failed > 0 { 2 } else { 0 });
    // An unreadable input file is bad input, with a message naming it.
    let missing = path.with_file_name("no_such_file.jsonl");
    let r = mfh(&["eval", "--input", missing.to_str().unwrap()], "");
    assert_eq!(r.status, 2);
    assert_eq!(r.stdout, "");
    assert!(r.stderr.contains("no_such_file.jsonl"), "{}", r.stderr);
}

#[test]
fn command_line_errors_and_help() {
    let r = mfh(&["frobnicate"], "");
    assert_eq!(r.status, 2);
    assert!(r.stderr.contains("frobnicate"), "{}", r.stderr);
    let r = mfh(&["eval", "--no-such-flag"], "");
    assert_eq!(r.status, 2);
    assert!(!r.stderr.is_empty());
    let r = mfh(&["--help"], "");
    assert_eq!(r.status, 0);
    assert!(r.stdout.contains("eval"), "{}", r.stdout);
    let r = mfh(&["eval", "--help"], "");
    assert_eq!(r.status, 0);
    assert!(r.stdout.contains("--input"), "{}", r.stdout);
}

/// The contract's model list covers every family of the registry (its examples are appended
/// to the hand-picked cases above).
#[test]
fn the_contract_covers_every_registered_family() {
    let listed: std::collections::BTreeSet<String> = families()
        .iter()
        .filter_map(|m| m["family"].as_str().map(str::to_string))
        .collect();
    for f in mfh_reference::registry::FAMILIES {
        assert!(
            listed.contains(f.name),
            "{} missing from the eval contract",
            f.name
        );
    }
}
