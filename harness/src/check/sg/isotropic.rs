//! SG identities and closed forms of document 003 §1–2 (evaluation, integral, inner and vector
//! products, cap integral, ε-support, lobe warp, clamped-cosine fit), each against sphere
//! quadrature or its definition.

use super::{accuracy, around, axis, compare_claim, compare_worst, cover, error};
use super::{compare_route, planned, sharpness_grid, sphere, unit, width};
use crate::check::{compare, Planned, Profile};
use crate::oracle::quadrature::integrate_pieces;
use crate::oracle::Estimate;
use crate::record::CheckRecord;
use crate::tolerance::{
    Tolerance, CLAMPED_COSINE_FIT, CLOSED_FORM, NUMERICAL_ROUTE, SG_IDENTITY, SG_WARP_AREA,
};
use mfh_reference::geometry::dot;
use mfh_reference::sg::Sg;
use serde_json::json;
use std::f64::consts::{LN_10, PI, TAU};
use std::sync::{Arc, OnceLock};

const SRC_EVAL: &str = "seed 003 §1: G(v; p, λ, μ) = μ e^{λ(v·p − 1)}";
pub(super) const SRC_INTEGRAL: &str = "seed 003 §1: ∫G = 2πμ(1 − e^{−2λ})/λ (inner product with 1)";
const SRC_INNER: &str =
    "seed 003 §1: G₁·G₂ = 4πμ₁μ₂ e^{−(λ₁+λ₂)} sinh(d_m)/d_m, d_m = ‖λ₁p₁ + λ₂p₂‖";
const SRC_PRODUCT: &str =
    "seed 003 §1: G₁⊗G₂ = G(p_m/‖p_m‖, λ_m‖p_m‖, μ₁μ₂e^{λ_m(‖p_m‖−1)}), p_m = (λ₁p₁+λ₂p₂)/λ_m";
const SRC_CAP: &str = "seed 003 §2.2: G·V' = μ f_h(θ_d, λ); cap product G ⊗ V' (ERRATA 003 E2)";
const SRC_SUPPORT: &str = "seed 003 §1: ∫_{G ≥ ε} dv = −2π ln ε / λ (ERRATA 003 N1)";
const SRC_CLAMPED: &str = "seed 003 §2.4: max(v·n, 0) ≈ G(v; n, 2.133, 1.170), no error stated";
const SRC_WARP: &str =
    "seed 003 §2.1: p_W = 2(o·p)p − o, λ_W = λ/(4|p·o|), μ_W = μ (f_a(λ_W) ≈ area of ψ(A))";

/// The `sg.product` comparison for one pair of lobes: `product(a, b)` evaluated at points
/// around its axis against a(v)·b(v). Takes the product as a function so that `mfh selftest`
/// can pass a mutant through the same check.
pub fn product_check(r: &mut CheckRecord, a: &Sg, b: &Sg, product: &dyn Fn(&Sg, &Sg) -> Sg) {
    let m = product(a, b);
    let pairs: Vec<(f64, f64)> = [(0.0, 0.0), (1.0, 0.3), (2.0, 2.0), (0.5, 4.0)]
        .iter()
        .map(|&(k, phi)| {
            let v = around(m.axis(), (k * width(m.sharpness())).min(PI), phi);
            (m.eval(v), a.eval(v) * b.eval(v))
        })
        .collect();
    compare_worst(r, &pairs, &SG_IDENTITY);
}

pub(super) fn plan_sg(profile: Profile, why: &str, out: &mut Vec<Planned>) {
    let p = axis();
    for &lambda in sharpness_grid(profile) {
        let a = match Sg::new(p, lambda, 1.7) {
            Ok(a) => a,
            Err(_) => continue,
        };
        // The second lobe: 1/√λ away (capped at 1 rad), so that the inner product is O(1).
        let q = around(p, width(lambda).min(1.0), 0.8);
        let b = Sg::new(q, 0.5 * lambda + 0.3, 0.6).expect("valid SG");
        // Evaluation against the definition at angles 0, 1, 3 widths.
        out.push(planned(
            "sg.eval",
            json!({"sharpness": lambda, "amplitude": 1.7}),
            &format!("{why}: SG evaluation"),
            vec![cover("sg_eval", "default")],
            SRC_EVAL,
            move |r| {
                let pairs: Vec<(f64, f64)> = [0.0, 1.0, 3.0]
                    .iter()
                    .map(|k| {
                        let theta = (k * width(lambda)).min(PI);
                        let s = (0.5 * theta).sin();
                        let v = around(p, theta, 2.0);
                        (a.eval(v), 1.7 * (-2.0 * lambda * s * s).exp())
                    })
                    .collect();
                compare_worst(r, &pairs, &SG_IDENTITY);
            },
        ));
        // The integral over the sphere, both routes.
        for route in ["default", "exact"] {
            out.push(planned(
                "sg.integral_route",
                json!({"sharpness": lambda, "route": route}),
                &format!("{why}: SG integral by route `{route}`"),
                vec![cover("sg_integral", route)],
                SRC_INTEGRAL,
                move |r| {
                    let value = if route == "exact" {
                        a.integral_exact()
                    } else {
                        a.integral()
                    };
                    let o = sphere(&|v| a.eval(v), p, PI, width(lambda), None);
                    compare_route(r, value, o, route);
                },
            ));
        }
        // The inner product, every route.
        for route in ["default", "printed", "exact"] {
            out.push(planned(
                "sg.inner_route",
                json!({"sharpness": [lambda, b.sharpness()], "route": route}),
                &format!("{why}: SG inner product by route `{route}`"),
                vec![cover("sg_inner", route)],
                SRC_INNER,
                move |r| {
                    let value = match route {
                        "printed" => a.inner_printed(&b),
                        "exact" => a.inner_exact(&b),
                        _ => a.inner(&b),
                    };
                    let (la, lb) = (a.sharpness(), b.sharpness());
                    let peak = unit([
                        la * p[0] + lb * q[0],
                        la * p[1] + lb * q[1],
                        la * p[2] + lb * q[2],
                    ]);
                    let o = sphere(&|v| a.eval(v) * b.eval(v), peak, PI, width(la + lb), None);
                    compare_route(r, value, o, route);
                },
            ));
        }
        // The vector product at points against the product of evaluations.
        out.push(planned(
            "sg.product",
            json!({"sharpness": [lambda, b.sharpness()]}),
            &format!("{why}: SG vector product"),
            vec![cover("sg_product", "default")],
            SRC_PRODUCT,
            move |r| product_check(r, &a, &b, &|a, b| a.product(b)),
        ));
        // The cap integral, every route, at two caps.
        for theta_d in [0.4, 2.0] {
            for route in ["default", "exact", "cap_product"] {
                out.push(planned(
                    "sg.cap_integral_route",
                    json!({"sharpness": lambda, "cap": theta_d, "route": route}),
                    &format!("{why}: SG cap integral by route `{route}`"),
                    vec![cover("sg_integral", route)],
                    SRC_CAP,
                    move |r| {
                        let value = match route {
                            "exact" => a.cap_integral_exact(theta_d),
                            "cap_product" => a.cap_product(theta_d).map(|g| g.integral()),
                            _ => a.cap_integral(theta_d),
                        };
                        let value = match value {
                            Ok(v) => v,
                            Err(e) => return error(r, e),
                        };
                        let o = sphere(&|v| a.eval(v), p, theta_d, width(lambda), None);
                        compare_route(r, value, o, route);
                    },
                ));
            }
        }
        // The ε-support area against the area of the cap where the definition is ≥ ε.
        out.push(planned(
            "sg.epsilon_support",
            json!({"sharpness": lambda, "epsilon": [0.1, 1e-3]}),
            &format!("{why}: SG ε-support"),
            vec![cover("epsilon_support", "default")],
            SRC_SUPPORT,
            move |r| {
                let mut pairs = Vec::new();
                for eps in [0.1f64, 1e-3] {
                    let value = match a.epsilon_support_area(eps) {
                        Ok(v) => v,
                        Err(e) => return error(r, e),
                    };
                    // θ_ε by bisection of e^{−2λ sin²(θ/2)} = ε on [0, π]; then ∫ 2π sin θ.
                    let g = |t: f64| -2.0 * lambda * (0.5 * t).sin().powi(2) - eps.ln();
                    let theta_eps = if g(PI) >= 0.0 {
                        PI
                    } else {
                        let (mut lo, mut hi) = (0.0, PI);
                        for _ in 0..200 {
                            let mid = 0.5 * (lo + hi);
                            if g(mid) >= 0.0 {
                                lo = mid
                            } else {
                                hi = mid
                            }
                        }
                        0.5 * (lo + hi)
                    };
                    let area = integrate_pieces(
                        &|t| TAU * t.sin(),
                        &[0.0, 0.5 * theta_eps, theta_eps],
                        accuracy(),
                    );
                    pairs.push((value, area.value));
                }
                compare_worst(r, &pairs, &CLOSED_FORM);
            },
        ));
        // The clamped-cosine fit in use: G · C*(·; n) against ∫ G max(v·n, 0), light at 0° and
        // 60° from n; and the reference's quadrature route.
        // The oracle depends on the light angle only: computed once per angle by whichever
        // route's check runs first, shared with the other.
        let oracles: Vec<(f64, Arc<OnceLock<Estimate>>)> = [0.0, PI / 3.0]
            .into_iter()
            .map(|t| (t, Arc::new(OnceLock::new())))
            .collect();
        for (angle, route) in [(0.0, "default"), (PI / 3.0, "default"), (PI / 3.0, "exact")] {
            let memo = oracles
                .iter()
                .find(|(t, _)| *t == angle)
                .map(|(_, m)| m.clone())
                .unwrap_or_default();
            out.push(planned(
                "sg.clamped_cosine",
                json!({"sharpness": lambda, "light_angle": angle, "route": route}),
                &format!("{why}: clamped-cosine SG fit (route `{route}`)"),
                vec![cover("clamped_cosine", route)],
                SRC_CLAMPED,
                move |r| {
                    let n = around(p, angle, 1.1);
                    let value = if route == "exact" {
                        a.clamped_cosine_inner_exact(n)
                    } else {
                        a.clamped_cosine_inner(n)
                    };
                    let value = match value {
                        Ok(v) => v,
                        Err(e) => return error(r, e),
                    };
                    let o = *memo.get_or_init(|| {
                        sphere(
                            &|v| a.eval(v) * dot(v, n).max(0.0),
                            p,
                            PI,
                            width(lambda),
                            Some(n),
                        )
                    });
                    if route == "exact" {
                        compare(r, value, o, &NUMERICAL_ROUTE);
                    } else {
                        compare_claim(r, value, o, &CLAMPED_COSINE_FIT);
                    }
                },
            ));
        }
        // The lobe warp: its axis is the mirror of o about p (p is the half vector of o and
        // p_W), μ_W = μ; and f_a(λ_W) against the true area of ψ(A).
        if lambda > LN_10 {
            let o_dir = around(p, 0.6, 0.3);
            out.push(planned(
                "sg.warp_axis",
                json!({"sharpness": lambda}),
                &format!("{why}: SG lobe warp (axis)"),
                vec![cover("sg_warp", "default")],
                SRC_WARP,
                move |r| {
                    let w = match a.warp(o_dir) {
                        Ok(w) => w,
                        Err(e) => return error(r, e),
                    };
                    let pw = w.axis();
                    let h = unit([pw[0] + o_dir[0], pw[1] + o_dir[1], pw[2] + o_dir[2]]);
                    let pairs = [
                        (1.0 + dot(h, p), 2.0),
                        (1.0 + dot(pw, p), 1.0 + dot(o_dir, p)),
                        (w.amplitude(), a.amplitude()),
                    ];
                    compare_worst(r, &pairs, &SG_IDENTITY);
                },
            ));
            out.push(planned(
                "sg.warp_area",
                json!({"sharpness": lambda}),
                &format!("{why}: SG lobe warp (sharpness against the warped support's area)"),
                vec![cover("sg_warp", "default")],
                SRC_WARP,
                move |r| {
                    let w = match a.warp(o_dir) {
                        Ok(w) => w,
                        Err(e) => return error(r, e),
                    };
                    let value = TAU * LN_10 / w.sharpness();
                    let theta0 = (1.0 - LN_10 / lambda).acos();
                    let o = sphere(
                        &|h| 4.0 * dot(h, o_dir).abs(),
                        p,
                        theta0,
                        0.25 * theta0,
                        None,
                    );
                    // The warp's own first-order error: 2/(1 + cos θ₀) − 1 ≈ ln 10/(2λ).
                    let tol = Tolerance {
                        value: SG_WARP_AREA.value * (2.0 / (1.0 + theta0.cos()) - 1.0),
                        ..SG_WARP_AREA
                    };
                    compare_claim(r, value, o, &tol);
                },
            ));
        }
    }
}
