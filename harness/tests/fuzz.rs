//! Fuzzing every parser of user input with proptest ("Bad input"): scene JSON, eval
//! lines (one at a time and as a byte stream), and `mfh chi2`'s arguments as the library
//! validates them. Each answers a value or a typed error, never panics, and respects its stated
//! size limits. 10⁴ cases per parser here (seconds at the test profile's opt-level 2);
//! `MFH_EXTENSIVE=1` runs 10⁶.

use mfh_harness::eval::{answer_line, eval_stream};
use mfh_harness::sampler_chi2::{self, Chi2Request, SamplingKind, MAX_RESOLUTION, MAX_SAMPLES};
use mfh_harness::scene::{Scene, MAX_MATERIALS};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use serde_json::{json, Map, Value};

/// Cases per parser: 10⁴, or 10⁶ with `MFH_EXTENSIVE=1` (the `mfh_extensive` flag of the
/// build script, `mfh-test-tiers`).
fn cases() -> u32 {
    if cfg!(mfh_extensive) {
        1_000_000
    } else {
        10_000
    }
}

fn runner() -> TestRunner {
    TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    })
}

/// Numbers a hostile user writes: extremes, boundaries, specials as strings, huge counts.
fn number() -> impl Strategy<Value = Value> {
    prop_oneof![
        any::<f64>().prop_map(|x| if x.is_finite() {
            json!(x)
        } else {
            json!(x.to_string())
        }),
        prop::sample::select(vec![
            0.0,
            -0.0,
            1.0,
            1.5,
            2.0,
            3.0,
            0.3,
            1e-300,
            1e-7,
            1e-8,
            1e4,
            1e5,
            1e155,
            1e308,
            -1.0,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            1e8,
            2e8,
        ])
        .prop_map(|x| json!(x)),
        any::<u64>().prop_map(|x| json!(x)),
        any::<i64>().prop_map(|x| json!(x)),
        prop::sample::select(vec!["inf", "nan", "-inf", "Infinity", "", "1.5"])
            .prop_map(|s| json!(s)),
    ]
}

/// Any small JSON value, numbers as above.
fn value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        number(),
        Just(Value::Null),
        any::<bool>().prop_map(Value::Bool),
        "[a-z_]{0,8}".prop_map(Value::String),
    ];
    leaf.prop_recursive(3, 24, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::btree_map(key(), inner, 0..4)
                .prop_map(|m| Value::Object(m.into_iter().collect())),
        ]
    })
}

/// Keys: the ones the parsers know, misspellings, and anything.
fn key() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => prop::sample::select(vec![
            "family", "alpha", "alpha_x", "alpha_y", "gamma", "b", "c", "x", "y", "mean", "cov",
            "theta", "value", "m", "w", "wo", "wi", "theta_o", "theta_i", "phi", "phi_o",
            "phi_i", "u", "p", "q", "k", "masking", "route", "quantity", "model", "a", "v",
            "o", "cap", "asg", "sg", "axis", "sharpness", "amplitude", "z", "bandwidths", "ph",
            "name", "materials", "sampling", "filtering", "lighting", "incidence", "theta_max",
        ])
        .prop_map(str::to_string),
        1 => "[a-z_]{0,6}",
    ]
}

/// A model spec: a known family with known (or wrong) keys and hostile values.
fn model() -> impl Strategy<Value = Value> {
    let family = prop::sample::select(vec![
        "beckmann",
        "ggx",
        "std",
        "hyper_cauchy",
        "student_fixed_variance",
        "student_general",
        "piecewise_linear",
        "blend",
        "gaussian_slopes",
        "gtr",
        "nope",
    ]);
    (
        family,
        prop::collection::btree_map(key(), prop_oneof![3 => number(), 1 => value()], 0..4),
    )
        .prop_map(|(f, fields)| {
            let mut o: Map<String, Value> = fields.into_iter().collect();
            o.insert("family".into(), json!(f));
            Value::Object(o)
        })
}

/// Every quantity `mfh eval` knows, and one it does not.
fn quantities() -> Vec<&'static str> {
    let mut all: Vec<&str> = mfh_harness::eval::QUANTITIES.to_vec();
    all.extend_from_slice(&mfh_harness::eval::sg::QUANTITIES);
    all.push("unknown");
    all
}

/// An eval query: a quantity, a model, and arguments under known and unknown keys. Routes are
/// the default ones: the quadrature routes (`exact`) take milliseconds each and are fuzzed in
/// the extensive tier only.
fn query() -> impl Strategy<Value = Value> {
    let extensive = cases() > 10_000;
    let routes: Vec<&'static str> = if extensive {
        vec!["default", "printed", "exact", "integer", "nope"]
    } else {
        vec!["default", "printed", "integer", "nope"]
    };
    (
        prop::sample::select(quantities()),
        model(),
        prop::collection::btree_map(key(), prop_oneof![2 => number(), 1 => value()], 0..5),
        prop::option::of(prop::sample::select(routes)),
    )
        .prop_map(move |(quantity, model, args, route)| {
            let mut o: Map<String, Value> = args.into_iter().collect();
            o.insert("quantity".into(), json!(quantity));
            o.insert("model".into(), model);
            if !extensive && o.get("route") == Some(&json!("exact")) {
                o.remove("route");
            }
            if let Some(r) = route {
                o.insert("route".into(), json!(r));
            }
            Value::Object(o)
        })
}

/// Every answer is one object: a value, or an error with a known kind and a short message.
fn assert_answer(a: &Value) {
    if let Some(e) = a.get("error") {
        let kind = e["kind"].as_str().expect("a kind");
        assert!(
            ["parse", "model", "argument", "unsupported", "route"].contains(&kind),
            "{a}"
        );
        let message = e["message"].as_str().expect("a message");
        assert!(message.chars().count() <= 401, "{message}");
        assert!(!message.contains("untagged enum"), "{message}");
    } else {
        assert!(a.get("value").is_some(), "{a}");
    }
}

#[test]
fn eval_lines_answer_a_value_or_a_typed_error() {
    runner()
        .run(&query(), |q| {
            assert_answer(&answer_line(&q.to_string()));
            Ok(())
        })
        .unwrap();
}

#[test]
fn eval_text_lines_never_panic() {
    // Arbitrary text, and JSON-ish text with a quantity and a model spliced in.
    let text = prop_oneof![
        ".{0,80}",
        (value(), "[ -~]{0,10}").prop_map(|(v, junk)| format!("{v}{junk}")),
    ];
    runner()
        .run(&text, |line| {
            assert_answer(&answer_line(&line));
            Ok(())
        })
        .unwrap();
}

#[test]
fn eval_streams_answer_every_nonblank_line_in_bounded_memory() {
    // Raw bytes with line ends: invalid UTF-8 answers an error for its line, the others are
    // answered, and the count of answers is the count of non-blank lines.
    let bytes = prop::collection::vec(
        prop_oneof![
            4 => any::<u8>(),
            1 => Just(b'\n'),
        ],
        0..400,
    );
    runner()
        .run(&bytes, |input| {
            let mut out = Vec::new();
            let summary = eval_stream(&mut input.as_slice(), &mut out).expect("in memory");
            let nonblank = input
                .split(|&b| b == b'\n')
                .filter(|l| match std::str::from_utf8(l) {
                    Ok(s) => !s.trim().is_empty(),
                    Err(_) => true,
                })
                .count();
            prop_assert_eq!(summary.answered, nonblank);
            let text = String::from_utf8(out).expect("answers are UTF-8");
            prop_assert_eq!(text.lines().count(), nonblank);
            for line in text.lines() {
                assert_answer(&serde_json::from_str(line).expect("answers are JSON"));
            }
            Ok(())
        })
        .unwrap();
}

/// A scene: known keys with hostile values, materials with random models.
fn scene() -> impl Strategy<Value = Value> {
    let material = (
        "[a-c]{0,2}",
        model(),
        prop::option::of(prop_oneof![
            Just(json!("uncorrelated")),
            Just(json!("height_correlated")),
            value()
        ]),
        prop::option::of(prop_oneof![
            Just(json!("normals")),
            Just(json!("visible_normals")),
            Just(json!("pseudo_vnis")),
            value()
        ]),
        prop::collection::btree_map(key(), value(), 0..2),
    )
        .prop_map(|(name, model, masking, sampling, extra)| {
            let mut o: Map<String, Value> = extra.into_iter().collect();
            o.insert("name".into(), json!(name));
            o.insert("model".into(), model);
            if let Some(m) = masking {
                o.insert("masking".into(), m);
            }
            if let Some(s) = sampling {
                o.insert("sampling".into(), s);
            }
            Value::Object(o)
        });
    (
        prop::collection::vec(material, 0..4),
        prop::collection::btree_map(key(), value(), 0..3),
        prop::option::of(number()),
    )
        .prop_map(|(materials, extra, theta_max)| {
            let mut o: Map<String, Value> = extra.into_iter().collect();
            o.insert("name".into(), json!("fuzz"));
            o.insert("materials".into(), Value::Array(materials));
            if let Some(t) = theta_max {
                o.insert("incidence".into(), json!({ "theta_max": t }));
            }
            Value::Object(o)
        })
}

#[test]
fn scenes_parse_or_give_a_typed_error() {
    runner()
        .run(&scene(), |s| {
            if let Ok(scene) = Scene::parse(&s.to_string(), "fuzz.json") {
                prop_assert!(!scene.materials.is_empty() && scene.materials.len() <= MAX_MATERIALS);
                let t = scene.incidence.theta_max;
                prop_assert!(t > 0.0 && t <= std::f64::consts::FRAC_PI_2 + 1e-12);
            }
            Ok(())
        })
        .unwrap();
    runner()
        .run(&".{0,120}", |text| {
            let _ = Scene::parse(&text, "fuzz.json");
            Ok(())
        })
        .unwrap();
}

#[test]
fn chi2_requests_validate_within_the_stated_limits() {
    let request = (
        prop_oneof![
            model().prop_map(|m| m.to_string()),
            ".{0,40}",
            Just(r#"{"family":"ggx","alpha":0.3}"#.to_string()),
        ],
        prop_oneof![any::<u64>(), 0u64..100_000_000],
        prop_oneof![any::<usize>(), 0usize..2_000],
        any::<f64>(),
        any::<bool>(),
        prop::option::of(any::<f64>()),
        prop::option::of(any::<f64>()),
    );
    runner()
        .run(
            &request,
            |(model, samples, resolution, alpha, visible, incidence, azimuth)| {
                let r = Chi2Request {
                    model,
                    samples,
                    resolution,
                    seed: 1,
                    alpha,
                    sampling: if visible {
                        SamplingKind::Visible
                    } else {
                        SamplingKind::Normals
                    },
                    incidence,
                    azimuth,
                };
                match sampler_chi2::validate(&r) {
                    Ok(plan) => {
                        let c = &plan.config;
                        prop_assert!(
                            (sampler_chi2::MIN_RESOLUTION..=MAX_RESOLUTION).contains(&c.resolution)
                        );
                        prop_assert!(c.samples <= MAX_SAMPLES);
                        prop_assert!(c.samples >= sampler_chi2::min_samples(c.resolution));
                        prop_assert!(c.alpha > 0.0 && c.alpha < 1.0);
                        prop_assert_eq!(plan.incidence.is_some(), visible);
                    }
                    Err(e) => prop_assert!(e.to_string().starts_with("--"), "{e}"),
                }
                Ok(())
            },
        )
        .unwrap();
}
