//! Normalization: ∫ D(m)(m·n) dm = 1 over the hemisphere, by nested adaptive quadrature.

use super::{compare, covers, lobe_width, theta_kinks, timed, Planned};
use crate::oracle::quadrature::{integrate_hemisphere, Accuracy, Cuts};
use crate::oracle::Estimate;
use crate::record::CheckRecord;
use crate::tolerance::NORMALIZATION;
use mfh_reference::Model;
use serde_json::{json, Value};
use std::sync::Arc;

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
                let kinks = theta_kinks(&spec_run);
                let e = integrate_hemisphere(
                    &|w| m.d(w) * w[2],
                    lobe_width(&spec_run),
                    Some(Cuts {
                        theta: &|_| kinks.clone(),
                        phi: &[],
                    }),
                    Accuracy::relative(1e-11),
                );
                // The value under test is the quadrature of the closed form, so the
                // quadrature's error bound is the slack `compare` grants (reported as the
                // oracle's uncertainty).
                compare(
                    &mut r,
                    e.value,
                    Estimate { value: 1.0, ..e },
                    &NORMALIZATION,
                );
                r
            })
        }),
    }]
}
