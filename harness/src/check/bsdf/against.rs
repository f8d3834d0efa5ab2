//! `bsdf.against`: a user's BSDF against the reference BSDF of a spec, on what the reference
//! defines — one record per quantity:
//!
//! - `eval` and `pdf`, value by value, on the reciprocity grid of direction pairs (normal to
//!   cos θ = 1e-6, both sides, the critical angle ± 1e-9 rad) and, at every incidence of the
//!   audit, towards the 3072 directions the *reference* samples for the lobe choices
//!   [`LOBE_U0`] × [`LOBE_STRATA`]² strata of (u1, u2) (its lobes, densely: a discrepancy
//!   anywhere in them is met);
//! - `sample`: at the 3072 directions the *user's* BSDF samples for the same u at every
//!   incidence, the sample's pdf and weight against the reference's pdf and eval/pdf there
//!   (its lobes: a sampler that puts mass where the reference has another density is met). The map from u
//!   to wo is the user's own business (a concentric or polar disk map, either u order, another
//!   tangent frame): the distribution of the sampled directions is `bsdf.chi2`'s. Only a BSDF
//!   that declares the reference's map ([`Bsdf::reference_map`]) has its direction for each u
//!   compared with the reference's instead.
//!
//! # The comparison of two values
//!
//! A pair (wi, wo) compares the user's value a with the reference's b by
//!
//! ```text
//! e = |a − b| / (max(|a|, |b|) + M(wi)),   M(wi) = max over the compared wo of |b|
//! ```
//!
//! against the tolerance t of the BSDF's precision: a relative part and an absolute part t·M(wi)
//! scaled to the BSDF's magnitude at that incidence. Why the absolute part: a correct
//! implementation evaluates Walter's product of terms to a few ε relative to those terms, so its
//! absolute error is bounded by the largest value the product takes at that wi times that
//! relative accuracy; where the value itself vanishes (the tail of D at 2.6e-32, 1 − F cancelling
//! near the critical angle, a cosine of 1e-6) its relative error is unbounded but its absolute
//! error stays below t·M(wi), and a difference that small changes any estimate at wi — a sum of
//! contributions at most M(wi) each — by at most t relative. A relative error δ at a value v
//! is still found wherever v > t·M(wi)/δ: an error of 1e-3 anywhere the BSDF is above 1e-6 of
//! its peak at f64 (t = 1e-9).
//!
//! **The grazing guard.** Renderers set D(m) = 0 where m is within floating-point reach of the
//! horizon (pbrt-v4's `TrowbridgeReitzDistribution::D`: cos⁴θm < 1e-16, i.e. cos θm < 1e-4;
//! Mitsuba 3's `MicrofacetDistribution::eval`: D cos θm ≤ 1e-20), so eval and pdf are 0 at the
//! pairs whose half vector h (Walter eq 13/16: wi + wo, or η_i wi + η_o wo across the surface)
//! has |cos θh| < [`GRAZING_GUARD_COS`]. There, and only there, a value of the user's between 0
//! and the reference's (within the tolerance) is accepted and counted
//! (`excused_grazing_guard`); a larger value, a negative one or one elsewhere is judged as
//! above. Bound of what that hides: at most the mass of the half vectors within 1e-4 of the
//! horizon, D's density there times a band of 1e-4 rad.
//!
//! Each record states how many pairs differ beyond the tolerance and where (the worst eight,
//! and the count per incidence), not only the worst.
//!
//! The declared relative index is compared at the BSDF's precision (a float32 BSDF states
//! 1/1.5 as 0.6666667), and the transport convention and two-sidedness exactly.

use super::reciprocity::directions;
use super::{incidences, BsdfSubject, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck};
use crate::precision::Precision;
use crate::record::{Measured, Verdict};
use crate::tolerance::{BSDF_AGAINST_REFERENCE, BSDF_SAMPLE_DIRECTION};
use mfh_reference::bsdf::{Bsdf, BsdfSample, BsdfSpec, Directions};
use mfh_reference::geometry::{dot, Vec3};
use serde_json::{json, Value};
use std::sync::Arc;

/// u values per coordinate of the sampled-direction comparison (interior and edges), for a
/// BSDF that declares the reference's map.
const U_STEPS: [f64; 7] = [0.0, 0.05, 0.25, 0.5, 0.75, 0.95, 1.0 - f64::EPSILON / 2.0];

/// The lobe choices u0 of the sampled directions compared at each incidence: 0 (reflection
/// wherever a dielectric reflects at all: u0 < F), 1 − 2⁻²⁴ (refraction wherever it refracts,
/// the largest float32 below 1) and ½ (a mixture, for a BSDF that chooses otherwise).
pub const LOBE_U0: [f64; 3] = [0.0, 0.5, 1.0 - 1.0 / 16_777_216.0];

/// The strata of (u1, u2) per lobe choice (midpoints): 32 × 32, spaced ~0.04 rad in direction
/// at α 0.3, so that a defect in a cone of 0.05 rad anywhere in a lobe is met (tested in
/// `against_tests.rs`).
pub const LOBE_STRATA: usize = 32;

/// The cosine of the half vector below which a renderer's grazing guard may zero D (and with
/// it eval and pdf): pbrt-v4's cos⁴θ < 1e-16, the largest guard in use.
pub const GRAZING_GUARD_COS: f64 = 1e-4;

/// The most differing pairs a record lists.
const LISTED: usize = 8;

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

/// The u of the sampled directions: [`LOBE_U0`] × the midpoints of [`LOBE_STRATA`]² (float32
/// values, so that a float32 BSDF receives them exactly).
fn lobe_u() -> Vec<[f64; 3]> {
    let n = LOBE_STRATA;
    let mid = |i: usize| (i as f64 + 0.5) / n as f64;
    let mut out = Vec::with_capacity(LOBE_U0.len() * n * n);
    for &u0 in &LOBE_U0 {
        for j in 0..n {
            for k in 0..n {
                out.push([u0, mid(j), mid(k)]);
            }
        }
    }
    out
}

/// Whether two declared indices agree at `precision`: both absent, or within one ε of the
/// format (relative): 0.6666667 (float32) is 1/1.5 at f32.
fn same_eta(a: Option<f64>, b: Option<f64>, precision: Precision) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => (a - b).abs() <= precision.epsilon() * a.abs().max(b.abs()),
        _ => false,
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
                    let declared = |b: &dyn Bsdf| {
                        format!(
                            "eta {:?}, transport {}, two_sided {}",
                            b.eta(),
                            b.transport().name(),
                            b.two_sided()
                        )
                    };
                    if !same_eta(user.eta(), reference.eta(), s.precision)
                        || user.transport() != reference.transport()
                        || user.two_sided() != reference.two_sided()
                    {
                        r.verdict = Verdict::Fail;
                        r.case["mismatch"] = json!(format!(
                            "the BSDF states {}; the reference {} (eta compared at {})",
                            declared(user),
                            declared(reference.as_ref()),
                            s.precision
                        ));
                        return Ok(());
                    }
                    let (comparison, tolerance) = match quantity {
                        "sample"
                            if user.reference_map().is_some()
                                && user.reference_map() == reference.reference_map() =>
                        {
                            r.case["compared"] = json!(format!(
                                "the direction sampled for the same u (the BSDF declares the \
                                 reference map of {} sampling)",
                                reference.reference_map().map_or("no", |m| m.name())
                            ));
                            (
                                sample_directions(user, reference.as_ref(), s.precision),
                                BSDF_SAMPLE_DIRECTION.at(s.precision),
                            )
                        }
                        "sample" => {
                            r.case["compared"] = json!(
                                "the pdf and weight of the BSDF's samples against the \
                                 reference's pdf and eval/pdf at the sampled directions (its own \
                                 map from u: directions for the same u are not compared)"
                            );
                            let tolerance = BSDF_AGAINST_REFERENCE.at(s.precision);
                            (
                                sample_values(user, reference.as_ref(), tolerance.value),
                                tolerance,
                            )
                        }
                        q => {
                            r.case["compared"] = json!(
                                "value by value on the grid of pairs and towards the \
                                 reference's sampled directions at each incidence; error = \
                                 |a − b| / (max(|a|, |b|) + M(wi)), M(wi) the reference's \
                                 largest value at wi"
                            );
                            let tolerance = BSDF_AGAINST_REFERENCE.at(s.precision);
                            (
                                values(user, reference.as_ref(), q == "pdf", tolerance.value),
                                tolerance,
                            )
                        }
                    };
                    r.cost.evaluations += comparison.evaluations;
                    let worst = comparison.worst;
                    r.value = Some(worst);
                    r.measured = Some(Measured::Relative { error: worst });
                    r.tolerance = Some(applied(&tolerance));
                    if let Value::Object(case) = &mut r.case {
                        case.extend(comparison.case);
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

/// What one comparison found: the worst error, the case fields that say where and how often,
/// and the evaluations it spent (the user's and the reference's).
struct Comparison {
    worst: f64,
    case: serde_json::Map<String, Value>,
    evaluations: u64,
}

/// Pairs of one incidence: wi and the wo it is compared towards.
struct Group {
    wi: Vec3,
    wo: Vec<Vec3>,
}

/// The normalized error of the user's `a` against the reference's `b` at an incidence of
/// magnitude `m` (see the module documentation); ∞ where one is NaN or infinite and the other
/// is not the same.
fn error(a: f64, b: f64, m: f64) -> f64 {
    if a == b {
        return 0.0;
    }
    let e = (a - b).abs() / (a.abs().max(b.abs()) + m);
    if e.is_nan() || !a.is_finite() || !b.is_finite() {
        f64::INFINITY
    } else {
        e
    }
}

/// The cosine of the half vector of (wi, wo) through a surface of relative index `eta` (Walter
/// eq 13 for reflection, eq 16 across the surface), in [0, 1]; 1 where it is undefined (so that
/// no guard is presumed there).
fn half_vector_cos(wi: Vec3, wo: Vec3, eta: Option<f64>) -> f64 {
    let h = if wi[2] * wo[2] >= 0.0 {
        [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]
    } else {
        let eta = eta.unwrap_or(1.0);
        let (ei, eo) = if wi[2] > 0.0 { (1.0, eta) } else { (eta, 1.0) };
        [
            ei * wi[0] + eo * wo[0],
            ei * wi[1] + eo * wo[1],
            ei * wi[2] + eo * wo[2],
        ]
    };
    let len = dot(h, h).sqrt();
    if len > 0.0 && len.is_finite() {
        h[2].abs() / len
    } else {
        1.0
    }
}

/// Tallies the differences of one quantity over the groups: `user[g][k]` against
/// `reference[g][k]`, judged at `tolerance` with the grazing-guard band of `eta`.
struct Tally {
    tolerance: f64,
    eta: Option<f64>,
    pairs: u64,
    differ: u64,
    excused: u64,
    worst_excused: f64,
    worst: f64,
    worst_passing: f64,
    at_passing: Value,
    at: Value,
    listed: Vec<(f64, Value)>,
    by_incidence: Vec<Value>,
}

impl Tally {
    fn new(tolerance: f64, eta: Option<f64>) -> Self {
        Self {
            tolerance,
            eta,
            pairs: 0,
            differ: 0,
            excused: 0,
            worst_excused: 0.0,
            worst: 0.0,
            worst_passing: 0.0,
            at_passing: Value::Null,
            at: Value::Null,
            listed: Vec::new(),
            by_incidence: Vec::new(),
        }
    }

    /// One incidence's pairs: `name` the quantity, `a` the user's values, `b` the reference's.
    fn group(&mut self, name: &str, wi: Vec3, wo: &[Vec3], a: &[f64], b: &[f64]) {
        let m = b
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let mut differ = 0u64;
        for k in 0..wo.len() {
            self.pairs += 1;
            let e = error(a[k], b[k], m);
            if e <= self.tolerance {
                if e > self.worst_passing || self.at_passing.is_null() {
                    self.worst_passing = self.worst_passing.max(e);
                    self.at_passing = json!({"wi": wi, "wo": wo[k], "of": name, "value": a[k],
                                             "reference": b[k], "magnitude": m, "error": e});
                }
                continue;
            }
            // A grazing guard: the user's value between 0 and the reference's.
            let guarded = half_vector_cos(wi, wo[k], self.eta) < GRAZING_GUARD_COS
                && a[k] >= 0.0
                && (a[k] - b[k]) / (b[k].abs() + m) <= self.tolerance;
            if guarded {
                self.excused += 1;
                self.worst_excused = self.worst_excused.max(e);
                continue;
            }
            differ += 1;
            let at = json!({"wi": wi, "wo": wo[k], "of": name, "value": a[k], "reference": b[k],
                            "magnitude": m, "error": e});
            if e > self.worst || e.is_nan() {
                self.worst = e;
                self.at = at.clone();
            }
            self.listed.push((e, at));
            if self.listed.len() > 4 * LISTED {
                self.trim();
            }
        }
        self.differ += differ;
        if differ > 0 {
            self.by_incidence
                .push(json!({"wi": wi, "differ": differ, "of": wo.len(), "magnitude": m}));
        }
    }

    fn trim(&mut self) {
        self.listed.sort_by(|x, y| y.0.total_cmp(&x.0));
        self.listed.truncate(LISTED);
    }

    /// The worst error (passing pairs' included: the largest e of all, 0 if none differs) and
    /// the case fields.
    fn finish(mut self, evaluations: u64) -> Comparison {
        self.trim();
        let mut case = serde_json::Map::new();
        case.insert("pairs".into(), json!(self.pairs));
        case.insert("differ".into(), json!(self.differ));
        case.insert("excused_grazing_guard".into(), json!(self.excused));
        case.insert("worst_excused_error".into(), json!(self.worst_excused));
        case.insert(
            "grazing_guard".into(),
            json!(format!(
                "where the half vector is within cos θh < {GRAZING_GUARD_COS:e} of the horizon, \
                 a value between 0 and the reference's is accepted (a renderer's guard on D)"
            )),
        );
        if self.differ == 0 {
            case.insert("worst".into(), self.at_passing);
        } else {
            case.insert("worst".into(), self.at);
            case.insert(
                "differing".into(),
                Value::Array(self.listed.into_iter().map(|(_, v)| v).collect()),
            );
            case.insert(
                "differ_by_incidence".into(),
                Value::Array(self.by_incidence.into_iter().take(16).collect()),
            );
        }
        Comparison {
            worst: if self.differ > 0 {
                self.worst
            } else {
                self.worst_passing
            },
            case,
            evaluations,
        }
    }
}

/// The groups of eval/pdf pairs: every grid direction towards every grid direction, and every
/// audit incidence towards the grid and the reference's sampled directions.
fn groups(reference: &dyn Bsdf) -> Vec<Group> {
    let dirs = directions(reference.eta());
    let mut out: Vec<Group> = dirs
        .iter()
        .map(|&wi| Group {
            wi,
            wo: dirs.clone(),
        })
        .collect();
    let u = lobe_u();
    for inc in incidences(reference) {
        let mut sampled = Directions::new(u.len());
        reference.sample_wo_batch(inc.wi, &u, &mut sampled);
        let mut wo = dirs.clone();
        wo.extend(sampled.iter().flatten());
        out.push(Group { wi: inc.wi, wo });
    }
    out
}

/// eval (or pdf) of both BSDFs on [`groups`], in one batch each, judged pair by pair.
fn values(user: &dyn Bsdf, reference: &dyn Bsdf, pdf: bool, tolerance: f64) -> Comparison {
    let groups = groups(reference);
    let wi: Vec<Vec3> = groups
        .iter()
        .flat_map(|g| std::iter::repeat_n(g.wi, g.wo.len()))
        .collect();
    let wo: Vec<Vec3> = groups.iter().flat_map(|g| g.wo.iter().copied()).collect();
    let (mut a, mut b) = (vec![0.0; wo.len()], vec![0.0; wo.len()]);
    if pdf {
        user.pdf_batch(&wi, &wo, &mut a);
        reference.pdf_batch(&wi, &wo, &mut b);
    } else {
        user.eval_batch(&wi, &wo, &mut a);
        reference.eval_batch(&wi, &wo, &mut b);
    }
    let name = if pdf { "pdf" } else { "eval" };
    let mut tally = Tally::new(tolerance, reference.eta());
    let mut start = 0;
    for g in &groups {
        let r = start..start + g.wo.len();
        tally.group(name, g.wi, &g.wo, &a[r.clone()], &b[r.clone()]);
        start = r.end;
    }
    tally.finish(2 * wo.len() as u64)
}

/// At every incidence, the user's samples for the lobe u ([`LOBE_U0`] × [`LOBE_STRATA`]²
/// strata): their pdf against the reference's pdf, and their weight against the reference's
/// eval/pdf, at the sampled wo.
fn sample_values(user: &dyn Bsdf, reference: &dyn Bsdf, tolerance: f64) -> Comparison {
    let u = lobe_u();
    let mut pdf_tally = Tally::new(tolerance, reference.eta());
    let mut weight_tally = Tally::new(tolerance, reference.eta());
    let (mut evaluations, mut failed) = (0u64, 0u64);
    for inc in incidences(reference) {
        let mut samples: Vec<Option<BsdfSample>> = vec![None; u.len()];
        user.sample_batch(inc.wi, &u, &mut samples);
        let ok: Vec<BsdfSample> = samples
            .into_iter()
            .flatten()
            .filter(|s| s.pdf != 0.0)
            .collect();
        failed += (u.len() - ok.len()) as u64;
        let wo: Vec<Vec3> = ok.iter().map(|s| s.wo).collect();
        let wis = vec![inc.wi; wo.len()];
        let (mut pdf, mut eval) = (vec![0.0; wo.len()], vec![0.0; wo.len()]);
        reference.pdf_batch(&wis, &wo, &mut pdf);
        reference.eval_batch(&wis, &wo, &mut eval);
        evaluations += u.len() as u64 + 2 * wo.len() as u64;
        let a: Vec<f64> = ok.iter().map(|s| s.pdf).collect();
        pdf_tally.group("sample_pdf", inc.wi, &wo, &a, &pdf);
        // The weight where the reference has a density (else the pdf record says it all).
        let keep: Vec<usize> = (0..wo.len()).filter(|&k| pdf[k] > 0.0).collect();
        let wo_w: Vec<Vec3> = keep.iter().map(|&k| wo[k]).collect();
        let a_w: Vec<f64> = keep.iter().map(|&k| ok[k].weight).collect();
        let b_w: Vec<f64> = keep.iter().map(|&k| eval[k] / pdf[k]).collect();
        weight_tally.group("sample_weight", inc.wi, &wo_w, &a_w, &b_w);
    }
    let pdf = pdf_tally.finish(0);
    let weight = weight_tally.finish(0);
    let worst = pdf.worst.max(weight.worst);
    let mut case = serde_json::Map::new();
    case.insert("failed_samples".into(), json!(failed));
    case.insert("sample_pdf".into(), Value::Object(pdf.case));
    case.insert("sample_weight".into(), Value::Object(weight.case));
    Comparison {
        worst,
        case,
        evaluations,
    }
}

/// The worst angle between the user's and the reference's sampled directions for the same u
/// (π where one fails and the other does not), and where: for a BSDF that declares the
/// reference's map.
fn sample_directions(user: &dyn Bsdf, reference: &dyn Bsdf, precision: Precision) -> Comparison {
    let steps = u_steps(precision);
    let (mut worst, mut at) = (0.0f64, Value::Null);
    let (mut differ, mut pairs) = (0u64, 0u64);
    let tolerance = BSDF_SAMPLE_DIRECTION.at(precision).value;
    let mut u = Vec::with_capacity(steps.len().pow(3));
    for &a in &steps {
        for &b in &steps {
            for &c in &steps {
                u.push([a, b, c]);
            }
        }
    }
    let ok = |s: &Option<BsdfSample>| s.filter(|s| s.pdf != 0.0).map(|s| s.wo);
    for inc in incidences(reference) {
        let (mut x, mut y) = (vec![None; u.len()], vec![None; u.len()]);
        user.sample_batch(inc.wi, &u, &mut x);
        reference.sample_batch(inc.wi, &u, &mut y);
        for k in 0..u.len() {
            pairs += 1;
            let (x, y) = (ok(&x[k]), ok(&y[k]));
            let e = match (x, y) {
                (None, None) => 0.0,
                (Some(x), Some(y)) => angle(x, y),
                _ => std::f64::consts::PI,
            };
            let e = if e.is_nan() { f64::INFINITY } else { e };
            if e > tolerance {
                differ += 1;
            }
            if e > worst || at.is_null() {
                worst = worst.max(e);
                at = json!({"wi": inc.wi, "u": u[k], "wo": x, "reference_wo": y});
            }
        }
    }
    let mut case = serde_json::Map::new();
    case.insert("samples".into(), json!(pairs));
    case.insert("differ".into(), json!(differ));
    case.insert("worst".into(), at);
    Comparison {
        worst,
        case,
        evaluations: 2 * pairs,
    }
}

/// The angle between two directions (radians), accurate for small angles.
fn angle(a: Vec3, b: Vec3) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let s = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    2.0 * dot(d, d).sqrt().atan2(dot(s, s).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_scale_with_the_magnitude_and_nan_is_infinite() {
        assert_eq!(error(0.0, 0.0, 0.0), 0.0);
        // 2.6e-32 against 0 at a magnitude of 1: nothing.
        assert!(error(0.0, 2.6e-32, 1.0) < 1e-31);
        // 1e-3 relative at the peak: 5e-4 of (value + magnitude).
        assert!((error(1.001, 1.0, 1.0) - 0.001 / 2.001).abs() < 1e-15);
        assert_eq!(error(f64::NAN, 1.0, 1.0), f64::INFINITY);
        assert_eq!(error(f64::INFINITY, 1.0, 1.0), f64::INFINITY);
        assert_eq!(error(f64::INFINITY, f64::INFINITY, 1.0), 0.0);
        assert!(same_eta(
            Some(f64::from(1.0f32 / 1.5f32)),
            Some(1.0 / 1.5),
            Precision::F32
        ));
        assert!(!same_eta(
            Some(f64::from(1.0f32 / 1.5f32)),
            Some(1.0 / 1.5),
            Precision::F64
        ));
        assert!(!same_eta(None, Some(1.5), Precision::F32));
        // The half vector of a grazing reflection pair is at the horizon.
        let c = 1e-6f64;
        let s = (1.0 - c * c).sqrt();
        assert!(half_vector_cos([s, 0.0, c], [0.0, s, c], None) < 2e-6);
        assert!(half_vector_cos([s, 0.0, c], [-s, 0.0, c], None) > 0.99);
    }
}
