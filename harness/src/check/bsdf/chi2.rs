//! `bsdf.chi2`: the directions `sample` returns against `pdf` over the whole sphere, at one
//! incidence ([`crate::oracle::chi2::sphere`]).

use super::{BsdfSubject, Incidence, Integrals, SOURCE};
use crate::check::{applied, covers, Check, PlannedCheck, Profile};
use crate::oracle::chi2::sphere::{
    sphere_chi2_against, SphereChi2Result, MASS_BUDGET, MASS_NONCENTRALITY,
};
use crate::oracle::chi2::{Chi2Config, TestOutcome};
use crate::record::{Measured, OracleValue, RecordData, Verdict};
use crate::tolerance::STATISTICAL_ALPHA;
use mfh_reference::bsdf::Directions;
use serde_json::{json, Value};
use std::sync::Arc;

/// Cells of each hemisphere: R z-rows × 2R φ-columns.
pub const RESOLUTION: usize = 16;

/// Plans the chi-square of `subject` at `incidence`.
pub fn plan<'a>(
    subject: &Arc<BsdfSubject<'a>>,
    incidence: Incidence,
    shared: &Arc<Integrals>,
    profile: Profile,
    why: &str,
) -> PlannedCheck<'a> {
    let samples = profile.chi2_samples();
    let mut case = incidence.case();
    case["samples"] = json!(samples);
    case["resolution"] = json!(RESOLUTION);
    let s = subject.clone();
    let shared = shared.clone();
    Check::new("bsdf.chi2", subject.label.clone(), case, SOURCE)
        .why(format!("{why}: the BSDF's sampling over the whole sphere"))
        .covers(vec![covers(subject.family(), "bsdf_sample", "default")])
        .statistical()
        .run(move |r, ctx| {
            let bsdf = s.bsdf.as_ref();
            let wi = incidence.wi;
            let config = Chi2Config {
                resolution: RESOLUTION,
                samples,
                seed: ctx.seed,
                alpha: STATISTICAL_ALPHA.value,
            };
            let (masses, spent) = shared.pdf_masses(bsdf);
            let result = sphere_chi2_against(
                &|u: &[[f64; 3]], out: &mut Directions| bsdf.sample_wo_batch(wi, u, out),
                masses.clone(),
                &config,
            );
            r.cost.samples = samples;
            r.cost.evaluations += spent;
            r.tolerance = Some(applied(&STATISTICAL_ALPHA));
            r.oracle = Some(OracleValue {
                value: result.mass(),
                uncertainty: result.mass_error_bound(),
                kind: "error_bound",
                noise_floor: None,
            });
            if let Value::Object(case) = &mut r.case {
                case.insert("pdf_mass".into(), json!(result.mass()));
                case.insert("failed_samples".into(), json!(result.observed.failed));
                case.insert(
                    "mass_noncentrality".into(),
                    json!(result.mass_noncentrality()),
                );
            }
            r.data = Some(table(&result));
            if result.sanity_failure {
                r.verdict = Verdict::Fail;
                if let Value::Object(case) = &mut r.case {
                    case.insert("sanity_failure".into(), json!(result.reason));
                }
            } else {
                r.measured = Some(Measured::PValue {
                    p: result.p_value,
                    statistic: result.statistic,
                    dof: result.dof,
                    alpha: STATISTICAL_ALPHA.value,
                });
                r.verdict = if result.verdict == TestOutcome::Pass {
                    Verdict::Pass
                } else {
                    Verdict::Fail
                };
                // Masses too uncertain to judge by: neither a pass nor a fail is earned.
                let lambda = result.mass_noncentrality();
                if !(lambda <= MASS_NONCENTRALITY) {
                    r.verdict = Verdict::Error {
                        message: format!(
                            "expected masses unresolved within the budget of {MASS_BUDGET} \
                             pdf evaluations a hemisphere: their error bounds could move the \
                             statistic by up to {:.2} (noncentrality {lambda:.3} > \
                             {MASS_NONCENTRALITY})",
                            2.0 * lambda.sqrt() + lambda
                        ),
                    };
                }
            }
            Ok(())
        })
}

/// The observed and expected counts of both hemispheres with their cells' edges, as the
/// `bsdf.chi2` records (and `mfh chi2 --bsdf`) carry them.
pub fn table(result: &SphereChi2Result) -> RecordData {
    let expected = result.expected_counts();
    let cells = result.observed.upper.len();
    RecordData::SphereChi2Table {
        rows: result.resolution,
        columns: 2 * result.resolution,
        samples: result.samples,
        seed: result.seed,
        upper_observed: result.observed.upper.clone(),
        upper_expected: expected[..cells].to_vec(),
        lower_observed: result.observed.lower.clone(),
        lower_expected: expected[cells..].to_vec(),
        upper_z_edges: result.upper_grid.z_edges(),
        upper_phi_edges: result.upper_grid.phi_edges(),
        lower_z_edges: result.lower_grid.z_edges(),
        lower_phi_edges: result.lower_grid.phi_edges(),
    }
}
