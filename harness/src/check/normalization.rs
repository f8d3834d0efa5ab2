//! Normalization: ∫ D(m)(m·n) dm = 1 over the hemisphere, by nested adaptive quadrature.

use super::{compare, covers, timed, Planned};
use crate::oracle::quadrature::{integrate_hemisphere, Accuracy};
use crate::record::CheckRecord;
use crate::tolerance::NORMALIZATION;
use mfh_reference::Model;
use serde_json::{json, Value};
use std::sync::Arc;

/// The angular width of a model's lobe, read from its spec (α, or the smaller of α_x, α_y; the
/// square root of the smaller slope variance for Gaussian slopes), for placing quadrature cuts.
pub fn lobe_width(spec: &Value) -> f64 {
    let get = |k: &str| spec.get(k).and_then(Value::as_f64);
    let mut w = f64::INFINITY;
    for k in ["alpha", "alpha_x", "alpha_y"] {
        if let Some(a) = get(k) {
            w = w.min(a);
        }
    }
    if let Some(cov) = spec.get("cov").and_then(Value::as_array) {
        for (i, row) in cov.iter().enumerate() {
            if let Some(v) = row.get(i).and_then(Value::as_f64) {
                w = w.min(v.abs().sqrt());
            }
        }
    }
    if w.is_finite() && w > 0.0 {
        w.atan()
    } else {
        0.3
    }
}

/// Plans the normalization check of one model.
pub fn plan(model: Arc<dyn Model>, why: &str) -> Vec<Planned> {
    let spec = serde_json::to_value(model.spec()).unwrap_or(Value::Null);
    let family = model.family();
    let m = model.clone();
    let spec_run = spec.clone();
    vec![Planned {
        check: "normalization.projected_area".to_string(),
        model: spec.clone(),
        case: json!({}),
        why: why.to_string(),
        covers: vec![covers(family, "d", "default")],
        statistical: false,
        run: Box::new(move |_| {
            timed(|| {
                let mut r = CheckRecord::new(
                    "normalization.projected_area",
                    spec_run.clone(),
                    json!({}),
                    "DESIGN.md model boundary: ∫ D(m)(m·n) dm = 1 (seed 001 eq 3; seed 000 eq 2; \
                     seed 004 §2)",
                );
                r.covers = vec![covers(family, "d", "default")];
                let width = lobe_width(&spec_run);
                let e = integrate_hemisphere(
                    &|w| m.d(w) * w[2],
                    width,
                    None,
                    Accuracy::relative(1e-11),
                );
                compare(
                    &mut r,
                    e.value,
                    crate::oracle::Estimate {
                        value: 1.0,
                        error_bound: 0.0,
                        evaluations: e.evaluations,
                    },
                    &NORMALIZATION,
                );
                // The value under test is the integral of the closed form; the oracle's own
                // error bound belongs to it.
                if let Some(o) = r.oracle.as_mut() {
                    o.uncertainty = e.error_bound;
                }
                let slack = e.error_bound;
                if let Some(crate::record::Measured::Relative { error }) = r.measured {
                    r.verdict = if error <= NORMALIZATION.value + slack {
                        crate::record::Verdict::Pass
                    } else {
                        crate::record::Verdict::Fail
                    };
                }
                r
            })
        }),
    }]
}
