//! Spherical Gaussians (document 003): SG identities and closed forms (evaluation, integral, inner
//! and vector products, cap integral, ε-support, lobe warp, clamped-cosine fit), circular
//! Gaussians (von Mises integral, products, the SG decomposition) and ASGs (evaluation,
//! integral, product, ASG–SG convolution), each against sphere quadrature or its definition.
//!
//! The shared geometry and record helpers live here; the checks mirror `reference/src/sg/`:
//! `isotropic.rs`, `circular.rs`, `asg.rs`.

mod asg;
mod circular;
mod isotropic;

use crate::check::Check;
use asg::plan_asg;
use circular::plan_circular;
use isotropic::plan_sg;
pub use isotropic::product_check;

use super::{compare, compare_exact, covers, Planned, Profile};
use crate::oracle::quadrature::{frame_about, integrate_cap, Accuracy, Cuts};
use crate::oracle::Estimate;
use crate::record::{CheckRecord, Verdict};
use crate::tolerance::{Tolerance, CLOSED_FORM, NUMERICAL_ROUTE};
use mfh_reference::geometry::dot;
use mfh_reference::Vec3;
use serde_json::Value;
use std::f64::consts::{PI, TAU};

/// Every closed-form id `mfh eval` exposes for SGs and ASGs (`harness/src/eval/sg.rs`):
/// `sg/<quantity>/<route>`.
pub const CLOSED_FORMS: &[&str] = &[
    "sg/sg_eval/default",
    "sg/sg_inner/default",
    "sg/sg_inner/printed",
    "sg/sg_inner/exact",
    "sg/sg_product/default",
    "sg/sg_integral/default",
    "sg/sg_integral/exact",
    "sg/sg_integral/cap_product",
    "sg/sg_warp/default",
    "sg/asg_eval/default",
    "sg/asg_integral/default",
    "sg/asg_integral/large_bandwidth",
    "sg/asg_integral/exact",
    "sg/asg_sg_convolution/default",
    "sg/asg_sg_convolution/exact",
];

/// Library forms of document 003 that `mfh eval` does not expose, also covered here.
pub const LIBRARY_FORMS: &[&str] = &[
    "sg/epsilon_support/default",
    "sg/clamped_cosine/default",
    "sg/clamped_cosine/exact",
    "sg/von_mises/default",
    "sg/circular/default",
    "sg/circular_interval/erf",
    "sg/circular_interval/exact",
    "sg/sg_decomposition/default",
    "sg/asg_product/default",
];

const FAMILY: &str = "sg";

/// The quadrature accuracy asked of the oracle.
fn accuracy() -> Accuracy {
    Accuracy::relative(1e-12)
}

fn unit(v: Vec3) -> Vec3 {
    let l = dot(v, v).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// The direction at polar angle θ and azimuth φ about `axis` (harness frame).
fn around(axis: Vec3, theta: f64, phi: f64) -> Vec3 {
    let [t, b, n] = frame_about(axis);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    unit([
        st * cp * t[0] + st * sp * b[0] + ct * n[0],
        st * cp * t[1] + st * sp * b[1] + ct * n[1],
        st * cp * t[2] + st * sp * b[2] + ct * n[2],
    ])
}

/// The kink of ⟨v·normal⟩⁺ (a great circle) in the polar coordinates about `axis`: for each
/// azimuth φ, the polar angle where v·normal = 0, and the azimuths where that curve has kinks.
fn great_circle(axis: Vec3, normal: Vec3) -> (impl Fn(f64) -> Vec<f64>, Vec<f64>) {
    let [t, b, n] = frame_about(axis);
    let (ct, cb, c0) = (dot(t, normal), dot(b, normal), dot(n, normal));
    let phi_c = cb.atan2(ct);
    let r = ct.hypot(cb);
    let theta = move |phi: f64| {
        let g = r * (phi - phi_c).cos();
        vec![if c0 == 0.0 {
            0.5 * PI
        } else {
            c0.abs().atan2(-g * c0.signum())
        }]
    };
    let phis = [0.0, 0.5 * PI, PI, 1.5 * PI]
        .iter()
        .map(|d| (phi_c + d).rem_euclid(TAU))
        .collect();
    (theta, phis)
}

/// ∫ f over the directions within `theta_max` of `axis`, optionally cut along the great circle
/// ⊥ `kink`.
fn sphere(
    f: &dyn Fn(Vec3) -> f64,
    axis: Vec3,
    theta_max: f64,
    width: f64,
    kink: Option<Vec3>,
) -> Estimate {
    match kink {
        None => integrate_cap(f, axis, theta_max, width, None, accuracy()),
        Some(normal) => {
            let (theta, phis) = great_circle(axis, normal);
            integrate_cap(
                f,
                axis,
                theta_max,
                width,
                Some(Cuts {
                    theta: &theta,
                    phi: &phis,
                }),
                accuracy(),
            )
        }
    }
}

/// The angular width of an SG of sharpness λ (capped at π).
fn width(lambda: f64) -> f64 {
    (1.0 / lambda.max(1e-12).sqrt()).min(PI)
}

/// Builds a planned check whose runner makes the record and lets `body` fill it.
fn planned(
    check: &'static str,
    case: Value,
    why: &str,
    covered: Vec<String>,
    source: &'static str,
    body: impl Fn(&mut CheckRecord) + Send + Sync + 'static,
) -> Planned {
    Check::new(check, Value::Null, case, source)
        .why(why.to_string())
        .covers(covered)
        .run(move |r, _| {
            body(r);
            Ok(())
        })
}

fn cover(quantity: &str, route: &str) -> String {
    covers(FAMILY, quantity, route)
}

fn error(r: &mut CheckRecord, message: impl std::fmt::Display) {
    r.verdict = Verdict::Error {
        message: message.to_string(),
    };
}

/// Fills `r` with the worst of several comparisons `(value, expected)` that must agree to
/// `tolerance` (relative).
fn compare_worst(r: &mut CheckRecord, pairs: &[(f64, f64)], tolerance: &Tolerance) {
    let mut worst = (f64::NAN, f64::NAN, -1.0);
    for &(v, e) in pairs {
        let err = crate::record::relative_error(v, e);
        if !err.is_finite() || err > worst.2 {
            worst = (v, e, if err.is_finite() { err } else { f64::INFINITY });
        }
    }
    compare_exact(r, worst.0, worst.1, tolerance);
}

/// Fills `r` with an approximation's error against the oracle, judged against a tolerance
/// that is the approximation's claimed (or measured) bound.
fn compare_claim(r: &mut CheckRecord, value: f64, oracle: Estimate, tolerance: &Tolerance) {
    compare(r, value, oracle, tolerance);
}

/// Fills `r` with a route's value against the oracle: the `exact` route (a numerical
/// evaluation) to [`NUMERICAL_ROUTE`], the closed forms to [`CLOSED_FORM`], then the table of
/// expected failures for (`sg`, route).
fn compare_route(r: &mut CheckRecord, value: f64, oracle: Estimate, route: &str) {
    let tol = if route == "exact" {
        &NUMERICAL_ROUTE
    } else {
        &CLOSED_FORM
    };
    compare(r, value, oracle, tol);
    super::apply_expected(r, FAMILY, route);
}

/// Sharpness grid of the profile.
fn sharpness_grid(profile: Profile) -> &'static [f64] {
    match profile {
        Profile::Ci | Profile::Quick => &[1e-3, 1.0, 100.0, 1e4],
        _ => &[1e-3, 1.0, 10.0, 100.0, 1e3, 1e4],
    }
}

/// A fixed tilted axis (not a coordinate axis, so that frames are exercised).
fn axis() -> Vec3 {
    unit([0.3, -0.5, 0.8])
}

/// Plans the SG/ASG checks for a scene that uses SGs (`spherical`) and/or ASGs
/// (`anisotropic`).
pub fn plan(profile: Profile, spherical: bool, anisotropic: bool, why: &str) -> Vec<Planned> {
    let mut out = Vec::new();
    if spherical {
        plan_sg(profile, why, &mut out);
        plan_circular(profile, why, &mut out);
    }
    if anisotropic {
        plan_asg(profile, why, &mut out);
    }
    out
}

#[cfg(test)]
mod tests;
