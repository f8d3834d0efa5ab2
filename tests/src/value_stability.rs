//! Value-stability vectors: the query set, the stored file's format, and the comparison of a
//! stored answer with a current one.
//!
//! The file `tests/data/value_stability.jsonl` holds one header line and then one line per
//! query, `{"query": {…}, "answer": {…}}`, the answer as `mfh eval` gave it when the file was
//! generated (`cargo run -p mfh-tests --example generate_value_stability`). The test
//! `tests/value_stability.rs` asserts that today's answers match within [`REL_TOLERANCE`].

use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;
use std::path::PathBuf;

/// The largest relative difference between a stored and a current number.
pub const REL_TOLERANCE: f64 = 1e-15;

/// The command that regenerates the data file.
pub const REGENERATE: &str = "cargo run -p mfh-tests --example generate_value_stability";

/// The path of the data file.
pub fn data_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/value_stability.jsonl")
}

/// The unit vector at (θ, φ), as the reference library computes it.
fn unit(theta: f64, phi: f64) -> Value {
    json!(mfh_reference::geometry::from_spherical(theta, phi))
}

/// A piecewise-linear profile (values of D_iso at the breakpoints; normalized internally).
fn profile_x() -> Value {
    json!({"theta": [0.0, 0.3, 0.8, 1.2, FRAC_PI_2], "value": [3.0, 2.0, 0.6, 0.1, 0.0]})
}

fn profile_y() -> Value {
    json!({"theta": [0.0, 0.5, 1.0, FRAC_PI_2], "value": [1.5, 1.2, 0.3, 0.05]})
}

/// The model specs of the vectors: every example of every family of the registry
/// (`mfh_reference::registry`), so that a new family gets vectors without editing this list.
pub fn models() -> Vec<Value> {
    mfh_reference::registry::FAMILIES
        .iter()
        .flat_map(|f| f.examples.iter())
        .map(|e| serde_json::from_str(e).expect("registry examples are JSON"))
        .collect()
}

/// The shapes at which every Student Λ route that applies is recorded.
pub const STUDENT_GAMMAS: [f64; 7] = [2.0, 2.5, 3.0, 3.5, 4.0, 7.5, 20.0];

/// The query set, in file order: a battery of quantities per model (unsupported ones answer
/// errors, which are recorded too), Λ by every route of every family, Λ near normal and at
/// grazing incidence, and a few malformed queries.
pub fn queries() -> Vec<Value> {
    let mut q = Vec::new();
    for model in models() {
        let with = |fields: Value| {
            let mut obj = json!({ "model": model.clone() });
            for (k, v) in fields.as_object().expect("an object") {
                obj[k] = v.clone();
            }
            obj
        };
        q.push(with(json!({"quantity": "d", "theta": 0.8, "phi": 0.3})));
        q.push(with(
            json!({"quantity": "lambda", "theta": 1.2, "phi": 0.3}),
        ));
        q.push(with(
            json!({"quantity": "g1", "w": unit(1.0, 0.2), "m": unit(0.2, 0.1)}),
        ));
        q.push(with(
            json!({"quantity": "g2", "theta_o": 0.9, "theta_i": 1.2, "phi_i": 3.0,
                            "masking": "height_correlated"}),
        ));
        q.push(with(json!({"quantity": "p2", "q": 0.3, "phi": 0.5})));
        q.push(with(
            json!({"quantity": "slope_moment", "k": 1, "phi": 0.5}),
        ));
        q.push(with(json!({"quantity": "sample_wm", "u": [0.3, 0.7]})));
        q.push(with(json!({"quantity": "pdf_wm", "m": unit(0.4, 1.0)})));
        q.push(with(
            json!({"quantity": "sample_wm_visible", "theta_i": 1.1, "phi_i": 0.4,
                   "u": [0.3, 0.7]}),
        ));
        q.push(with(
            json!({"quantity": "pdf_wm_visible", "theta_i": 1.1, "phi_i": 0.4,
                   "m": unit(0.4, 1.0)}),
        ));
        q.push(with(
            json!({"quantity": "visible_moments", "theta": 0.8, "phi": 0.5}),
        ));
    }
    // Λ by every route. Student: every route of student_lambda::ROUTES at every γ (the routes
    // that do not apply answer a "route" error, recorded too).
    for gamma in STUDENT_GAMMAS {
        for &(route, _) in mfh_reference::ndf::student_lambda::ROUTES {
            q.push(
                json!({"model": {"family": "std", "gamma": gamma, "alpha": 0.3},
                          "quantity": "lambda", "theta": 1.2, "route": route}),
            );
        }
    }
    for family in ["beckmann", "ggx"] {
        for route in ["default", "table1"] {
            for theta in [0.2, 1.2] {
                q.push(json!({"model": {"family": family, "alpha": 0.3},
                              "quantity": "lambda", "theta": theta, "route": route}));
            }
        }
    }
    // GTR: every route of gtr_lambda::ROUTES at integer and fractional γ.
    for gamma in [0.0, 1.0, 1.5, 2.0, 3.0, 4.0] {
        for &(route, _) in mfh_reference::ndf::gtr_lambda::ROUTES {
            q.push(
                json!({"model": {"family": "gtr", "gamma": gamma, "alpha": 0.3},
                          "quantity": "lambda", "theta": 1.2, "route": route}),
            );
        }
    }
    let piecewise = json!({"family": "piecewise_linear", "x": profile_x(), "y": profile_y()});
    for route in [
        "exact",
        "domain_split",
        "domain_split_adaptive",
        "slope_space",
    ] {
        q.push(
            json!({"model": piecewise, "quantity": "lambda", "theta": 1.2, "phi": 0.7,
                      "route": route}),
        );
    }
    // Near normal incidence (where the printed forms cancel) and at grazing (Λ = ∞).
    for theta in [1e-3, 0.05, FRAC_PI_2] {
        for route in ["stable", "2f1"] {
            q.push(
                json!({"model": {"family": "std", "gamma": 3.5, "alpha": 0.3},
                          "quantity": "lambda", "theta": theta, "route": route}),
            );
        }
    }
    // Moments that exist and that do not (null), and the Student γ extremes.
    q.push(
        json!({"model": {"family": "std", "gamma": 7.5, "alpha": 0.3},
                  "quantity": "excess_kurtosis"}),
    );
    q.push(
        json!({"model": {"family": "std", "gamma": 2.5, "alpha": 0.3},
                  "quantity": "slope_moment", "k": 2}),
    );
    q.push(
        json!({"model": {"family": "std", "gamma": 1e8, "alpha": 0.3},
                  "quantity": "lambda", "theta": 1.2}),
    );
    q.push(
        json!({"model": {"family": "std", "gamma": 1.2, "alpha": 0.3},
                  "quantity": "sample_wm", "u": [0.4, 0.999]}),
    );
    // Spherical Gaussians (document 003): no model.
    let a = json!({"axis": unit(0.3, 0.2), "sharpness": 8.0, "amplitude": 1.5});
    let b = json!({"axis": unit(0.5, 1.9), "sharpness": 20.0, "amplitude": 0.7});
    let asg = json!({"x": [1.0, 0.0, 0.0], "y": [0.0, 1.0, 0.0], "z": [0.0, 0.0, 1.0],
                     "bandwidths": [6.0, 15.0], "amplitude": 2.0});
    q.push(json!({"quantity": "sg_eval", "a": a, "v": unit(0.4, 0.6)}));
    for route in ["default", "printed", "exact"] {
        q.push(json!({"quantity": "sg_inner", "a": a, "b": b, "route": route}));
    }
    q.push(json!({"quantity": "sg_product", "a": a, "b": b}));
    q.push(json!({"quantity": "sg_integral", "a": a}));
    q.push(json!({"quantity": "sg_integral", "a": a, "cap": 0.7}));
    q.push(json!({"quantity": "asg_eval", "asg": asg, "v": unit(0.4, 0.6)}));
    for route in ["default", "large_bandwidth", "exact"] {
        q.push(json!({"quantity": "asg_integral", "asg": asg, "route": route}));
    }
    q.push(json!({"quantity": "asg_sg_convolution", "asg": asg, "sg": b}));
    // Malformed queries: their error kinds are part of the contract.
    q.push(json!({"model": {"family": "ggx", "alpha": -1}, "quantity": "d", "theta": 0}));
    q.push(json!({"model": {"family": "ggx", "alpha": 0.3}, "quantity": "d"}));
    q.push(
        json!({"model": {"family": "std", "gamma": 2.7, "alpha": 0.3},
                  "quantity": "lambda", "theta": 1, "route": "integer"}),
    );
    q.push(
        json!({"model": {"family": "std", "gamma": 1.2, "alpha": 0.3},
                  "quantity": "lambda", "theta": 1}),
    );
    q
}

/// The header line of the data file.
pub fn header(count: usize) -> Value {
    json!({
        "what": "mfh value-stability vectors: each line after this one is a query of `mfh eval` \
                 and the answer the code gave when this file was generated",
        "generated_by": "tests/examples/generate_value_stability.rs (query set: \
                         tests/src/value_stability.rs)",
        "regenerate": REGENERATE,
        "tolerance": "numbers match to 1e-15 relative; error lines match by kind",
        "count": count,
    })
}

/// One line of the data file: the query and the answer `mfh eval` gives now.
pub fn record(query: &Value) -> Value {
    let line = serde_json::to_string(query).expect("a query serializes");
    json!({ "query": query, "answer": mfh_harness::eval::answer_line(&line) })
}

/// Whether a current answer matches a stored one: same shape, numbers within
/// [`REL_TOLERANCE`] relative (zero only as zero), the same strings (`"inf"`, `"nan"`) and
/// nulls, errors of the same kind. `Err` says where they differ.
pub fn compare(stored: &Value, current: &Value) -> Result<(), String> {
    match (stored.get("error"), current.get("error")) {
        (Some(s), Some(c)) => {
            return if s["kind"] == c["kind"] {
                Ok(())
            } else {
                Err(format!("error kind {} became {}", s["kind"], c["kind"]))
            };
        }
        (None, None) => {}
        _ => return Err(format!("{stored} became {current}")),
    }
    compare_values(&stored["value"], &current["value"])
}

fn compare_values(stored: &Value, current: &Value) -> Result<(), String> {
    match (stored, current) {
        (Value::Number(s), Value::Number(c)) => {
            let (s, c) = (
                s.as_f64().unwrap_or(f64::NAN),
                c.as_f64().unwrap_or(f64::NAN),
            );
            let scale = s.abs().max(c.abs());
            if s == c || (c - s).abs() <= REL_TOLERANCE * scale {
                Ok(())
            } else {
                Err(format!(
                    "{s:e} became {c:e} (relative difference {:.2e})",
                    (c - s).abs() / scale
                ))
            }
        }
        (Value::Array(s), Value::Array(c)) if s.len() == c.len() => {
            s.iter().zip(c).enumerate().try_for_each(|(i, (s, c))| {
                compare_values(s, c).map_err(|e| format!("component {i}: {e}"))
            })
        }
        (s, c) if s == c => Ok(()),
        (s, c) => Err(format!("{s} became {c}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comparison_rules() {
        let v = |x: Value| json!({ "value": x });
        assert!(compare(&v(json!(1.0)), &v(json!(1.0 + 4e-16))).is_ok());
        assert!(compare(&v(json!(1.0)), &v(json!(1.0 + 4e-15))).is_err());
        assert!(compare(&v(json!(0.0)), &v(json!(1e-300))).is_err());
        assert!(compare(&v(json!("inf")), &v(json!("inf"))).is_ok());
        assert!(compare(&v(json!("inf")), &v(json!(1e308))).is_err());
        assert!(compare(&v(json!(null)), &v(json!(null))).is_ok());
        assert!(compare(&v(json!([0.5, 1.0])), &v(json!([0.5, 1.0]))).is_ok());
        assert!(compare(&v(json!([0.5, 1.0])), &v(json!([0.5]))).is_err());
        let e = |k: &str| json!({"error": {"kind": k, "message": "…"}});
        assert!(compare(&e("route"), &e("route")).is_ok());
        assert!(compare(&e("route"), &e("model")).is_err());
        assert!(compare(&e("route"), &v(json!(1.0))).is_err());
    }

    #[test]
    fn query_set_is_a_few_hundred_distinct_queries() {
        let q = queries();
        assert!((100..=300).contains(&q.len()), "{}", q.len());
        let mut seen = std::collections::HashSet::new();
        for query in &q {
            assert!(seen.insert(query.to_string()), "duplicate query {query}");
        }
    }
}
