//! Smith masking: every Λ route against the oracle (∫(q − μ)P2 dq for slope-space models,
//! ∫⟨−w·m⟩⁺D(m)dm otherwise), the weak white furnace ∫G1(w,m)⟨w·m⟩⁺D(m)dm = cos θ, and the
//! identities Λ(−w) = −1 − Λ(w), 0 ≤ G1 ≤ 1, G2 ≤ min G1.

use super::{apply_expected, compare, compare_exact, covers, PlannedCheck, Profile};
use crate::check::{need, Check};
use crate::oracle::quadrature::{
    integrate_hemisphere_polar_batch, integrate_pieces_batch, integrate_pieces_many,
    integrate_upper, Accuracy, Cuts,
};
use crate::oracle::{student_t, Estimate};
use crate::record::Verdict;
use crate::subject::Subject;
use crate::tolerance::{CLOSED_FORM, IDENTITY, NUMERICAL_ROUTE};
use mfh_reference::geometry::{dot, from_spherical};
use mfh_reference::trig::{sin_cos, sin_cos_block};
use mfh_reference::{Masking, Model, Vec3};
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
/// a mean, seed 002).
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

/// Below this exponent C of a Student-t slope marginal, the tail of (q − μ)P2 is out of reach
/// of quadrature (half of Λ beyond q ~ e^{1/(2C − 3)}), and Λ's oracle is the Student-t partial
/// expectation of `oracle::student_t` instead.
const STUDENT_TAIL_LIMIT: f64 = 1.6;

/// The oracle of Λ(w): (1/μ)∫_μ^∞ (q − μ) P2(q) dq along the azimuth of w for slope-space
/// models; otherwise ∫⟨−w·m⟩⁺ D(m) dm / cos θ (the back-facing projected area, which equals
/// Λ cos θ without the cancellation of ∫⟨w·m⟩⁺D dm − cos θ).
pub fn lambda_oracle(model: &dyn Model, w: Vec3) -> Estimate {
    lambda_oracle_for(&Subject::borrowed(model), w)
}

/// [`lambda_oracle`] of a subject (its hints and registry entry place the quadrature's cuts).
pub fn lambda_oracle_for(subject: &Subject, w: Vec3) -> Estimate {
    lambda_oracle_to(subject, w, LAMBDA_ORACLE_RELATIVE)
}

/// The relative accuracy the Λ oracle asks of its quadrature: a hundredth of the tightest
/// tolerance it serves (`CLOSED_FORM`, 1e-10).
const LAMBDA_ORACLE_RELATIVE: f64 = 1e-12;

/// [`lambda_oracle_for`] with the slope-space quadrature asked for `relative` (the lune
/// quadrature of models without slopes keeps its own target): for a claim that measures
/// errors of 1e-4 and needs a few digits of 600 Λ values, not twelve.
pub fn lambda_oracle_to(subject: &Subject, w: Vec3, relative: f64) -> Estimate {
    let (sin_t, cos_t) = ((w[0] * w[0] + w[1] * w[1]).sqrt(), w[2]);
    if cos_t >= 1.0 || sin_t == 0.0 {
        return Estimate::default();
    }
    let accuracy = Accuracy::relative(relative);
    if let Some(slopes) = subject.model.as_slopes() {
        let mu = cos_t / sin_t;
        let phi = w[1].atan2(w[0]);
        if let Some(c) = subject.tail_exponent().filter(|c| *c < STUDENT_TAIL_LIMIT) {
            if let Some(e) = student_t::lambda(c, slopes.p2(0.0, phi), mu) {
                return e;
            }
        }
        let scale = subject.lobe().width().tan().max(1e-6);
        let e = integrate_upper(&|q| (q - mu) * slopes.p2(q, phi), mu, scale, accuracy);
        return Estimate {
            value: e.value / mu,
            error_bound: e.error_bound / mu,
            evaluations: e.evaluations,
        };
    }
    lambda_oracle_lune(subject, w)
}

/// Λ at several μ = cot θ along one azimuth φ of a slope-space model, each (1/μ)∫_μ^∞ (q − μ)
/// P2(q) dq to the relative target `relative` (as [`lambda_oracle_to`], for models whose tail
/// quadrature converges), with P2 evaluated once per node for all of them: the integral of μ_j
/// is split at the larger μ_k (a piece [μ_k, μ_{k+1}] per k ≥ j, the tail past the largest), so
/// every μ integrates over the same pieces with the same nodes, and a memo of P2 serves them
/// all. For a claim over a grid of μ with a P2 that is itself a quadrature (GTR: 600 Λ in
/// the spline claim); the integrands (q − μ_j)P2 ≥ 0, so nothing cancels.
pub fn lambda_oracle_many(
    slopes: &dyn mfh_reference::model::SlopeDistribution,
    phi: f64,
    mus: &[f64],
    scale: f64,
    relative: f64,
) -> Vec<Estimate> {
    let memo = std::cell::RefCell::new(std::collections::HashMap::<u64, f64>::new());
    let p2 = |q: f64| -> f64 {
        if let Some(v) = memo.borrow().get(&q.to_bits()) {
            return *v;
        }
        let v = slopes.p2(q, phi);
        memo.borrow_mut().insert(q.to_bits(), v);
        v
    };
    let mut cuts: Vec<f64> = mus.iter().copied().filter(|m| *m > 0.0).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let accuracy = Accuracy::relative(relative);
    mus.iter()
        .map(|&mu| {
            if !(mu > 0.0 && mu.is_finite()) {
                return Estimate {
                    value: f64::NAN,
                    error_bound: f64::INFINITY,
                    evaluations: 0,
                };
            }
            let f = |q: f64| (q - mu) * p2(q);
            let mut points = vec![mu];
            points.extend(cuts.iter().copied().filter(|c| *c > mu));
            let last = *points.last().unwrap_or(&mu);
            // The tail's substitution depends on its start and scale only: the same nodes for
            // every μ (a scale depending on μ would defeat the memo).
            let mut total = integrate_upper(&f, last, scale.max(1e-6), accuracy);
            for w in points.windows(2) {
                let e = crate::oracle::quadrature::integrate_pieces(&f, w, accuracy);
                total.value += e.value;
                total.error_bound += e.error_bound;
                total.evaluations += e.evaluations;
            }
            Estimate {
                value: total.value / mu,
                error_bound: total.error_bound / mu,
                evaluations: total.evaluations,
            }
        })
        .collect()
}

/// ∫⟨−w·m⟩⁺ D(m) dm / cos θ over the lune of back-facing normals: m at azimuth
/// ψ and elevation ε above the horizon, m = (cos ε cos ψ, cos ε sin ψ, sin ε), dm = cos ε dε dψ.
/// At ψ with cos(ψ − φ_w) < 0 the sliver is ε ∈ [0, ε_t], tan ε_t = −tan θ cos(ψ − φ_w), and
/// −w·m = R sin(ε_t − ε) with R = |(sin θ cos(ψ − φ_w), cos θ)|: both the nodes (next to ε = 0)
/// and the integrand keep their relative accuracy however thin the lune. (Polar coordinates
/// about n, with the terminator as a polar cut, resolve the sliver of width ~θ at normal
/// incidence only to ~1e-16/θ: at θ = 1e-6 that oracle took 1.4e9 evaluations and was 2e-9
/// off; this one takes 2e5 and agrees with the closed forms to 3e-14.)
fn lambda_oracle_lune(subject: &Subject, w: Vec3) -> Estimate {
    let model = subject.model.as_ref();
    let (st, ct) = ((w[0] * w[0] + w[1] * w[1]).sqrt(), w[2]);
    let phi_w = w[1].atan2(w[0]);
    // The model's polar kinks θ_k, as elevations π/2 − θ_k.
    let kinks: Vec<f64> = subject
        .theta_kinks()
        .iter()
        .map(|k| FRAC_PI_2 - k)
        .collect();
    let evaluations = std::cell::Cell::new(0u64);
    let inner_error = std::cell::Cell::new(0.0f64);
    // The inner integrals of one outer step run in lockstep, D in batches (one round trip per
    // step for an external model); the arithmetic is that of one integral at a time.
    let inner = |psis: &[f64], out: &mut [f64]| {
        let (mut problems, mut geometry, mut index) = (Vec::new(), Vec::new(), Vec::new());
        for (i, &psi) in psis.iter().enumerate() {
            out[i] = 0.0;
            let a = -st * (psi - phi_w).cos();
            if !(a > 0.0) {
                continue;
            }
            let r = a.hypot(ct);
            let eps_t = a.atan2(ct);
            let mut points = vec![0.0];
            points.extend(kinks.iter().copied().filter(|k| *k > 0.0 && *k < eps_t));
            points.push(eps_t);
            points.sort_by(f64::total_cmp);
            problems.push((points, Accuracy::relative(2e-13)));
            geometry.push((r, eps_t, sin_cos(psi)));
            index.push(i);
        }
        let (mut dirs, mut angles, mut sines, mut cosines) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let estimates = integrate_pieces_many(
            &mut |tx: &[(usize, f64)], values: &mut [f64]| {
                // sin and cos of every ε and sin(ε_t − ε), a block at a time (vectorized).
                let n = tx.len();
                angles.clear();
                angles.extend(tx.iter().map(|&(_, eps)| eps));
                angles.extend(tx.iter().map(|&(k, eps)| geometry[k].1 - eps));
                sines.resize(2 * n, 0.0);
                cosines.resize(2 * n, 0.0);
                sin_cos_block(&angles, &mut sines, &mut cosines);
                dirs.clear();
                dirs.extend(tx.iter().enumerate().map(|(j, &(k, _))| {
                    let (se, ce) = (sines[j], cosines[j]);
                    let (sp, cp) = geometry[k].2;
                    [ce * cp, ce * sp, se]
                }));
                model.d_batch(&dirs, values);
                for (j, (v, &(k, _))) in values.iter_mut().zip(tx).enumerate() {
                    let ce = cosines[j];
                    let (r, _, _) = geometry[k];
                    *v = r * sines[n + j] * *v * ce;
                }
            },
            &problems,
        );
        for (e, i) in estimates.iter().zip(index) {
            evaluations.set(evaluations.get() + e.evaluations);
            inner_error.set(inner_error.get().max(e.error_bound));
            out[i] = e.value;
        }
    };
    let (lo, hi) = (phi_w + 0.5 * PI, phi_w + 1.5 * PI);
    // The outer integrand has kinks where ε_t(ψ) crosses a kink elevation ε_k:
    // cos(ψ − φ_w) = −tan ε_k / tan θ.
    let mut points = vec![lo, phi_w + PI, hi];
    for k in &kinks {
        let c = -k.tan() * ct / st;
        if c.abs() < 1.0 && *k > 0.0 {
            let d = c.acos();
            points.extend([phi_w + d, phi_w + TAU - d]);
        }
    }
    points.retain(|p| *p >= lo && *p <= hi);
    points.sort_by(f64::total_cmp);
    let outer = integrate_pieces_batch(&inner, &points, Accuracy::relative(1e-12));
    Estimate {
        value: outer.value / ct,
        error_bound: (outer.error_bound + inner_error.get() * (hi - lo)) / ct,
        evaluations: evaluations.get(),
    }
}

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

/// Plans the Smith checks of one model.
pub fn plan<'a>(
    subject: &Arc<Subject<'a>>,
    profile: Profile,
    theta_max: f64,
    why: &str,
) -> Vec<PlannedCheck<'a>> {
    let Some(smith) = subject.model.as_smith() else {
        return Vec::new();
    };
    let family = subject.family();
    let spec = subject.label.clone();
    let mut out = Vec::new();
    // One oracle per direction, shared by every route checked there (computed by whichever
    // route check runs first; the others wait for it).
    let oracles: Vec<((f64, f64), SharedOracle)> =
        directions(subject.anisotropic(), profile, theta_max)
            .into_iter()
            .map(|d| (d, Arc::new(OnceLock::new())))
            .collect();
    // A user's model is audited through the method a renderer calls; the other routes of a
    // reference model are the reference's own business (each against the same oracle).
    let routes = if subject.reference.is_some() {
        smith.lambda_routes()
    } else {
        vec!["default"]
    };
    for route in routes {
        for ((theta, phi), memo) in oracles.iter().cloned() {
            let case = json!({"route": route, "theta": theta, "phi": phi});
            let m = subject.clone();
            out.push(
                Check::new("smith.lambda_route", spec.clone(), case, SOURCE_LAMBDA)
                    .why(format!("{why}: Λ by route `{route}`"))
                    .covers(vec![covers(family, "lambda", route)])
                    .run(move |r, _| {
                        let w = from_spherical(theta, phi);
                        let smith = need(m.model.as_smith(), "Smith masking")?;
                        // The default route is the method a renderer calls (and G1, G2 use).
                        let value = if route == "default" {
                            Ok(smith.lambda(w))
                        } else {
                            smith.lambda_route(w, route)
                        };
                        let value = match value {
                            Ok(v) => v,
                            Err(e) => {
                                r.verdict = Verdict::Skipped {
                                    reason: format!("route does not apply: {e}"),
                                };
                                return Ok(());
                            }
                        };
                        let oracle = *memo.get_or_init(|| lambda_oracle_for(&m, w));
                        let tol = if m.lambda_numerical() && matches!(route, "default" | "exact") {
                            &NUMERICAL_ROUTE
                        } else {
                            &CLOSED_FORM
                        };
                        compare(r, value, oracle, tol);
                        apply_expected(r, family, route);
                        Ok(())
                    }),
            );
        }
    }
    // The weak white furnace at two incidences.
    for theta in [0.6, 1.3].into_iter().filter(|t| *t <= theta_max) {
        let case = json!({"theta": theta, "phi": 0.4});
        let m = subject.clone();
        out.push(
            Check::new(
                "smith.white_furnace",
                spec.clone(),
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
                let kinks = m.theta_kinks();
                let phis = terminator_azimuths(w, &kinks);
                let theta_cut = terminator(w, kinks);
                let p = projection(w);
                // D in batches (one round trip per step for an external model).
                let e = integrate_hemisphere_polar_batch(
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
                    Accuracy::relative(1e-11),
                );
                let tol = if m.lambda_numerical() {
                    &NUMERICAL_ROUTE
                } else {
                    &CLOSED_FORM
                };
                // With a mean slope q̄ along w's azimuth (Gaussian slopes, seed 002), the
                // microsurface is tilted, ∫ m D dm ≠ n, and the constraint becomes
                // G1 (∫⟨w·m⟩⁺D dm + sin θ q̄) = cos θ: in slope space ∫⟨w·m⟩⁺D dm =
                // sin θ ∫_{−∞}^{μ}(μ − q)P2 dq = cos θ (1 + Λ) − sin θ q̄ (μ = cot θ).
                let q_bar = mean_slope(&m, 0.4);
                // The closed form enters through G1; the integral is the value under test and
                // its quadrature error bound is the slack `compare` grants.
                compare(
                    r,
                    e.value + g1 * theta.sin() * q_bar,
                    Estimate { value: w[2], ..e },
                    tol,
                );
                Ok(())
            }),
        );
    }
    // G1 and both G2 forms through the methods a renderer calls, against G1 = 1/(1 + Λ) and
    // G2 = G1·G1 (eq 22) or 1/(1 + Λo + Λi) (eq 23) from the oracle's Λ.
    let pairs = [
        ((0.5, 0.0), (1.2, 2.0)),
        ((1e-3, 0.0), (super::NEAR_GRAZING, 1.0)),
        ((1.5, 0.3), (1.5, 3.0)),
    ];
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
                    spec.clone(),
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
                    let lo = *memo_o.get_or_init(|| lambda_oracle_for(&m, wo));
                    let li = *memo_i.get_or_init(|| lambda_oracle_for(&m, wi));
                    let (go, gi) = (1.0 / (1.0 + lo.value), 1.0 / (1.0 + li.value));
                    let (value, want, bound) = match quantity {
                        "g1" => (smith.g1(wo, n), go, lo.error_bound * go * go),
                        "g2_uncorrelated" => (
                            smith.g2(wo, wi, n, Masking::Uncorrelated),
                            go * gi,
                            (lo.error_bound + li.error_bound) * go * gi,
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
                    let tol = if m.lambda_numerical() {
                        &NUMERICAL_ROUTE
                    } else {
                        &CLOSED_FORM
                    };
                    compare(
                        r,
                        value,
                        Estimate {
                            value: want,
                            error_bound: bound,
                            evaluations: lo.evaluations + li.evaluations,
                        },
                        tol,
                    );
                    Ok(())
                }),
            );
        }
    }
    // Identities over a grid of directions.
    let m = subject.clone();
    let covered = vec![
        covers(family, "g1", "default"),
        covers(family, "g2", "uncorrelated"),
        covers(family, "g2", "height_correlated"),
    ];
    out.push(
        Check::new(
            "smith.identities",
            spec.clone(),
            json!({"grid": "θ ∈ {0, …, π/2} × φ ∈ {0, 1, 2.5, 4}"}),
            "Heitz 2014 §5.2 (Λ(−w) = −1 − Λ(w)); seed 001 eq 16, 22, 23",
        )
        .why(format!(
            "{why}: Λ(−w) = −1 − Λ(w), 0 ≤ G1 ≤ 1, G2 ≤ min G1, Λ(n) = 0, G1(π/2) = 0"
        ))
        .covers(covered)
        .run(move |r, _| {
            let smith = need(m.model.as_smith(), "Smith masking")?;
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
            // Against 0: the measured error is the worst violation, absolute.
            compare_exact(r, worst, 0.0, &IDENTITY);
            if r.verdict == Verdict::Fail {
                r.case = json!({"worst": what});
            }
            Ok(())
        }),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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
