//! Errata: every printed formula of the source documents with an erratum in reference/ERRATA.md
//! becomes the check `errata.printed_formula`, which evaluates the printed form and the corrected
//! one against an independent oracle (harness quadrature of the defining integral, or the
//! defining property) and is an expected failure exactly when the printed form fails and the
//! corrected one holds.
//!
//! Where the printed form is reachable through the reference crate (a route, a `*_printed`
//! function, or a public building block), it is evaluated there; printed derivation steps that no
//! route evaluates are transcribed here, each with its document and equation. The oracle is
//! always harness code (`crate::oracle`), never the reference crate's `*_exact` routes.

use super::smith::lambda_oracle;
use super::{applied, covers, timed, Planned};
use crate::oracle::cubature::{integrate_rectangle, Tolerance as CubatureTolerance};
use crate::oracle::quadrature::{
    integrate, integrate_cap, integrate_hemisphere, integrate_line, integrate_pieces,
    integrate_upper, Accuracy,
};
use crate::oracle::Estimate;
use crate::record::{relative_error, CheckRecord, Measured, OracleValue, Verdict};
use crate::tolerance::{Tolerance, ERRATUM, ERRATUM_ASYMPTOTIC, ERRATUM_VISIBLE_MOMENTS};
use mfh_reference::geometry::{dot, from_spherical};
use mfh_reference::ndf::gtr::Gtr;
use mfh_reference::ndf::piecewise::{PiecewiseLinear, Profile};
use mfh_reference::ndf::piecewise_lambda::{domain_split, Remaining};
use mfh_reference::ndf::student::{Member, Student};
use mfh_reference::ndf::student_lambda::{alternating_tail_sum, eq33_prefactor};
use mfh_reference::sg::asg::Asg;
use mfh_reference::sg::circular::{fiber_direction, CircularGaussian};
use mfh_reference::sg::sg::{f_h, Sg};
use mfh_reference::slopes::gaussian::GaussianSlopes;
use mfh_reference::special::gamma_ratio::gamma_half_ratio;
use mfh_reference::special::hyp2f1::{
    hyp2f1_lambda, hyp2f1_lambda_algorithm2, hyp2f1_lambda_algorithm2_corrected,
};
use mfh_reference::special::student_tail::student_lambda;
use mfh_reference::{Masking, Model, ModelSpec, Ndf, NormalSampler, Smith, Vec3};
use serde_json::{json, Value};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The check id of every record this module writes.
pub const CHECK: &str = "errata.printed_formula";

/// Every erratum of reference/ERRATA.md: (id, what is wrong as printed).
pub const ERRATA: &[(&str, &str)] = &[
    ("001-1", "seed 001 Table 1, Λ row for γ = 7/2 garbled"),
    (
        "001-2",
        "seed 001 eq 36–37: arctan(μ/√((γ−1)σ)) for arctan(μ/(σ√(γ−1)))",
    ),
    (
        "001-3",
        "seed 001 eq 11/39–40: φ sampling by arctan loses the quadrant",
    ),
    ("001-4", "seed 001 eq 28 last line: square root misplaced"),
    ("001-5", "seed 001 eq 20: spurious ½ on the ₂F₁ term"),
    (
        "001-6",
        "seed 001 eq 32–33: prefactor keeps q, drops 1/μ and 1/(2k+1)",
    ),
    (
        "001-7",
        "seed 001 §7.1 visible-slope cdf: (γ−1)^{γ−½} for (γ−1)^{½−γ}",
    ),
    (
        "001-8",
        "seed 001 §7.1 conditional cdf: substitution 1/(γ−1) + p² for γ − 1 + p²",
    ),
    (
        "001-9",
        "seed 001 Table 1 anisotropic Beckmann D lacks tan²θ",
    ),
    (
        "001-10",
        "seed 001 §8 Algorithm 2 (₂F₁): lines 1, 6, 7, 9, 12 wrong",
    ),
    (
        "001-11",
        "seed 001 eq 41 θ cdf keeps the φ density (not normalized)",
    ),
    (
        "000-E1",
        "seed 000 eq 8: conditional cdf of θ integrates over φ (the marginal)",
    ),
    (
        "000-E2",
        "seed 000 text after eq 9: B^aniso uses the x profile twice",
    ),
    (
        "000-E3",
        "seed 000 after eq 9 / Algorithm 2: undefined b for the normalization c",
    ),
    (
        "000-E4",
        "seed 000 eq 4 vs §2–3: segment indexing (θ₀ = 0 vs θ₁ = 0)",
    ),
    ("000-E5", "seed 000 eq 23 y line: cos 2φ_o for cos 2θ_o"),
    (
        "000-E6",
        "seed 000 eq 14, 20: ∫sin²φ for ∫cos²φ in the D_x term (harmless)",
    ),
    ("000-E7", "seed 000 eq 32: Λ integral from −∞ instead of μ"),
    (
        "000-E8",
        "seed 000 eq 31: P₂ not taken along the azimuth of v",
    ),
    (
        "000-E9",
        "seed 000 eq 33 (10, 29): no Heaviside factors in G",
    ),
    (
        "000-E10",
        "seed 000 eq 28: trapezoid rule (unbounded approximation)",
    ),
    ("000-E11", "seed 000 eq 34: I₁ for I₁₁"),
    ("000-E12", "seed 000 eq 27: \"Λ\" names a partial integral"),
    (
        "000-E13",
        "seed 000 Algorithms 1–2: tolerance 1e-5 on the cdf",
    ),
    (
        "000-E14",
        "seed 000 eq 2: c defined by an integral of D, which contains c",
    ),
    ("000-E15", "seed 000 eq 18: cos φ_m for cos(φ_m − φ_o)"),
    ("002-1", "seed 002 eq 59: value and sign of E₁"),
    (
        "002-2",
        "seed 002 pseudocode lines 36–39: misplaced bracket in I_para_ortho2",
    ),
    ("002-3", "seed 002 eq 52 (54): wrong coefficients"),
    ("002-4", "seed 002 eq 53, 54: last term lacks H"),
    ("004-E1", "seed 004 §3.5 P2⁴: \"4α²q2\" for 4α²q²"),
    ("004-E2", "seed 004 §4: G1^γ → G1⁰ as μ → 1, α → 0 is false"),
    (
        "004-E3",
        "seed 004 §2, §5: spline in γ \"less than 0.1 % error\"",
    ),
    (
        "003-E1",
        "seed 003 §2.1 Fresnel g = √(η² − c² − 1): wrong sign",
    ),
    (
        "003-E2",
        "seed 003 §2.2 cap product: amplitude by f_h(π/2, λ) misses the integral",
    ),
    (
        "003-E3",
        "seed 003 §3.2.1 ASG integral printed as an equality",
    ),
    (
        "003-E4",
        "seed 003 §3.2.3 convolution Gaussian integral over S² ≈ π/√(…)",
    ),
    (
        "003-E5",
        "seed 003 §3.2.3 convolution L2-error claims (0.2 %, 2.8 %)",
    ),
    (
        "003-E6",
        "seed 003 §3.3.3 visibility lookup f_h(θ_d, ν) for f_h(θ_d, 2ν)",
    ),
    ("003-E7", "seed 003 §4.3 ∫g^c printed equal to ∫g"),
    ("003-E8", "seed 003 §4.1 derivation line drops the − 1"),
    ("003-E9", "seed 003 §3.3.2 ASG warp axis printed as o"),
    (
        "003-S1",
        "seed 003 §2.3 sphere-light sharpness doubles its solid angle (suspected)",
    ),
];

/// Errata that no computation can show failing, with the reason: their check is planned and
/// records `skipped` with that reason (so the audit lists them).
pub const NOT_DEMONSTRABLE: &[(&str, &str)] = &[
    (
        "000-E3",
        "the printed symbol b is undefined where the normalization c is meant: there is no \
         printed value to evaluate (the sampler built with c is checked by sampling.chi2)",
    ),
    (
        "000-E6",
        "∫sin²φ and ∫cos²φ agree over the half periods eq 14 and 20 integrate over, so the \
         printed result is right; only the integrand is misprinted",
    ),
];

/// What a demonstration found: the printed and the corrected value against one oracle.
struct Shown {
    printed: f64,
    corrected: f64,
    oracle: Estimate,
    tolerance: &'static Tolerance,
}

impl Shown {
    fn new(printed: f64, corrected: f64, oracle: Estimate, tolerance: &'static Tolerance) -> Self {
        Self {
            printed,
            corrected,
            oracle,
            tolerance,
        }
    }
}

/// An exact oracle value (a defining property: a cdf ends at 1, G₂ vanishes, …).
fn exact(value: f64) -> Estimate {
    Estimate {
        value,
        error_bound: 0.0,
        evaluations: 0,
    }
}

/// One planned demonstration.
struct Demo {
    id: &'static str,
    source: &'static str,
    covers: Vec<String>,
    model: Value,
    case: Value,
    run: fn() -> Result<Shown, String>,
}

fn acc() -> Accuracy {
    Accuracy::relative(1e-12)
}

fn build(spec: Value) -> Result<Box<dyn Model>, String> {
    let s: ModelSpec = serde_json::from_value(spec).map_err(|e| e.to_string())?;
    s.build().map_err(|e| e.to_string())
}

/// The verdict of a demonstration: expected failure when the printed form fails and the
/// corrected one holds; fail otherwise (so the check can fail).
fn decide(record: &mut CheckRecord, id: &str, description: &str, shown: &Shown) {
    let o = shown.oracle;
    let allowed = shown.tolerance.value + relative_error(o.value + o.error_bound, o.value).min(1.0);
    let printed_error = relative_error(shown.printed, o.value);
    let corrected_error = relative_error(shown.corrected, o.value);
    record.value = Some(shown.printed);
    record.oracle = Some(OracleValue {
        value: o.value,
        uncertainty: o.error_bound,
        kind: "error_bound",
    });
    record.cost.evaluations += o.evaluations;
    record.measured = Some(if o.value == 0.0 {
        Measured::Absolute {
            error: printed_error,
        }
    } else {
        Measured::Relative {
            error: printed_error,
        }
    });
    record.tolerance = Some(applied(shown.tolerance));
    let corrected_holds = corrected_error.is_finite() && corrected_error <= allowed;
    let printed_fails = !(printed_error <= allowed);
    record.verdict = if corrected_holds && printed_fails {
        Verdict::ExpectedFailure {
            reason: format!(
                "[{id}] {description}: printed {:.6e} is off the oracle {:.6e} by {printed_error:.2e}; \
                 corrected {:.6e} within {corrected_error:.1e} (allowed {allowed:.1e}); \
                 ERRATA.md {id}",
                shown.printed, o.value, shown.corrected
            ),
        }
    } else {
        Verdict::Fail
    };
}

/// The description of an erratum id.
pub fn description(id: &str) -> &'static str {
    ERRATA
        .iter()
        .find(|(i, _)| *i == id)
        .map(|(_, d)| *d)
        .unwrap_or("unknown erratum")
}

/// Plans one `errata.printed_formula` check per erratum of the given documents (seed ids
/// "000" … "004").
pub fn plan(documents: &[&str], why: &str) -> Vec<Planned> {
    let mut out = Vec::new();
    for demo in demos() {
        let document = &demo.id[..3];
        if !documents.contains(&document) {
            continue;
        }
        let Demo {
            id,
            source,
            covers,
            model,
            case,
            run,
        } = demo;
        let mut case = case;
        if let Value::Object(map) = &mut case {
            map.insert("erratum".into(), json!(id));
        }
        let (model_run, case_run, covers_run) = (model.clone(), case.clone(), covers.clone());
        out.push(Planned {
            check: CHECK.into(),
            model,
            case,
            why: format!("{why}: erratum {id} ({})", description(id)),
            covers,
            statistical: false,
            run: Box::new(move |_| {
                timed(|| {
                    let mut r =
                        CheckRecord::new(CHECK, model_run.clone(), case_run.clone(), source);
                    r.covers = covers_run.clone();
                    match run() {
                        Ok(shown) => decide(&mut r, id, description(id), &shown),
                        Err(message) => r.verdict = Verdict::Error { message },
                    }
                    r
                })
            }),
        });
    }
    for (id, reason) in NOT_DEMONSTRABLE {
        if !documents.contains(&&id[..3]) {
            continue;
        }
        let case = json!({"erratum": id});
        let case_run = case.clone();
        out.push(Planned {
            check: CHECK.into(),
            model: Value::Null,
            case,
            why: format!("{why}: erratum {id} ({})", description(id)),
            covers: Vec::new(),
            statistical: false,
            run: Box::new(move |_| {
                let mut r =
                    CheckRecord::new(CHECK, Value::Null, case_run.clone(), "reference/ERRATA.md");
                r.verdict = Verdict::Skipped {
                    reason: format!("[{id}] not demonstrable: {reason}"),
                };
                r
            }),
        });
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Seed 001 (STD).

/// The STD P2 of seed 001 in the document's variables, unnormalized: ((γ−1)σ² + q²)^{½−γ}.
fn std_p2_unnormalized(g: f64, sigma: f64, q: f64) -> f64 {
    ((g - 1.0) * sigma * sigma + q * q).powf(0.5 - g)
}

/// Λ by its definition (seed 001 eq 17): (1/μ)∫_μ^∞ (q − μ) P2 dq / ∫ P2 dq, by harness
/// quadrature.
fn std_lambda_oracle(g: f64, sigma: f64, mu: f64) -> Estimate {
    let k = ((g - 1.0) * sigma * sigma).sqrt();
    let total = integrate_line(&|q| std_p2_unnormalized(g, sigma, q), 0.0, k, acc());
    let upper = integrate_upper(
        &|q| (q - mu) * std_p2_unnormalized(g, sigma, q),
        mu,
        k,
        acc(),
    );
    Estimate {
        value: upper.value / total.value / mu,
        error_bound: (upper.error_bound / upper.value.abs() + total.error_bound / total.value)
            * (upper.value / total.value / mu).abs(),
        evaluations: upper.evaluations + total.evaluations,
    }
}

/// ∫_{t0}^∞ (1 + t²)^{½−γ} dt by harness quadrature.
fn tail_oracle(g: f64, t0: f64) -> Estimate {
    integrate_upper(&|t| (1.0 + t * t).powf(0.5 - g), t0, 1.0, acc())
}

fn std_route(route: &'static str, gamma: f64) -> Result<Shown, String> {
    let spec = json!({"family": "std", "gamma": gamma, "alpha": 0.3});
    let m = build(spec.clone())?;
    let w = from_spherical(1.0, 0.0);
    let smith = m.as_smith().ok_or("no Smith")?;
    let (printed_route, corrected_route) = match route {
        "table1_printed" => ("table1_printed", "table1"),
        _ => ("half_integer_printed", "half_integer"),
    };
    let printed = smith
        .lambda_route(w, printed_route)
        .map_err(|e| e.to_string())?;
    let corrected = smith
        .lambda_route(w, corrected_route)
        .map_err(|e| e.to_string())?;
    Ok(Shown::new(
        printed,
        corrected,
        lambda_oracle(m.as_ref(), &spec, w),
        &ERRATUM,
    ))
}

/// 001-3: the fraction of sampled normals with m_x < 0 over a midpoint grid of u (the NDF is
/// even in m_x, so the fraction of mass there is ½ exactly; a midpoint grid of 4k points in u₁
/// gives ½ exactly for the corrected atan2 form).
fn e001_3() -> Result<Shown, String> {
    let s = Student::new(Member::Std, 3.0, 0.2, 0.5).map_err(|e| e.to_string())?;
    let n = 400;
    let fraction = |f: &dyn Fn([f64; 2]) -> Vec3| {
        (0..n)
            .filter(|i| f([(*i as f64 + 0.5) / n as f64, 0.6])[0] < 0.0)
            .count() as f64
            / n as f64
    };
    Ok(Shown::new(
        fraction(&|u| s.sample_wm_printed(u)),
        fraction(&|u| s.sample_wm(u)),
        exact(0.5),
        &ERRATUM,
    ))
}

/// 001-4: seed 001 eq 28, the alternating sum Σ C(n,k)(−1)^k/(2k+1)(1 − s^{2k+1}) for
/// ∫_{t0}^∞ (1+t²)^{½−γ} dt at integer γ, with s as printed and as corrected.
fn e001_4() -> Result<Shown, String> {
    let (g, sigma, mu) = (3.0f64, 0.3f64, 0.4f64);
    let t0 = mu / ((g - 1.0).sqrt() * sigma);
    let sum = |s: f64| alternating_tail_sum(g as u64 - 2, s);
    Ok(Shown::new(
        sum(mu / (sigma * (g - 1.0).sqrt() + mu * mu / (sigma * sigma))),
        sum(mu / (sigma * ((g - 1.0) + mu * mu / (sigma * sigma)).sqrt())),
        tail_oracle(g, t0),
        &ERRATUM,
    ))
}

/// 001-5: seed 001 eq 20, ∫_{t0}^∞ (1+t²)^{½−γ} dt = √πΓ(γ−1)/(2Γ(γ−½)) − (μ/2)₂F₁(…)/√((γ−1)σ²)
/// as printed; without the ½ (= t0 ₂F₁) corrected.
fn e001_5() -> Result<Shown, String> {
    let (g, sigma, mu) = (2.5f64, 0.3f64, 0.4f64);
    let k = (g - 1.0) * sigma * sigma;
    let t0 = mu / k.sqrt();
    let whole = PI.sqrt() / (2.0 * gamma_half_ratio(g - 1.0));
    let f = hyp2f1_lambda(g, -t0 * t0);
    Ok(Shown::new(
        whole - mu / 2.0 * f / k.sqrt(),
        whole - t0 * f,
        tail_oracle(g, t0),
        &ERRATUM,
    ))
}

/// 001-6: seed 001 eq 32–33 (half-integer γ), the printed prefactor (with a free q, bound to μ)
/// against 2(γ−1)^γσ^{2γ−2}/(πμ) Σ C(n,k)(−1)^k/(2k+1).
fn e001_6() -> Result<Shown, String> {
    let (g, sigma, mu) = (2.5f64, 0.3f64, 0.4f64);
    let k2 = (g - 1.0) * sigma * sigma;
    let t0 = mu / k2.sqrt();
    let tail = tail_oracle(g, t0).value;
    let bracket = (k2 + mu * mu).powf(1.5 - g) / (2.0 * g - 3.0) - mu / k2.powf(g - 1.0) * tail;
    let prefactor = |printed| eq33_prefactor(g, sigma, mu, printed);
    Ok(Shown::new(
        prefactor(true) * bracket,
        prefactor(false) * bracket,
        std_lambda_oracle(g, sigma, mu),
        &ERRATUM,
    ))
}

/// P2 of seed 001 §7.1 (σ = 1): (γ−1)^γ Γ(γ−½)/(√π Γ(γ) (γ − 1 + p²)^{γ−½}).
fn p2_sec71(g: f64, p: f64) -> f64 {
    let ln = (g - 1.0) * (g - 1.0).ln() + gamma_half_ratio(g - 1.0).ln()
        - (g - 0.5) * (g - 1.0 + p * p).ln();
    ln.exp() / PI.sqrt()
}

/// 001-7: seed 001 §7.1 visible-slope cdf C²_ωi(p), printed (γ−1)^{γ−½} p ₂F₁ against
/// (γ−1)^{½−γ} p ₂F₁, oracle ∫_{−∞}^p G1 (1 − p′ tan θ) P2(p′) dp′.
fn e001_7() -> Result<Shown, String> {
    let (g, theta, p) = (3.0f64, 0.8f64, 0.3f64);
    let t = theta.tan();
    let g1 = 1.0 / (1.0 + student_lambda(g, 1.0 / (t * (g - 1.0).sqrt())));
    let o = integrate_upper(
        &|u| (1.0 - (p - u) * t) * p2_sec71(g, p - u),
        0.0,
        1.0,
        acc(),
    );
    let c = g1 * (g - 1.0).powf(g) / (PI.sqrt() * (g - 1.0)) * gamma_half_ratio(g - 1.0);
    let f = hyp2f1_lambda(g, -p * p / (g - 1.0));
    let rest = PI.sqrt() / (2.0 * (g - 1.0).powf(g) / (g - 1.0) * gamma_half_ratio(g - 1.0))
        + t / ((2.0 * g - 3.0) * (p * p + g - 1.0).powf(g - 1.5));
    Ok(Shown::new(
        c * ((g - 1.0).powf(g - 0.5) * p * f + rest),
        c * ((g - 1.0).powf(0.5 - g) * p * f + rest),
        Estimate {
            value: g1 * o.value,
            error_bound: g1 * o.error_bound,
            evaluations: o.evaluations,
        },
        &ERRATUM,
    ))
}

/// 001-8: seed 001 §7.1 C^{2|2}(q|p): the conditional cdf of q′ with the printed kernel
/// (1/(γ−1) + p² + q′²)^{−γ} and the corrected (γ − 1 + p² + q′²)^{−γ}, against the kernel of
/// P22, (1 + p²/(γ−1) + q′²/(γ−1))^{−γ}; all by harness quadrature.
fn e001_8() -> Result<Shown, String> {
    let (g, p, q) = (3.0f64, 0.7f64, 0.2f64);
    let cdf = |h: &dyn Fn(f64) -> f64| -> Estimate {
        let below = integrate_upper(&|u| h(q - u), 0.0, 1.0, acc());
        let above = integrate_upper(&|u| h(q + u), 0.0, 1.0, acc());
        let value = below.value / (below.value + above.value);
        Estimate {
            value,
            error_bound: value * (below.error_bound + above.error_bound) / below.value,
            evaluations: below.evaluations + above.evaluations,
        }
    };
    Ok(Shown::new(
        cdf(&|s| (1.0 / (g - 1.0) + p * p + s * s).powf(-g)).value,
        cdf(&|s| (g - 1.0 + p * p + s * s).powf(-g)).value,
        cdf(&|s| (1.0 + p * p / (g - 1.0) + s * s / (g - 1.0)).powf(-g)),
        &ERRATUM,
    ))
}

/// 001-9: seed 001 Table 1 anisotropic Beckmann D: ∫ D cos θ dω = 1 (normalization). The
/// printed D does not decay at the horizon: its integral over θ ≤ 1.3 alone is the value.
fn e001_9() -> Result<Shown, String> {
    let (sx, sy) = (0.2f64, 0.5f64);
    let d = |m: Vec3, printed: bool| {
        let r2 = m[0] * m[0] + m[1] * m[1];
        if m[2] <= 0.0 || r2 == 0.0 {
            return if m[2] > 0.0 {
                1.0 / (PI * sx * sy)
            } else {
                0.0
            };
        }
        let (c2, s2) = (m[0] * m[0] / r2, m[1] * m[1] / r2);
        let a = c2 / (sx * sx) + s2 / (sy * sy);
        let tan2 = r2 / (m[2] * m[2]);
        let e = if printed { a.tan().powi(2) } else { tan2 * a };
        (-e).exp() / (PI * sx * sy * m[2].powi(4)) * m[2]
    };
    // The printed D (tan of the exponent) oscillates through poles of tan: it needs only to
    // be shown far from 1, so 1e-6 suffices (1e-12 took 40 s).
    let printed = integrate_cap(
        &|m| d(m, true),
        [0.0, 0.0, 1.0],
        1.3,
        0.3,
        None,
        Accuracy::relative(1e-6),
    );
    let corrected = integrate_hemisphere(&|m| d(m, false), 0.2, None, acc());
    Ok(Shown::new(
        printed.value,
        corrected.value,
        exact(1.0),
        &ERRATUM,
    ))
}

/// 001-10: seed 001 §8 Algorithm 2 for ₂F₁(½, γ−½; 3/2; z), printed and corrected, against
/// ₂F₁(½, γ−½; 3/2; −x²) = (1/x)∫₀ˣ (1 + q²)^{½−γ} dq by harness quadrature (γ = 5/2, z = −3:
/// line 12).
fn e001_10() -> Result<Shown, String> {
    let (g, z) = (2.5f64, -3.0f64);
    let x = (-z).sqrt();
    let o = integrate(&|q| (1.0 + q * q).powf(0.5 - g), 0.0, x, acc());
    Ok(Shown::new(
        hyp2f1_lambda_algorithm2(g, z),
        hyp2f1_lambda_algorithm2_corrected(g, z),
        Estimate {
            value: o.value / x,
            error_bound: o.error_bound / x,
            evaluations: o.evaluations,
        },
        &ERRATUM,
    ))
}

/// 001-11: seed 001 eq 41, the cdf of θ given φ at θ = 1.2: printed (1/(σxσyA_φ))(1 − (1 +
/// A tan²θ)^{1−γ}), corrected 1 − (1 + A tan²θ)^{1−γ}, against ∫₀^θ D(t, φ) cos t sin t dt /
/// ∫₀^{π/2} (D of seed 001 eq 1 with B = A/(γ−1)… at fixed φ, by harness quadrature).
fn e001_11() -> Result<Shown, String> {
    let (g, sx, sy, phi, theta) = (3.0f64, 0.2f64, 0.5f64, 0.7f64, 1.2f64);
    let a_phi = (phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2);
    let a = a_phi / (g - 1.0);
    // D(t, φ) cos t sin t ∝ (1 + A tan²t)^{−γ} tan t / cos²t; in u = tan t: (1 + A u²)^{−γ} u.
    let f = |u: f64| (1.0 + a * u * u).powf(-g) * u;
    let part = integrate(&f, 0.0, theta.tan(), acc());
    let whole = integrate_upper(&f, 0.0, 1.0 / a.sqrt(), acc());
    let value = part.value / whole.value;
    let base = 1.0 - (1.0 + a * theta.tan().powi(2)).powf(1.0 - g);
    Ok(Shown::new(
        base / (sx * sy * a_phi),
        base,
        Estimate {
            value,
            error_bound: value * (part.error_bound / part.value + whole.error_bound / whole.value),
            evaluations: part.evaluations + whole.evaluations,
        },
        &ERRATUM,
    ))
}

// ---------------------------------------------------------------------------------------------
// Seed 000 (piecewise-linear NDF).

const PL_X: [f64; 6] = [3.0, 2.2, 1.4, 0.9, 0.3, 0.05];
const PL_Y: [f64; 5] = [1.0, 0.95, 0.7, 0.2, 0.02];

fn pl_spec() -> Value {
    let grid = |n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| FRAC_PI_2 * i as f64 / (n - 1) as f64)
            .collect()
    };
    json!({
        "family": "piecewise_linear",
        "x": {"theta": grid(PL_X.len()), "value": PL_X.to_vec()},
        "y": {"theta": grid(PL_Y.len()), "value": PL_Y.to_vec()},
    })
}

fn pl() -> Result<PiecewiseLinear, String> {
    PiecewiseLinear::new(
        Profile::uniform(PL_X.to_vec()),
        Some(Profile::uniform(PL_Y.to_vec())),
    )
    .map_err(|e| e.to_string())
}

/// ∫_a^b D(t, φ) cos t sin t dt by harness quadrature with the breakpoints as cuts.
fn theta_mass(m: &PiecewiseLinear, phi: f64, a: f64, b: f64) -> Estimate {
    let mut cuts = vec![a];
    cuts.extend(m.breakpoints().iter().copied().filter(|&t| t > a && t < b));
    cuts.push(b);
    let (sp, cp) = phi.sin_cos();
    integrate_pieces(
        &|t| {
            let (st, ct) = t.sin_cos();
            m.d([st * cp, st * sp, ct]) * ct * st
        },
        &cuts,
        acc(),
    )
}

fn ratio(a: Estimate, b: Estimate) -> Estimate {
    let value = a.value / b.value;
    Estimate {
        value,
        error_bound: value.abs() * (a.error_bound / a.value.abs() + b.error_bound / b.value.abs()),
        evaluations: a.evaluations + b.evaluations,
    }
}

/// 000-E1: seed 000 eq 8 as printed integrates over φ ∈ [0, 2π]: the marginal cdf of θ. As
/// the conditional cdf of θ given φ_m (normalized to 1 at π/2) it is wrong; eq 9's form (no φ
/// integral, factor 2π) is right. Oracle: the conditional cdf from D by quadrature.
fn e000_1() -> Result<Shown, String> {
    let m = pl()?;
    let (phi, theta) = (0.3f64, 0.5f64);
    let (kx, ky) = m.weights();
    // ∫₀^{2π} cos²φ dφ = ∫₀^{2π} sin²φ dφ = π.
    let marginal = |t: f64| {
        integrate_pieces(
            &|s: f64| PI * (kx * m.d_x(s) + ky * m.d_y(s)) * s.cos() * s.sin(),
            &[0.0, t],
            acc(),
        )
        .value
    };
    let conditional = |t: f64| {
        let (c2, s2) = (phi.cos().powi(2), phi.sin().powi(2));
        integrate_pieces(
            &|s: f64| TAU * (kx * c2 * m.d_x(s) + ky * s2 * m.d_y(s)) * s.cos() * s.sin(),
            &[0.0, t],
            acc(),
        )
        .value
    };
    Ok(Shown::new(
        marginal(theta) / marginal(FRAC_PI_2),
        conditional(theta) / conditional(FRAC_PI_2),
        ratio(
            theta_mass(&m, phi, 0.0, theta),
            theta_mass(&m, phi, 0.0, FRAC_PI_2),
        ),
        &ERRATUM,
    ))
}

/// 000-E2: seed 000 text after eq 9: the segment integral ∫ (A θ + B) cos θ sin θ dθ with
/// B^aniso = cos²φ D_y(0) b^x + sin²φ D_x(0) b^x (printed) or … b^y (Algorithm 2, line 2),
/// against the mass of D on the segment by quadrature.
fn e000_2() -> Result<Shown, String> {
    let m = pl()?;
    let (phi, t0, t1) = (0.9f64, m.breakpoints()[1], m.breakpoints()[2]);
    let (kx, ky) = m.weights();
    let (wx, wy) = (kx * phi.cos().powi(2), ky * phi.sin().powi(2));
    let line = |d: &dyn Fn(f64) -> f64| {
        let a = (d(t1) - d(t0)) / (t1 - t0);
        (a, d(t0) - a * t0)
    };
    let (ax, bx) = line(&|t| m.d_x(t));
    let (ay, by) = line(&|t| m.d_y(t));
    let seg =
        |a: f64, b: f64| integrate(&|t: f64| (a * t + b) * t.cos() * t.sin(), t0, t1, acc()).value;
    let a = wx * ax + wy * ay;
    Ok(Shown::new(
        seg(a, wx * bx + wy * bx),
        seg(a, wx * bx + wy * by),
        theta_mass(&m, phi, t0, t1),
        &ERRATUM,
    ))
}

/// 000-E4: seed 000 eq 9 summed Σ_{i=1}^k ∫_{θᵢ}^{θᵢ₊₁} read with eq 4's θ₀ = 0 omits the first
/// segment: the conditional mass at π/2 then misses [θ₀, θ₁]. Value: the mass over the segments
/// the mixed reading sums; corrected: all segments; oracle: ∫₀^{π/2} by quadrature.
fn e000_4() -> Result<Shown, String> {
    let m = pl()?;
    let phi = 0.4;
    let b = m.breakpoints().to_vec();
    let sum = |from: usize| -> f64 {
        b.windows(2)
            .skip(from)
            .map(|w| theta_mass(&m, phi, w[0], w[1]).value)
            .sum()
    };
    Ok(Shown::new(
        sum(1),
        sum(0),
        theta_mass(&m, phi, 0.0, FRAC_PI_2),
        &ERRATUM,
    ))
}

/// 000-E5: seed 000 eq 23, partial segment ∫_{θ_k}^{E} (aθ + b) sin²θ dθ with cos 2φ_o (the
/// extracted y line) and cos 2θ_o (right), against quadrature.
fn e000_5() -> Result<Shown, String> {
    let (a, b, tk, theta_o, phi_o) = (0.7f64, 0.4f64, 0.2f64, 0.9f64, 0.3f64);
    let e = FRAC_PI_2 - theta_o;
    let with = |c: f64| {
        (a * ((2.0 * tk).cos() + c)
            + 2.0 * (e - tk) * (a * (tk + e) + 2.0 * b)
            + 2.0 * (a * tk + b) * (2.0 * tk).sin()
            - 2.0 * (a * e + b) * (2.0 * theta_o).sin())
            / 8.0
    };
    Ok(Shown::new(
        with((2.0 * phi_o).cos()),
        with((2.0 * theta_o).cos()),
        integrate(&|t: f64| (a * t + b) * t.sin().powi(2), tk, e, acc()),
        &ERRATUM,
    ))
}

/// Smith Λ of the piecewise model by the harness oracle (back-facing projected area).
fn pl_lambda_oracle(w: Vec3) -> Result<(Box<dyn Model>, Estimate), String> {
    let spec = pl_spec();
    let m = build(spec.clone())?;
    let o = lambda_oracle(m.as_ref(), &spec, w);
    Ok((m, o))
}

/// 000-E7: seed 000 eq 32 with the lower limit −∞: (1/μ)∫(q − μ)P₂ dq = (E[q] − μ)/μ, and
/// E[q] = 0 because D(θ, φ + π) = D(θ, φ) (eq 1) and ∫P₂ = 1, so the printed Λ is −1 for every
/// direction; with the lower limit μ it is Smith's Λ (route `domain_split_adaptive`, eq 34),
/// against the back-facing oracle.
fn e000_7() -> Result<Shown, String> {
    let (theta, phi) = (0.3f64, 0.7f64);
    let (_, o) = pl_lambda_oracle(from_spherical(theta, phi))?;
    Ok(Shown::new(
        -1.0,
        split(theta, phi, Remaining::Adaptive)?,
        o,
        &ERRATUM,
    ))
}

/// 000-E8: seed 000 eq 31 with p, q the slopes of the fixed frame: the printed P₂ is the one
/// along φ_v = π/2, so for v at φ_v = 0 it yields Λ(θ, π/2); along the azimuth of v it is
/// Λ(θ, 0) (both by eq 34 with eq 27 integrated adaptively), against the oracle at φ_v = 0.
fn e000_8() -> Result<Shown, String> {
    let theta = 0.3f64;
    let (_, o) = pl_lambda_oracle(from_spherical(theta, 0.0))?;
    Ok(Shown::new(
        split(theta, FRAC_PI_2, Remaining::Adaptive)?,
        split(theta, 0.0, Remaining::Adaptive)?,
        o,
        &ERRATUM,
    ))
}

/// 000-E9: seed 000 eq 33, G = 1/(1 + Λ(i) + Λ(o)) without χ⁺: for a back-facing microfacet G₂
/// must vanish.
fn e000_9() -> Result<Shown, String> {
    let m = pl()?;
    let wi = from_spherical(0.6, 0.2);
    let wo = from_spherical(1.1, 2.5);
    let back = from_spherical(1.3, 2.5 + PI);
    if dot(wo, back) >= 0.0 {
        return Err("the chosen microfacet is not back-facing".into());
    }
    Ok(Shown::new(
        m.g2_eq33(wi, wo),
        m.g2(wo, wi, back, Masking::HeightCorrelated),
        exact(0.0),
        &ERRATUM,
    ))
}

/// The domain-split Λ of seed 000 (eq 34) with the remaining integral by `remaining`.
fn split(theta: f64, phi: f64, remaining: Remaining) -> Result<f64, String> {
    Ok(domain_split(&pl()?, theta, (2.0 * phi).cos(), remaining).lambda)
}

/// 000-E10: seed 000 eq 28, the trapezoid rule, against Λ by quadrature (θ_o = 0.3, where
/// [E, π/2] lies in one segment); corrected: eq 27 integrated adaptively.
fn e000_10() -> Result<Shown, String> {
    let (theta, phi) = (0.3, 0.7);
    let (_, o) = pl_lambda_oracle(from_spherical(theta, phi))?;
    Ok(Shown::new(
        split(theta, phi, Remaining::Trapezoid)?,
        split(theta, phi, Remaining::Adaptive)?,
        o,
        &ERRATUM,
    ))
}

/// 000-E11: seed 000 eq 34 with eq 16's I₁ (= I₁₁ + cos θ_o/2) for the display: Λ is ½ too large.
fn e000_11() -> Result<Shown, String> {
    let (theta, phi) = (0.3f64, 0.7f64);
    let (_, o) = pl_lambda_oracle(from_spherical(theta, phi))?;
    let ds = domain_split(&pl()?, theta, (2.0 * phi).cos(), Remaining::Adaptive);
    let i1 = ds.i11 + 0.5 * theta.cos();
    Ok(Shown::new(
        (i1 + ds.i2_1 + ds.i2_2) / theta.cos() - 0.5,
        (ds.i11 + ds.i2_1 + ds.i2_2) / theta.cos() - 0.5,
        o,
        &ERRATUM,
    ))
}

/// 000-E12: seed 000 eq 27 calls the remaining integral "Λ": taken as Smith's Λ it is wrong.
/// Printed: Λ_doc = I₂² + (cos θ_o/4)·T_rest read as Λ (recovered as I₂² … is not available, so
/// the partial integral I₂² itself); corrected: eq 34's Λ.
fn e000_12() -> Result<Shown, String> {
    let (theta, phi) = (0.3f64, 0.7f64);
    let (_, o) = pl_lambda_oracle(from_spherical(theta, phi))?;
    let ds = domain_split(&pl()?, theta, (2.0 * phi).cos(), Remaining::Adaptive);
    Ok(Shown::new(ds.i2_2, ds.lambda, o, &ERRATUM))
}

/// 000-E13: Algorithms 1–2 stop at |cdf − ξ| < 1e-5: θ sampled so is off its quantile by up to
/// 1e-5 in probability. Value: the conditional cdf (by quadrature) at the θ sampled with the
/// printed tolerance; corrected: with the default 1e-12; oracle: ξ.
fn e000_13() -> Result<Shown, String> {
    let m = pl()?;
    let coarse = pl()?.with_tolerance(1e-5).map_err(|e| e.to_string())?;
    let phi = 0.4f64;
    let total = theta_mass(&m, phi, 0.0, FRAC_PI_2);
    let cdf = |t: f64| theta_mass(&m, phi, 0.0, t).value / total.value;
    let xis = [0.05, 0.2, 0.37, 0.5, 0.63, 0.81, 0.95];
    let worst = |s: &PiecewiseLinear| {
        xis.iter()
            .map(|&xi| (cdf(s.sample_theta(xi, phi)) - xi).abs())
            .fold(0.0f64, f64::max)
    };
    Ok(Shown::new(
        0.5 + worst(&coarse),
        0.5 + worst(&m),
        exact(0.5),
        &ERRATUM,
    ))
}

/// 000-E14: seed 000 eq 2 defines c as ∫∫ D cos θ sin θ dθ dφ with the normalized D of eq 1,
/// which is 1, not eq 3's c; the third line's integrand gives c. Oracle: that integral by
/// hemisphere quadrature of the unnormalized blend.
fn e000_14() -> Result<Shown, String> {
    let m = pl()?;
    let c = m.normalization_constants().2.ok_or("isotropic: no c")?;
    let (dx0, dy0) = (m.d_x(0.0), m.d_y(0.0));
    let blend = |v: Vec3| {
        let r2 = v[0] * v[0] + v[1] * v[1];
        let theta = r2.sqrt().atan2(v[2]);
        let (c2, s2) = if r2 > 0.0 {
            (v[0] * v[0] / r2, v[1] * v[1] / r2)
        } else {
            (0.5, 0.5)
        };
        (c2 * m.d_x(theta) * dy0 + s2 * m.d_y(theta) * dx0) * v[2]
    };
    // Cut at the profiles' breakpoints, where D has kinks (22 s without, in the audit).
    let kinks = super::theta_kinks(&serde_json::to_value(m.spec()).unwrap_or(Value::Null));
    let at_kinks = |_: f64| kinks.clone();
    let cuts = || {
        Some(crate::oracle::quadrature::Cuts {
            theta: &at_kinks,
            phi: &[],
        })
    };
    let printed = integrate_hemisphere(&|v| m.d(v) * v[2], 0.5, cuts(), acc()).value;
    Ok(Shown::new(
        printed,
        c,
        integrate_hemisphere(&blend, 0.5, cuts(), acc()),
        &ERRATUM,
    ))
}

/// 000-E15: seed 000 eq 18, the front-facing condition with cos φ_m (φ_o = 0 assumed) for
/// cos(φ_m − φ_o): ∫ χ (o·m) D dm with the printed χ, against cos θ_o (1 + Λ(o)) (Λ by the
/// back-facing oracle).
fn e000_15() -> Result<Shown, String> {
    let (theta, phi) = (0.3f64, 0.7f64);
    let o = from_spherical(theta, phi);
    let (m, lam) = pl_lambda_oracle(o)?;
    let (so, co) = theta.sin_cos();
    let projected = |printed: bool| {
        integrate_hemisphere(
            &|v: Vec3| {
                let r = (v[0] * v[0] + v[1] * v[1]).sqrt();
                let (st, ct) = (r, v[2]);
                let pm = v[1].atan2(v[0]);
                let cosd = if printed { pm.cos() } else { (pm - phi).cos() };
                if so * st * cosd + co * ct > 0.0 {
                    dot(o, v) * m.d(v)
                } else {
                    0.0
                }
            },
            0.5,
            None,
            Accuracy::relative(1e-7),
        )
        .value
    };
    Ok(Shown::new(
        projected(true),
        projected(false),
        Estimate {
            value: co * (1.0 + lam.value),
            error_bound: co * lam.error_bound,
            evaluations: lam.evaluations,
        },
        &ERRATUM_VISIBLE_MOMENTS,
    ))
}

// ---------------------------------------------------------------------------------------------
// Seed 002 (Gaussian slopes).

const GS_MEAN: [f64; 2] = [1.0, 1.0];
const GS_COV: [[f64; 2]; 2] = [[1.0, 0.75], [0.75, 1.0]];

/// The visible-slope moments (mean x, mean y, σx², cxy, σy²) of D_s ∝ p_s(s)(w_z − s·w_xy)⁺ by
/// harness cubature in the frame of w's azimuth (u along, v across; the cut is u = cot θ).
pub fn visible_moments_oracle(gs: &GaussianSlopes, theta: f64, phi: f64) -> [Estimate; 5] {
    let (sp, cp) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let mean = gs.mean();
    let cov = gs.cov();
    let mu_u = mean[0] * cp + mean[1] * sp;
    let mu_v = -mean[0] * sp + mean[1] * cp;
    let var_u = cov[0][0] * cp * cp + 2.0 * cov[0][1] * sp * cp + cov[1][1] * sp * sp;
    let var_v = cov[0][0] * sp * sp - 2.0 * cov[0][1] * sp * cp + cov[1][1] * cp * cp;
    let (wu, wv) = (12.0 * var_u.sqrt(), 12.0 * var_v.sqrt());
    let cut = ct / st;
    let hi = (mu_u + wu).min(cut);
    let tol = CubatureTolerance {
        absolute: 1e-14,
        relative: 1e-11,
    };
    let moment = |f: &dyn Fn(f64, f64) -> f64| {
        integrate_rectangle(
            &|u: f64, v: f64| {
                let s = [u * cp - v * sp, u * sp + v * cp];
                gs.ps(s) * (ct - st * u) * f(s[0], s[1])
            },
            [mu_u - wu, hi],
            [mu_v - wv, mu_v + wv],
            tol,
        )
    };
    let n = moment(&|_, _| 1.0);
    let mx = moment(&|x, _| x);
    let my = moment(&|_, y| y);
    let xx = moment(&|x, _| x * x);
    let xy = moment(&|x, y| x * y);
    let yy = moment(&|_, y| y * y);
    let e = |a: Estimate| a.error_bound / n.value + a.value.abs() * n.error_bound / n.value.powi(2);
    let (ex, ey) = (mx.value / n.value, my.value / n.value);
    let est = |value: f64, error_bound: f64| Estimate {
        value,
        error_bound,
        evaluations: n.evaluations,
    };
    [
        est(ex, e(mx)),
        est(ey, e(my)),
        est(xx.value / n.value - ex * ex, e(xx) + 2.0 * ex.abs() * e(mx)),
        est(
            xy.value / n.value - ex * ey,
            e(xy) + ex.abs() * e(my) + ey.abs() * e(mx),
        ),
        est(yy.value / n.value - ey * ey, e(yy) + 2.0 * ey.abs() * e(my)),
    ]
}

/// 002-1 and 002-2: the routes `equations_printed` (eq 59's E₁) and `pseudocode_printed` (lines
/// 36–39) against the corrected `pseudocode` and the cubature oracle, on σx² of D_s (Table 3,
/// row 4: s̄ = (1, 1), Σ = [[1, 0.75], [0.75, 1]], θ = 1.56, φ = −π/2 for 002-2; θ = 1.2, φ = 0
/// for 002-1).
fn visible_route(printed_route: &str, theta: f64, phi: f64) -> Result<Shown, String> {
    use mfh_reference::model::VisibleSlopeMoments;
    let gs = GaussianSlopes::new(GS_MEAN, GS_COV).map_err(|e| e.to_string())?;
    let w = from_spherical(theta, phi);
    let printed = gs
        .visible_moments_route(w, printed_route)
        .map_err(|e| e.to_string())?;
    let corrected = gs
        .visible_moments_route(w, "pseudocode")
        .map_err(|e| e.to_string())?;
    let o = visible_moments_oracle(&gs, theta, phi);
    Ok(Shown::new(
        printed.cov[0][0],
        corrected.cov[0][0],
        o[2],
        &ERRATUM_VISIBLE_MOMENTS,
    ))
}

fn e002_1() -> Result<Shown, String> {
    visible_route("equations_printed", 1.2, 0.0)
}

fn e002_2() -> Result<Shown, String> {
    visible_route("pseudocode_printed", 1.56, -FRAC_PI_2)
}

/// The Gaussian p_s of seed 002 in the frame (s_o, s_⊥) along φ = 0, with its gradient.
fn gaussian_and_gradient(gs: &GaussianSlopes, s: [f64; 2]) -> (f64, [f64; 2]) {
    let m = gs.mean();
    let c = gs.cov();
    let det = c[0][0] * c[1][1] - c[0][1] * c[0][1];
    let inv = [
        [c[1][1] / det, -c[0][1] / det],
        [-c[0][1] / det, c[0][0] / det],
    ];
    let d = [s[0] - m[0], s[1] - m[1]];
    let g = [
        inv[0][0] * d[0] + inv[0][1] * d[1],
        inv[1][0] * d[0] + inv[1][1] * d[1],
    ];
    let p = gs.ps(s);
    (p, [-g[0] * p, -g[1] * p])
}

/// 002-3: seed 002 eq 52, s_⊥ p_s = −σ_o² ∂p_s/∂s_⊥ + c_o⊥ ∂p_s/∂s_o + s̄_⊥ p_s (printed) against
/// −σ_⊥² ∂p_s/∂s_⊥ − c_o⊥ ∂p_s/∂s_o + s̄_⊥ p_s; oracle: the left side.
fn e002_3() -> Result<Shown, String> {
    let gs =
        GaussianSlopes::new([0.3, -0.2], [[0.5, 0.2], [0.2, 0.3]]).map_err(|e| e.to_string())?;
    let s = [0.7, 0.4];
    let (p, grad) = gaussian_and_gradient(&gs, s);
    let c = gs.cov();
    let (var_o, var_perp, c_op) = (c[0][0], c[1][1], c[0][1]);
    let mean_perp = gs.mean()[1];
    Ok(Shown::new(
        -var_o * grad[1] + c_op * grad[0] + mean_perp * p,
        -var_perp * grad[1] - c_op * grad[0] + mean_perp * p,
        exact(s[1] * p),
        &ERRATUM,
    ))
}

/// 002-4: seed 002 eq 53 at a back-facing slope off the cut (H = 0 in a neighbourhood): the
/// left side s_o p_s H and every derivative term vanish; the printed last term s̄_o p_s does not.
fn e002_4() -> Result<Shown, String> {
    let gs =
        GaussianSlopes::new([0.3, -0.2], [[0.5, 0.2], [0.2, 0.3]]).map_err(|e| e.to_string())?;
    let theta = 1.0f64;
    let s = [1.0 / theta.tan() + 0.5, 0.1]; // s_o > cot θ: H = 0
    let h = if s[0] < 1.0 / theta.tan() { 1.0 } else { 0.0 };
    let p = gs.ps(s);
    Ok(Shown::new(
        gs.mean()[0] * p,
        gs.mean()[0] * p * h,
        exact(s[0] * p * h),
        &ERRATUM,
    ))
}

// ---------------------------------------------------------------------------------------------
// Seed 004 (GTR).

/// 004-E1: seed 004 §3.5, P2⁴ with "4α²q2" read literally (8α²q) and as 4α²q², against
/// ∫ P22⁴(p, q) dp by harness quadrature (α = 0.3, q = 0.5).
fn e004_1() -> Result<Shown, String> {
    let (alpha, q) = (0.3f64, 0.5f64);
    let m = Gtr::new(4.0, alpha).map_err(|e| e.to_string())?;
    let slopes = m.as_slopes().ok_or("no slopes")?;
    let o = integrate_line(&|p| slopes.p22(p, q), 0.0, alpha, acc());
    let a2 = alpha * alpha;
    let p2 = |middle: f64| {
        3.0 * a2.powi(3) * (8.0 * q.powi(4) + middle + 12.0 * q * q + a2 * a2 + 2.0 * a2 + 5.0)
            / (16.0 * (a2 * a2 + a2 + 1.0) * (q * q + a2).powf(3.5))
    };
    Ok(Shown::new(
        p2(4.0 * a2 * q * 2.0),
        p2(4.0 * a2 * q * q),
        o,
        &ERRATUM,
    ))
}

/// G1⁰ of seed 004 §3.1: 2/(1 + √(1/μ² + 1)).
pub fn g1_gamma0(mu: f64) -> f64 {
    2.0 / (1.0 + (1.0 / (mu * mu) + 1.0).sqrt())
}

/// G1 of GTR by the harness oracle of Λ (1/(1 + Λ)).
pub fn gtr_g1_oracle(gamma: f64, alpha: f64, theta: f64) -> Result<Estimate, String> {
    let spec = json!({"family": "gtr", "gamma": gamma, "alpha": alpha});
    let m = build(spec.clone())?;
    let lam = lambda_oracle(m.as_ref(), &spec, from_spherical(theta, 0.0));
    Ok(Estimate {
        value: 1.0 / (1.0 + lam.value),
        error_bound: lam.error_bound / (1.0 + lam.value).powi(2),
        evaluations: lam.evaluations,
    })
}

/// 004-E2: seed 004 §4 "all height fields converge to G1⁰ when μ → 1 and α → 0": at μ = 1,
/// α = 1e-4, γ = 2 the printed limit is G1⁰(1) = 0.83; the true limit is 1.
fn e004_2() -> Result<Shown, String> {
    let o = gtr_g1_oracle(2.0, 1e-4, FRAC_PI_2 / 2.0)?;
    Ok(Shown::new(
        g1_gamma0(1.0),
        1.0,
        o,
        &crate::tolerance::GTR_LIMIT,
    ))
}

/// 004-E3: seed 004 §2/§5 spline "less than 0.1 % error" at its worst point of the plot domain
/// (γ = 0.5, α = 0.1, μ = 0.3); corrected: G1 by the exact route.
fn e004_3() -> Result<Shown, String> {
    let (gamma, alpha, mu) = (0.5f64, 0.1f64, 0.3f64);
    let theta = (1.0 / mu).atan();
    let m = Gtr::new(gamma, alpha).map_err(|e| e.to_string())?;
    let w = from_spherical(theta, 0.0);
    Ok(Shown::new(
        m.g1_route(w, "spline").map_err(|e| e.to_string())?,
        m.g1_route(w, "exact").map_err(|e| e.to_string())?,
        gtr_g1_oracle(gamma, alpha, theta)?,
        &crate::tolerance::GTR_SPLINE,
    ))
}

// ---------------------------------------------------------------------------------------------
// Seed 003 (spherical Gaussians).

/// 003-E1: seed 003 §2.1 Cook–Torrance Fresnel factor with g = √(η² − c² − 1) (printed) and
/// √(η² + c² − 1), against the mean of the s and p reflectances from Snell's law (η = 1.5,
/// c = 0.6).
fn e003_1() -> Result<Shown, String> {
    let (eta, c) = (1.5f64, 0.6f64);
    let fresnel = |g: f64| {
        let a = (g - c) / (g + c);
        let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
        0.5 * a * a * (1.0 + b * b)
    };
    let sin_t = (1.0 - c * c).sqrt() / eta;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = ((c - eta * cos_t) / (c + eta * cos_t)).powi(2);
    let rp = ((eta * c - cos_t) / (eta * c + cos_t)).powi(2);
    Ok(Shown::new(
        fresnel((eta * eta - c * c - 1.0).sqrt()),
        fresnel((eta * eta + c * c - 1.0).sqrt()),
        exact(0.5 * (rs + rp)),
        &ERRATUM,
    ))
}

/// ∫ f over the sphere by harness quadrature (a peak of angular width `width` at `axis`).
fn sphere(f: &dyn Fn(Vec3) -> f64, axis: Vec3, width: f64) -> Estimate {
    integrate_cap(f, axis, PI, width, None, acc())
}

/// 003-E2: seed 003 §2.2 cap product G ⊗ V′ ≈ G(·; p, λ, μ f_h(θ_d, λ)/f_h(π/2, λ)); its
/// integral must equal ∫_cap G (λ = 3, θ_d = 1).
fn e003_2() -> Result<Shown, String> {
    let (lambda, theta_d) = (3.0, 1.0);
    let sg = Sg::new([0.0, 0.0, 1.0], lambda, 1.0).map_err(|e| e.to_string())?;
    let printed = sg.cap_product(theta_d).map_err(|e| e.to_string())?;
    let matched = sg.cap_product_matched(theta_d).map_err(|e| e.to_string())?;
    let width = 1.0 / lambda.sqrt();
    let oracle = integrate_cap(
        &|v| sg.eval(v),
        [0.0, 0.0, 1.0],
        theta_d,
        width,
        None,
        acc(),
    );
    Ok(Shown::new(
        sphere(&|v| printed.eval(v), [0.0, 0.0, 1.0], width).value,
        sphere(&|v| matched.eval(v), [0.0, 0.0, 1.0], width).value,
        oracle,
        &ERRATUM,
    ))
}

fn asg(bandwidths: [f64; 2]) -> Result<Asg, String> {
    Asg::new(
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        bandwidths,
        1.0,
    )
    .map_err(|e| e.to_string())
}

/// 003-E3: seed 003 §3.2.1, the ASG integral formula printed as an equality, against the sphere
/// integral of the ASG by harness quadrature (λ = 2, μ = 1, where it is worst).
fn e003_3() -> Result<Shown, String> {
    let a = asg([2.0, 1.0])?;
    let oracle = integrate_hemisphere(&|v| a.eval(v), 0.7, None, acc());
    Ok(Shown::new(
        a.integral().map_err(|e| e.to_string())?,
        a.integral_exact(),
        oracle,
        &ERRATUM,
    ))
}

/// 003-E4: seed 003 §3.2.3, ∫_{S²} e^{−A(v·x − a)² − B(v·y − b)²} dv ≈ π/√(AB) (printed) against
/// 2π/√(AB) (both hemispheres), A = B = 1e4, by harness quadrature. Centred (a = b = 0): off
/// centre each peak also carries the Jacobian 1/|v·z| = 1/√(1 − a² − b²) of dv = dv_x dv_y/|v_z|
/// (2.6 % at a = 0.2, b = 0.1), which neither form has.
fn e003_4() -> Result<Shown, String> {
    let (big_a, big_b, a, b) = (1e4f64, 1e4f64, 0.0f64, 0.0f64);
    let f = |v: Vec3| (-big_a * (v[0] - a).powi(2) - big_b * (v[1] - b).powi(2)).exp();
    let z = (1.0 - a * a - b * b).sqrt();
    let upper = integrate_cap(&f, [a, b, z], 0.3, 0.01, None, acc());
    let lower = integrate_cap(&f, [a, b, -z], 0.3, 0.01, None, acc());
    Ok(Shown::new(
        PI / (big_a * big_b).sqrt(),
        2.0 * PI / (big_a * big_b).sqrt(),
        Estimate {
            value: upper.value + lower.value,
            error_bound: upper.error_bound + lower.error_bound,
            evaluations: upper.evaluations + lower.evaluations,
        },
        &ERRATUM_ASYMPTOTIC,
    ))
}

/// 003-E5: seed 003 §3.2.3 "when λ, μ > 3, the L2-error is less than 0.2 %": the relative L2
/// error over the SG axis p (a 2-D grid of axes on the upper hemisphere, quadrature-weighted) at
/// λ = μ = 3.5, SG sharpness 2ν = 20, against the claim; corrected: the weaker 2.8 % bound at
/// SG sharpness 200, where it holds.
fn e003_5() -> Result<Shown, String> {
    let l2 = |lambda: f64, nu: f64| -> Result<f64, String> {
        let a = asg([lambda, lambda])?;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..6 {
            let theta = (i as f64 + 0.5) / 6.0 * 1.2;
            for j in 0..4 {
                let phi = (j as f64 + 0.5) / 4.0 * FRAC_PI_2;
                let p = from_spherical(theta, phi);
                let sg = Sg::new(p, 2.0 * nu, 1.0).map_err(|e| e.to_string())?;
                let approx = a.convolve_sg(&sg).map_err(|e| e.to_string())?;
                let width = 1.0 / (2.0 * nu).sqrt();
                // Percent-level errors are measured: 1e-9 is ample.
                let exact = integrate_cap(
                    &|v| a.eval(v) * sg.eval(v),
                    p,
                    PI,
                    width,
                    None,
                    Accuracy::relative(1e-9),
                )
                .value;
                let weight = theta.sin();
                num += weight * (approx - exact).powi(2);
                den += weight * exact * exact;
            }
        }
        Ok((num / den).sqrt())
    };
    // As relative errors against an exact 0: value = the measured L2 error, tolerance = claim.
    let printed = l2(3.5, 10.0)?;
    let corrected = l2(3.5, 100.0)?;
    Ok(Shown::new(
        printed,
        corrected * (2e-3 / 2.8e-2),
        exact(0.0),
        &crate::tolerance::SG_CONVOLUTION_L2,
    ))
}

/// 003-E6: seed 003 §3.3.3, ∫ e^{2ν(i·p − 1)} V(i) di ≈ f_h(θ_d, ν) (printed) for a cap
/// visibility, against f_h(θ_d, 2ν), oracle by quadrature (ν = 5, θ_d = 1).
fn e003_6() -> Result<Shown, String> {
    let (nu, theta_d) = (5.0, 1.0);
    let f = |v: Vec3| (2.0 * nu * (v[2] - 1.0)).exp();
    Ok(Shown::new(
        f_h(theta_d, nu),
        f_h(theta_d, 2.0 * nu),
        integrate_cap(&f, [0.0, 0.0, 1.0], theta_d, 0.3, None, acc()),
        &ERRATUM,
    ))
}

/// 003-E7: seed 003 §4.3, ∫_{−π/2}^{π/2} g^c = (√π σ/2)[erf − erf] printed as an equality
/// (σ = 0.5, mean 0.3), against quadrature of g^c.
fn e003_7() -> Result<Shown, String> {
    let g = CircularGaussian::new(0.3, 0.5).map_err(|e| e.to_string())?;
    Ok(Shown::new(
        g.integral_interval(-FRAC_PI_2, FRAC_PI_2),
        g.integral_interval_exact(-FRAC_PI_2, FRAC_PI_2),
        integrate_pieces(&|x| g.eval(x), &[-FRAC_PI_2, 0.3, FRAC_PI_2], acc()),
        &ERRATUM,
    ))
}

/// 003-E8: seed 003 §4.1, the third line of the derivation of ω·ξ − 1 (printed without − 1),
/// against ln(G(ω)/μ)/λ of the SG.
fn e003_8() -> Result<Shown, String> {
    let (t, p, t1, p1) = (0.3f64, 0.8f64, -0.2f64, 0.4f64);
    let xi = fiber_direction(t1, p1);
    let sg = Sg::new(xi, 4.0, 1.0).map_err(|e| e.to_string())?;
    let omega = fiber_direction(t, p);
    let line = t.sin() * t1.sin() + t.cos() * t1.cos() * (p.cos() * p1.cos() + p.sin() * p1.sin());
    Ok(Shown::new(
        line,
        line - 1.0,
        exact(sg.eval(omega).ln() / 4.0),
        &ERRATUM,
    ))
}

/// 003-E9: seed 003 §3.3.2, the ASG warp axis z_i = o (printed) against 2(o·z_h)z_h − o: the
/// BRDF lobe G_h(h(i)), h(i) = (i + o)/‖i + o‖, must peak (= c) at z_i.
fn e003_9() -> Result<Shown, String> {
    let z_h = from_spherical(0.3, 0.5);
    let x_h = {
        let t = from_spherical(0.3 + FRAC_PI_2, 0.5);
        [t[0], t[1], t[2]]
    };
    let y_h = [
        z_h[1] * x_h[2] - z_h[2] * x_h[1],
        z_h[2] * x_h[0] - z_h[0] * x_h[2],
        z_h[0] * x_h[1] - z_h[1] * x_h[0],
    ];
    let g = Asg::new(x_h, y_h, z_h, [40.0, 10.0], 2.0).map_err(|e| e.to_string())?;
    let o = from_spherical(0.9, 2.0);
    let h = |i: Vec3| {
        let s = [i[0] + o[0], i[1] + o[1], i[2] + o[2]];
        let n = dot(s, s).sqrt();
        [s[0] / n, s[1] / n, s[2] / n]
    };
    let k = 2.0 * dot(o, z_h);
    let z_i = [k * z_h[0] - o[0], k * z_h[1] - o[1], k * z_h[2] - o[2]];
    Ok(Shown::new(
        g.eval(h(o)),
        g.eval(h(z_i)),
        exact(2.0),
        &ERRATUM,
    ))
}

/// 003-S1: seed 003 §2.3, the sphere light as an SG with f_a(λ) = 2πr²/d² (printed) against
/// πr²/d², the light's solid angle 2π(1 − √(1 − r²/d²)) to O(r²/d²) (r/d = 1e-3).
fn e003_s1() -> Result<Shown, String> {
    let rd2 = 1e-6f64;
    Ok(Shown::new(
        TAU * rd2,
        PI * rd2,
        exact(TAU * (1.0 - (1.0 - rd2).sqrt())),
        &ERRATUM_ASYMPTOTIC,
    ))
}

// ---------------------------------------------------------------------------------------------

fn demos() -> Vec<Demo> {
    let std_spec = |g: f64| json!({"family": "std", "gamma": g, "alpha": 0.3});
    let gtr = |g: f64, a: f64| json!({"family": "gtr", "gamma": g, "alpha": a});
    let gs = json!({"family": "gaussian_slopes", "mean": GS_MEAN, "cov": GS_COV});
    let d = |id, source, covers: Vec<String>, model, case, run| Demo {
        id,
        source,
        covers,
        model,
        case,
        run,
    };
    vec![
        d(
            "001-1",
            "seed 001 Table 1, Λ row γ = 7/2",
            vec![
                covers("std", "lambda", "table1_printed"),
                covers("std", "lambda", "table1"),
            ],
            std_spec(3.5),
            json!({"theta": 1.0, "route": "table1_printed", "corrected": "table1"}),
            || std_route("table1_printed", 3.5),
        ),
        d(
            "001-2",
            "seed 001 eq 36–37, A21–A22",
            vec![
                covers("std", "lambda", "half_integer_printed"),
                covers("std", "lambda", "half_integer"),
            ],
            std_spec(2.5),
            json!({"theta": 1.0, "route": "half_integer_printed", "corrected": "half_integer"}),
            || std_route("half_integer_printed", 2.5),
        ),
        d(
            "001-3",
            "seed 001 eq 11, 39–40",
            vec![
                covers("std", "sample_wm", "printed"),
                covers("std", "sample_wm", "default"),
            ],
            json!({"family": "std", "gamma": 3.0, "alpha_x": 0.2, "alpha_y": 0.5}),
            json!({"quantity": "fraction of sampled m with m_x < 0", "u2": 0.6, "n": 400}),
            e001_3,
        ),
        d(
            "001-4",
            "seed 001 eq 28, last line",
            vec![],
            Value::Null,
            json!({"gamma": 3.0, "sigma": 0.3, "mu": 0.4}),
            e001_4,
        ),
        d(
            "001-5",
            "seed 001 eq 20",
            vec![],
            Value::Null,
            json!({"gamma": 2.5, "sigma": 0.3, "mu": 0.4}),
            e001_5,
        ),
        d(
            "001-6",
            "seed 001 eq 32–33",
            vec![],
            Value::Null,
            json!({"gamma": 2.5, "sigma": 0.3, "mu": 0.4}),
            e001_6,
        ),
        d(
            "001-7",
            "seed 001 §7.1, C²_ωi(p)",
            vec![],
            Value::Null,
            json!({"gamma": 3.0, "theta": 0.8, "p": 0.3}),
            e001_7,
        ),
        d(
            "001-8",
            "seed 001 §7.1, C^{2|2}(q|p)",
            vec![],
            Value::Null,
            json!({"gamma": 3.0, "p": 0.7, "q": 0.2}),
            e001_8,
        ),
        d(
            "001-9",
            "seed 001 Table 1, anisotropic Beckmann D",
            vec![],
            Value::Null,
            json!({"sigma_x": 0.2, "sigma_y": 0.5, "quantity": "∫ D cos θ dω"}),
            e001_9,
        ),
        d(
            "001-10",
            "seed 001 §8, Algorithm 2",
            vec![
                covers("std", "lambda", "2f1_algorithm2"),
                covers("std", "lambda", "2f1_algorithm2_corrected"),
            ],
            Value::Null,
            json!({"gamma": 2.5, "z": -3.0, "quantity": "₂F₁(½, γ−½; 3/2; z)"}),
            e001_10,
        ),
        d(
            "001-11",
            "seed 001 eq 41",
            vec![],
            Value::Null,
            json!({"gamma": 3.0, "sigma_x": 0.2, "sigma_y": 0.5, "phi": 0.7, "theta": 1.2}),
            e001_11,
        ),
        d(
            "000-E1",
            "seed 000 eq 8",
            vec![covers("piecewise_linear", "cdf_theta", "default")],
            pl_spec(),
            json!({"phi": 0.3, "theta": 0.5}),
            e000_1,
        ),
        d(
            "000-E2",
            "seed 000 text after eq 9; Algorithm 2 line 2",
            vec![],
            pl_spec(),
            json!({"phi": 0.9, "segment": 1}),
            e000_2,
        ),
        d(
            "000-E4",
            "seed 000 eq 4, eq 9",
            vec![],
            pl_spec(),
            json!({"phi": 0.4}),
            e000_4,
        ),
        d(
            "000-E5",
            "seed 000 eq 23, y line",
            vec![],
            Value::Null,
            json!({"a": 0.7, "b": 0.4, "theta_k": 0.2, "theta_o": 0.9, "phi_o": 0.3}),
            e000_5,
        ),
        d(
            "000-E7",
            "seed 000 eq 32",
            vec![covers("piecewise_linear", "lambda", "slope_space")],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7}),
            e000_7,
        ),
        d(
            "000-E8",
            "seed 000 eq 31",
            vec![covers("piecewise_linear", "p2", "default")],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.0}),
            e000_8,
        ),
        d(
            "000-E9",
            "seed 000 eq 33 (10, 29)",
            vec![
                covers("piecewise_linear", "g2", "eq33"),
                covers("piecewise_linear", "g2", "height_correlated"),
            ],
            pl_spec(),
            json!({"wi": [0.6, 0.2], "wo": [1.1, 2.5], "m": [1.3, 2.5 + PI]}),
            e000_9,
        ),
        d(
            "000-E10",
            "seed 000 eq 28",
            vec![
                covers("piecewise_linear", "lambda", "domain_split"),
                covers("piecewise_linear", "lambda", "domain_split_adaptive"),
            ],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7, "route": "domain_split"}),
            e000_10,
        ),
        d(
            "000-E11",
            "seed 000 eq 34",
            vec![covers(
                "piecewise_linear",
                "lambda",
                "domain_split_adaptive",
            )],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7}),
            e000_11,
        ),
        d(
            "000-E12",
            "seed 000 eq 27",
            vec![covers(
                "piecewise_linear",
                "lambda",
                "domain_split_adaptive",
            )],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7}),
            e000_12,
        ),
        d(
            "000-E13",
            "seed 000 Algorithms 1–2",
            vec![covers("piecewise_linear", "sample_wm", "default")],
            pl_spec(),
            json!({"phi": 0.4, "xi": [0.05, 0.2, 0.37, 0.5, 0.63, 0.81, 0.95], "printed_tolerance": 1e-5, "quantity": "½ + max |cdf(θ(ξ)) − ξ|"}),
            e000_13,
        ),
        d(
            "000-E14",
            "seed 000 eq 2–3",
            vec![covers("piecewise_linear", "d", "default")],
            pl_spec(),
            json!({"quantity": "c"}),
            e000_14,
        ),
        d(
            "000-E15",
            "seed 000 eq 18–19",
            vec![covers("piecewise_linear", "d", "default")],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7, "quantity": "∫ χ (o·m) D dm"}),
            e000_15,
        ),
        d(
            "002-1",
            "seed 002 eq 59 (pseudocode line 23)",
            vec![
                covers("gaussian_slopes", "visible_moments", "equations_printed"),
                covers("gaussian_slopes", "visible_moments", "pseudocode"),
            ],
            gs.clone(),
            json!({"theta": 1.2, "phi": 0.0, "route": "equations_printed", "quantity": "σx²(D_s)"}),
            e002_1,
        ),
        d(
            "002-2",
            "seed 002 pseudocode lines 36–39 (eq 68), Table 3 row 4",
            vec![
                covers("gaussian_slopes", "visible_moments", "pseudocode_printed"),
                covers("gaussian_slopes", "visible_moments", "pseudocode"),
            ],
            gs,
            json!({"theta": 1.56, "phi": -FRAC_PI_2, "route": "pseudocode_printed", "quantity": "σx²(D_s)"}),
            e002_2,
        ),
        d(
            "002-3",
            "seed 002 eq 52",
            vec![],
            json!({"family": "gaussian_slopes", "mean": [0.3, -0.2], "cov": [[0.5, 0.2], [0.2, 0.3]]}),
            json!({"s": [0.7, 0.4]}),
            e002_3,
        ),
        d(
            "002-4",
            "seed 002 eq 53",
            vec![],
            json!({"family": "gaussian_slopes", "mean": [0.3, -0.2], "cov": [[0.5, 0.2], [0.2, 0.3]]}),
            json!({"theta": 1.0, "s_offset_past_cut": 0.5}),
            e002_4,
        ),
        d(
            "004-E1",
            "seed 004 §3.5, P2⁴",
            vec![covers("gtr", "p22", "default")],
            gtr(4.0, 0.3),
            json!({"q": 0.5}),
            e004_1,
        ),
        d(
            "004-E2",
            "seed 004 §4",
            vec![],
            gtr(2.0, 1e-4),
            json!({"mu": 1.0}),
            e004_2,
        ),
        d(
            "004-E3",
            "seed 004 §2, §5",
            vec![covers("gtr", "g1", "spline"), covers("gtr", "g1", "exact")],
            gtr(0.5, 0.1),
            json!({"mu": 0.3, "route": "spline"}),
            e004_3,
        ),
        d(
            "003-E1",
            "seed 003 §2.1",
            vec![],
            Value::Null,
            json!({"eta": 1.5, "c": 0.6}),
            e003_1,
        ),
        d(
            "003-E2",
            "seed 003 §2.2",
            vec![
                covers("sg", "cap_product", "printed"),
                covers("sg", "cap_product", "matched"),
            ],
            Value::Null,
            json!({"sharpness": 3.0, "theta_d": 1.0}),
            e003_2,
        ),
        d(
            "003-E3",
            "seed 003 §3.2.1",
            vec![
                covers("asg", "asg_integral", "default"),
                covers("asg", "asg_integral", "exact"),
            ],
            Value::Null,
            json!({"bandwidths": [2.0, 1.0]}),
            e003_3,
        ),
        d(
            "003-E4",
            "seed 003 §3.2.3",
            vec![],
            Value::Null,
            json!({"A": 1e4, "B": 1e4, "a": 0.0, "b": 0.0}),
            e003_4,
        ),
        d(
            "003-E5",
            "seed 003 §3.2.3",
            vec![covers("asg", "asg_sg_convolution", "default")],
            Value::Null,
            json!({"bandwidths": [3.5, 3.5], "sg_sharpness": 20.0, "axes": "6 × 4 grid, θ ≤ 1.2"}),
            e003_5,
        ),
        d(
            "003-E6",
            "seed 003 §3.3.3",
            vec![],
            Value::Null,
            json!({"nu": 5.0, "theta_d": 1.0}),
            e003_6,
        ),
        d(
            "003-E7",
            "seed 003 §4.3",
            vec![covers("circular", "integral_interval", "default")],
            Value::Null,
            json!({"mean": 0.3, "sigma": 0.5}),
            e003_7,
        ),
        d(
            "003-E8",
            "seed 003 §4.1",
            vec![],
            Value::Null,
            json!({"theta": 0.3, "phi": 0.8, "theta_axis": -0.2, "phi_axis": 0.4}),
            e003_8,
        ),
        d(
            "003-E9",
            "seed 003 §3.3.2",
            vec![],
            Value::Null,
            json!({"bandwidths": [40.0, 10.0], "o": [0.9, 2.0]}),
            e003_9,
        ),
        d(
            "003-S1",
            "seed 003 §2.3",
            vec![],
            Value::Null,
            json!({"r_over_d": 1e-3}),
            e003_s1,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The erratum ids of reference/ERRATA.md, by section.
    fn ids_in_errata_md() -> Vec<String> {
        let text = include_str!("../../../reference/ERRATA.md");
        let mut out = Vec::new();
        let mut seed = "";
        for line in text.lines() {
            if let Some(rest) = line.strip_prefix("## Seed ") {
                seed = &rest[..3];
                continue;
            }
            let t = line.trim();
            if seed == "001" && t.starts_with("| ") {
                let cell = t[2..].split('|').next().unwrap_or("").trim();
                if !cell.is_empty() && cell.chars().all(|c| c.is_ascii_digit()) {
                    out.push(format!("001-{cell}"));
                }
            } else if let Some(rest) = t.strip_prefix("### ") {
                let head = rest.split([' ', '—']).next().unwrap_or("");
                let head = head.trim_end_matches('.');
                if seed == "002" && head.chars().all(|c| c.is_ascii_digit()) && !head.is_empty() {
                    out.push(format!("002-{head}"));
                } else if (head.starts_with('E') || head.starts_with('S'))
                    && head.len() > 1
                    && head[1..].chars().all(|c| c.is_ascii_digit())
                {
                    out.push(format!("{seed}-{head}"));
                }
            }
        }
        out
    }

    #[test]
    fn every_erratum_in_errata_md_is_demonstrated() {
        let ids = ids_in_errata_md();
        assert!(ids.len() >= 40, "parsed {ids:?}");
        for id in &ids {
            assert!(
                ERRATA.iter().any(|(i, _)| i == id),
                "ERRATA.md lists {id} but errata::ERRATA has no check for it"
            );
        }
        let plan = plan(&["000", "001", "002", "003", "004"], "test");
        let records: Vec<CheckRecord> = plan
            .iter()
            .map(|p| {
                let r = (p.run)(&ctx());
                println!("{} {:.3}s {:?}", r.case, r.cost.wall_seconds, r.verdict);
                r
            })
            .collect();
        for (id, _) in ERRATA {
            let tag = format!("[{id}]");
            let skipped = NOT_DEMONSTRABLE.iter().any(|(i, _)| i == id);
            let found = records.iter().any(|r| match &r.verdict {
                Verdict::ExpectedFailure { reason } => !skipped && reason.starts_with(&tag),
                Verdict::Skipped { reason } => skipped && reason.starts_with(&tag),
                _ => false,
            });
            let mine: Vec<_> = records
                .iter()
                .filter(|r| r.case.get("erratum").and_then(Value::as_str) == Some(id))
                .map(|r| (r.verdict.clone(), r.value, r.oracle))
                .collect();
            assert!(found, "{id}: {mine:?}");
        }
    }

    fn ctx() -> super::super::RunContext {
        super::super::RunContext { seed: 1, out: None }
    }
}
