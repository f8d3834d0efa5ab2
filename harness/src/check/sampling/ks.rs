//! Kolmogorov–Smirnov tests of the cos θ and φ marginals of a normal sampler, one record per
//! marginal, with the model's and the samples' CDF curves in the record's data.

use super::SOURCE;
use crate::check::Check;
use crate::check::{applied, covers, PlannedCheck};
use crate::oracle::ks::{self, KsConfig, Marginal};
use crate::precision::Precision;
use crate::record::{CheckRecord, Measured, NoiseFloor, OracleValue, Verdict};
use crate::subject::Subject;
use crate::tolerance::STATISTICAL_ALPHA;
use mfh_reference::Vec3;
use serde_json::{json, Value};
use std::sync::Arc;

/// Plans the KS test of one marginal of a model's sampler: `sampling.ks_marginals`, case
/// `{"marginal": "cos_theta" | "phi", "samples": N}`. The record's value is D_N; its case gains
/// the table's knots and error bound, Stephens' λ and where D_N is attained. Sanity failures
/// fail without a p-value; a CDF table too coarse for N is an error (no verdict).
pub(super) fn plan_ks<'a>(
    subject: &Arc<Subject<'a>>,
    marginal: Marginal,
    samples: u64,
    why: &str,
) -> PlannedCheck<'a> {
    let family = subject.family();
    let spec = &subject.label;
    let model = subject.clone();
    let case = json!({"marginal": marginal.name(), "samples": samples});
    let kinks = subject.theta_kinks();
    Check::new("sampling.ks_marginals", spec.clone(), case, SOURCE)
        .why(format!(
            "{why}: the {} marginal of the sampled normals must follow the pdf's",
            marginal.name()
        ))
        .covers(vec![covers(family, "sample_wm", "default")])
        .statistical()
        .run(move |r, ctx| {
            let Some(sampler) = model.model.as_sampler() else {
                r.verdict = Verdict::Error {
                    message: "the model has no sampler".into(),
                };
                return Ok(());
            };
            let config = KsConfig {
                samples,
                seed: ctx.seed,
                alpha: STATISTICAL_ALPHA.value,
            };
            let kept = ks::ks_test_lobe_batch_kept_at(
                &|u: &[[f64; 2]], out: &mut [Vec3]| sampler.sample_wm_batch(u, out),
                &|m: &[Vec3], out: &mut [f64]| sampler.pdf_wm_batch(m, out),
                marginal,
                model.lobe(),
                &kinks,
                &config,
                model.precision,
            );
            fill_ks(r, &kept.result);
            note_table_floor(r, &kept.result, model.precision);
            r.data = ks_marginal_data(&kept);
            Ok(())
        })
}

/// Points of the KS marginal curves in a record's data.
pub(super) const KS_CURVE_POINTS: usize = 256;

/// The KS marginal's curves for the report: the model's CDF (the test's own table) and the
/// empirical CDF of the very samples the test drew and judged (kept by the test, not drawn
/// again), at [`KS_CURVE_POINTS`] points of the marginal's range. `None` after a sanity failure
/// (no statistic to show).
pub(super) fn ks_marginal_data(kept: &ks::KsKept) -> Option<crate::record::RecordData> {
    let result = &kept.result;
    if matches!(&result.reason, Some(reason) if !matches!(reason, ks::Failure::Rejected { .. })) {
        return None;
    }
    let values = &kept.sorted;
    let [lo, hi] = result.marginal.range();
    let n = values.len().max(1) as f64;
    let x: Vec<f64> = (0..KS_CURVE_POINTS)
        .map(|i| lo + (hi - lo) * i as f64 / (KS_CURVE_POINTS - 1) as f64)
        .collect();
    let empirical_cdf = x
        .iter()
        .map(|&t| values.partition_point(|&v| v <= t) as f64 / n)
        .collect();
    let model_cdf = x.iter().map(|&t| kept.table.cdf(t)).collect();
    Some(crate::record::RecordData::KsMarginal {
        marginal: result.marginal.name().to_string(),
        x,
        model_cdf,
        empirical_cdf,
        samples: result.samples,
        seed: result.seed,
    })
}

/// Where the CDF table of a pdf computed in `precision` stopped at its rounding floor (16 ε
/// per span, `SIMPSON_NOISE_FLOOR`: every precision above f64's), the record's oracle is the
/// table — its total mass and error bound — with that floor.
fn note_table_floor(r: &mut CheckRecord, result: &ks::KsResult, precision: Precision) {
    if precision == Precision::F64 {
        return;
    }
    r.oracle = Some(OracleValue {
        value: result.pdf_mass,
        uncertainty: result.table_error_bound,
        kind: "error_bound",
        noise_floor: Some(NoiseFloor {
            noise: precision.epsilon(),
            floor: ks::SIMPSON_NOISE_FLOOR * precision.epsilon(),
        }),
    });
}

/// Fills a `sampling.ks_marginals` record from a KS result.
fn fill_ks(r: &mut CheckRecord, result: &ks::KsResult) {
    r.cost.samples = result.samples;
    r.cost.evaluations = result.evaluations;
    r.tolerance = Some(applied(&STATISTICAL_ALPHA));
    if let Value::Object(case) = &mut r.case {
        case.insert("knots".into(), json!(result.knots));
        case.insert("table_error_bound".into(), json!(result.table_error_bound));
    }
    match &result.reason {
        Some(ks::Failure::TableInaccurate { .. }) => {
            r.verdict = Verdict::Error {
                message: result
                    .reason
                    .as_ref()
                    .map(ToString::to_string)
                    .unwrap_or_default(),
            };
        }
        Some(reason) if !matches!(reason, ks::Failure::Rejected { .. }) => {
            r.verdict = Verdict::Fail;
            if let Value::Object(case) = &mut r.case {
                case.insert("sanity_failure".into(), json!(reason.to_string()));
            }
        }
        _ => {
            r.value = Some(result.statistic);
            if let Value::Object(case) = &mut r.case {
                case.insert("lambda".into(), json!(result.lambda));
                case.insert("at".into(), json!(result.at));
            }
            r.measured = Some(Measured::PValue {
                p: result.p_value,
                statistic: result.statistic,
                dof: 0,
                alpha: STATISTICAL_ALPHA.value,
            });
            // Provisional: the audit re-decides with the Šidák level.
            r.verdict = if result.p_value >= STATISTICAL_ALPHA.value {
                Verdict::Pass
            } else {
                Verdict::Fail
            };
        }
    }
}
