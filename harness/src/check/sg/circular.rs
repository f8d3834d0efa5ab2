//! Circular Gaussians of document 003 §4 (von Mises integral, products, the SG decomposition),
//! each against quadrature over the period or its definition.

use super::{accuracy, compare_worst, cover, error};
use super::{compare_route, planned, sharpness_grid, width};
use crate::check::{compare, Planned, Profile};
use crate::oracle::quadrature::integrate_pieces;
use crate::oracle::Estimate;
use crate::tolerance::{CLOSED_FORM, SG_IDENTITY};
use mfh_reference::geometry::dot;
use mfh_reference::sg::circular::{decompose_sg, von_mises_integral, von_mises_integral_scaled};
use mfh_reference::sg::CircularGaussian;
use serde_json::json;
use std::f64::consts::{PI, TAU};

const SRC_VON_MISES: &str = "seed 003 §4.3: ∫₀^{2π} exp(κ cos(x − μ)) dx = 2π I₀(κ)";
const SRC_CIRCULAR: &str = "seed 003 §4.1, §4.3: g^c(x; μ, σ) = exp((2/σ²)(cos(x − μ) − 1))";
const SRC_DECOMPOSITION: &str =
    "seed 003 §4.1: G(ω; ξ, σ) = g^c(θ; θ', σ) g^c(φ; φ', σ/√(cos θ cos θ')) (ERRATA 003 E8)";
const SRC_INTERVAL: &str =
    "seed 003 §4.3: ∫ g^c = ∫ g = (√π σ/2)[erf((b − μ)/σ) − erf((a − μ)/σ)] (ERRATA 003 E7)";

/// ∫ over one period of a function peaked at `center` (mod 2π) with width `w`.
fn period(f: &dyn Fn(f64) -> f64, center: f64, w: f64) -> Estimate {
    let c = center.rem_euclid(TAU);
    let mut pts = vec![0.0, TAU];
    for k in [0.0, 1e-2, 0.1, 1.0, 3.0, 10.0, 30.0] {
        for s in [-1.0, 1.0] {
            let x = (c + s * k * w).rem_euclid(TAU);
            pts.push(x);
        }
    }
    pts.sort_by(f64::total_cmp);
    pts.dedup();
    integrate_pieces(f, &pts, accuracy())
}

pub(super) fn plan_circular(profile: Profile, why: &str, out: &mut Vec<Planned>) {
    for &kappa in sharpness_grid(profile) {
        out.push(planned(
            "sg.von_mises",
            json!({"kappa": kappa}),
            &format!("{why}: von Mises integral"),
            vec![cover("von_mises", "default")],
            SRC_VON_MISES,
            move |r| {
                let w = width(kappa);
                let scaled = period(&|x| (kappa * (x.cos() - 1.0)).exp(), 0.0, w);
                if kappa < 700.0 {
                    let full = period(&|x| (kappa * x.cos()).exp(), 0.0, w);
                    let e = crate::record::relative_error(von_mises_integral(kappa), full.value);
                    if !(e <= CLOSED_FORM.value + full.error_bound / full.value) {
                        return compare(r, von_mises_integral(kappa), full, &CLOSED_FORM);
                    }
                }
                compare(r, von_mises_integral_scaled(kappa), scaled, &CLOSED_FORM);
            },
        ));
        let sigma = (2.0 / kappa).sqrt();
        out.push(planned(
            "sg.circular",
            json!({"sigma": sigma}),
            &format!("{why}: circular Gaussian period integral and product"),
            vec![cover("circular", "default")],
            SRC_CIRCULAR,
            move |r| {
                let (g1, g2) = match (
                    CircularGaussian::new(0.4, sigma),
                    CircularGaussian::new(0.4 + sigma.min(1.0), 1.3 * sigma),
                ) {
                    (Ok(a), Ok(b)) => (a, b),
                    _ => return error(r, "circular Gaussian rejected"),
                };
                let (alpha, g) = match g1.product(&g2) {
                    Ok(x) => x,
                    Err(e) => return error(r, e),
                };
                let mut pairs: Vec<(f64, f64)> = [-1.0, 0.0, 0.5, 2.0]
                    .iter()
                    .map(|k| {
                        let x = g.mean() + k * g.bandwidth();
                        (alpha * g.eval(x), g1.eval(x) * g2.eval(x))
                    })
                    .collect();
                let sq = |x: f64| {
                    let s = (0.5 * (x - 0.4)).sin();
                    (-4.0 / (sigma * sigma) * s * s).exp()
                };
                let q = period(&sq, 0.4, sigma);
                pairs.push((g1.integral_period(), q.value));
                compare_worst(r, &pairs, &CLOSED_FORM);
            },
        ));
        for route in ["erf", "exact"] {
            out.push(planned(
                "sg.circular_interval",
                json!({"sigma": sigma, "mean": 0.5, "route": route}),
                &format!("{why}: ∫ of a circular Gaussian over [−π/2, π/2] (route `{route}`)"),
                vec![cover("circular_interval", route)],
                SRC_INTERVAL,
                move |r| {
                    let g = match CircularGaussian::new(0.5, sigma) {
                        Ok(g) => g,
                        Err(e) => return error(r, e),
                    };
                    let (a, b) = (-0.5 * PI, 0.5 * PI);
                    let value = if route == "erf" {
                        g.integral_interval(a, b)
                    } else {
                        g.integral_interval_exact(a, b)
                    };
                    let mut pts = vec![a, b];
                    for k in [0.0, -1.0, 1.0, -4.0, 4.0, -16.0, 16.0] {
                        let x = 0.5 + k * sigma;
                        if x > a && x < b {
                            pts.push(x);
                        }
                    }
                    pts.sort_by(f64::total_cmp);
                    let o = integrate_pieces(
                        &|x| {
                            let s = (0.5 * (x - 0.5)).sin();
                            (-4.0 / (sigma * sigma) * s * s).exp()
                        },
                        &pts,
                        accuracy(),
                    );
                    compare_route(r, value, o, route);
                },
            ));
        }
        out.push(planned(
            "sg.decomposition",
            json!({"sigma": sigma}),
            &format!("{why}: SG as a product of two circular Gaussians"),
            vec![cover("sg_decomposition", "default")],
            SRC_DECOMPOSITION,
            move |r| {
                let fibre = |t: f64, f: f64| [t.sin(), t.cos() * f.cos(), t.cos() * f.sin()];
                let (ta, pa) = (0.3, -0.7);
                let xi = fibre(ta, pa);
                let mut pairs = Vec::new();
                for (dt, dp) in [(0.0, 0.0), (0.5, 0.5), (-1.0, 2.0), (2.0, -1.0)] {
                    let (t, f) = (ta + dt * sigma.min(0.5), pa + dp * sigma.min(0.5));
                    let w = fibre(t, f);
                    let d = [w[0] - xi[0], w[1] - xi[1], w[2] - xi[2]];
                    // ω·ξ − 1 = −‖ω − ξ‖²/2.
                    let expected = (-(2.0 / (sigma * sigma)) * 0.5 * dot(d, d)).exp();
                    match decompose_sg(t, f, ta, pa, sigma) {
                        Ok((l, az)) => pairs.push((l * az, expected)),
                        Err(e) => return error(r, e),
                    }
                }
                compare_worst(r, &pairs, &SG_IDENTITY);
            },
        ));
    }
}
