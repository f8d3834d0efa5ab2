//! The pseudo-VNIS of document 001 §7.2 for STD: the chi-square of Algorithm 1's proxy against its
//! density, and the bias of its estimator with eq 43's weight as printed and with the unbiased
//! one.

use super::visible::{terminator_azimuths, visible_kinks, VISIBLE_INCIDENCES};
use super::{chi2_kinked, skipped};
use crate::check::Check;
use crate::check::{applied, Planned, Profile};
use crate::oracle::monte_carlo::{estimate, two_sided_p};
use crate::oracle::quadrature::{integrate_hemisphere, Accuracy, Cuts};
use crate::record::{CheckRecord, Measured, OracleValue, Verdict};
use crate::tolerance::STATISTICAL_ALPHA;
use mfh_reference::geometry::{dot, from_spherical, Vec3};
use mfh_reference::ndf::student_vnis::{reflect, PseudoVnis};
use mfh_reference::{Masking, ModelSpec, Ndf, Smith};
use serde_json::{json, Value};
use std::sync::Arc;

/// The pseudo-VNIS parameters (γ, αx, αy) of an STD spec with finite γ, or why there are none.
fn std_parameters(spec: &ModelSpec) -> Result<(f64, f64, f64), String> {
    match *spec {
        ModelSpec::Std(mfh_reference::ndf::student::StdSpec {
            gamma,
            alpha,
            alpha_x,
            alpha_y,
        }) if gamma.is_finite() => {
            let ax = alpha.or(alpha_x).unwrap_or(f64::NAN);
            let ay = alpha.or(alpha_y).unwrap_or(f64::NAN);
            Ok((gamma, ax, ay))
        }
        ModelSpec::Std(mfh_reference::ndf::student::StdSpec { .. }) => {
            Err("STD with γ = ∞ is Beckmann, whose visible-normal \
             sampling is exact (Algorithm 1 line 3 picks it): use `visible_normals`"
                .into())
        }
        _ => Err(format!(
            "the pseudo-VNIS of seed 001 §7.2 is defined for STD only (got {})",
            spec.family()
        )),
    }
}

const PSEUDO_VNIS_SOURCE: &str = "seed 001 §7.2, Algorithm 1 and eq 43 (weight(v) = G/G1(v))";

/// Plans `sampling.chi2_pseudo_vnis` and `sampling.pseudo_vnis` for one material sampled with
/// the pseudo-VNIS of document 001 §7.2 (scene `sampling: pseudo_vnis`): at each of
/// [`VISIBLE_INCIDENCES`], the chi-square of the proxy's samples against the proxy's density,
/// and the Monte Carlo mean of
/// the estimator of E(wi) = ∫ G2(wo, wi, m)⟨wi·m⟩⁺D(m)/cos θi dm (wo the mirror of wi about m,
/// F = 1) with samples from Algorithm 1's proxy, against E(wi) by quadrature, once with eq 43's
/// weight as printed (`weight: printed`; an expected failure, erratum `001-§7.2`, where the bias
/// is significant) and once with the unbiased weight D_wi^STD/p_proxy (`weight: unbiased`; must
/// pass). A z-test with the estimator's standard error decides. With the Beckmann proxy the
/// unbiased weight has infinite variance (see `PseudoVnis::weight`): the z-test is then
/// self-normalized but heuristic; the default scene's STD material uses the GGX proxy, where
/// the variance is finite. Models other than STD with finite γ get one skipped record with the
/// reason.
pub fn plan_pseudo_vnis(
    spec: &ModelSpec,
    masking: Option<Masking>,
    profile: Profile,
    why: &str,
) -> Vec<Planned> {
    let spec_value = serde_json::to_value(spec).unwrap_or(Value::Null);
    let built = std_parameters(spec).and_then(|(g, ax, ay)| {
        PseudoVnis::new(g, ax, ay).map_err(|e| format!("no pseudo-VNIS for this STD: {e}"))
    });
    let vnis = match built {
        Ok(v) => Arc::new(v),
        Err(reason) => {
            return vec![skipped(
                "sampling.pseudo_vnis",
                &spec_value,
                json!({}),
                why,
                reason,
            )]
        }
    };
    // Eq 43 is stated for the uncorrelated GAF; a material that masks otherwise uses its own.
    let masking = masking.unwrap_or(Masking::Uncorrelated);
    let samples = profile.chi2_samples();
    let width = crate::subject::spec_width(spec);
    let mut out = Vec::new();
    for &(theta, phi) in &VISIBLE_INCIDENCES {
        let resolution = 16;
        let case = json!({"theta_i": theta, "phi_i": phi, "proxy": vnis.proxy().name(),
                          "sigma": vnis.sigma(), "samples": samples, "resolution": resolution});
        let v = vnis.clone();
        out.push(
            Check::new(
                "sampling.chi2_pseudo_vnis",
                spec_value.clone(),
                case,
                PSEUDO_VNIS_SOURCE,
            )
            .why(format!(
                "{why}: the pseudo-VNIS sampler ({} proxy) must draw from its density",
                vnis.proxy().name()
            ))
            .statistical()
            .run(move |r, ctx| {
                let wi = from_spherical(theta, phi);
                chi2_kinked(
                    r,
                    ctx,
                    (resolution, samples),
                    &|u: &[[f64; 2]], out: &mut [Vec3]| {
                        for (o, &u) in out.iter_mut().zip(u) {
                            *o = v.sample_wm(wi, u);
                        }
                    },
                    &|m: &[Vec3], out: &mut [f64]| {
                        for (o, &m) in out.iter_mut().zip(m) {
                            *o = v.pdf_wm(wi, m);
                        }
                    },
                    (false, crate::precision::Precision::F64),
                );
                Ok(())
            }),
        );
        for weight in ["printed", "unbiased"] {
            let case = json!({"theta_i": theta, "phi_i": phi, "weight": weight,
                              "proxy": vnis.proxy().name(), "sigma": vnis.sigma(),
                              "masking": masking, "samples": samples});
            let v = vnis.clone();
            out.push(
                Check::new(
                    "sampling.pseudo_vnis",
                    spec_value.clone(),
                    case,
                    PSEUDO_VNIS_SOURCE,
                )
                .why(format!(
                    "{why}: the pseudo-VNIS estimator ({} proxy, weight {weight}) must be \
                     unbiased",
                    vnis.proxy().name()
                ))
                .statistical()
                .run(move |r, ctx| {
                    pseudo_vnis_record(r, &v, theta, phi, weight, masking, samples, width);
                    r.seed = Some(ctx.seed);
                    Ok(())
                }),
            );
        }
    }
    out
}

/// Runs one pseudo-VNIS bias test into `r` (seeded by `r.seed`).
#[allow(clippy::too_many_arguments)]
fn pseudo_vnis_record(
    r: &mut CheckRecord,
    v: &PseudoVnis,
    theta: f64,
    phi: f64,
    weight: &str,
    masking: Masking,
    samples: u64,
    width: f64,
) {
    let wi = from_spherical(theta, phi);
    let printed = weight == "printed";
    let seed = r.seed.unwrap_or(0);
    let mc = estimate(
        &|u| {
            let m = v.sample_wm(wi, u);
            let wo = reflect(wi, m);
            if printed {
                v.weight_printed(wi, wo, m, masking)
            } else {
                v.weight(wi, wo, m, masking)
            }
        },
        samples,
        seed,
    );
    let std = v.target();
    let kinks = |p: f64| visible_kinks(wi, p);
    let phi_cuts = terminator_azimuths(phi);
    let truth = integrate_hemisphere(
        &|m| {
            let c = dot(wi, m);
            if !(c > 0.0) || !(m[2] > 0.0) {
                return 0.0;
            }
            let d = std.d(m);
            if d == 0.0 {
                return 0.0;
            }
            std.g2(reflect(wi, m), wi, m, masking) * c * d / wi[2]
        },
        width,
        Some(Cuts {
            theta: &kinks,
            phi: &phi_cuts,
        }),
        Accuracy::relative(1e-9),
    );
    r.value = Some(mc.mean);
    r.oracle = Some(OracleValue {
        value: truth.value,
        uncertainty: truth.error_bound,
        kind: "error_bound",
        noise_floor: None,
    });
    r.cost.samples = samples;
    r.cost.evaluations = truth.evaluations;
    let sigma = mc.standard_error.hypot(truth.error_bound);
    let bias = mc.mean - truth.value;
    let z = bias / sigma;
    let p = if sigma > 0.0 {
        two_sided_p(z)
    } else if bias == 0.0 {
        1.0
    } else {
        0.0
    };
    if let Value::Object(case) = &mut r.case {
        case.insert("standard_error".into(), json!(mc.standard_error));
        case.insert("bias".into(), json!(bias));
        case.insert("relative_bias".into(), json!(bias / truth.value));
    }
    r.measured = Some(Measured::PValue {
        p,
        statistic: z,
        dof: 0,
        alpha: STATISTICAL_ALPHA.value,
    });
    r.tolerance = Some(applied(&STATISTICAL_ALPHA));
    r.verdict = if p >= STATISTICAL_ALPHA.value && mc.mean.is_finite() {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
    if printed {
        crate::check::apply_expected(r, "std", "printed");
    }
}
