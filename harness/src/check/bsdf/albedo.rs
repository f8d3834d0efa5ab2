//! `bsdf.albedo`: ∫ eval(wi, wo) dωo by cubature with an error bound against the mean weight
//! of sampled directions (Monte Carlo with its standard error; a failed sample weighs 0). It
//! sees `eval` errors that the chi-square cannot (which compares `sample` with `pdf` only).
//! The record's case also splits both into the reflected (wo on wi's side) and transmitted
//! parts (`reflection`, `transmission`: each ∫ over its hemisphere with its bound, and the mean
//! of the weights of the samples that land there, the others counting 0, with its standard
//! error), which the HTML report plots against the incidence.
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
    /// Sum and sum of squares of the weights of the samples on wi's side (reflected).
    reflected: (f64, f64),
}

impl Sums {
    fn add(self, b: Sums) -> Sums {
        Sums {
            n: self.n + b.n,
            sum: self.sum + b.sum,
            squares: self.squares + b.squares,
            non_finite: self.non_finite + b.non_finite,
            reflected: (
                self.reflected.0 + b.reflected.0,
                self.reflected.1 + b.reflected.1,
            ),
        }
    }
}

/// The mean of n values of sum `sum` and sum of squares `squares`, and its standard error.
fn mean_and_error(n: f64, sum: f64, squares: f64) -> (f64, f64) {
    let mean = sum / n;
    let variance = ((squares / n - mean * mean) * n / (n - 1.0)).max(0.0);
    (mean, (variance / n).sqrt())
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
                    let s = s.filter(|s| s.pdf != 0.0);
                    let w = s.map_or(0.0, |s| s.weight);
                    acc.n += 1.0;
                    if w.is_finite() {
                        acc.sum += w;
                        acc.squares += w * w;
                        if s.is_some_and(|s| s.wo[2] * wi[2] > 0.0) {
                            acc.reflected.0 += w;
                            acc.reflected.1 += w * w;
                        }
                    } else {
                        acc.non_finite += 1;
                    }
                });
                let all = parts.iter().fold(Sums::default(), |a, &b| a.add(b));
                let (mean, se) = mean_and_error(all.n, all.sum, all.squares);
                let (r_mean, r_se) = mean_and_error(all.n, all.reflected.0, all.reflected.1);
                let (t_mean, t_se) = mean_and_error(
                    all.n,
                    all.sum - all.reflected.0,
                    all.squares - all.reflected.1,
                );
                // The hemispheres' integrals: the reflected one is wi's side.
                let (upper, lower) = integrals.albedo_hemispheres(bsdf);
                let (reflected, transmitted) = if wi[2] > 0.0 {
                    (upper, lower)
                } else {
                    (lower, upper)
                };
                // Each weight is eval/pdf rounded in the BSDF's precision (≤ 16 ε for its ~20
                // operations; a float32 GGX conductor at α = 0.001 measures 9 ε₃₂ of bias, all
                // its weights equal): the mean carries that systematic error, which no
                // standard error shows (0 when the weights are all equal), so 64 ε of it are
                // allowed (1.4e-14 relative in f64, 7.6e-6 in float32).
                let rounding = 64.0 * s.precision.epsilon() * mean.abs();
                let deviation = ((mean - quad.value).abs() - quad.error_bound - rounding).max(0.0);
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
                    case.insert("rounding_allowance".into(), json!(rounding));
                    for (name, quad, mean, se) in [
                        ("reflection", reflected, r_mean, r_se),
                        ("transmission", transmitted, t_mean, t_se),
                    ] {
                        case.insert(
                            name.into(),
                            json!({
                                "albedo": quad.value,
                                "error_bound": quad.error_bound,
                                "mean_weight": mean,
                                "standard_error": se,
                            }),
                        );
                    }
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
                let tolerance = BSDF_ENERGY.at(s.precision);
                r.tolerance = Some(applied(&tolerance));
                r.verdict =
                    if quad.value.is_finite() && excess <= tolerance.value + quad.error_bound {
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
