//! Sampling: chi-square of `sample_wm` against `pdf_wm` over the hemisphere, Kolmogorov–Smirnov
//! tests of its cos θ and φ marginals (one record per marginal, each a statistical test of its
//! own), `pdf_wm` against D(m)(m·n) at the sampled normals, and a Monte Carlo estimate of Λ through the sampler
//! (E[⟨−w·m⟩⁺/(m·n)] = Λ(w) cos θ) against the closed form; for visible-normal samplers the
//! chi-square of `sample_wm_visible` against `pdf_wm_visible` at fixed incidences and the
//! normalization of `pdf_wm_visible`; for STD materials sampled by the pseudo-VNIS of document 001
//! §7.2, the bias of its estimator with the weight of eq 43 as printed and with the unbiased one.
//!
//! One concept a file: the normal sampler's checks here (chi-square, pdf consistency, Λ by Monte
//! Carlo), the KS marginals in `ks.rs`, visible normals in `visible.rs`, the pseudo-VNIS of seed
//! 001 §7.2 in `pseudo_vnis.rs`, the batch paths against the scalar ones in `batch_agrees.rs`.

pub mod batch_agrees;
mod ks;
mod pseudo_vnis;
mod visible;
pub mod visible_jacobian;

pub use pseudo_vnis::plan_pseudo_vnis;
pub use visible::{plan_visible, terminator_azimuths, visible_kinks, VISIBLE_INCIDENCES};

use super::{applied, compare_exact, covers, Planned, PlannedCheck, Profile};
use crate::check::{need, Check};
use crate::oracle::chi2::{chi2_test_batches_cut, BatchPdf, BatchSampler, Chi2Config};
use crate::oracle::ks::Marginal;
use crate::oracle::monte_carlo::{estimate_batch, two_sided_p};
use crate::precision::Precision;
use crate::record::{CheckRecord, Measured, NoiseFloor, OracleValue, Verdict};
use crate::subject::Subject;
use crate::tolerance::{
    cell_relative_tolerance, CELL_ABSOLUTE_TOLERANCE, CELL_RELATIVE_TOLERANCE,
    KINKED_CELL_RELATIVE_TOLERANCE, PDF_CONSISTENCY, REMOTE_CELL_ABSOLUTE_TOLERANCE,
    STATISTICAL_ALPHA,
};
use mfh_reference::geometry::{dot, from_spherical, Vec3};
use mfh_reference::Ndf;
use serde_json::{json, Value};
use std::sync::Arc;

const SOURCE: &str =
    "seed 001 eq 11–12, 40–42; seed 004 (Burley 2012 B.2); seed 000 Algorithms 1–2";

/// Plans the sampling checks of one model that has a normal sampler.
pub fn plan<'a>(subject: &Arc<Subject<'a>>, profile: Profile, why: &str) -> Vec<PlannedCheck<'a>> {
    if subject.model.as_sampler().is_none() {
        return Vec::new();
    }
    let spec = subject.label.clone();
    let family = subject.family();
    let mut out = Vec::new();
    let samples = profile.chi2_samples();
    let resolution = 16;
    {
        let m = subject.clone();
        let kinks = subject.theta_kinks();
        let case = json!({"samples": samples, "resolution": resolution});
        out.push(
            Check::new("sampling.chi2", spec.clone(), case, SOURCE)
                .why(format!("{why}: importance sampling of normals"))
                .covers(vec![covers(family, "sample_wm", "default")])
                .statistical()
                .run(move |r, ctx| {
                    let sampler = need(m.model.as_sampler(), "normal sampler")?;
                    let config = Chi2Config {
                        resolution,
                        samples,
                        seed: ctx.seed,
                        alpha: STATISTICAL_ALPHA.value,
                    };
                    // Cut at the registry's kinks (a piecewise-linear profile's breakpoints):
                    // the cubature then meets smooth pieces only (the piecewise material's
                    // expected masses took 15.8 s with the kinks inside its cells).
                    let result = chi2_test_batches_cut(
                        &|u: &[[f64; 2]], out: &mut [Vec3]| sampler.sample_wm_batch(u, out),
                        &|mm: &[Vec3], out: &mut [f64]| sampler.pdf_wm_batch(mm, out),
                        &config,
                        (
                            cell_relative_tolerance(CELL_RELATIVE_TOLERANCE, m.precision),
                            CELL_ABSOLUTE_TOLERANCE,
                        ),
                        Some(m.lobe()),
                        &kinks,
                    );
                    let floor = cell_noise_floor(CELL_RELATIVE_TOLERANCE, m.precision);
                    fill_chi2(r, &result, ctx, samples, floor);
                    Ok(())
                }),
        );
    }
    for marginal in [Marginal::CosTheta, Marginal::Phi] {
        out.push(ks::plan_ks(
            subject,
            marginal,
            profile.ks_samples(subject.slow_sampler()),
            why,
        ));
    }
    {
        let m = subject.clone();
        out.push(
            Check::new(
                "sampling.pdf_consistency",
                spec.clone(),
                json!({"points": 4096}),
                SOURCE,
            )
            .why(format!(
                "{why}: the sampler's pdf must be D(m)(m·n) at what it samples"
            ))
            .covers(vec![covers(family, "pdf_wm", "default")])
            .run(move |r, _| {
                let sampler = need(m.model.as_sampler(), "normal sampler")?;
                let mut worst = 0.0f64;
                let g = 0.618_033_988_749_894_9;
                // In batches: three round trips for an external model.
                let u: Vec<[f64; 2]> = (0..4096u32)
                    .map(|i| [(f64::from(i) + 0.5) / 4096.0, (f64::from(i) * g).fract()])
                    .collect();
                let mut normals = vec![[0.0; 3]; u.len()];
                sampler.sample_wm_batch(&u, &mut normals);
                let (mut pdfs, mut ds) = (vec![0.0; u.len()], vec![0.0; u.len()]);
                sampler.pdf_wm_batch(&normals, &mut pdfs);
                m.model.d_batch(&normals, &mut ds);
                for i in 0..u.len() {
                    let (mm, pdf) = (normals[i], pdfs[i]);
                    let len = dot(mm, mm).sqrt();
                    let want = ds[i] * mm[2];
                    let e = if !(mm[2] >= 0.0) || !pdf.is_finite() {
                        f64::INFINITY
                    } else {
                        crate::record::relative_error(pdf, want).max((len - 1.0).abs())
                    };
                    worst = worst.max(e);
                }
                compare_exact(r, worst, 0.0, &PDF_CONSISTENCY.at(m.precision));
                // `worst` is itself a relative error (against 0, `compare` says absolute).
                r.measured = Some(Measured::Relative { error: worst });
                Ok(())
            }),
        );
    }
    out.push(super::jacobian::plan(subject, why));
    out.extend(batch_agrees::plan_normal(subject, why));
    if subject.model.as_smith().is_some() {
        let m = subject.clone();
        let theta = 1.2;
        let mc_samples = samples;
        let case = json!({"theta": theta, "phi": 0.3, "samples": mc_samples});
        out.push(
            Check::new(
                "sampling.lambda_monte_carlo",
                spec.clone(),
                case,
                "Λ(w) cos θ = ∫⟨−w·m⟩⁺D(m)dm = E_{m∼D(m)(m·n)}[⟨−w·m⟩⁺/(m·n)]",
            )
            .why(format!(
                "{why}: the sampler and Λ must agree on the back-facing projected area"
            ))
            .covers(vec![covers(family, "sample_wm", "default")])
            .statistical()
            .run(move |r, ctx| {
                let sampler = need(m.model.as_sampler(), "normal sampler")?;
                let smith = need(m.model.as_smith(), "Smith masking")?;
                let w = from_spherical(theta, 0.3);
                // Normals in batches (one round trip per chunk for an external model).
                let e = estimate_batch(
                    &|u: &[[f64; 2]], out: &mut [f64]| {
                        let mut normals = vec![[0.0; 3]; u.len()];
                        sampler.sample_wm_batch(u, &mut normals);
                        for (o, mm) in out.iter_mut().zip(normals) {
                            let c = -dot(w, mm);
                            *o = if c > 0.0 && mm[2] > 0.0 {
                                c / mm[2]
                            } else {
                                0.0
                            };
                        }
                    },
                    mc_samples,
                    ctx.seed,
                );
                let value = smith.lambda(w) * w[2];
                r.value = Some(value);
                r.oracle = Some(OracleValue {
                    value: e.mean,
                    uncertainty: e.standard_error,
                    kind: "standard_error",
                    noise_floor: None,
                });
                r.cost.samples = mc_samples;
                let z = (value - e.mean) / e.standard_error;
                let p = if e.standard_error > 0.0 {
                    two_sided_p(z)
                } else if value == e.mean {
                    1.0
                } else {
                    0.0
                };
                r.measured = Some(Measured::PValue {
                    p,
                    statistic: z,
                    dof: 0,
                    alpha: STATISTICAL_ALPHA.value,
                });
                r.tolerance = Some(applied(&STATISTICAL_ALPHA));
                r.verdict = if p >= STATISTICAL_ALPHA.value {
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

/// Fills a chi-square record from the test's result: a sanity failure (samples outside the
/// domain, pdf mass off, samples in zero-pdf cells) fails outright; otherwise the p-value,
/// provisionally judged at the unshared α (the audit re-decides with the Šidák level). The
/// observed and expected tables go into the record's data (no I/O here: the sinks write them
/// and their heat maps into `out/chi2/<model and case>/`).
///
/// Where the cell tolerance was raised to the implementation's rounding floor (`floor`, a
/// float32 pdf), the record's oracle is the expected masses — their total and summed error
/// bound — with that floor.
fn fill_chi2(
    r: &mut CheckRecord,
    result: &crate::oracle::chi2::Chi2Result,
    _ctx: &super::RunContext,
    samples: u64,
    floor: Option<NoiseFloor>,
) {
    r.cost.samples = samples;
    r.tolerance = Some(applied(&STATISTICAL_ALPHA));
    r.data = Some(chi2_table(result));
    if floor.is_some() {
        r.oracle = Some(OracleValue {
            value: result.expected_mass,
            uncertainty: result.expected_error_bound / result.samples.max(1) as f64,
            kind: "error_bound",
            noise_floor: floor,
        });
    }
    match &result.reason {
        // The oracle out of budget: an error naming it, never a pass nor a model's failure.
        Some(reason @ crate::oracle::chi2::Failure::CubatureBudget { .. }) => {
            r.verdict = Verdict::Error {
                message: reason.to_string(),
            };
        }
        Some(reason) if !matches!(reason, crate::oracle::chi2::Failure::Rejected { .. }) => {
            r.verdict = Verdict::Fail;
            if let Value::Object(case) = &mut r.case {
                case.insert("sanity_failure".into(), json!(reason.to_string()));
            }
        }
        _ => {
            r.measured = Some(Measured::PValue {
                p: result.p_value,
                statistic: result.statistic,
                dof: result.dof,
                alpha: STATISTICAL_ALPHA.value,
            });
            r.verdict = if result.p_value >= STATISTICAL_ALPHA.value {
                Verdict::Pass
            } else {
                Verdict::Fail
            };
        }
    }
}

/// The rounding floor of the chi-square cell masses of a pdf computed in `precision`, where it
/// raises the per-cell relative tolerance `asked` (`cell_relative_tolerance`: 64 ε per cell).
fn cell_noise_floor(asked: f64, precision: Precision) -> Option<NoiseFloor> {
    let floor = cell_relative_tolerance(asked, precision);
    (floor > asked).then_some(NoiseFloor {
        noise: precision.epsilon(),
        floor,
    })
}

/// The observed and expected counts of a chi-square test as a record's table (what the sinks
/// draw as heat maps, for `mfh audit` and `mfh chi2` alike).
pub fn chi2_table(result: &crate::oracle::chi2::Chi2Result) -> crate::record::RecordData {
    crate::record::RecordData::Chi2Table {
        rows: result.resolution,
        columns: 2 * result.resolution,
        samples: result.samples,
        seed: result.seed,
        observed: result.observed.clone(),
        expected: result.expected.clone(),
        z_edges: result.z_edges.clone(),
        phi_edges: result.phi_edges.clone(),
    }
}

/// The chi-square of a batch sampler of a density with kinks (visible normals, the pseudo-VNIS
/// proxy) on the `resolution` grid with `samples` samples from the record's stream, into `r`.
/// `remote` (an external model, whose evaluations are protocol traffic) takes the looser stated
/// cell tolerances; reference models keep the tight ones.
fn chi2_kinked(
    r: &mut CheckRecord,
    ctx: &super::RunContext,
    (resolution, samples): (usize, u64),
    sample: &BatchSampler<'_>,
    pdf: &BatchPdf<'_>,
    (remote, precision): (bool, Precision),
) {
    let config = Chi2Config {
        resolution,
        samples,
        seed: ctx.seed,
        alpha: STATISTICAL_ALPHA.value,
    };
    let absolute = if remote {
        REMOTE_CELL_ABSOLUTE_TOLERANCE
    } else {
        CELL_ABSOLUTE_TOLERANCE
    };
    let tolerance = (
        cell_relative_tolerance(KINKED_CELL_RELATIVE_TOLERANCE, precision),
        absolute,
    );
    let result = chi2_test_batches_cut(sample, pdf, &config, tolerance, None, &[]);
    let floor = cell_noise_floor(KINKED_CELL_RELATIVE_TOLERANCE, precision);
    fill_chi2(r, &result, ctx, samples, floor);
}

/// A skipped record for a check the scene calls for but the model cannot support.
fn skipped(check: &str, spec: &Value, case: Value, why: &str, reason: String) -> Planned {
    Check::new(check, spec.clone(), case, "")
        .why(why)
        .skipped(reason)
}

#[cfg(test)]
mod tests;
