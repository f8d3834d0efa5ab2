//! Stability: the hard cases stay finite, in range and accurate — roughness and shape at the
//! ends of their domains (α = 1e-4 and 10, γ = 1.5 + 1e-9 and 1e8 for the Student family,
//! γ → 0 and 10 for GTR), incidence from exactly normal to exactly grazing.

use super::smith::lambda_oracle;
use super::{compare, covers, timed, Planned};
use crate::record::{CheckRecord, Verdict};
use crate::tolerance::{CLOSED_FORM, IDENTITY, NUMERICAL_ROUTE};
use mfh_reference::geometry::from_spherical;
use mfh_reference::ModelSpec;
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;

/// The stressed variants of a material's spec: each parameter pushed to the ends of its
/// domain, one at a time.
pub fn variants(spec: &Value) -> Vec<(String, Value)> {
    let family = spec.get("family").and_then(Value::as_str).unwrap_or("");
    let mut out = Vec::new();
    let alphas: &[f64] = match family {
        "gtr" => &[1e-4, 0.999],
        "beckmann" | "ggx" | "std" | "hyper_cauchy" | "student_fixed_variance" => &[1e-4, 10.0],
        _ => &[],
    };
    for &a in alphas {
        let mut v = spec.clone();
        if let Some(o) = v.as_object_mut() {
            o.remove("alpha_x");
            o.remove("alpha_y");
            o.insert("alpha".into(), json!(a));
        }
        out.push((format!("alpha = {a}"), v));
    }
    let gammas: &[f64] = match family {
        "std" | "hyper_cauchy" => &[1.5 + 1e-9, 1e8],
        "student_fixed_variance" => &[2.0 + 1e-9, 1e8],
        "gtr" => &[1e-6, 10.0],
        _ => &[],
    };
    for &g in gammas {
        let mut v = spec.clone();
        if let Some(o) = v.as_object_mut() {
            o.insert("gamma".into(), json!(g));
        }
        out.push((format!("gamma = {g}"), v));
    }
    if family == "gaussian_slopes" {
        // A near-singular covariance: correlation 1 − 1e-9.
        out.push((
            "cov correlation 1 − 1e-9".into(),
            json!({"family": "gaussian_slopes", "mean": [0.1, -0.05],
                   "cov": [[0.04, 0.04 * (1.0 - 1e-9)], [0.04 * (1.0 - 1e-9), 0.04]]}),
        ));
    }
    out
}

/// Plans the stability checks of one material's stressed variants.
pub fn plan(spec: &Value, why: &str) -> Vec<Planned> {
    let family = spec
        .get("family")
        .and_then(Value::as_str)
        .unwrap_or("")
        .to_string();
    variants(spec)
        .into_iter()
        .map(|(label, variant)| {
            let fam = family.clone();
            let covered = vec![
                covers(&family, "d", "default"),
                covers(&family, "lambda", "default"),
            ];
            let covered_run = covered.clone();
            let case = json!({"variant": label});
            let (case_run, variant_run) = (case.clone(), variant.clone());
            Planned {
                check: "stability.extremes".into(),
                model: variant,
                case,
                why: format!("{why}: hard case {label}"),
                covers: covered,
                statistical: false,
                run: Box::new(move |_| {
                    timed(|| {
                        let mut r = CheckRecord::new(
                            "stability.extremes",
                            variant_run.clone(),
                            case_run.clone(),
                            "issue 2 / DESIGN.md: finite and accurate for γ ∈ (1.5, 1e8], α ∈ [1e-4, 10], θ ∈ [0, π/2]",
                        );
                        r.covers = covered_run.clone();
                        let model = match serde_json::from_value::<ModelSpec>(variant_run.clone())
                            .map_err(|e| e.to_string())
                            .and_then(|s| s.build().map_err(|e| e.to_string()))
                        {
                            Ok(m) => m,
                            Err(e) => {
                                r.verdict = Verdict::Error { message: format!("variant rejected: {e}") };
                                return r;
                            }
                        };
                        let mut problems = Vec::new();
                        let thetas = [0.0, 1e-12, 1e-8, 1e-4, 0.01, 0.3, 0.8, 1.2, 1.5, FRAC_PI_2 - 1e-6, FRAC_PI_2 - 1e-12, FRAC_PI_2];
                        let mut last = 0.0f64;
                        for &t in &thetas {
                            let w = from_spherical(t, 0.4);
                            let d = model.d(w);
                            if !(d.is_finite() && d >= 0.0) {
                                problems.push(format!("D = {d} at θ = {t}"));
                            }
                            if let Some(s) = model.as_smith() {
                                let l = s.lambda(w);
                                let ok = if t == FRAC_PI_2 { !(l < 0.0) } else { l.is_finite() && l >= 0.0 };
                                if !ok {
                                    problems.push(format!("Λ = {l} at θ = {t}"));
                                }
                                if l < last * (1.0 - IDENTITY.value) {
                                    problems.push(format!("Λ decreases: {l} < {last} at θ = {t}"));
                                }
                                last = l;
                            }
                        }
                        if let Some(s) = model.as_smith() {
                            let l0 = s.lambda([0.0, 0.0, 1.0]);
                            if l0 != 0.0 {
                                problems.push(format!("Λ(n) = {l0}, not 0"));
                            }
                            let g = s.g1(from_spherical(FRAC_PI_2, 0.4), [0.0, 0.0, 1.0]);
                            if g != 0.0 {
                                problems.push(format!("G1(π/2) = {g}, not 0"));
                            }
                        }
                        if let Some(sampler) = model.as_sampler() {
                            let top = 1.0 - f64::EPSILON / 2.0;
                            for u in [[0.0, 0.0], [0.5, 0.5], [top, top], [0.25, top], [0.75, 0.0]] {
                                let m = sampler.sample_wm(u);
                                let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                                if !(m[2] >= 0.0 && (len - 1.0).abs() < 1e-12) {
                                    problems.push(format!("sample_wm({u:?}) = {m:?}"));
                                }
                            }
                        }
                        // Accuracy at one interior incidence, against the oracle.
                        if let Some(s) = model.as_smith() {
                            let w = from_spherical(1.0, 0.4);
                            let value = s.lambda(w);
                            let oracle = lambda_oracle(model.as_ref(), &variant_run, w);
                            let tol = if matches!(fam.as_str(), "gtr" | "piecewise_linear" | "blend") {
                                &NUMERICAL_ROUTE
                            } else {
                                &CLOSED_FORM
                            };
                            compare(&mut r, value, oracle, tol);
                            if r.verdict == Verdict::Fail {
                                problems.push(format!("Λ(θ = 1) = {value} against the oracle {}", oracle.value));
                            }
                        }
                        r.verdict = if problems.is_empty() {
                            Verdict::Pass
                        } else {
                            r.case = json!({"variant": case_run["variant"], "problems": problems});
                            Verdict::Fail
                        };
                        r
                    })
                }),
            }
        })
        .collect()
}
