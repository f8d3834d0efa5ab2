//! Value by value against a reference model: a user's D, Λ, G1, both G2 and pdf_wm against
//! mfh's reference closed forms of the spec the user names (`Audit::against`), over a grid of
//! directions that includes exactly normal and near-grazing incidence and several azimuths; one
//! record per quantity, with the worst relative error and where it is attained.

use super::{compare_exact, covers, PlannedCheck};
use crate::check::Check;
use crate::record::{relative_error, Verdict};
use crate::subject::Subject;
use crate::tolerance::AGAINST_REFERENCE;
use mfh_reference::geometry::from_spherical;
use mfh_reference::{Masking, Model, ModelSpec, Vec3};
use serde_json::json;
use std::sync::Arc;

/// The polar angles of the grid (radians).
pub const THETAS: [f64; 10] = [
    0.0,
    1e-6,
    1e-3,
    0.3,
    0.7,
    1.0,
    1.3,
    1.5,
    1.56,
    super::NEAR_GRAZING,
];
/// The azimuths of the grid (radians).
pub const PHIS: [f64; 4] = [0.0, 0.7, 1.9, 4.0];

/// The quantities compared, where both models have them.
const QUANTITIES: [&str; 6] = [
    "d",
    "lambda",
    "g1",
    "g2_uncorrelated",
    "g2_height_correlated",
    "pdf_wm",
];

fn grid() -> Vec<(f64, f64, Vec3)> {
    let mut out = Vec::new();
    for &t in &THETAS {
        for &p in &PHIS {
            out.push((t, p, from_spherical(t, p)));
        }
    }
    out
}

/// The user's value and the reference's of one quantity at grid point `w` (with `wi` the
/// second direction of G2), or None where either model lacks the capability.
fn values(
    quantity: &str,
    user: &Subject,
    reference: &dyn Model,
    w: Vec3,
    wi: Vec3,
) -> Option<(f64, f64)> {
    let n = [0.0, 0.0, 1.0];
    Some(match quantity {
        "d" => (user.model.d(w), reference.d(w)),
        "lambda" => (
            user.model.as_smith()?.lambda(w),
            reference.as_smith()?.lambda(w),
        ),
        "g1" => (
            user.model.as_smith()?.g1(w, n),
            reference.as_smith()?.g1(w, n),
        ),
        "g2_uncorrelated" => (
            user.model.as_smith()?.g2(w, wi, n, Masking::Uncorrelated),
            reference.as_smith()?.g2(w, wi, n, Masking::Uncorrelated),
        ),
        "g2_height_correlated" => (
            user.model
                .as_smith()?
                .g2(w, wi, n, Masking::HeightCorrelated),
            reference
                .as_smith()?
                .g2(w, wi, n, Masking::HeightCorrelated),
        ),
        _ => (
            user.model.as_sampler()?.pdf_wm(w),
            reference.as_sampler()?.pdf_wm(w),
        ),
    })
}

/// Plans the comparison of a model with the reference built from `spec`.
pub fn plan<'a>(subject: &Arc<Subject<'a>>, spec: &ModelSpec, why: &str) -> Vec<PlannedCheck<'a>> {
    let reference: Arc<dyn Model> = match spec.build() {
        Ok(m) => Arc::from(m),
        Err(_) => return Vec::new(), // the builder has validated the spec already
    };
    let spec_value = serde_json::to_value(spec).unwrap_or_default();
    let has = |q: &str| match q {
        "d" => true,
        "pdf_wm" => subject.model.as_sampler().is_some() && reference.as_sampler().is_some(),
        _ => subject.model.as_smith().is_some() && reference.as_smith().is_some(),
    };
    QUANTITIES
        .iter()
        .filter(|q| has(q))
        .map(|&quantity| {
            let case = json!({"quantity": quantity, "reference": spec_value,
                              "grid": format!("θ ∈ {THETAS:?} × φ ∈ {PHIS:?}")});
            let (s, r_model) = (subject.clone(), reference.clone());
            let family = subject.family();
            Check::new(
                "against.reference",
                subject.label.clone(),
                case,
                "the reference closed forms of mfh-reference (each cites its source)",
            )
            .why(format!(
                "{why}: {quantity} value by value against the reference"
            ))
            .covers(vec![covers(family, quantity, "default")])
            .run(move |r, _| {
                let mut worst = (0.0f64, 0.0, 0.0, 0.0, 0.0);
                let points = grid();
                for (i, &(t, p, w)) in points.iter().enumerate() {
                    let wi = points[(i * 7 + 3) % points.len()].2;
                    let Some((u, v)) = values(quantity, &s, r_model.as_ref(), w, wi) else {
                        continue;
                    };
                    let e = if u == v {
                        0.0
                    } else if u.is_finite() && v.is_finite() {
                        relative_error(u, v)
                    } else {
                        f64::INFINITY
                    };
                    if !(e <= worst.0) {
                        worst = (e, u, v, t, p);
                    }
                }
                let (e, u, v, t, p) = worst;
                compare_exact(r, u, v, &AGAINST_REFERENCE.at(s.precision));
                if e == f64::INFINITY {
                    r.verdict = Verdict::Fail;
                }
                r.case["worst_at"] = json!({"theta": t, "phi": p});
                Ok(())
            })
        })
        .collect()
}
