//! `bsdf.against`: a user's BSDF value by value against the reference BSDF of a spec — `eval`
//! and `pdf` on the reciprocity grid of direction pairs, and the direction `sample` returns for
//! the same u at every incidence of the audit — worst discrepancy per quantity. The relative
//! index and the transport convention must be the spec's.

use super::reciprocity::directions;
use super::{incidences, BsdfSubject, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck};
use crate::precision::Precision;
use crate::record::{Measured, Verdict};
use crate::tolerance::{BSDF_AGAINST_REFERENCE, BSDF_SAMPLE_DIRECTION};
use mfh_reference::bsdf::{Bsdf, BsdfSpec};
use mfh_reference::geometry::{dot, Vec3};
use serde_json::{json, Value};
use std::sync::Arc;

/// u values per coordinate of the sampled-direction comparison (interior and edges).
const U_STEPS: [f64; 7] = [0.0, 0.05, 0.25, 0.5, 0.75, 0.95, 1.0 - f64::EPSILON / 2.0];

/// [`U_STEPS`] as an implementation computing in `precision` receives them. A float32
/// implementation gets each step rounded to float32 (exactly what the reference is sampled
/// at too) and, for the top step, 1 − 2⁻¹² instead of 1 − 2⁻⁵³ (which rounds to 1.0): within
/// 2⁻²⁴ of 1 the visible-normal disk point lies within √ε₃₂ of its rim, the microfacet within
/// ~10⁻⁴ rad of the silhouette, and float32 rounding alone decides whether the sample
/// succeeds at all (measured: a float32 GGX dielectric at α 0.02 refracts where the f64
/// reference fails). At 1 − 2⁻¹² the rim is 2⁻⁶ away and the direction conditioned.
fn u_steps(precision: Precision) -> [f64; 7] {
    match precision {
        Precision::F64 => U_STEPS,
        _ => U_STEPS.map(|u| f64::from(u as f32).min(1.0 - 1.0 / 4096.0)),
    }
}

/// Plans the comparison of `subject` with the reference BSDF `spec` (already validated).
pub fn plan_against<'a>(
    subject: &Arc<BsdfSubject<'a>>,
    spec: &BsdfSpec,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let Ok(reference) = spec.build() else {
        return Vec::new();
    };
    let spec_json = serde_json::to_value(spec).unwrap_or(Value::Null);
    let why = format!("{why}: against the reference BSDF {spec_json}");
    let family = spec.kind();
    let mut out = Vec::new();
    for quantity in ["eval", "pdf", "sample"] {
        let s = subject.clone();
        let reference = reference.clone();
        let case = json!({"quantity": quantity, "reference": spec_json});
        out.push(
            Check::new("bsdf.against", subject.label.clone(), case, SOURCE)
                .why(why.clone())
                .covers(vec![covers(family, &format!("bsdf_{quantity}"), "against")])
                .run(move |r, _| {
                    let user = s.bsdf.as_ref();
                    if user.eta() != reference.eta() || user.transport() != reference.transport() {
                        r.verdict = Verdict::Fail;
                        if let Value::Object(case) = &mut r.case {
                            case.insert(
                                "mismatch".into(),
                                json!(format!(
                                    "the BSDF states eta {:?}, transport {}; the reference \
                                     eta {:?}, transport {}",
                                    user.eta(),
                                    user.transport().name(),
                                    reference.eta(),
                                    reference.transport().name()
                                )),
                            );
                        }
                        return Ok(());
                    }
                    let ((worst, at), tolerance) = match quantity {
                        "sample" => (
                            sample_discrepancy(user, reference.as_ref(), s.precision),
                            BSDF_SAMPLE_DIRECTION.at(s.precision),
                        ),
                        q => (
                            value_discrepancy(user, reference.as_ref(), q == "pdf"),
                            BSDF_AGAINST_REFERENCE.at(s.precision),
                        ),
                    };
                    r.value = Some(worst);
                    r.measured = Some(Measured::Relative { error: worst });
                    r.tolerance = Some(applied(&tolerance));
                    if let Value::Object(case) = &mut r.case {
                        case.insert("worst".into(), at);
                    }
                    r.verdict = if worst <= tolerance.value {
                        Verdict::Pass
                    } else {
                        Verdict::Fail
                    };
                    Ok(())
                }),
        );
    }
    out
}

/// The worst relative discrepancy of eval (or pdf) on the grid of pairs, and where.
fn value_discrepancy(user: &dyn Bsdf, reference: &dyn Bsdf, pdf: bool) -> (f64, Value) {
    let dirs = directions(reference.eta());
    let (mut worst, mut at) = (0.0f64, Value::Null);
    for &wi in &dirs {
        for &wo in &dirs {
            let (a, b) = if pdf {
                (user.pdf(wi, wo), reference.pdf(wi, wo))
            } else {
                (user.eval(wi, wo), reference.eval(wi, wo))
            };
            let scale = a.abs().max(b.abs());
            let e = if scale == 0.0 {
                0.0
            } else if (a - b).is_nan() {
                f64::INFINITY
            } else {
                (a - b).abs() / scale
            };
            if e > worst {
                worst = e;
                at = json!({"wi": wi, "wo": wo, "value": a, "reference": b});
            }
        }
    }
    (worst, at)
}

/// The worst angle between the user's and the reference's sampled directions for the same u
/// (π where one fails and the other does not), and where.
fn sample_discrepancy(user: &dyn Bsdf, reference: &dyn Bsdf, precision: Precision) -> (f64, Value) {
    let steps = u_steps(precision);
    let (mut worst, mut at) = (0.0f64, Value::Null);
    for inc in incidences(reference) {
        for &a in &steps {
            for &b in &steps {
                for &c in &steps {
                    let u = [a, b, c];
                    let ok = |s: Option<mfh_reference::bsdf::BsdfSample>| {
                        s.filter(|s| s.pdf != 0.0).map(|s| s.wo)
                    };
                    let (x, y) = (ok(user.sample(inc.wi, u)), ok(reference.sample(inc.wi, u)));
                    let e = match (x, y) {
                        (None, None) => 0.0,
                        (Some(x), Some(y)) => angle(x, y),
                        _ => std::f64::consts::PI,
                    };
                    if e > worst || e.is_nan() {
                        worst = if e.is_nan() { f64::INFINITY } else { e };
                        at = json!({"wi": inc.wi, "u": u, "wo": x, "reference_wo": y});
                    }
                }
            }
        }
    }
    (worst, at)
}

/// The angle between two directions (radians), accurate for small angles.
fn angle(a: Vec3, b: Vec3) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let s = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    2.0 * dot(d, d).sqrt().atan2(dot(s, s).sqrt())
}
