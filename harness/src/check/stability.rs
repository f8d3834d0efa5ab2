//! Stability: the hard cases stay finite, in range and accurate. For any model
//! (`stability.incidence`): incidence from exactly normal to exactly grazing, and the sampler on
//! the edges and corners of [0, 1)². For reference models (`stability.extremes`): the same at
//! the parameters the registry lists as the ends of each family's domain (α = 1e-4 and 10,
//! γ = 1.5 + 1e-9 and 1e8 for the Student family, γ → 0 and 10 for GTR, a near-singular
//! covariance), plus Λ against the oracle at one interior incidence.

use super::{compare, covers, Planned, PlannedCheck};
use crate::check::Check;
use crate::oracle::smith_lambda::lambda_oracle;
use crate::precision::Precision;
use crate::record::Verdict;
use crate::subject::Subject;
use crate::tolerance::{CLOSED_FORM, IDENTITY, NUMERICAL_ROUTE};
use mfh_reference::family::FamilyInfo;
use mfh_reference::geometry::from_spherical;
use mfh_reference::{ModelSpec, Ndf};
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

const SOURCE: &str =
    "ARCHITECTURE.md model boundary: D, Λ, G1 finite and in range for θ ∈ [0, π/2]; \
                      sample_wm(u) a unit vector with m_z ≥ 0 for every u ∈ [0, 1)²";

/// The largest double below 1.
const TOP: f64 = 1.0 - f64::EPSILON / 2.0;

/// The u at which samplers are probed: the four corners, and 17 points along each edge of
/// [0, 1)² (u₁ = 0, u₁ = 1 − 2⁻⁵³, u₂ = 0, u₂ = 1 − 2⁻⁵³), plus points one ulp inside.
pub fn edge_points() -> Vec<[f64; 2]> {
    let along: Vec<f64> = (0..=16)
        .map(|i| f64::from(i) / 16.0)
        .map(|t| if t >= 1.0 { TOP } else { t })
        .chain([f64::MIN_POSITIVE, f64::EPSILON, 0.5 + f64::EPSILON])
        .collect();
    let mut out = Vec::new();
    for &edge in &[0.0, f64::MIN_POSITIVE, TOP] {
        for &t in &along {
            out.push([edge, t]);
            out.push([t, edge]);
        }
    }
    out
}

/// Everything that is wrong with a model at the hard inputs, as readable lines (empty: none).
pub fn probe(model: &dyn Ndf) -> Vec<String> {
    probe_at(model, Precision::F64)
}

/// How far from 1 a sampled normal's length may be: 1e-12 (≈ 4500 ε) for f64, and for a
/// float32 sampler `identity_f32` (64 ε₃₂ = 7.6e-6): a float32 unit vector normalized in
/// float32 is off by a few ε₃₂.
fn unit_tolerance(precision: Precision) -> f64 {
    match precision {
        Precision::F64 => 1e-12,
        p => IDENTITY.at(p).value,
    }
}

/// [`probe`] for a model computing in `precision` (the unit-length and monotonicity
/// tolerances are that precision's).
pub fn probe_at(model: &dyn Ndf, precision: Precision) -> Vec<String> {
    let identity = IDENTITY.at(precision).value;
    let unit = unit_tolerance(precision);
    let mut problems = Vec::new();
    let thetas = [
        0.0,
        1e-300,
        1e-12,
        1e-8,
        1e-4,
        0.01,
        0.3,
        0.8,
        1.2,
        1.5,
        FRAC_PI_2 - 1e-6,
        FRAC_PI_2 - 1e-12,
        FRAC_PI_2,
    ];
    let n = [0.0, 0.0, 1.0];
    for phi in [0.4, 2.0] {
        let mut last = 0.0f64;
        for &t in &thetas {
            let w = from_spherical(t, phi);
            let d = model.d(w);
            if !(d.is_finite() && d >= 0.0) {
                problems.push(format!("D = {d} at θ = {t}, φ = {phi}"));
            }
            if let Some(s) = model.as_smith() {
                let l = s.lambda(w);
                let ok = if t == FRAC_PI_2 {
                    !(l < 0.0) && !l.is_nan()
                } else {
                    l.is_finite() && l >= 0.0
                };
                if !ok {
                    problems.push(format!("Λ = {l} at θ = {t}, φ = {phi}"));
                }
                if l < last * (1.0 - identity) {
                    problems.push(format!("Λ decreases: {l} < {last} at θ = {t}, φ = {phi}"));
                }
                last = l;
                let g = s.g1(w, n);
                if !(0.0..=1.0).contains(&g) {
                    problems.push(format!("G1 = {g} at θ = {t}, φ = {phi}"));
                }
            }
        }
    }
    if let Some(s) = model.as_smith() {
        let l0 = s.lambda(n);
        if l0 != 0.0 {
            problems.push(format!("Λ(n) = {l0}, not 0"));
        }
        let g = s.g1(from_spherical(FRAC_PI_2, 0.4), n);
        if g != 0.0 {
            problems.push(format!("G1(π/2) = {g}, not 0"));
        }
    }
    if let Some(sampler) = model.as_sampler() {
        for u in edge_points() {
            let m = sampler.sample_wm(u);
            let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
            if !(m[2] >= 0.0 && (len - 1.0).abs() < unit) {
                problems.push(format!("sample_wm({u:?}) = {m:?}"));
                continue;
            }
            let pdf = sampler.pdf_wm(m);
            if !(pdf.is_finite() && pdf >= 0.0) {
                problems.push(format!("pdf_wm(sample_wm({u:?})) = {pdf}"));
            }
        }
    }
    problems
}

/// Plans the hard-input check of any model.
pub fn plan_incidence<'a>(subject: &Arc<Subject<'a>>, why: &str) -> PlannedCheck<'a> {
    let family = subject.family();
    let covered = vec![covers(family, "d", "default")];
    let s = subject.clone();
    let case = json!({"theta": "0 … π/2 exactly", "u": "edges and corners of [0, 1)²"});
    Check::new("stability.incidence", subject.label.clone(), case, SOURCE)
        .why(format!(
            "{why}: exactly normal and grazing incidence, samplers at the edges of u"
        ))
        .covers(covered)
        .run(move |r, _| {
            let problems = probe_at(s.model.as_ref(), s.precision);
            r.verdict = if problems.is_empty() {
                Verdict::Pass
            } else {
                r.case["problems"] = json!(problems);
                Verdict::Fail
            };
            Ok(())
        })
}

/// The stressed variants of a reference spec: each parameter the registry lists pushed to the
/// ends of its domain, one at a time, and the registry's hard whole specs.
pub fn variants(spec: &Value, info: &FamilyInfo) -> Vec<(String, Value)> {
    let mut out = Vec::new();
    for &a in info.stress_alpha {
        let mut v = spec.clone();
        if let Some(o) = v.as_object_mut() {
            o.remove("alpha_x");
            o.remove("alpha_y");
            o.insert("alpha".into(), json!(a));
        }
        out.push((format!("alpha = {a}"), v));
    }
    for &g in info.stress_gamma {
        let mut v = spec.clone();
        if let Some(o) = v.as_object_mut() {
            o.insert("gamma".into(), json!(g));
        }
        out.push((format!("gamma = {g}"), v));
    }
    for (label, s) in info.stress_specs {
        if let Ok(v) = serde_json::from_str(s) {
            out.push((label.to_string(), v));
        }
    }
    out
}

/// Plans the stability checks of one reference spec's stressed variants.
pub fn plan(spec: &ModelSpec, why: &str) -> Vec<Planned> {
    let info = mfh_reference::registry::info(spec);
    let family = info.name;
    let value = serde_json::to_value(spec).unwrap_or(Value::Null);
    variants(&value, info)
        .into_iter()
        .map(|(label, variant)| {
            let covered = vec![
                covers(family, "d", "default"),
                covers(family, "lambda", "default"),
            ];
            let case = json!({"variant": label});
            let (case_run, variant_run) = (case.clone(), variant.clone());
            Check::new(
                "stability.extremes",
                variant,
                case,
                "ARCHITECTURE.md: finite and accurate for γ ∈ (1.5, 1e8], \
                             α ∈ [1e-4, 10], θ ∈ [0, π/2]",
            )
            .why(format!("{why}: hard case {label}"))
            .covers(covered)
            .run(move |r, _| {
                let subject = match serde_json::from_value::<ModelSpec>(variant_run.clone())
                    .map_err(|e| e.to_string())
                    .and_then(|s| Subject::reference(&s).map_err(|e| e.to_string()))
                {
                    Ok(m) => m,
                    Err(e) => {
                        r.verdict = Verdict::Error {
                            message: format!("variant rejected: {e}"),
                        };
                        return Ok(());
                    }
                };
                let mut problems = probe(subject.model.as_ref());
                // Accuracy at one interior incidence, against the oracle.
                if let Some(s) = subject.model.as_smith() {
                    let w = from_spherical(1.0, 0.4);
                    let value = s.lambda(w);
                    let oracle = lambda_oracle(subject.as_ref(), w);
                    let tol = if subject.lambda_numerical() {
                        &NUMERICAL_ROUTE
                    } else {
                        &CLOSED_FORM
                    };
                    compare(r, value, oracle, tol);
                    if r.verdict == Verdict::Fail {
                        problems.push(format!(
                            "Λ(θ = 1) = {value} against the oracle {}",
                            oracle.value
                        ));
                    }
                }
                r.verdict = if problems.is_empty() {
                    Verdict::Pass
                } else {
                    r.case = json!({"variant": case_run["variant"], "problems": problems});
                    Verdict::Fail
                };
                Ok(())
            })
        })
        .collect()
}
