//! Sampling: chi-square of `sample_wm` against `pdf_wm` over the hemisphere, Kolmogorov–Smirnov
//! tests of its cos θ and φ marginals (one record per marginal, each a statistical test of its
//! own), `pdf_wm` against D(m)(m·n) at the sampled normals, and a Monte Carlo estimate of Λ
//! through the sampler (E[⟨−w·m⟩⁺/(m·n)] = Λ(w) cos θ) against the closed form.

use super::{applied, compare_exact, covers, lobe_width, theta_kinks, timed, Planned, Profile};
use crate::oracle::chi2::{chi2_test_sampler, Chi2Config};
use crate::oracle::ks::{self, ks_test_sampler, KsConfig, LobeHints, Marginal};
use crate::oracle::monte_carlo::{estimate, two_sided_p};
use crate::record::{CheckRecord, Measured, OracleValue, Verdict};
use crate::tolerance::{PDF_CONSISTENCY, STATISTICAL_ALPHA};
use mfh_reference::geometry::{dot, from_spherical};
use mfh_reference::Model;
use serde_json::{json, Value};
use std::sync::Arc;

const SOURCE: &str =
    "seed 001 eq 11–12, 40–42; seed 004 (Burley 2012 B.2); seed 000 Algorithms 1–2";

/// Plans the sampling checks of one model that has a normal sampler.
pub fn plan(model: Arc<dyn Model>, profile: Profile, why: &str) -> Vec<Planned> {
    if model.as_sampler().is_none() {
        return Vec::new();
    }
    let spec = serde_json::to_value(model.spec()).unwrap_or(Value::Null);
    let family = model.family();
    let mut out = Vec::new();
    let samples = profile.chi2_samples();
    let resolution = 16;
    {
        let (m, spec_run) = (model.clone(), spec.clone());
        let case = json!({"samples": samples, "resolution": resolution});
        let case_run = case.clone();
        out.push(Planned {
            check: "sampling.chi2".into(),
            model: spec.clone(),
            case,
            why: format!("{why}: importance sampling of normals"),
            covers: vec![covers(family, "sample_wm", "default")],
            statistical: true,
            run: Box::new(move |ctx| {
                timed(|| {
                    let mut r = CheckRecord::new(
                        "sampling.chi2",
                        spec_run.clone(),
                        case_run.clone(),
                        SOURCE,
                    );
                    r.covers = vec![covers(family, "sample_wm", "default")];
                    r.seed = Some(ctx.seed);
                    let sampler = m.as_sampler().expect("planned for samplers");
                    let config = Chi2Config {
                        resolution,
                        samples,
                        seed: ctx.seed,
                        alpha: STATISTICAL_ALPHA.value,
                    };
                    let result = chi2_test_sampler(sampler, &config);
                    r.cost.samples = samples;
                    r.tolerance = Some(applied(&STATISTICAL_ALPHA));
                    if let Some(dir) = &ctx.out {
                        let sub = dir.join("chi2").join(folder_name(&spec_run, &case_run));
                        write_chi2_artefacts(&mut r, &sub, &result);
                    }
                    match &result.reason {
                        Some(reason)
                            if !matches!(reason, crate::oracle::chi2::Failure::Rejected { .. }) =>
                        {
                            r.verdict = Verdict::Fail;
                            r.case = json!({"samples": samples, "resolution": resolution,
                                            "sanity_failure": reason.to_string()});
                        }
                        _ => {
                            r.measured = Some(Measured::PValue {
                                p: result.p_value,
                                statistic: result.statistic,
                                dof: result.dof,
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
                    r
                })
            }),
        });
    }
    for marginal in [Marginal::CosTheta, Marginal::Phi] {
        out.push(plan_ks(
            model.clone(),
            &spec,
            marginal,
            profile.ks_samples(family),
            why,
        ));
    }
    {
        let (m, spec_run) = (model.clone(), spec.clone());
        out.push(Planned {
            check: "sampling.pdf_consistency".into(),
            model: spec.clone(),
            case: json!({"points": 4096}),
            why: format!("{why}: the sampler's pdf must be D(m)(m·n) at what it samples"),
            covers: vec![covers(family, "pdf_wm", "default")],
            statistical: false,
            run: Box::new(move |_| {
                timed(|| {
                    let mut r = CheckRecord::new(
                        "sampling.pdf_consistency",
                        spec_run.clone(),
                        json!({"points": 4096}),
                        SOURCE,
                    );
                    r.covers = vec![covers(family, "pdf_wm", "default")];
                    let sampler = m.as_sampler().expect("planned for samplers");
                    let mut worst = 0.0f64;
                    let g = 0.618_033_988_749_894_9;
                    for i in 0..4096u32 {
                        let u = [(f64::from(i) + 0.5) / 4096.0, (f64::from(i) * g).fract()];
                        let mm = sampler.sample_wm(u);
                        let len = dot(mm, mm).sqrt();
                        let pdf = sampler.pdf_wm(mm);
                        let want = m.d(mm) * mm[2];
                        let e = if !(mm[2] >= 0.0) || !pdf.is_finite() {
                            f64::INFINITY
                        } else {
                            crate::record::relative_error(pdf, want).max((len - 1.0).abs())
                        };
                        worst = worst.max(e);
                    }
                    compare_exact(&mut r, worst, 0.0, &PDF_CONSISTENCY);
                    // `worst` is itself a relative error (against 0, `compare` says absolute).
                    r.measured = Some(Measured::Relative { error: worst });
                    r
                })
            }),
        });
    }
    if model.as_smith().is_some() {
        let (m, spec_run) = (model.clone(), spec.clone());
        let theta = 1.2;
        let mc_samples = samples;
        let case = json!({"theta": theta, "phi": 0.3, "samples": mc_samples});
        let case_run = case.clone();
        out.push(Planned {
            check: "sampling.lambda_monte_carlo".into(),
            model: spec.clone(),
            case,
            why: format!("{why}: the sampler and Λ must agree on the back-facing projected area"),
            covers: vec![covers(family, "sample_wm", "default")],
            statistical: true,
            run: Box::new(move |ctx| {
                timed(|| {
                    let mut r = CheckRecord::new(
                        "sampling.lambda_monte_carlo",
                        spec_run.clone(),
                        case_run.clone(),
                        "Λ(w) cos θ = ∫⟨−w·m⟩⁺D(m)dm = E_{m∼D(m)(m·n)}[⟨−w·m⟩⁺/(m·n)]",
                    );
                    r.covers = vec![covers(family, "sample_wm", "default")];
                    r.seed = Some(ctx.seed);
                    let sampler = m.as_sampler().expect("planned for samplers");
                    let smith = m.as_smith().expect("planned for Smith models");
                    let w = from_spherical(theta, 0.3);
                    let e = estimate(
                        &|u| {
                            let mm = sampler.sample_wm(u);
                            let c = -dot(w, mm);
                            if c > 0.0 && mm[2] > 0.0 {
                                c / mm[2]
                            } else {
                                0.0
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
                    r
                })
            }),
        });
    }
    out
}

/// Plans the KS test of one marginal of a model's sampler: `sampling.ks_marginals`, case
/// `{"marginal": "cos_theta" | "phi", "samples": N}`. The record's value is D_N; its case gains
/// the table's knots and error bound, Stephens' λ and where D_N is attained. Sanity failures
/// fail without a p-value; a CDF table too coarse for N is an error (no verdict).
fn plan_ks(
    model: Arc<dyn Model>,
    spec: &Value,
    marginal: Marginal,
    samples: u64,
    why: &str,
) -> Planned {
    let family = model.family();
    let case = json!({"marginal": marginal.name(), "samples": samples});
    let (spec_run, case_run) = (spec.clone(), case.clone());
    let (width, kinks) = (lobe_width(spec), theta_kinks(spec));
    Planned {
        check: "sampling.ks_marginals".into(),
        model: spec.clone(),
        case,
        why: format!(
            "{why}: the {} marginal of the sampled normals must follow the pdf's",
            marginal.name()
        ),
        covers: vec![covers(family, "sample_wm", "default")],
        statistical: true,
        run: Box::new(move |ctx| {
            timed(|| {
                let mut r = CheckRecord::new(
                    "sampling.ks_marginals",
                    spec_run.clone(),
                    case_run.clone(),
                    SOURCE,
                );
                r.covers = vec![covers(family, "sample_wm", "default")];
                r.seed = Some(ctx.seed);
                let Some(sampler) = model.as_sampler() else {
                    r.verdict = Verdict::Error {
                        message: "the model has no sampler".into(),
                    };
                    return r;
                };
                let hints = LobeHints {
                    width,
                    theta_kinks: &kinks,
                };
                let config = KsConfig {
                    samples,
                    seed: ctx.seed,
                    alpha: STATISTICAL_ALPHA.value,
                };
                let result = ks_test_sampler(sampler, marginal, &hints, &config);
                fill_ks(&mut r, &result);
                r
            })
        }),
    }
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

/// A file-name-safe folder name for a model and case: their compact JSON with every run of
/// characters outside `[A-Za-z0-9.-]` turned into one `_`; past 120 characters, the first 111
/// and 8 hex digits of a hash (FNV-1a) of the whole, so that long names stay distinct.
pub fn folder_name(model: &Value, case: &Value) -> String {
    let text = format!("{model}_{case}");
    let mut out = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    let mut out = out.trim_matches('_').to_string();
    if out.len() > 120 {
        let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        out = format!("{}_{:08x}", &out[..111], hash >> 32);
    }
    if out.is_empty() {
        "case".to_string()
    } else {
        out
    }
}

/// Writes a chi-square result's tables into `dir`, and its heat maps when it fails at the
/// uncorrected level α (a superset of the audit's failures at the Šidák level, so every chi-square
/// check the audit fails has its maps) or on a sanity failure; lists what was written in the
/// record's artefacts. A write error is noted in the artefacts, not fatal.
fn write_chi2_artefacts(
    r: &mut CheckRecord,
    dir: &std::path::Path,
    result: &crate::oracle::chi2::Chi2Result,
) {
    let written = crate::chi2_command::write_tables(dir, result)
        .map_err(crate::heatmap::HeatMapError::from)
        .and_then(|mut paths| {
            if result.verdict == crate::oracle::chi2::Verdict::Fail {
                paths.extend(crate::chi2_command::write_heat_maps(dir, result)?);
            }
            Ok(paths)
        });
    match written {
        Ok(paths) => r
            .artefacts
            .extend(paths.iter().map(|p| p.display().to_string())),
        Err(e) => r
            .artefacts
            .push(format!("(could not write to {}: {e})", dir.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::folder_name;
    use serde_json::json;

    #[test]
    fn folder_names_are_safe_and_distinct() {
        let name = folder_name(
            &json!({"family": "ggx", "alpha": 0.3}),
            &json!({"samples": 10}),
        );
        assert_eq!(name, "alpha_0.3_family_ggx_samples_10");
        let long = |v: f64| {
            folder_name(
                &json!({"family": "piecewise_linear", "x": {"theta": [0.0, 0.5, 1.0, 1.5],
                        "value": [1.0, 0.6, 0.1, 0.0]}, "y": {"theta": [0.0, 0.3, 0.9, 1.5],
                        "value": [2.0, 0.8, 0.05, v]}}),
                &json!({"samples": 200000, "resolution": 16}),
            )
        };
        let (a, b) = (long(0.0), long(1e-3));
        assert!(a.len() == 120 && b.len() == 120 && a != b, "{a} {b}");
        assert!(a
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c)));
    }
}
