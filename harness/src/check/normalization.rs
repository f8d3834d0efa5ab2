//! Normalization: ∫ D(m)(m·n) dm = 1 over the hemisphere, by nested adaptive quadrature.

use super::{compare_at, covers, PlannedCheck};
use crate::check::Check;
use crate::oracle::quadrature::{integrate_hemisphere_lobe_batch, Accuracy, Cuts};
use crate::oracle::Estimate;
use crate::subject::Subject;
use crate::tolerance::NORMALIZATION;
use mfh_reference::Vec3;
use serde_json::json;
use std::sync::Arc;

/// Plans the normalization check of one model.
pub fn plan<'a>(subject: &Arc<Subject<'a>>, why: &str) -> Vec<PlannedCheck<'a>> {
    let family = subject.family();
    let s = subject.clone();
    vec![Check::new(
        "normalization.projected_area",
        subject.label.clone(),
        json!({}),
        "ARCHITECTURE.md model boundary: ∫ D(m)(m·n) dm = 1 (seed 001 eq 3; seed 000 eq 2; \
                     seed 004 §2)",
    )
    .why(why.to_string())
    .covers(vec![covers(family, "d", "default")])
    .run(move |r, _| {
        let kinks = s.theta_kinks();
        // D in batches (one round trip per step for an external model).
        let e = integrate_hemisphere_lobe_batch(
            &|w: &[Vec3], out: &mut [f64]| {
                s.model.d_batch(w, out);
                for (o, w) in out.iter_mut().zip(w) {
                    *o *= w[2];
                }
            },
            s.lobe(),
            Some(Cuts {
                theta: &|_| kinks.clone(),
                phi: &[],
            }),
            Accuracy::relative(1e-11).at(s.precision),
        );
        // The value under test is the quadrature of the closed form, so the
        // quadrature's error bound is the slack `compare` grants (reported as the
        // oracle's uncertainty).
        compare_at(
            r,
            e.value,
            Estimate { value: 1.0, ..e },
            &NORMALIZATION.at(s.precision),
            Accuracy::relative(1e-11).at(s.precision).noise_floor(),
        );
        Ok(())
    })]
}
