//! `bsdf.stability`: the BSDF at the hard cases — directions at cos θ = ±1e-6 and ±1, exactly
//! at the critical angle of a transmitting BSDF, a degenerate half vector (wo = −wi, where
//! wi + wo = 0), wo = wi — is finite and non-negative, has a pdf wherever it has a value (a
//! value where the BSDF never samples biases every estimator that samples it), and samples
//! (with u at 0, ½ and the largest double below 1 in every coordinate) unit, finite directions
//! with a positive finite pdf and a finite non-negative weight, or fails cleanly.
//!
//! For a reference BSDF the planner also runs it on variants of the spec at the extremes of
//! its parameters (α = 1e-4, anisotropy 1:100, η from 1.0001 to 4 and the inverses).

use super::reciprocity::direction;
use super::{BsdfSubject, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck};
use crate::record::{Measured, Verdict};
use crate::tolerance::BSDF_STABILITY;
use mfh_reference::bsdf::{Bsdf, BsdfSpec};
use mfh_reference::geometry::Vec3;
use serde_json::{json, Value};
use std::sync::Arc;

/// The largest double below 1.
const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;

/// The hard incidences (and outgoing directions) of a BSDF of relative index `eta`.
fn hard_directions(eta: Option<f64>) -> Vec<Vec3> {
    let mut cosines = vec![1.0, 1e-6, 0.5];
    if let Some(eta) = eta {
        cosines.push(eta.min(1.0 / eta).asin().cos());
    }
    let mut out = Vec::new();
    for &c in &cosines {
        for inside in [false, true] {
            if eta.is_none() && inside {
                continue;
            }
            out.push(direction(c, 0.4, inside));
        }
    }
    out
}

/// What is wrong with the BSDF at the hard cases: (violations, the first).
pub fn violations(bsdf: &dyn Bsdf) -> (u64, Option<Value>) {
    let dirs = hard_directions(bsdf.eta());
    let mut count = 0u64;
    let mut first = None;
    let mut flag = |what: &str, at: Value| {
        count += 1;
        if first.is_none() {
            first = Some(json!({"violation": what, "at": at}));
        }
    };
    for &wi in &dirs {
        let mut outgoing = dirs.clone();
        outgoing.push([-wi[0], -wi[1], -wi[2]]);
        outgoing.push(wi);
        for &wo in &outgoing {
            let (value, pdf) = (bsdf.eval(wi, wo), bsdf.pdf(wi, wo));
            let at = || json!({"wi": wi, "wo": wo, "eval": value, "pdf": pdf});
            if !(value.is_finite() && value >= 0.0) {
                flag("eval is not finite and non-negative", at());
            } else if !(pdf.is_finite() && pdf >= 0.0) {
                flag("pdf is not finite and non-negative", at());
            } else if value > 0.0 && pdf == 0.0 {
                flag(
                    "eval > 0 where pdf = 0 (a value the BSDF never samples)",
                    at(),
                );
            }
        }
        let edges = [0.0, 0.5, BELOW_ONE];
        for &a in &edges {
            for &b in &edges {
                for &c in &edges {
                    let u = [a, b, c];
                    let Some(s) = bsdf.sample(wi, u) else {
                        continue;
                    };
                    if s.pdf == 0.0 {
                        continue;
                    }
                    let at =
                        || json!({"wi": wi, "u": u, "wo": s.wo, "pdf": s.pdf, "weight": s.weight});
                    let len = s.wo.iter().map(|c| c * c).sum::<f64>().sqrt();
                    if !((len - 1.0).abs() <= 1e-6) {
                        flag("sampled direction is not a finite unit vector", at());
                    } else if !(s.pdf.is_finite() && s.pdf > 0.0) {
                        flag("sampled pdf is not finite and positive", at());
                    } else if !(s.weight.is_finite() && s.weight >= 0.0) {
                        flag("sample weight is not finite and non-negative", at());
                    }
                }
            }
        }
    }
    (count, first)
}

/// Plans the stability check of `subject` (and of its extreme variants, for a reference BSDF).
pub fn plan<'a>(subject: &Arc<BsdfSubject<'a>>, why: &str) -> Vec<PlannedCheck<'a>> {
    let mut out = vec![plan_one(subject, json!({"variant": "as given"}), why)];
    if let Some(spec) = &subject.reference {
        for (name, variant) in variants(spec) {
            if let Ok(v) = BsdfSubject::reference(&variant) {
                out.push(plan_one(&v, json!({"variant": name}), why));
            }
        }
    }
    out
}

fn plan_one<'a>(subject: &Arc<BsdfSubject<'a>>, case: Value, why: &str) -> PlannedCheck<'a> {
    let s = subject.clone();
    Check::new("bsdf.stability", subject.label.clone(), case, SOURCE)
        .why(format!("{why}: the BSDF at the hard cases"))
        .covers(vec![covers(subject.family(), "bsdf_eval", "stability")])
        .run(move |r, _| {
            let (count, first) = violations(s.bsdf.as_ref());
            r.value = Some(count as f64);
            r.measured = Some(Measured::Absolute {
                error: count as f64,
            });
            r.tolerance = Some(applied(&BSDF_STABILITY));
            if let (Value::Object(case), Some(first)) = (&mut r.case, first) {
                case.insert("first_violation".into(), first);
            }
            r.verdict = if (count as f64) <= BSDF_STABILITY.value {
                Verdict::Pass
            } else {
                Verdict::Fail
            };
            Ok(())
        })
}

/// The variants of a reference spec at the extremes of its parameters: roughness 1e-4,
/// anisotropy 1:100 and, for a dielectric, η ∈ {1.0001, 4} and their inverses. A variant whose
/// NDF family does not take `alpha` is left out.
pub fn variants(spec: &BsdfSpec) -> Vec<(&'static str, BsdfSpec)> {
    let Ok(base) = serde_json::to_value(spec) else {
        return Vec::new();
    };
    let with = |f: &dyn Fn(&mut Value)| -> Option<BsdfSpec> {
        let mut v = base.clone();
        f(&mut v);
        serde_json::from_value::<BsdfSpec>(v)
            .ok()
            .filter(|s| s.validate().is_ok())
    };
    let roughness = |ax: f64, ay: f64| {
        move |v: &mut Value| {
            if let Some(ndf) = v.get_mut("ndf").and_then(Value::as_object_mut) {
                if ndf.contains_key("alpha") || ndf.contains_key("alpha_x") {
                    ndf.remove("alpha");
                    ndf.insert("alpha_x".into(), json!(ax));
                    ndf.insert("alpha_y".into(), json!(ay));
                }
            }
        }
    };
    let mut out = Vec::new();
    let candidates: Vec<(&'static str, Option<BsdfSpec>)> = vec![
        ("alpha 1e-4", with(&roughness(1e-4, 1e-4))),
        ("anisotropy 1:100", with(&roughness(0.01, 1.0))),
    ];
    out.extend(
        candidates
            .into_iter()
            .filter_map(|(n, s)| s.map(|s| (n, s))),
    );
    if spec.eta().is_some() {
        for (name, eta) in [
            ("eta 1.0001", 1.0001),
            ("eta 1/1.0001", 1.0 / 1.0001),
            ("eta 4", 4.0),
            ("eta 1/4", 0.25),
        ] {
            if let Some(s) = with(&|v: &mut Value| v["eta"] = json!(eta)) {
                out.push((name, s));
            }
        }
    }
    out
}
