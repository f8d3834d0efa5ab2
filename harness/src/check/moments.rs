//! Slope moments: ν₂ₖ, variance and excess kurtosis against integrals of P2, the marginal
//! P2 = ∫P22 dp, and the normalization ∫P2 dq = 1 (document 001 eq 4, 6–7, 15; document 002 eq 2–10).

use super::{compare, covers, PlannedCheck};
use crate::check::{need, Check};
use crate::oracle::quadrature::{integrate_line, integrate_pieces, Accuracy};
use crate::oracle::Estimate;
use crate::record::Verdict;
use crate::subject::Subject;
use crate::tolerance::MOMENT;

use serde_json::json;
use std::sync::Arc;

const SOURCE: &str = "seed 001 eq 4, 6–7, 15 (ν₂ₖ = ∫ q^{2k} P2(q) dq); seed 002 eq 2–10";

/// The quantities checked, with the closed form each covers.
const QUANTITIES: &[(&str, &str)] = &[
    ("p2_normalization", "p2"),
    ("p22_marginal", "p22"),
    ("nu2", "slope_moment"),
    ("nu4", "slope_moment"),
    ("variance", "slope_moment"),
    ("excess_kurtosis", "slope_moment"),
];

/// Plans the moment checks of one slope-space model.
pub fn plan<'a>(subject: &Arc<Subject<'a>>, why: &str) -> Vec<PlannedCheck<'a>> {
    if subject.model.as_slopes().is_none() {
        return Vec::new();
    }
    let spec = subject.label.clone();
    let family = subject.family();
    let phi = 0.7;
    QUANTITIES
        .iter()
        .map(|&(quantity, closed)| {
            let m = subject.clone();
            let case = json!({"quantity": quantity, "phi": phi});
            Check::new("moments.slopes", spec.clone(), case, SOURCE)
                .why(format!("{why}: slope-space quantity {quantity}"))
                .covers(vec![covers(family, closed, "default")])
                .run(move |r, _| {
                    let slopes = need(m.model.as_slopes(), "slope distribution")?;
                    let scale = m.lobe().width().tan().max(1e-6);
                    let acc = Accuracy::relative(1e-12);
                    let raw = |k: i32| {
                        integrate_line(&|q| q.powi(k) * slopes.p2(q, phi), 0.0, scale, acc)
                    };
                    let finite = |k: u32| slopes.slope_moment(k, phi);
                    let (value, oracle): (Option<f64>, Estimate) = match quantity {
                        "p2_normalization" => {
                            let e = raw(0);
                            (
                                Some(e.value),
                                Estimate {
                                    value: 1.0,
                                    error_bound: e.error_bound,
                                    evaluations: e.evaluations,
                                },
                            )
                        }
                        "p22_marginal" => {
                            // P2 along x (φ = 0) at q = scale/2 is ∫ P22(q, p) dp.
                            let q = 0.5 * scale;
                            let e = integrate_line(&|p| slopes.p22(q, p), 0.0, scale, acc);
                            (Some(slopes.p2(q, 0.0)), e)
                        }
                        "nu2" => (finite(1), raw(2)),
                        "nu4" => (finite(2), raw(4)),
                        "variance" | "excess_kurtosis" => {
                            let (m1, m2) = (raw(1), raw(2));
                            let mean = m1.value;
                            let central = |k: i32| {
                                integrate_line(
                                    &|q| (q - mean).powi(k) * slopes.p2(q, phi),
                                    mean,
                                    scale,
                                    acc,
                                )
                            };
                            let var = central(2);
                            if quantity == "variance" {
                                (
                                    slopes.variance(phi),
                                    Estimate {
                                        value: var.value,
                                        error_bound: var.error_bound + m2.error_bound,
                                        evaluations: var.evaluations
                                            + m1.evaluations
                                            + m2.evaluations,
                                    },
                                )
                            } else {
                                let c4 = central(4);
                                let v = c4.value / (var.value * var.value) - 3.0;
                                let bound = (c4.error_bound / c4.value.abs()
                                    + 2.0 * var.error_bound / var.value.abs())
                                    * (v + 3.0).abs();
                                // Compared as the kurtosis ν₄/ν₂² = excess + 3: the excess
                                // of Gaussian-like members is ~0, where a relative error
                                // means nothing.
                                (
                                    slopes.excess_kurtosis().map(|k| k + 3.0),
                                    Estimate {
                                        value: v + 3.0,
                                        error_bound: bound,
                                        evaluations: c4.evaluations + var.evaluations,
                                    },
                                )
                            }
                        }
                        _ => (None, Estimate::default()),
                    };
                    match value {
                        Some(v) => compare(r, v, oracle, &MOMENT),
                        None => {
                            // An undefined moment must belong to a divergent integral:
                            // ∫_{−Q}^{Q} q^{2k} P2 must keep growing between Q = 10⁴ s and
                            // Q = 10⁸ s (a convergent moment changes by its tail only,
                            // ≪ 1e-3 for the tails of these models).
                            // Excess kurtosis needs ν₄; variance needs ν₂.
                            let k = if matches!(quantity, "nu4" | "excess_kurtosis") {
                                4
                            } else {
                                2
                            };
                            let truncated = |top: f64| {
                                let mut cuts = vec![0.0];
                                let mut c = 1e-3 * scale;
                                while c < top {
                                    cuts.push(c);
                                    c *= 10.0;
                                }
                                cuts.push(top);
                                integrate_pieces(
                                    &|q| q.powi(k) * (slopes.p2(q, phi) + slopes.p2(-q, phi)),
                                    &cuts,
                                    Accuracy::relative(1e-10),
                                )
                            };
                            let (near, far) = (truncated(1e4 * scale), truncated(1e8 * scale));
                            let growth = (far.value - near.value) / near.value;
                            r.value = Some(growth);
                            r.oracle = Some(crate::record::OracleValue {
                                value: far.value,
                                uncertainty: far.error_bound,
                                kind: "error_bound",
                                noise_floor: None,
                            });
                            // The growth is evidence of divergence, not an error: it
                            // stays out of the worst-error summaries.
                            r.measured = None;
                            r.verdict = if growth > 1e-3 {
                                Verdict::Pass
                            } else {
                                Verdict::Fail
                            };
                            r.case = json!({"quantity": quantity, "phi": phi,
                                                "closed_form": "undefined (diverges)",
                                                "growth_from_1e4_to_1e8_scales": growth});
                        }
                    }
                    Ok(())
                })
        })
        .collect()
}
