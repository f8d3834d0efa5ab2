//! `bsdf.sample_consistency`: at every sampled direction, the pdf and the weight `sample`
//! returns equal `pdf(wi, wo)` and `eval(wi, wo) / pdf(wi, wo)` (the record's value the worst
//! of both relative errors, its case each apart: `worst_pdf_error`, `worst_weight_error`); `bsdf.failure_rate`: the rate
//! of failed samples equals 1 − ∫ pdf dωo (a sampler that silently loses mass fails).

use super::{fold_samples, BsdfSubject, Incidence, Integrals, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck, Profile};
use crate::oracle::monte_carlo::two_sided_p;
use crate::record::{relative_error, Measured, OracleValue, Verdict};
use crate::tolerance::{BSDF_SAMPLE_CONSISTENCY, STATISTICAL_ALPHA};
use mfh_reference::bsdf::{Bsdf, BsdfSample};
use mfh_reference::geometry::{normalize, Vec3};
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
        let tolerance = BSDF_SAMPLE_CONSISTENCY.at(s.precision);
        let mut worst = Worst::default();
        let mut beyond = Vec::new();
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
                if e > tolerance.value {
                    beyond.push(Candidate {
                        index,
                        u,
                        sample: s,
                        pdf: pdf[k],
                        eval: eval[k],
                        error: e,
                        spread: 0.0,
                    });
                    continue;
                }
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
        let excusing = excuse(bsdf, wi, &mut beyond, s.precision.epsilon());
        let excused = beyond
            .iter()
            .filter(|c| c.error - c.spread <= tolerance.value)
            .count();
        for c in &beyond {
            // Judged: what the direction's rounding does not explain.
            let e = (c.error - c.spread).max(0.0);
            if worst.at.is_none() || e > worst.error {
                worst.error = e;
                worst.at = Some(json!({
                    "sample": c.index, "u": c.u, "wo": c.sample.wo,
                    "sample_pdf": c.sample.pdf, "pdf": c.pdf,
                    "sample_weight": c.sample.weight, "eval_over_pdf": c.eval / c.pdf,
                    "raw_error": c.error, "conditioning": c.spread,
                }));
            }
        }
        r.cost.samples = n;
        r.cost.evaluations += excusing;
        r.value = Some(worst.error);
        r.measured = Some(Measured::Relative { error: worst.error });
        r.tolerance = Some(applied(&tolerance));
        if let Value::Object(case) = &mut r.case {
            case.insert("excused_by_conditioning".into(), json!(excused));
        }
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

/// A sample whose pdf or weight disagrees with `pdf`/`eval` beyond the tolerance.
struct Candidate {
    index: u64,
    u: [f64; 3],
    sample: BsdfSample,
    pdf: f64,
    eval: f64,
    /// The larger relative error of the pdf and the weight.
    error: f64,
    /// How much pdf and eval/pdf vary over the 16 ε neighbourhood of the sampled wo
    /// (relative, the larger of the two; filled by [`excuse`]).
    spread: f64,
}

/// The most candidates whose conditioning is measured (the worst by raw error; the rest are
/// judged by their raw error, so a BSDF with more than this many disagreeing samples fails on
/// them: a correct float32 dielectric has a handful at 10⁷ samples).
const MAX_EXCUSED: usize = 1024;

/// The conditioning of each candidate (the worst [`MAX_EXCUSED`] by raw error): the largest
/// relative change of pdf(wi, ·) and eval/pdf over the six directions wo ± 16 ε eₖ
/// (renormalized), ε the BSDF's precision. `sample` computes its pdf and weight from the
/// microfacet normal it drew, `pdf` and `eval` from the half vector rebuilt from wo, which the
/// BSDF's arithmetic knows only to a few ε: where the pdf varies by more than the tolerance
/// over that neighbourhood (near a critical angle, where 1 − F has an infinite slope, or the
/// horizon) the two legitimately differ by that much, and the check judges only the excess.
/// A misplaced factor is not excused: it shows at the well-conditioned samples too. Returns
/// the evaluations spent.
fn excuse(bsdf: &dyn Bsdf, wi: Vec3, candidates: &mut [Candidate], eps: f64) -> u64 {
    candidates.sort_by(|a, b| b.error.total_cmp(&a.error));
    let take = candidates.len().min(MAX_EXCUSED);
    let h = 16.0 * eps;
    let mut wo = Vec::with_capacity(6 * take);
    for c in &candidates[..take] {
        for k in 0..6 {
            let mut w = c.sample.wo;
            w[k / 2] += if k % 2 == 0 { h } else { -h };
            wo.push(normalize(w));
        }
    }
    let wis = vec![wi; wo.len()];
    let (mut pdf, mut eval) = (vec![0.0; wo.len()], vec![0.0; wo.len()]);
    bsdf.pdf_batch(&wis, &wo, &mut pdf);
    bsdf.eval_batch(&wis, &wo, &mut eval);
    for (j, c) in candidates[..take].iter_mut().enumerate() {
        let weight = c.eval / c.pdf;
        let mut spread = 0.0f64;
        for k in 6 * j..6 * j + 6 {
            let sp = relative_error(pdf[k], c.pdf);
            let sw = relative_error(eval[k] / pdf[k], weight);
            // A neighbour where the BSDF is 0 or not finite says nothing of the rounding.
            if sp.is_finite() && sw.is_finite() {
                spread = spread.max(sp).max(sw);
            }
        }
        c.spread = spread;
    }
    2 * wo.len() as u64
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
