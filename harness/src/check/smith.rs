//! Smith masking: every Λ route against the oracle (`oracle::smith_lambda`: ∫(q − μ)P2 dq for
//! slope-space models, ∫⟨−w·m⟩⁺D(m)dm otherwise), the weak white furnace ∫G1(w,m)⟨w·m⟩⁺D(m)dm = cos θ, and the
//! identities Λ(−w) = −1 − Λ(w), 0 ≤ G1 ≤ 1, G2 ≤ min G1.

use super::{apply_expected, compare_at, compare_exact, covers, PlannedCheck, Profile};
use crate::check::{need, Check};
use crate::oracle::quadrature::{integrate_hemisphere_polar_batch, Accuracy, Cuts};
use crate::oracle::smith_lambda::{lambda_oracle, lambda_oracle_noise_floor};
use crate::oracle::Estimate;
use crate::precision::Precision;
use crate::record::Verdict;
use crate::subject::Subject;
use crate::tolerance::{Tolerance, CLOSED_FORM, IDENTITY, NUMERICAL_ROUTE};
use mfh_reference::geometry::{dot, from_spherical};
use mfh_reference::trig::{sin_cos, sin_cos_block};
use mfh_reference::{Masking, QueryError, Smith, Vec3};
use serde_json::json;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::{Arc, OnceLock};

const SOURCE_LAMBDA: &str =
    "seed 001 eq 5 (Λ = (1/μ)∫_μ^∞ (q − μ) P2(q) dq), eq 16–21; seed 004 §2; seed 000 eq 10–13";

/// w·m for m = (θ_m, φ_m), as R sin(θ_t − θ_m) with R = |(sin θ cos Δφ, cos θ)| and θ_t the
/// polar angle of the terminator at that azimuth (> π/2 when w sees the whole meridian): the
/// Cartesian dot product cancels near the terminator (relative noise 1e-16/|w·m|, which kept
/// the adaptive inner integrals bisecting for ever at normal incidence); this form does not.
fn projection(w: Vec3) -> impl Fn(f64) -> (f64, f64) {
    let (st, ct) = ((w[0] * w[0] + w[1] * w[1]).sqrt(), w[2]);
    let phi_w = w[1].atan2(w[0]);
    move |phi_m: f64| {
        let a = st * (phi_m - phi_w).cos();
        (a.hypot(ct), PI - ct.atan2(a))
    }
}

/// `from_spherical(θ, φ)` with φ's (sin, cos) given (hoisted out of a run of nodes at one
/// azimuth): the same operations, so the same direction bit for bit.
fn spherical(theta: f64, (st, ct): (f64, f64), (sp, cp): (f64, f64)) -> Vec3 {
    let ct = if (theta - FRAC_PI_2).abs() < 1e-15 {
        0.0
    } else {
        ct
    };
    [st * cp, st * sp, ct]
}

/// The mean slope along azimuth φ: mean · (cos φ, sin φ) (non-zero for Gaussian slopes with
/// a mean, document 002).
fn mean_slope(subject: &Subject, phi: f64) -> f64 {
    let mean = subject.mean_slope();
    mean[0] * phi.cos() + mean[1] * phi.sin()
}

/// The polar cuts for azimuth φ_m: the terminator of w on the hemisphere of normals (the polar
/// angle where w·m = 0, none when it lies below the horizon) and the model's own kinks
/// (`theta_kinks`).
fn terminator(w: Vec3, kinks: Vec<f64>) -> impl Fn(f64) -> Vec<f64> {
    let p = projection(w);
    move |phi: f64| {
        let mut cuts = kinks.clone();
        let (_, theta_t) = p(phi);
        if theta_t < FRAC_PI_2 {
            cuts.push(theta_t);
        }
        cuts
    }
}

/// The azimuths where the polar cuts of `terminator` have kinks: φ_w ± π/2 and φ_w + π, and
/// where the terminator crosses one of the model's polar kinks (there the inner integral's
/// pieces change, and the outer integrand has a kink), in [0, 2π).
fn terminator_azimuths(w: Vec3, kinks: &[f64]) -> Vec<f64> {
    let (st, ct) = ((w[0] * w[0] + w[1] * w[1]).sqrt(), w[2]);
    let phi_w = w[1].atan2(w[0]);
    let mut offsets = vec![0.5 * PI, PI, 1.5 * PI];
    if st > 0.0 {
        for k in kinks {
            // tan θ_t = cot θ / (−cos Δφ) = tan k.
            let c = -ct / (st * k.tan());
            if c.abs() < 1.0 {
                let d = c.acos();
                offsets.extend([d, TAU - d]);
            }
        }
    }
    offsets
        .iter()
        .map(|d| (phi_w + d).rem_euclid(TAU))
        .collect()
}

/// An oracle computed once and shared by the checks of one direction.
type SharedOracle = Arc<OnceLock<Estimate>>;

/// Directions (θ, φ) at which direction-dependent checks run: the profile's θ grid, along x
/// and, for anisotropic models, along a second azimuth.
pub fn directions(anisotropic: bool, profile: Profile, theta_max: f64) -> Vec<(f64, f64)> {
    let phis: &[f64] = if anisotropic { &[0.0, 2.2] } else { &[0.0] };
    let mut out = Vec::new();
    for t in profile.thetas(theta_max) {
        for p in phis {
            out.push((t, *p));
        }
    }
    out
}

/// Plans the Smith checks of one model: Λ by every route against the oracle
/// ([`plan_lambda_routes`]), the weak white furnace ([`plan_white_furnace`]), G1 and both G2
/// forms ([`plan_g1_g2`]) and the identities ([`plan_identities`]).
pub fn plan<'a>(
    subject: &Arc<Subject<'a>>,
    profile: Profile,
    theta_max: f64,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    if subject.model.as_smith().is_none() {
        return Vec::new();
    }
    let mut out = plan_lambda_routes(subject, profile, theta_max, why);
    out.extend(plan_white_furnace(subject, theta_max, why));
    out.extend(plan_g1_g2(subject, theta_max, why));
    out.push(plan_identities(subject, why));
    out
}

/// `smith.lambda_route`: Λ by each route at the profile's directions against the oracle. A
/// user's model is audited through the method a renderer calls; the other routes of a
/// reference model are the reference's own business (each against the same oracle), planned
/// only where they apply: the planner asks the route ([`route_answer`]), a refusal is not
/// planned (`route_domain` states where a route does not apply), and an answer is the value
/// the check judges.
pub fn plan_lambda_routes<'a>(
    subject: &Arc<Subject<'a>>,
    profile: Profile,
    theta_max: f64,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let Some(smith) = subject.model.as_smith() else {
        return Vec::new();
    };
    let family = subject.family();
    // One oracle per direction, shared by every route checked there (computed by whichever
    // route check runs first; the others wait for it).
    let oracles: Vec<((f64, f64), SharedOracle)> =
        directions(subject.anisotropic(), profile, theta_max)
            .into_iter()
            .map(|d| (d, Arc::new(OnceLock::new())))
            .collect();
    let mut out = Vec::new();
    for route in lambda_routes(subject) {
        for ((theta, phi), memo) in oracles.iter().cloned() {
            let Ok(answer) = route_answer(smith, route, theta, phi) else {
                continue;
            };
            let case = json!({"route": route, "theta": theta, "phi": phi});
            let m = subject.clone();
            out.push(
                Check::new(
                    "smith.lambda_route",
                    subject.label.clone(),
                    case,
                    SOURCE_LAMBDA,
                )
                .why(format!("{why}: Λ by route `{route}`"))
                .covers(vec![covers(family, "lambda", route)])
                .run(move |r, _| {
                    let w = from_spherical(theta, phi);
                    let smith = need(m.model.as_smith(), "Smith masking")?;
                    // The default route is the method a renderer calls (and G1, G2 use).
                    let value = answer.unwrap_or_else(|| smith.lambda(w));
                    let oracle = *memo.get_or_init(|| lambda_oracle(m.as_ref(), w));
                    let tol = if m.lambda_numerical() && matches!(route, "default" | "exact") {
                        NUMERICAL_ROUTE
                    } else {
                        CLOSED_FORM
                    };
                    if m.precision == Precision::F64 {
                        compare_at(
                            r,
                            value,
                            oracle,
                            &tol,
                            lambda_oracle_noise_floor(m.precision),
                        );
                    } else {
                        // Λ enters every use as 1 + Λ (G1 = 1/(1 + Λ), G2 = 1/(1 + Λo + Λi)):
                        // a float32 Λ is judged there, where its rounding is ~ε(1 + Λ) (Λ
                        // itself near normal incidence, ~1e-8, is only ε absolute: the
                        // cancellation of √(1 + α²tan²θ) − 1 every float32 renderer has).
                        let shift = |e: Estimate| Estimate {
                            value: 1.0 + e.value,
                            ..e
                        };
                        compare_at(
                            r,
                            1.0 + value,
                            shift(oracle),
                            &tol.at(m.precision),
                            lambda_oracle_noise_floor(m.precision),
                        );
                        r.case["judged"] = json!("1 + Λ");
                    }
                    apply_expected(r, family, route);
                    Ok(())
                }),
            );
        }
    }
    out
}

/// The Λ routes audited for a subject: every route of a reference model, the default (the
/// method a renderer calls) of a user's model.
pub fn lambda_routes(subject: &Subject) -> Vec<&'static str> {
    match subject.model.as_smith() {
        Some(smith) if subject.reference.is_some() => smith.lambda_routes(),
        Some(_) => vec!["default"],
        None => Vec::new(),
    }
}

/// Whether `route` applies at (θ, φ), asked of the route itself: its answer Λ, `None` for the
/// default route (not asked: it applies everywhere, and the check evaluates it), or the error
/// with which the route refuses.
pub fn route_answer(
    smith: &dyn Smith,
    route: &str,
    theta: f64,
    phi: f64,
) -> Result<Option<f64>, QueryError> {
    if route == "default" {
        return Ok(None);
    }
    smith
        .lambda_route(from_spherical(theta, phi), route)
        .map(Some)
}

/// The tolerance of a quantity computed from the default Λ: the numerical route's where that Λ
/// is itself a numerical integral (registry), the closed form's otherwise, at the subject's
/// precision.
fn default_tolerance(subject: &Subject) -> Tolerance {
    if subject.lambda_numerical() {
        NUMERICAL_ROUTE
    } else {
        CLOSED_FORM
    }
    .at(subject.precision)
}

/// `smith.white_furnace`: the weak white furnace ∫G1(w,m)⟨w·m⟩⁺D(m)dm = cos θ at two
/// incidences.
pub fn plan_white_furnace<'a>(
    subject: &Arc<Subject<'a>>,
    theta_max: f64,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let family = subject.family();
    let mut out = Vec::new();
    for theta in [0.6, 1.3].into_iter().filter(|t| *t <= theta_max) {
        let case = json!({"theta": theta, "phi": 0.4});
        let m = subject.clone();
        out.push(
            Check::new(
                "smith.white_furnace",
                subject.label.clone(),
                case,
                "seed 001 eq 16 with the projected-area constraint ∫G1⟨w·m⟩⁺D dm = cos θ \
                         (Heitz 2014, eq 17)",
            )
            .why(format!("{why}: G1 must conserve the projected area"))
            .covers(vec![covers(family, "g1", "default")])
            .run(move |r, _| {
                let w = from_spherical(theta, 0.4);
                let smith = need(m.model.as_smith(), "Smith masking")?;
                // G1(w, m) = χ⁺(w·m) G1(w, n) (eq 16): its m-dependence is the indicator,
                // which `smith.identities` checks; evaluating G1 (a quadrature for GTR and
                // the piecewise-linear NDF) once keeps it out of the integrand.
                let g1 = smith.g1(w, [0.0, 0.0, 1.0]);
                let e = projected_area(&m, w, g1);
                // With a mean slope q̄ along w's azimuth (Gaussian slopes, document 002), the
                // microsurface is tilted, ∫ m D dm ≠ n, and the constraint becomes
                // G1 (∫⟨w·m⟩⁺D dm + sin θ q̄) = cos θ: in slope space ∫⟨w·m⟩⁺D dm =
                // sin θ ∫_{−∞}^{μ}(μ − q)P2 dq = cos θ (1 + Λ) − sin θ q̄ (μ = cot θ).
                let q_bar = mean_slope(&m, 0.4);
                // The closed form enters through G1; the integral is the value under test and
                // its quadrature error bound is the slack `compare` grants.
                compare_at(
                    r,
                    e.value + g1 * theta.sin() * q_bar,
                    Estimate { value: w[2], ..e },
                    &default_tolerance(&m),
                    projected_area_accuracy(&m).noise_floor(),
                );
                Ok(())
            }),
        );
    }
    out
}

/// g1 · ∫⟨w·m⟩⁺ D(m) dm over the hemisphere of normals, in polar coordinates cut at the
/// terminator of w and the model's polar kinks, D in batches (one round trip per step for an
/// external model).
fn projected_area(m: &Subject, w: Vec3, g1: f64) -> Estimate {
    let kinks = m.theta_kinks();
    let phis = terminator_azimuths(w, &kinks);
    let theta_cut = terminator(w, kinks);
    let p = projection(w);
    integrate_hemisphere_polar_batch(
        &|tp: &[[f64; 2]], out: &mut [f64]| {
            // D only where the normal faces w (as the scalar form did). The nodes
            // of one inner integral share φ_m and come together: the projection at
            // φ_m is computed once per run of equal φ_m (the same values).
            // The sines and cosines of the kept nodes' θ_m and θ_t − θ_m a block at
            // a time (vectorized).
            let (mut at, mut angles) = (Vec::new(), Vec::new());
            let mut memo = (f64::NAN, (0.0, 0.0), (0.0, 0.0));
            let mut at_phi = |phi_m: f64| {
                if phi_m.to_bits() != memo.0.to_bits() {
                    memo = (phi_m, p(phi_m), sin_cos(phi_m));
                }
                (memo.1, memo.2)
            };
            for (i, &[theta_m, phi_m]) in tp.iter().enumerate() {
                out[i] = 0.0;
                let ((_, theta_t), _) = at_phi(phi_m);
                if theta_m < theta_t {
                    at.push(i);
                    angles.push(theta_m);
                }
            }
            let n = at.len();
            for &i in &at {
                let [theta_m, phi_m] = tp[i];
                angles.push(at_phi(phi_m).0 .1 - theta_m);
            }
            let (mut sines, mut cosines) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
            sin_cos_block(&angles, &mut sines, &mut cosines);
            let dirs: Vec<Vec3> = at
                .iter()
                .enumerate()
                .map(|(j, &i)| {
                    let [theta_m, phi_m] = tp[i];
                    spherical(theta_m, (sines[j], cosines[j]), at_phi(phi_m).1)
                })
                .collect();
            let mut d = vec![0.0; n];
            m.model.d_batch(&dirs, &mut d);
            for (j, (d, &i)) in d.into_iter().zip(&at).enumerate() {
                let ((rr, _), _) = at_phi(tp[i][1]);
                out[i] = g1 * rr * sines[n + j] * d;
            }
        },
        m.lobe().width(),
        Some(Cuts {
            theta: &theta_cut,
            phi: &phis,
        }),
        projected_area_accuracy(m),
    )
}

/// The accuracy of [`projected_area`]'s quadrature.
fn projected_area_accuracy(m: &Subject) -> Accuracy {
    Accuracy::relative(1e-11).at(m.precision)
}

/// `smith.g1_g2`: G1 and both G2 forms through the methods a renderer calls, against
/// G1 = 1/(1 + Λ) and G2 = G1·G1 (eq 22) or 1/(1 + Λo + Λi) (eq 23) from the oracle's Λ.
pub fn plan_g1_g2<'a>(
    subject: &Arc<Subject<'a>>,
    theta_max: f64,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let family = subject.family();
    let pairs = [
        ((0.5, 0.0), (1.2, 2.0)),
        ((1e-3, 0.0), (super::NEAR_GRAZING, 1.0)),
        ((1.5, 0.3), (1.5, 3.0)),
    ];
    let mut out = Vec::new();
    for ((to, po), (ti, pi)) in pairs {
        if to > theta_max || ti > theta_max {
            continue;
        }
        // Λ's oracles at w_o and w_i, shared by the three quantities of the pair (computed by
        // whichever check runs first, as the route checks' oracles).
        let (memo_o, memo_i): (SharedOracle, SharedOracle) =
            (Arc::new(OnceLock::new()), Arc::new(OnceLock::new()));
        for quantity in ["g1", "g2_uncorrelated", "g2_height_correlated"] {
            let (memo_o, memo_i) = (memo_o.clone(), memo_i.clone());
            let case = json!({"quantity": quantity, "theta_o": to, "phi_o": po, "theta_i": ti, "phi_i": pi});
            let m = subject.clone();
            let covered = vec![match quantity {
                "g1" => covers(family, "g1", "default"),
                "g2_uncorrelated" => covers(family, "g2", "uncorrelated"),
                _ => covers(family, "g2", "height_correlated"),
            }];
            out.push(
                Check::new(
                    "smith.g1_g2",
                    subject.label.clone(),
                    case,
                    "seed 001 eq 16 (G1 = 1/(1 + Λ)), eq 22 (uncorrelated G2), eq 23 \
                             (height-correlated G2)",
                )
                .why(format!("{why}: {quantity} against the oracle's Λ"))
                .covers(covered)
                .run(move |r, _| {
                    let smith = need(m.model.as_smith(), "Smith masking")?;
                    let (wo, wi) = (from_spherical(to, po), from_spherical(ti, pi));
                    let n = [0.0, 0.0, 1.0];
                    let lo = *memo_o.get_or_init(|| lambda_oracle(m.as_ref(), wo));
                    let li = *memo_i.get_or_init(|| lambda_oracle(m.as_ref(), wi));
                    let (go, gi) = (1.0 / (1.0 + lo.value), 1.0 / (1.0 + li.value));
                    let (value, want, bound) = match quantity {
                        "g1" => (smith.g1(wo, n), go, lo.error_bound * go * go),
                        "g2_uncorrelated" => (
                            smith.g2(wo, wi, n, Masking::Uncorrelated),
                            go * gi,
                            // δ(go·gi)/(go·gi) = δΛo·go + δΛi·gi (each G1 = 1/(1 + Λ)).
                            (lo.error_bound * go + li.error_bound * gi) * go * gi,
                        ),
                        _ => {
                            let g = 1.0 / (1.0 + lo.value + li.value);
                            (
                                smith.g2(wo, wi, n, Masking::HeightCorrelated),
                                g,
                                (lo.error_bound + li.error_bound) * g * g,
                            )
                        }
                    };
                    compare_at(
                        r,
                        value,
                        Estimate {
                            value: want,
                            error_bound: bound,
                            evaluations: lo.evaluations + li.evaluations,
                        },
                        &default_tolerance(&m),
                        lambda_oracle_noise_floor(m.precision),
                    );
                    Ok(())
                }),
            );
        }
    }
    out
}

/// `smith.identities`: Λ(−w) = −1 − Λ(w), 0 ≤ G1 ≤ 1, G2 ≤ min G1, Λ(n) = 0, G1(π/2) = 0 and
/// eq 16's indicator over a grid of directions, as one record of the worst violation.
pub fn plan_identities<'a>(subject: &Arc<Subject<'a>>, why: &str) -> PlannedCheck<'a> {
    let family = subject.family();
    let m = subject.clone();
    let covered = vec![
        covers(family, "g1", "default"),
        covers(family, "g2", "uncorrelated"),
        covers(family, "g2", "height_correlated"),
    ];
    Check::new(
        "smith.identities",
        subject.label.clone(),
        json!({"grid": "θ ∈ {0, …, π/2} × φ ∈ {0, 1, 2.5, 4}"}),
        "Heitz 2014 §5.2 (Λ(−w) = −1 − Λ(w)); seed 001 eq 16, 22, 23",
    )
    .why(format!(
        "{why}: Λ(−w) = −1 − Λ(w), 0 ≤ G1 ≤ 1, G2 ≤ min G1, Λ(n) = 0, G1(π/2) = 0"
    ))
    .covers(covered)
    .run(move |r, _| {
        let smith = need(m.model.as_smith(), "Smith masking")?;
        let (worst, what) = worst_identity_violation(smith);
        // Against 0: the measured error is the worst violation, absolute.
        compare_exact(r, worst, 0.0, &IDENTITY.at(m.precision));
        if r.verdict == Verdict::Fail {
            r.case = json!({"worst": what});
        }
        Ok(())
    })
}

/// The largest violation of the identities of [`plan_identities`] over its grid (infinite for
/// a NaN), and which one it is.
fn worst_identity_violation(smith: &dyn Smith) -> (f64, String) {
    let mut worst = 0.0f64;
    let mut what = String::new();
    let mut note = |v: f64, label: String| {
        if !(v <= worst) {
            worst = if v.is_nan() { f64::INFINITY } else { v };
            what = label;
        }
    };
    let thetas = [0.0, 1e-6, 0.3, 0.8, 1.2, 1.5, FRAC_PI_2 - 1e-6];
    let phis = [0.0, 1.0, 2.5, 4.0];
    let n = [0.0, 0.0, 1.0];
    let l0 = smith.lambda(n);
    note(l0.abs(), format!("Λ(n) = {l0}"));
    let g_grazing = smith.g1(from_spherical(FRAC_PI_2, 0.3), n);
    note(g_grazing.abs(), format!("G1(π/2) = {g_grazing}"));
    for &t in &thetas {
        for &p in &phis {
            let w = from_spherical(t, p);
            let l = smith.lambda(w);
            let lm = smith.lambda([-w[0], -w[1], -w[2]]);
            let d = (lm + 1.0 + l).abs() / (1.0 + l);
            note(d, format!("Λ(−w) + 1 + Λ(w) at θ = {t}, φ = {p}"));
            note(-l, format!("Λ < 0 at θ = {t}, φ = {p}"));
            let g = smith.g1(w, n);
            note((g - 1.0).max(0.0).max(-g), format!("G1 = {g} at θ = {t}"));
            // eq 16: G1(w, m) is G1(w, n) on the facets w sees, 0 on the others.
            for m_t in [0.4, 1.3] {
                let mm = from_spherical(m_t, p + 2.8);
                let want = if dot(w, mm) > 0.0 { g } else { 0.0 };
                let got = smith.g1(w, mm);
                note(
                    (got - want).abs(),
                    format!("G1(w, m) = {got}, want {want} at θ = {t}, θ_m = {m_t}"),
                );
            }
            for &t2 in &thetas[..4] {
                let wi = from_spherical(t2, p + 1.0);
                let gi = smith.g1(wi, n);
                for masking in [Masking::Uncorrelated, Masking::HeightCorrelated] {
                    let g2 = smith.g2(w, wi, n, masking);
                    note(
                        (g2 - g.min(gi)).max(0.0).max(-g2),
                        format!("G2 {masking:?} = {g2} > min G1 = {}", g.min(gi)),
                    );
                }
            }
        }
    }
    (worst, what)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::RunContext;
    use mfh_reference::ModelSpec;

    /// A reference route is planned exactly where it answers, every planned case judged (none
    /// skipped); the default route of a user's model is always planned.
    #[test]
    fn reference_routes_are_planned_only_where_they_apply() {
        let spec: ModelSpec =
            serde_json::from_value(json!({"family": "std", "gamma": 3.0, "alpha": 0.2})).unwrap();
        let subject = Subject::reference(&spec).unwrap();
        let smith = subject.model.as_smith().unwrap();
        let planned = plan_lambda_routes(&subject, Profile::Quick, FRAC_PI_2, "t");
        let mut applies = 0;
        let mut refuses = 0;
        for route in lambda_routes(&subject) {
            for (theta, phi) in directions(false, Profile::Quick, FRAC_PI_2) {
                let answers = route_answer(smith, route, theta, phi).is_ok();
                let is_planned = planned
                    .iter()
                    .any(|p| p.case == json!({"route": route, "theta": theta, "phi": phi}));
                assert_eq!(answers, is_planned, "{route} {theta}");
                applies += usize::from(answers);
                refuses += usize::from(!answers);
            }
        }
        assert_eq!(planned.len(), applies);
        assert!(refuses > 0, "the half-integer routes refuse at γ = 3");
        let ctx = RunContext { seed: 1 };
        for p in &planned {
            let r = (p.run)(&ctx);
            assert!(
                matches!(r.verdict, Verdict::Pass | Verdict::ExpectedFailure { .. }),
                "{r:?}"
            );
        }
        let user = Subject::user(subject.model.clone(), "user", Default::default());
        let planned = plan_lambda_routes(&user, Profile::Quick, FRAC_PI_2, "t");
        assert_eq!(
            planned.len(),
            directions(true, Profile::Quick, FRAC_PI_2).len()
        );
        assert!(planned.iter().all(|p| p.case["route"] == "default"));
    }

    /// The hoisted form of the white furnace's directions is `from_spherical` bit for bit
    /// when given the sines and cosines `from_spherical` computes, the horizon snap included.
    #[test]
    fn hoisted_spherical_is_from_spherical() {
        for theta in [0.0, 1e-9, 0.3, 1.0, FRAC_PI_2 - 1e-16, FRAC_PI_2, 1.7] {
            for phi in [0.0f64, 0.4, 2.0, 3.9, 6.2] {
                let got = spherical(theta, theta.sin_cos(), phi.sin_cos());
                let want = from_spherical(theta, phi);
                assert_eq!(
                    got.map(f64::to_bits),
                    want.map(f64::to_bits),
                    "{theta} {phi}"
                );
            }
        }
    }
}
