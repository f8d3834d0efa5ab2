//! `bsdf.albedo`: ∫ eval(wi, wo) dωo by cubature with an error bound against the mean weight
//! of sampled directions (Monte Carlo with its standard error; a failed sample weighs 0). It
//! sees `eval` errors that the chi-square cannot (which compares `sample` with `pdf` only).
//! `bsdf.energy`: the same integral ≤ 1 where the transport makes that a law (reflection, and
//! transmission where (η_i/η_o)² ≤ 1 or the transport is importance).

use super::{fold_samples, BsdfSubject, Incidence, Integrals, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck, Profile};
use crate::oracle::monte_carlo::two_sided_p;
use crate::record::{Measured, OracleValue, Verdict};
use crate::tolerance::{BSDF_ENERGY, STATISTICAL_ALPHA};
use mfh_reference::bsdf::Transport;
use serde_json::{json, Value};
use std::sync::Arc;

/// Running sums of the sampled weights of one chunk.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    n: f64,
    sum: f64,
    squares: f64,
    non_finite: u64,
}

/// Plans the albedo (and, where it is a law, the energy) check of `subject` at `incidence`.
pub fn plan<'a>(
    subject: &Arc<BsdfSubject<'a>>,
    incidence: Incidence,
    shared: &Arc<Integrals>,
    profile: Profile,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let n = profile.chi2_samples();
    let family = subject.family();
    let mut case = incidence.case();
    case["samples"] = json!(n);
    let s = subject.clone();
    let integrals = shared.clone();
    let mut out = vec![
        Check::new("bsdf.albedo", subject.label.clone(), case, SOURCE)
            .why(format!(
                "{why}: the BSDF's value against its sampling weights"
            ))
            .covers(vec![covers(family, "bsdf_eval", "albedo")])
            .statistical()
            .run(move |r, ctx| {
                let bsdf = s.bsdf.as_ref();
                let wi = incidence.wi;
                let quad = integrals.albedo(bsdf);
                let parts = fold_samples(bsdf, wi, n, ctx.seed, Sums::default, |acc, _, _, s| {
                    let w = s.filter(|s| s.pdf != 0.0).map_or(0.0, |s| s.weight);
                    acc.n += 1.0;
                    if w.is_finite() {
                        acc.sum += w;
                        acc.squares += w * w;
                    } else {
                        acc.non_finite += 1;
                    }
                });
                let all = parts.iter().fold(Sums::default(), |a, b| Sums {
                    n: a.n + b.n,
                    sum: a.sum + b.sum,
                    squares: a.squares + b.squares,
                    non_finite: a.non_finite + b.non_finite,
                });
                let mean = all.sum / all.n;
                let variance =
                    ((all.squares / all.n - mean * mean) * all.n / (all.n - 1.0)).max(0.0);
                let se = (variance / all.n).sqrt();
                let deviation = ((mean - quad.value).abs() - quad.error_bound).max(0.0);
                let z = if deviation == 0.0 {
                    0.0
                } else if se > 0.0 {
                    deviation / se
                } else {
                    f64::INFINITY
                };
                let p = two_sided_p(z);
                r.cost.samples = n;
                r.cost.evaluations += quad.evaluations;
                r.value = Some(mean);
                r.oracle = Some(OracleValue {
                    value: quad.value,
                    uncertainty: quad.error_bound,
                    kind: "error_bound",
                    noise_floor: None,
                });
                r.measured = Some(Measured::PValue {
                    p,
                    statistic: z,
                    dof: 0,
                    alpha: STATISTICAL_ALPHA.value,
                });
                r.tolerance = Some(applied(&STATISTICAL_ALPHA));
                if let Value::Object(case) = &mut r.case {
                    case.insert("standard_error".into(), json!(se));
                    case.insert("non_finite_weights".into(), json!(all.non_finite));
                }
                r.verdict = if all.non_finite == 0
                    && quad.value.is_finite()
                    && p >= STATISTICAL_ALPHA.value
                {
                    Verdict::Pass
                } else {
                    Verdict::Fail
                };
                Ok(())
            }),
    ];
    if energy_is_a_law(subject, incidence) {
        let s = subject.clone();
        let integrals = shared.clone();
        out.push(
            Check::new(
                "bsdf.energy",
                subject.label.clone(),
                incidence.case(),
                SOURCE,
            )
            .why(format!("{why}: the BSDF conserves energy"))
            .covers(vec![covers(family, "bsdf_eval", "energy")])
            .run(move |r, _| {
                // ∫ eval's evaluations are billed to bsdf.albedo ([`super::Integrals`]).
                let quad = integrals.albedo(s.bsdf.as_ref());
                r.value = Some(quad.value);
                r.oracle = Some(OracleValue {
                    value: 1.0,
                    uncertainty: quad.error_bound,
                    kind: "error_bound",
                    noise_floor: None,
                });
                let excess = (quad.value - 1.0).max(0.0);
                r.measured = Some(Measured::Absolute { error: excess });
                r.tolerance = Some(applied(&BSDF_ENERGY));
                r.verdict =
                    if quad.value.is_finite() && excess <= BSDF_ENERGY.value + quad.error_bound {
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

/// Whether ∫ eval dωo ≤ 1 is a law at this incidence: without transmission always; with it
/// when the transport is importance, or radiance with η_i ≤ η_o (radiance carried into the
/// denser medium is compressed, so its albedo from the denser side may exceed 1).
fn energy_is_a_law(subject: &BsdfSubject<'_>, incidence: Incidence) -> bool {
    let Some(eta) = subject.bsdf.eta() else {
        return true;
    };
    let (eta_i, eta_o) = if incidence.wi[2] > 0.0 {
        (1.0, eta)
    } else {
        (eta, 1.0)
    };
    subject.bsdf.transport() == Transport::Importance || eta_i <= eta_o
}
