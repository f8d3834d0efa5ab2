//! Claims: every quantitative claim of the five documents (error bounds, limits, "equivalent"
//! formulations, convergence) as a check with a verdict: value = the measured error, tolerance =
//! the claimed bound (with the document's words as its reason, `crate::tolerance`), oracle =
//! harness quadrature. A claim reference/ERRATA.md shows false is an expected failure tagged
//! with its erratum id. Forms a document presents as approximations without a bound (document 003
//! §3.2.1, §4.3) are measured against a bound on their measured error, so a changed form fails.
//! Each claim declares what it concerns ([`Concern`]); a scene plans only those it uses.

use super::errata::{Concern, Effect, Scope, STUDENT};
use super::{applied, covers, Planned};
use crate::check::Check;
use crate::oracle::gtr::g1_gamma0;
use crate::oracle::quadrature::{
    integrate, integrate_hemisphere, integrate_line, integrate_pieces, integrate_upper, Accuracy,
};
use crate::oracle::smith_lambda::{lambda_oracle, lambda_oracle_many, lambda_oracle_to};
use crate::oracle::Estimate;
use crate::record::{Measured, Verdict};
use crate::subject::Subject;
use crate::tolerance::{
    Tolerance, ASG_INTEGRAL_APPROXIMATION, CIRCULAR_ERF_LEADING_ORDER, CLOSED_FORM, GTR_CLAMP,
    GTR_LIMIT, GTR_SPLINE, IDENTITY, PIECEWISE_TRAPEZOID, SLOPE_MOMENT_CLAIM,
};
use mfh_reference::errata::document001;
use mfh_reference::geometry::from_spherical;
use mfh_reference::ndf::gtr::Gtr;
use mfh_reference::sg::asg::Asg;
use mfh_reference::sg::circular::CircularGaussian;
use mfh_reference::{Model, ModelSpec};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::f64::consts::FRAC_PI_2;

/// What a claim check measured.
struct Measurement {
    /// The measured error (or quantity the claim bounds).
    error: f64,
    /// Whether `error` is relative (else absolute).
    relative: bool,
    /// Other measured quantities, added to the record's case.
    detail: Value,
}

impl Measurement {
    fn new(error: f64, relative: bool) -> Self {
        Self {
            error,
            relative,
            detail: Value::Null,
        }
    }
}

/// One claim.
struct Claim {
    check: &'static str,
    concern: Concern,
    source: &'static str,
    covers: Vec<String>,
    model: Value,
    case: Value,
    tolerance: &'static Tolerance,
    /// The erratum id when reference/ERRATA.md shows the claim false (an expected failure).
    erratum: Option<&'static str>,
    run: fn() -> Result<Measurement, String>,
}

fn build(spec: Value) -> Result<Box<dyn Model>, String> {
    let s: ModelSpec = serde_json::from_value(spec).map_err(|e| e.to_string())?;
    s.build().map_err(|e| e.to_string())
}

/// Plans one check per claim that concerns what the scene uses (`scope`); the reason names
/// the families and effects that call for it.
pub fn plan(scope: &Scope, why: &str) -> Vec<Planned> {
    let mut out = Vec::new();
    for claim in claims() {
        let Some(used) = scope.uses(&claim.concern) else {
            continue;
        };
        let Claim {
            check,
            source,
            covers,
            model,
            case,
            tolerance,
            erratum,
            run,
            ..
        } = claim;
        out.push(
            Check::new(check, model, case, source)
                .why(format!("{why}: claim of {source}; {used}"))
                .covers(covers)
                .run(move |r, _| {
                    match run() {
                        Ok(m) => {
                            r.value = Some(m.error);
                            if let (Value::Object(case), Value::Object(detail)) =
                                (&mut r.case, m.detail)
                            {
                                case.extend(detail);
                            }
                            r.measured = Some(if m.relative {
                                Measured::Relative { error: m.error }
                            } else {
                                Measured::Absolute { error: m.error }
                            });
                            r.tolerance = Some(applied(tolerance));
                            let holds = m.error <= tolerance.value;
                            r.verdict = match (holds, erratum) {
                                (true, None) => Verdict::Pass,
                                (false, Some(id)) => Verdict::ExpectedFailure {
                                    reason: format!(
                                        "[{id}] the claim fails as ERRATA.md says: measured {:.3e} \
                                         against the claimed {:.3e} ({})",
                                        m.error, tolerance.value, tolerance.name
                                    ),
                                },
                                _ => Verdict::Fail,
                            };
                        }
                        Err(message) => r.verdict = Verdict::Error { message },
                    }
                    Ok(())
                }),
        );
    }
    out
}

/// The relative accuracy of Λ behind the G1 of the GTR claims: G1's absolute error is then
/// ≤ 1e-8 · Λ/(1 + Λ)² ≤ 2.5e-9, against measured differences of 3e-4 (spline mean, judged at
/// 1e-3) and a margin of 7e-3 (clamp: 0.293 judged at 0.3). The Λ oracle's default 1e-12 made
/// the spline claim the longest record of the quick audit (10 s) for digits no verdict reads.
const GTR_CLAIM_RELATIVE: f64 = 1e-8;

/// G1 of GTR by the harness oracle of Λ (`oracle::smith_lambda::lambda_oracle_to`: one quadrature of the
/// model's P2 to [`GTR_CLAIM_RELATIVE`]; the nested quadrature of `oracle::gtr`, which owes
/// nothing to the model, costs ~10⁵ evaluations per Λ, too many for the 600 points of the
/// spline grid).
fn gtr_g1(gamma: f64, alpha: f64, theta: f64) -> Estimate {
    let spec = json!({"family": "gtr", "gamma": gamma, "alpha": alpha});
    let Ok(m) = build(spec.clone()) else {
        return Estimate {
            value: f64::NAN,
            ..Estimate::default()
        };
    };
    let lam = lambda_oracle_to(
        &Subject::borrowed(m.as_ref()),
        from_spherical(theta, 0.0),
        GTR_CLAIM_RELATIVE,
    );
    g1_of(lam)
}

/// G1 = 1/(1 + Λ) with its error bound.
fn g1_of(lam: Estimate) -> Estimate {
    Estimate {
        value: 1.0 / (1.0 + lam.value),
        error_bound: lam.error_bound / (1.0 + lam.value).powi(2),
        evaluations: lam.evaluations,
    }
}

/// [`gtr_g1`] at several incidences of one GTR(γ, α), by `lambda_oracle_many` (P2, itself a
/// quadrature in the model, evaluated once per node for all of them): the same integrals as
/// [`gtr_g1`] to the same target, split at the other incidences' μ.
fn gtr_g1_many(gamma: f64, alpha: f64, thetas: &[f64]) -> Result<Vec<Estimate>, String> {
    let m = Gtr::new(gamma, alpha).map_err(|e| e.to_string())?;
    let subject = Subject::borrowed(&m);
    let slopes: &dyn mfh_reference::model::SlopeDistribution = &m;
    let mus: Vec<f64> = thetas
        .iter()
        .map(|t| {
            let w = from_spherical(*t, 0.0);
            w[2] / w[0].hypot(w[1])
        })
        .collect();
    let scale = subject.lobe().width().tan().max(1e-6);
    Ok(
        lambda_oracle_many(slopes, 0.0, &mus, scale, GTR_CLAIM_RELATIVE)
            .into_iter()
            .map(g1_of)
            .collect(),
    )
}

/// The plot domain of document 004 §5 with γ between the knots.
/// The μ of the spline grid (the innermost index of `spline_grid`).
const SPLINE_MUS: [f64; 6] = [0.1, 1.1, 2.1, 3.1, 4.1, 5.0];

fn spline_grid() -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    for i in 0..20 {
        let g = 0.1 + 0.2 * i as f64;
        for a in [0.1, 0.2, 0.3, 0.4, 0.5] {
            for mu in SPLINE_MUS {
                out.push((g, a, mu));
            }
        }
    }
    out
}

/// |G1_spline − G1| over the grid, G1 by the harness oracle: (max, mean), computed once for
/// both spline claims.
fn spline_errors() -> Result<(f64, f64), String> {
    static CACHE: std::sync::OnceLock<Result<(f64, f64), String>> = std::sync::OnceLock::new();
    if let Some(v) = CACHE.get() {
        return v.clone();
    }
    // Computed outside the cell's initialization: the computation is parallel, and a thread
    // waiting inside `get_or_init` for it could steal a job that calls this again (a
    // re-entrant initialization deadlocks). Two first callers at once compute it twice.
    let v = spline_errors_uncached();
    CACHE.get_or_init(|| v).clone()
}

fn spline_errors_uncached() -> Result<(f64, f64), String> {
    // The grid's (γ, α) pairs are independent: computed in parallel (the longest single record
    // of the quick audit when serial), each pair's six μ by one `gtr_g1_many`, collected in
    // grid order and summed in that order, so the result does not depend on the thread count.
    let grid = spline_grid();
    let errors: Vec<Result<Vec<f64>, String>> = grid
        .par_chunks(SPLINE_MUS.len())
        .map(|points| {
            let (g, a) = (points[0].0, points[0].1);
            let thetas: Vec<f64> = points.iter().map(|p| (1.0 / p.2).atan()).collect();
            let m = Gtr::new(g, a).map_err(|e| e.to_string())?;
            let oracle = gtr_g1_many(g, a, &thetas)?;
            thetas
                .iter()
                .zip(oracle)
                .map(|(theta, o)| {
                    let s = m
                        .g1_route(from_spherical(*theta, 0.0), "spline")
                        .map_err(|e| e.to_string())?;
                    Ok((s - o.value).abs())
                })
                .collect()
        })
        .collect();
    let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0.0);
    for e in errors {
        for e in e? {
            max = max.max(e);
            sum += e;
            n += 1.0;
        }
    }
    Ok((max, sum / n))
}

/// max over (α, μ) of |G1⁴ − G1¹⁰|, both by the harness oracle.
fn clamp_difference() -> Result<Measurement, String> {
    let mut max = 0.0f64;
    let thetas = [0.05f64, 0.1, 0.2, 0.5, 1.0, 1.5, 2.0].map(|mu| (1.0 / mu).atan());
    for a in [0.05, 0.2, 0.4, 0.57, 0.8, 0.95] {
        let (g4, g10) = (
            gtr_g1_many(4.0, a, &thetas)?,
            gtr_g1_many(10.0, a, &thetas)?,
        );
        for (x, y) in g4.iter().zip(&g10) {
            max = max.max((x.value - y.value).abs());
        }
    }
    Ok(Measurement::new(max, false))
}

/// max over γ ∈ {1, 2, 3, 4} of |G1^γ − G1⁰| at μ = 1, α = 1e-4.
fn convergence_to_g1_0() -> Result<Measurement, String> {
    let mut max = 0.0f64;
    for g in [1.0, 2.0, 3.0, 4.0] {
        let d = (gtr_g1(g, 1e-4, FRAC_PI_2 / 2.0).value - g1_gamma0(1.0)).abs();
        max = max.max(d);
    }
    Ok(Measurement::new(max, false))
}

/// The piecewise-linear model of the trapezoid claim (7 irregular breakpoints).
fn trapezoid_spec() -> Value {
    json!({
        "family": "piecewise_linear",
        "x": {"theta": [0.0, 0.1, 0.35, 0.6, 0.9, 1.3, FRAC_PI_2],
              "value": [3.0, 2.6, 1.5, 0.8, 0.3, 0.05, 0.0]},
    })
}

/// max relative error of G1 = 1/(1 + Λ) by the trapezoid route (document 000 eq 28) against the
/// harness oracle, θ_o ∈ {0.05, 0.3, 0.8, 1.2, 1.5}.
fn trapezoid_error() -> Result<Measurement, String> {
    let spec = trapezoid_spec();
    let m = build(spec.clone())?;
    let smith = m.as_smith().ok_or("no Smith")?;
    let mut max = 0.0f64;
    for theta in [0.05, 0.3, 0.8, 1.2, 1.5] {
        let w = from_spherical(theta, 0.0);
        let lam = smith
            .lambda_route(w, "domain_split")
            .map_err(|e| e.to_string())?;
        let o = lambda_oracle(&Subject::borrowed(m.as_ref()), w).value;
        let e = ((1.0 + o) / (1.0 + lam) - 1.0).abs();
        max = max.max(e);
    }
    Ok(Measurement::new(max, true))
}

/// ∫ q^{2k} P2(q) dq by harness quadrature of the model's P2.
fn moment(m: &dyn Model, k: i32, scale: f64) -> Result<f64, String> {
    let s = m.as_slopes().ok_or("no slopes")?;
    Ok(integrate_line(
        &|q| q.powi(2 * k) * s.p2(q, 0.0),
        0.0,
        scale,
        Accuracy::relative(1e-12),
    )
    .value)
}

/// Document 001 eq 9: the fixed-variance member has variance σ²/2 whatever γ (> 2); max relative
/// error over γ ∈ {3.5, 6, 20}, σ = α = 0.4, variance by quadrature.
fn fixed_variance() -> Result<Measurement, String> {
    let mut max = 0.0f64;
    for g in [3.5, 6.0, 20.0] {
        let m = build(json!({"family": "student_fixed_variance", "gamma": g, "alpha": 0.4}))?;
        let v = moment(m.as_ref(), 1, 0.4)?;
        max = max.max((v / (0.4 * 0.4 / 2.0) - 1.0).abs());
    }
    Ok(Measurement::new(max, true))
}

/// Document 001 eq 7: excess kurtosis 3/(C − 3) of D^G (STD γ = 8, α = 0.3), by quadrature.
fn excess_kurtosis() -> Result<Measurement, String> {
    let g = 8.0;
    let m = build(json!({"family": "std", "gamma": g, "alpha": 0.3}))?;
    let v = moment(m.as_ref(), 1, 0.3)?;
    let k4 = moment(m.as_ref(), 2, 0.3)?;
    let kurt = k4 / (v * v) - 3.0;
    Ok(Measurement::new(
        (kurt / (3.0 / (g - 3.0)) - 1.0).abs(),
        true,
    ))
}

/// Document 001 §1.1 / Table 1: "STD … includes GGX" (γ = 2) and Hyper-Cauchy includes GGX (γ = 2):
/// max relative difference of D over θ ∈ {0, 0.4, 0.9, 1.4}.
fn includes_ggx(family: &'static str) -> Result<Measurement, String> {
    let m = build(json!({"family": family, "gamma": 2.0, "alpha": 0.3}))?;
    let ggx = build(json!({"family": "ggx", "alpha": 0.3}))?;
    let mut max = 0.0f64;
    for t in [0.0, 0.4, 0.9, 1.4] {
        let w = from_spherical(t, 0.3);
        max = max.max((m.d(w) / ggx.d(w) - 1.0).abs());
    }
    Ok(Measurement::new(max, true))
}

/// Document 001 eq 41–42 as a pair: θ_m from eq 42 as printed, at φ ∈ {0, 0.7, 2} and ξ₂ on a
/// grid, must satisfy F(θ_m | φ) = ξ₂, F the conditional cdf of θ by harness quadrature of
/// D cos θ sin θ (in u = tan θ: (1 + A u²)^{−γ} u). Eq 41 alone tends to 1/(σxσy A′) ≠ 1 (it
/// keeps 2π p(φ)), but eq 42 divides ξ₂ by the same factor (formerly erratum 001-11,
/// withdrawn): the measured max |F − ξ₂| and the limit of eq 41 are recorded.
fn eq41_42_sampler() -> Result<Measurement, String> {
    let (g, sx, sy) = (3.0f64, 0.2f64, 0.5f64);
    let (mut max, mut limits) = (0.0f64, Vec::new());
    for phi in [0.0f64, 0.7, 2.0] {
        let a_phi = (phi.cos() / sx).powi(2) + (phi.sin() / sy).powi(2);
        let a = a_phi / (g - 1.0);
        let f = |u: f64| (1.0 + a * u * u).powf(-g) * u;
        let whole = integrate_upper(&f, 0.0, 1.0 / a.sqrt(), Accuracy::relative(1e-13)).value;
        for xi in [0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 0.98] {
            let theta = document001::eq42_theta_printed(g, sx, sy, phi, xi);
            let part = integrate(&f, 0.0, theta.tan(), Accuracy::relative(1e-13)).value;
            max = max.max((part / whole - xi).abs());
        }
        limits.push(document001::eq41_theta_cdf_printed(
            g,
            sx,
            sy,
            phi,
            FRAC_PI_2 - 1e-9,
        ));
    }
    Ok(Measurement {
        error: max,
        relative: false,
        detail: json!({"eq41_at_horizon": limits}),
    })
}

/// Document 003 §3.2.1: max relative error of the ASG integral with F against harness quadrature
/// of the ASG over the hemisphere, bandwidths λ ≥ μ ≥ 1.
fn asg_integral_error() -> Result<Measurement, String> {
    let mut worst = (0.0f64, [0.0f64; 2]);
    for (l, m) in [
        (1.0, 1.0),
        (2.0, 1.0),
        (5.0, 1.0),
        (20.0, 1.0),
        (5.0, 2.0),
        (10.0, 5.0),
    ] {
        let a = Asg::new(
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [l, m],
            1.0,
        )
        .map_err(|e| e.to_string())?;
        let width = 1.0 / f64::sqrt(l);
        let o = integrate_hemisphere(&|v| a.eval(v), width, None, Accuracy::relative(1e-10));
        let e = (a.integral().map_err(|e| e.to_string())? / o.value - 1.0).abs();
        if e > worst.0 {
            worst = (e, [l, m]);
        }
    }
    Ok(Measurement {
        error: worst.0,
        relative: true,
        detail: json!({"worst_bandwidths": worst.1}),
    })
}

/// Document 003 §4.3: max over σ ≤ 1 and means in [−1.4, 1.4] of the relative error of ∫g (the erf
/// form) for ∫g^c over [−π/2, π/2], in units of σ²/16; ∫g^c by harness quadrature.
fn circular_erf_error() -> Result<Measurement, String> {
    let mut worst = (0.0f64, [0.0f64; 2]);
    for sigma in [0.1, 0.3, 0.5, 1.0] {
        for mean in [-1.4, 0.0, 0.3, 1.4] {
            let g = CircularGaussian::new(mean, sigma).map_err(|e| e.to_string())?;
            let o = integrate_pieces(
                &|x| g.eval(x),
                &[-FRAC_PI_2, mean, FRAC_PI_2],
                Accuracy::relative(1e-13),
            );
            let e = (g.integral_interval(-FRAC_PI_2, FRAC_PI_2) / o.value - 1.0).abs()
                / (sigma * sigma / 16.0);
            if e > worst.0 {
                worst = (e, [sigma, mean]);
            }
        }
    }
    Ok(Measurement {
        error: worst.0,
        relative: true,
        detail: json!({"worst_sigma_mean": worst.1, "unit": "σ²/16"}),
    })
}

fn claims() -> Vec<Claim> {
    let gtr = |g: f64, a: f64| json!({"family": "gtr", "gamma": g, "alpha": a});
    vec![
        Claim {
            check: "claims.gtr_spline_mean",
            concern: Concern::new(&["gtr"], &[Effect::Masking]),
            source: "seed 004 §5 (\"the mean difference was 0.001\")",
            covers: vec![covers("gtr", "g1", "spline")],
            model: gtr(0.5, 0.1),
            case: json!({"quantity": "mean |G1_spline − G1|", "gamma": "0.1, 0.3, …, 3.9",
                         "alpha": [0.1, 0.2, 0.3, 0.4, 0.5], "mu": [0.1, 1.1, 2.1, 3.1, 4.1, 5.0]}),
            tolerance: &GTR_SPLINE,
            erratum: None,
            run: || {
                spline_errors().map(|(max, mean)| Measurement {
                    error: mean,
                    relative: false,
                    // The document bounds the mean only ("the mean difference was 0.001"); the
                    // max is reported, not judged (formerly erratum 004-E3, withdrawn).
                    detail: json!({"max_abs_error": max}),
                })
            },
        },
        Claim {
            check: "claims.gtr_clamp",
            concern: Concern::new(&["gtr"], &[Effect::Masking]),
            source: "seed 004 §6 (|G1⁴ − G1¹⁰| \"up to 0.3\")",
            covers: vec![covers("gtr", "g1", "exact")],
            model: gtr(4.0, 0.5),
            case: json!({"quantity": "max |G1⁴ − G1¹⁰|", "alpha": [0.05, 0.2, 0.4, 0.57, 0.8, 0.95],
                         "mu": [0.05, 0.1, 0.2, 0.5, 1.0, 1.5, 2.0]}),
            tolerance: &GTR_CLAMP,
            erratum: None,
            run: clamp_difference,
        },
        Claim {
            check: "claims.gtr_convergence",
            concern: Concern::new(&["gtr"], &[Effect::Masking]),
            source: "seed 004 §4 (\"All height fields converge to G1⁰ when μ → 1 and α → 0\")",
            covers: vec![covers("gtr", "g1", "exact")],
            model: gtr(2.0, 1e-4),
            case: json!({"quantity": "max_γ |G1^γ − G1⁰|", "gamma": [1, 2, 3, 4], "alpha": 1e-4, "mu": 1.0}),
            tolerance: &GTR_LIMIT,
            erratum: Some("004-E2"),
            run: convergence_to_g1_0,
        },
        Claim {
            check: "claims.piecewise_trapezoid",
            concern: Concern::new(&["piecewise_linear"], &[Effect::Masking]),
            source: "seed 000 eq 28 (trapezoid rule for the remaining Λ integral; no bound stated)",
            covers: vec![covers("piecewise_linear", "lambda", "domain_split")],
            model: trapezoid_spec(),
            case: json!({"quantity": "max relative error of G1", "theta": [0.05, 0.3, 0.8, 1.2, 1.5]}),
            tolerance: &PIECEWISE_TRAPEZOID,
            erratum: None,
            run: trapezoid_error,
        },
        Claim {
            check: "claims.student_fixed_variance",
            concern: Concern::new(&["student_fixed_variance"], &[]),
            source: "seed 001 eq 9 (\"The variance of this distribution is σ²/2 for γ > 2\")",
            covers: vec![covers("student_fixed_variance", "p2", "default")],
            model: json!({"family": "student_fixed_variance", "gamma": [3.5, 6.0, 20.0], "alpha": 0.4}),
            case: json!({"quantity": "∫q²P2 dq / (σ²/2) − 1"}),
            tolerance: &SLOPE_MOMENT_CLAIM,
            erratum: None,
            run: fixed_variance,
        },
        Claim {
            check: "claims.student_excess_kurtosis",
            concern: Concern::new(&["std", "student_general"], &[]),
            source: "seed 001 eq 7 (excess kurtosis 3/(C − 3))",
            covers: vec![covers("std", "p2", "default")],
            model: json!({"family": "std", "gamma": 8.0, "alpha": 0.3}),
            case: json!({"quantity": "kurtosis / (3/(C−3)) − 1"}),
            tolerance: &SLOPE_MOMENT_CLAIM,
            erratum: None,
            run: excess_kurtosis,
        },
        Claim {
            check: "claims.std_includes_ggx",
            concern: Concern::new(&["std"], &[]),
            source: "seed 001 §1.1 (\"It includes GGX\", γ = 2)",
            covers: vec![covers("std", "d", "default"), covers("ggx", "d", "default")],
            model: json!({"family": "std", "gamma": 2.0, "alpha": 0.3}),
            case: json!({"theta": [0.0, 0.4, 0.9, 1.4], "phi": 0.3}),
            tolerance: &IDENTITY,
            erratum: None,
            run: || includes_ggx("std"),
        },
        Claim {
            check: "claims.hyper_cauchy_includes_ggx",
            concern: Concern::new(&["hyper_cauchy"], &[]),
            source:
                "seed 001 eq 8 (\"The GGX distribution is included by Hyper-Cauchy (when γ = 2)\")",
            covers: vec![covers("hyper_cauchy", "d", "default")],
            model: json!({"family": "hyper_cauchy", "gamma": 2.0, "alpha": 0.3}),
            case: json!({"theta": [0.0, 0.4, 0.9, 1.4], "phi": 0.3}),
            tolerance: &IDENTITY,
            erratum: None,
            run: || includes_ggx("hyper_cauchy"),
        },
        Claim {
            check: "claims.std_eq41_42_sampler",
            concern: Concern::new(STUDENT, &[Effect::SampleNormals, Effect::PseudoVnis]),
            source: "seed 001 eq 41–42 (θ_m given φ_m: the cdf and its inversion)",
            covers: vec![covers("std", "sample_wm", "default")],
            model: json!({"family": "std", "gamma": 3.0, "alpha_x": 0.2, "alpha_y": 0.5}),
            case: json!({"quantity": "max |F(θ(ξ₂) | φ) − ξ₂|", "phi": [0.0, 0.7, 2.0],
                         "xi2": [0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 0.98]}),
            tolerance: &CLOSED_FORM,
            erratum: None,
            run: eq41_42_sampler,
        },
        Claim {
            check: "claims.asg_integral",
            concern: Concern::new(&[], &[Effect::AnisotropicSphericalGaussians]),
            source: "seed 003 §3.2.1 (ASG integral \"can be approximated as follows\")",
            covers: vec![covers("asg", "asg_integral", "default")],
            model: Value::Null,
            case: json!({"quantity": "max relative error of the F form",
                         "bandwidths": [[1, 1], [2, 1], [5, 1], [20, 1], [5, 2], [10, 5]]}),
            tolerance: &ASG_INTEGRAL_APPROXIMATION,
            erratum: None,
            run: asg_integral_error,
        },
        Claim {
            check: "claims.circular_interval_erf",
            concern: Concern::new(&[], &[Effect::SphericalGaussians]),
            source: "seed 003 §4.3 (∫g^c over [−π/2, π/2] \"approximated\" by the erf form)",
            covers: vec![covers("circular", "integral_interval", "default")],
            model: Value::Null,
            case: json!({"quantity": "max relative error / (σ²/16)", "sigma": [0.1, 0.3, 0.5, 1.0],
                         "mean": [-1.4, 0.0, 0.3, 1.4]}),
            tolerance: &CIRCULAR_ERF_LEADING_ORDER,
            erratum: None,
            run: circular_erf_error,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn claims_reach_the_verdicts_errata_md_records() {
        let plan = plan(&Scope::everything(), "test");
        let ctx = super::super::RunContext { seed: 1 };
        for p in &plan {
            let r = (p.run)(&ctx);
            println!("{} {:?} {:?}", r.check, r.value, r.verdict);
            assert!(
                !r.verdict.is_failure(),
                "{}: {:?} {:?}",
                r.check,
                r.value,
                r.verdict
            );
        }
    }
}
