//! Anisotropic spherical Gaussians of document 003 §3 (evaluation, integral, product, ASG–SG
//! convolution), each against sphere quadrature or its definition.

use super::{around, axis, compare_claim, compare_worst, cover, error};
use super::{planned, sphere, width, FAMILY};
use crate::check::{applied, apply_expected, compare, Planned, Profile};
use crate::oracle::quadrature::{frame_about, integrate_line, Accuracy};
use crate::oracle::Estimate;
use crate::record::{CheckRecord, Measured, OracleValue, Verdict};
use crate::tolerance::{
    ASG_CONVOLUTION_CLAIM, ASG_CONVOLUTION_CLAIM_SHARP, ASG_LARGE_BANDWIDTH, ASG_PRODUCT_FIT,
    CLOSED_FORM, NUMERICAL_ROUTE, SG_IDENTITY,
};
use mfh_reference::geometry::{dot, Vec3};
use mfh_reference::sg::{Asg, Sg};
use serde_json::json;
use std::f64::consts::{PI, TAU};
use std::sync::{Arc, OnceLock};

const SRC_ASG_EVAL: &str = "seed 003 §3.1: G(v) = c max(v·z, 0) e^{−λ(v·x)² − μ(v·y)²}";
const SRC_ASG_INTEGRAL: &str =
    "seed 003 §3.2.1: ∫G ≈ π/√(λμ) − e^{−μ}/(2λ)(F(ν) + (ν/μ)F(ν + ν/μ)); \
                                ≈ π/√(λμ) for λ, μ > 5 (ERRATA 003 E3)";
const SRC_ASG_PRODUCT: &str = "seed 003 §3.2.2: ASG × ASG with the smooth terms frozen at z₃";
const SRC_CONVOLUTION: &str = "seed 003 §3.2.3: C(p) ≈ c max(p·z, 0) e^{−λν/(λ+ν)(p·x)² − \
                               μν/(μ+ν)(p·y)²} π/√((λ+ν)(μ+ν)); claimed L2 error < 0.2 % for \
                               λ, μ > 3, < 2.8 % for λ, μ > 1 (ERRATA 003 E4, E5)";

/// The SG sharpness where the convolution's claim is tight (ERRATA 003 E5).
const SHARP_SG: f64 = 1e3;

/// The tangent-plane integral the ASG–SG convolution formula stands for (document 003 §3.2.3):
/// `amplitude` · (p·z) · ∫∫ e^{−λX² − μY²} e^{−ν((X − p·x)² + (Y − p·y)²)} dX dY with
/// ν = sharpness/2 (an SG e^{s(v·p − 1)} is e^{−(s/2)|v − p|²} near p), in the ASG's frame
/// (x, y, z) = `frame_about(z)`, by quadrature of each factor over the line.
fn planar_convolution(bw: [f64; 2], amplitude: f64, sharpness: f64, p: Vec3, z: Vec3) -> Estimate {
    let [x, y, zz] = frame_about(z);
    let nu = 0.5 * sharpness;
    let line = |a: f64, q: f64| {
        let f = move |t: f64| (-a * t * t - nu * (t - q) * (t - q)).exp();
        integrate_line(
            &f,
            nu * q / (a + nu),
            1.0 / (a + nu).sqrt(),
            Accuracy::relative(1e-13),
        )
    };
    let (ix, iy) = (line(bw[0], dot(p, x)), line(bw[1], dot(p, y)));
    let scale = amplitude * dot(p, zz).max(0.0);
    let value = scale * ix.value * iy.value;
    Estimate {
        value,
        error_bound: value.abs() * (ix.error_bound / ix.value + iy.error_bound / iy.value),
        evaluations: ix.evaluations + iy.evaluations,
    }
}

/// Judges the default route's convolution `value` against the oracle `o` by the document's
/// claim for the bandwidths `bw` (0.2 % for λ, μ > 3, else 2.8 %), marks whether the case lies
/// inside the claim's domain (λ, μ > 1), and applies the registered expected failures.
fn judge_claim(r: &mut CheckRecord, bw: [f64; 2], value: f64, o: Estimate) {
    let tol = if bw[0] > 3.0 && bw[1] > 3.0 {
        &ASG_CONVOLUTION_CLAIM_SHARP
    } else {
        &ASG_CONVOLUTION_CLAIM
    };
    compare_claim(r, value, o, tol);
    if let Some(c) = r.case.as_object_mut() {
        c.insert("inside_claim".into(), json!(bw[0] > 1.0 && bw[1] > 1.0));
    }
    apply_expected(r, FAMILY, "default");
}

fn asg_of(bandwidths: [f64; 2], amplitude: f64) -> Option<Asg> {
    let [x, y, z] = frame_about(axis());
    Asg::new(x, y, z, bandwidths, amplitude).ok()
}

pub(super) fn plan_asg(profile: Profile, why: &str, out: &mut Vec<Planned>) {
    let bands: &[[f64; 2]] = match profile {
        Profile::Ci | Profile::Quick => &[[1.0, 1.0], [2.0, 1.0], [30.0, 8.0], [200.0, 50.0]],
        _ => &[
            [0.01, 1e-3],
            [1.0, 1.0],
            [2.0, 1.0],
            [5.0, 5.0],
            [10.0, 3.0],
            [30.0, 8.0],
            [200.0, 50.0],
            [1e3, 20.0],
        ],
    };
    let z = axis();
    for &bw in bands {
        let Some(g) = asg_of(bw, 1.3) else { continue };
        out.push(planned(
            "sg.asg_eval",
            json!({"bandwidths": bw}),
            &format!("{why}: ASG evaluation"),
            vec![cover("asg_eval", "default")],
            SRC_ASG_EVAL,
            move |r| {
                let [x, y, zz] = frame_about(z);
                let pairs: Vec<(f64, f64)> = [(0.0, 0.0), (0.3, 0.5), (0.8, 2.0), (1.4, 4.0)]
                    .iter()
                    .map(|&(t, f)| {
                        let v = around(z, t, f);
                        let (a, b, c) = (dot(v, x), dot(v, y), dot(v, zz));
                        (
                            g.eval(v),
                            1.3 * c.max(0.0) * (-bw[0] * a * a - bw[1] * b * b).exp(),
                        )
                    })
                    .collect();
                compare_worst(r, &pairs, &SG_IDENTITY);
            },
        ));
        let inside = bw[0] > 5.0 && bw[1] > 5.0;
        for route in ["default", "large_bandwidth", "exact"] {
            let check = match route {
                "large_bandwidth" if inside => "sg.asg_integral_claim",
                "large_bandwidth" => "sg.asg_integral_outside_claim",
                _ => "sg.asg_integral_route",
            };
            out.push(planned(
                check,
                json!({"bandwidths": bw, "route": route}),
                &format!("{why}: ASG integral by route `{route}`"),
                vec![cover("asg_integral", route)],
                SRC_ASG_INTEGRAL,
                move |r| {
                    let value = match route {
                        "exact" => Ok(g.integral_exact()),
                        "large_bandwidth" => g.integral_large_bandwidth(),
                        _ => g.integral(),
                    };
                    let value = match value {
                        Ok(v) => v,
                        Err(e) => return error(r, e),
                    };
                    let o = sphere(&|v| g.eval(v), z, 0.5 * PI, width(bw[0].max(bw[1])), None);
                    let tol = match route {
                        "exact" => &NUMERICAL_ROUTE,
                        "large_bandwidth" => &ASG_LARGE_BANDWIDTH,
                        _ => &CLOSED_FORM,
                    };
                    compare(r, value, o, tol);
                    apply_expected(r, FAMILY, route);
                },
            ));
        }
        // The ASG product with a second ASG (axes 0.3 rad apart, bandwidths scaled), where the
        // measured bound applies (bandwidths ≥ 1; below, the frozen smooth terms are not a
        // small correction and no bound is known).
        if bw[0].min(bw[1]) >= 1.0 {
            out.push(planned(
                "sg.asg_product",
                json!({"bandwidths": bw}),
                &format!("{why}: ASG × ASG product"),
                vec![cover("asg_product", "default")],
                SRC_ASG_PRODUCT,
                move |r| {
                    let z2 = around(z, 0.3, 1.0);
                    let [x2, y2, _] = frame_about(z2);
                    let Ok(h) = Asg::new(x2, y2, z2, [0.5 * bw[1] + 0.5, 2.0 * bw[0]], 0.8) else {
                        return error(r, "second ASG rejected");
                    };
                    let m = match g.product(&h) {
                        Ok(m) => m,
                        Err(e) => return error(r, e),
                    };
                    let wd = width(bw[1].min(bw[0]) + 0.5);
                    let mut worst: (f64, f64) = (0.0, 0.0);
                    let mut peak = 0.0f64;
                    for k in 0..5 {
                        for j in 0..8 {
                            let v = around(m.z(), (k as f64) * 0.5 * wd, j as f64 * TAU / 8.0);
                            let exact = g.eval(v) * h.eval(v);
                            peak = peak.max(exact);
                            let d = (m.eval(v) - exact).abs();
                            if !(d <= worst.0) {
                                worst = (d, m.eval(v));
                            }
                        }
                    }
                    let err = worst.0 / peak;
                    r.value = Some(worst.1);
                    r.oracle = Some(OracleValue {
                        value: peak,
                        uncertainty: 0.0,
                        kind: "error_bound",
                        noise_floor: None,
                    });
                    r.measured = Some(Measured::Absolute { error: err });
                    r.tolerance = Some(applied(&ASG_PRODUCT_FIT));
                    r.verdict = if err <= ASG_PRODUCT_FIT.value {
                        Verdict::Pass
                    } else {
                        Verdict::Fail
                    };
                },
            ));
        }
        // The ASG–SG convolution, SG of sharpness 2ν = 20 at the ASG's axis and 0.3 rad off.
        // The oracle (a sphere quadrature) depends on the tilt only: computed once per tilt by
        // whichever route's check runs first, shared with the other (as Smith's Λ oracles).
        let oracles: Vec<(f64, Arc<OnceLock<Estimate>>)> = [0.0, 0.3]
            .into_iter()
            .map(|t| (t, Arc::new(OnceLock::new())))
            .collect();
        for (tilt, route) in [(0.0, "default"), (0.3, "default"), (0.3, "exact")] {
            let memo = oracles
                .iter()
                .find(|(t, _)| *t == tilt)
                .map(|(_, m)| m.clone())
                .unwrap_or_default();
            out.push(planned(
                "sg.asg_convolution",
                json!({"bandwidths": bw, "sg_sharpness": 20.0, "tilt": tilt, "route": route}),
                &format!("{why}: ASG–SG convolution by route `{route}`"),
                vec![cover("asg_sg_convolution", route)],
                SRC_CONVOLUTION,
                move |r| {
                    let p = around(z, tilt, 0.7);
                    let Ok(s) = Sg::new(p, 20.0, 0.9) else {
                        return error(r, "SG rejected");
                    };
                    let value = match route {
                        "exact" => Ok(g.convolve_sg_exact(&s)),
                        _ => g.convolve_sg(&s),
                    };
                    let value = match value {
                        Ok(v) => v,
                        Err(e) => return error(r, e),
                    };
                    // G vanishes below the horizon of its axis z: the sphere integral is the
                    // one over the hemisphere about z (its kink is the cap's rim), in polar
                    // coordinates about the narrower lobe's axis (z, where G peaks) at the
                    // narrower width, as `sg.asg_integral_route` integrates G itself (about p,
                    // 0.3 rad off the ASG's peak, the quadrature bisected its way to it).
                    let o = *memo.get_or_init(|| {
                        let narrow = width(bw[0].max(bw[1]).max(20.0));
                        sphere(&|v| g.eval(v) * s.eval(v), z, 0.5 * PI, narrow, None)
                    });
                    if route == "exact" {
                        compare(r, value, o, &NUMERICAL_ROUTE);
                    } else {
                        judge_claim(r, bw, value, o);
                    }
                },
            ));
        }
        // Where the claim is tight: an SG of sharpness 10³ at the ASG's axis, where the
        // approximation itself is within ~1.6e-3 of the exact convolution; a 0.5 % error fails.
        {
            out.push(planned(
                "sg.asg_convolution",
                json!({"bandwidths": bw, "sg_sharpness": SHARP_SG, "tilt": 0.0,
                       "route": "default"}),
                &format!("{why}: ASG–SG convolution where the claim is tight"),
                vec![cover("asg_sg_convolution", "default")],
                SRC_CONVOLUTION,
                move |r| {
                    let Ok(s) = Sg::new(z, SHARP_SG, 0.9) else {
                        return error(r, "SG rejected");
                    };
                    let value = match g.convolve_sg(&s) {
                        Ok(v) => v,
                        Err(e) => return error(r, e),
                    };
                    let narrow = width(bw[0].max(bw[1]).max(SHARP_SG));
                    let o = sphere(&|v| g.eval(v) * s.eval(v), z, 0.5 * PI, narrow, None);
                    judge_claim(r, bw, value, o);
                },
            ));
        }
        // The approximate formula itself, against an independent evaluation of what it
        // approximates the convolution by: the SG and the ASG as Gaussians in the tangent plane
        // of z, their product integrated over the plane numerically (two 1-D integrals over
        // the line), times the smooth terms frozen at p. Any error of the implementation's
        // algebra (a factor, a sign, the ν = λ_sg/2 of the SG's width) fails at 1e-9.
        for sharpness in [20.0, SHARP_SG] {
            out.push(planned(
                "sg.asg_convolution_formula",
                json!({"bandwidths": bw, "sg_sharpness": sharpness, "tilt": 0.3}),
                &format!("{why}: the ASG–SG convolution formula, evaluated independently"),
                vec![cover("asg_sg_convolution", "default")],
                SRC_CONVOLUTION,
                move |r| {
                    let p = around(z, 0.3, 0.7);
                    let Ok(sg) = Sg::new(p, sharpness, 0.9) else {
                        return error(r, "SG rejected");
                    };
                    let value = match g.convolve_sg(&sg) {
                        Ok(v) => v,
                        Err(e) => return error(r, e),
                    };
                    let o = planar_convolution(bw, 1.3 * 0.9, sharpness, p, z);
                    compare(r, value, o, &NUMERICAL_ROUTE);
                },
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::Value;

    /// The independent tangent-plane oracle agrees with the formula, and an implementation
    /// 0.5 % off (the scaling that passed the claim check at sharpness 20) fails both the
    /// formula check and, for λ, μ > 3, the check where the claim is tight.
    #[test]
    fn a_half_percent_convolution_fails_the_formula_and_the_sharp_claim() {
        let z = axis();
        let bw = [30.0, 8.0];
        let g = asg_of(bw, 1.3).unwrap();
        let p = around(z, 0.3, 0.7);
        let sg = Sg::new(p, 20.0, 0.9).unwrap();
        let value = g.convolve_sg(&sg).unwrap();
        let o = planar_convolution(bw, 1.3 * 0.9, 20.0, p, z);
        let mut r = CheckRecord::new("sg.asg_convolution_formula", Value::Null, json!({}), "");
        compare(&mut r, value, o, &NUMERICAL_ROUTE);
        assert_eq!(r.verdict, Verdict::Pass, "{value} vs {o:?}");
        compare(&mut r, value * 1.005, o, &NUMERICAL_ROUTE);
        assert_eq!(r.verdict, Verdict::Fail);

        let sharp = Sg::new(z, SHARP_SG, 0.9).unwrap();
        let value = g.convolve_sg(&sharp).unwrap();
        let narrow = width(bw[0].max(bw[1]).max(SHARP_SG));
        let o = sphere(&|v| g.eval(v) * sharp.eval(v), z, 0.5 * PI, narrow, None);
        let mut r = CheckRecord::new("sg.asg_convolution", Value::Null, json!({}), "");
        compare_claim(&mut r, value, o, &ASG_CONVOLUTION_CLAIM_SHARP);
        assert_eq!(r.verdict, Verdict::Pass, "{value} vs {o:?}");
        compare_claim(&mut r, value * 1.005, o, &ASG_CONVOLUTION_CLAIM_SHARP);
        assert_eq!(r.verdict, Verdict::Fail);
    }
}
