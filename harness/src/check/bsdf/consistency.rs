//! `bsdf.sample_consistency`: at every sampled direction, the pdf and the weight `sample`
//! returns equal `pdf(wi, wo)` and `eval(wi, wo) / pdf(wi, wo)` (the record's value the worst
//! of both relative errors, its case each apart: `worst_pdf_error`, `worst_weight_error`); `bsdf.failure_rate`: the rate
//! of failed samples equals 1 − ∫ pdf dωo (a sampler that silently loses mass fails).

use super::{fold_samples, BsdfSubject, Incidence, Integrals, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck, Profile};
use crate::oracle::monte_carlo::two_sided_p;
use crate::record::{relative_error, Measured, OracleValue, Verdict};
use crate::tolerance::{BSDF_SAMPLE_CONSISTENCY, STATISTICAL_ALPHA};
use mfh_reference::geometry::Vec3;
use serde_json::{json, Value};
use std::sync::Arc;

/// Samples drawn per incidence by the consistency and failure-rate checks.
pub fn samples(profile: Profile) -> u64 {
    match profile {
        Profile::Ci | Profile::Quick => 100_000,
        Profile::Standard => 1_000_000,
        Profile::Thorough => 10_000_000,
    }
}

/// The worst disagreement of one chunk of samples, and its failures.
#[derive(Debug, Clone, Default)]
struct Worst {
    error: f64,
    /// The worst relative errors of the sample's pdf and of its weight, apart.
    pdf_error: f64,
    weight_error: f64,
    at: Option<Value>,
    failed: u64,
    drawn: u64,
}

/// Plans both checks of `subject` at `incidence`.
pub fn plan<'a>(
    subject: &Arc<BsdfSubject<'a>>,
    incidence: Incidence,
    shared: &Arc<Integrals>,
    profile: Profile,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let n = samples(profile);
    let mut case = incidence.case();
    case["samples"] = json!(n);
    let family = subject.family();
    let s = subject.clone();
    let consistency = Check::new(
        "bsdf.sample_consistency",
        subject.label.clone(),
        case.clone(),
        SOURCE,
    )
    .why(format!("{why}: the BSDF's sample weights"))
    .covers(vec![covers(family, "bsdf_sample", "weight")])
    .seeded()
    .run(move |r, ctx| {
        let bsdf = s.bsdf.as_ref();
        let wi = incidence.wi;
        let parts = fold_samples(bsdf, wi, n, ctx.seed, Vec::new, |acc, index, u, sample| {
            acc.push((index, u, sample));
        });
        let mut worst = Worst::default();
        for part in parts {
            let ok: Vec<_> = part
                .iter()
                .filter_map(|&(i, u, s)| s.filter(|s| s.pdf != 0.0).map(|s| (i, u, s)))
                .collect();
            worst.failed += (part.len() - ok.len()) as u64;
            let wo: Vec<Vec3> = ok.iter().map(|(_, _, s)| s.wo).collect();
            let wis = vec![wi; wo.len()];
            let (mut pdf, mut eval) = (vec![0.0; wo.len()], vec![0.0; wo.len()]);
            bsdf.pdf_batch(&wis, &wo, &mut pdf);
            bsdf.eval_batch(&wis, &wo, &mut eval);
            for (k, &(index, u, s)) in ok.iter().enumerate() {
                let weight = eval[k] / pdf[k];
                let nan_inf = |e: f64| if e.is_nan() { f64::INFINITY } else { e };
                let (ep, ew) = (
                    nan_inf(relative_error(s.pdf, pdf[k])),
                    nan_inf(relative_error(s.weight, weight)),
                );
                worst.pdf_error = worst.pdf_error.max(ep);
                worst.weight_error = worst.weight_error.max(ew);
                let e = ep.max(ew);
                if worst.at.is_none() || e > worst.error {
                    worst.error = e;
                    worst.at = Some(json!({
                        "sample": index, "u": u, "wo": s.wo,
                        "sample_pdf": s.pdf, "pdf": pdf[k],
                        "sample_weight": s.weight, "eval_over_pdf": weight,
                    }));
                }
            }
        }
        r.cost.samples = n;
        r.value = Some(worst.error);
        r.measured = Some(Measured::Relative { error: worst.error });
        let tolerance = BSDF_SAMPLE_CONSISTENCY.at(s.precision);
        r.tolerance = Some(applied(&tolerance));
        if let (Value::Object(case), Some(at)) = (&mut r.case, worst.at) {
            case.insert("worst".into(), at);
            case.insert("failed_samples".into(), json!(worst.failed));
            case.insert("worst_pdf_error".into(), json!(worst.pdf_error));
            case.insert("worst_weight_error".into(), json!(worst.weight_error));
        }
        r.verdict = if worst.error <= tolerance.value {
            Verdict::Pass
        } else {
            Verdict::Fail
        };
        Ok(())
    });
    let s = subject.clone();
    let shared = shared.clone();
    let rate = Check::new("bsdf.failure_rate", subject.label.clone(), case, SOURCE)
        .why(format!("{why}: the BSDF's sampling loses no mass"))
        .covers(vec![covers(family, "bsdf_sample", "failures")])
        .statistical()
        .run(move |r, ctx| {
            let bsdf = s.bsdf.as_ref();
            let wi = incidence.wi;
            let parts = fold_samples(bsdf, wi, n, ctx.seed, Worst::default, |acc, _, _, s| {
                acc.drawn += 1;
                if !s.is_some_and(|s| s.pdf != 0.0) {
                    acc.failed += 1;
                }
            });
            let failed: u64 = parts.iter().map(|w| w.failed).sum();
            let mass = shared.pdf_mass(bsdf);
            r.cost.samples = n;
            // The masses' evaluations are billed to bsdf.chi2 ([`Integrals`]).
            judge_rate(r, failed, n, mass);
            Ok(())
        });
    vec![consistency, rate]
}

/// Judges `failed` of `n` samples against the failure probability 1 − mass: a z-test whose
/// deviation is first reduced by the mass's error bound (times n), with a variance floor of one
/// sample (so that a pdf of mass 1 and a handful of failures is not a division by zero).
fn judge_rate(
    r: &mut crate::record::CheckRecord,
    failed: u64,
    n: u64,
    mass: crate::oracle::Estimate,
) {
    let nf = n as f64;
    let p = (1.0 - mass.value).clamp(0.0, 1.0);
    let rate = failed as f64 / nf;
    let deviation = ((failed as f64 - nf * p).abs() - nf * mass.error_bound).max(0.0);
    let sd = (nf * p * (1.0 - p)).max(1.0).sqrt();
    let z = deviation / sd;
    let pv = two_sided_p(z);
    r.value = Some(rate);
    r.oracle = Some(OracleValue {
        value: p,
        uncertainty: mass.error_bound,
        kind: "error_bound",
        noise_floor: None,
    });
    r.measured = Some(Measured::PValue {
        p: pv,
        statistic: z,
        dof: 0,
        alpha: STATISTICAL_ALPHA.value,
    });
    r.tolerance = Some(applied(&STATISTICAL_ALPHA));
    if let Value::Object(case) = &mut r.case {
        case.insert("failed_samples".into(), json!(failed));
        case.insert("pdf_mass".into(), json!(mass.value));
    }
    r.verdict = if mass.value.is_finite() && pv >= STATISTICAL_ALPHA.value {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
}
