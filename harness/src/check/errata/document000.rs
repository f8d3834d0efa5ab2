//! Errata demonstrations of Document 000 (piecewise-linear NDF, Ribardière et al.): each printed form and its correction against a
//! harness oracle (reference/ERRATA.md, section "Document 000").

use super::*;
use mfh_reference::errata::document000;
use mfh_reference::family::FamilySpec;

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
        AngularProfile::uniform(PL_X.to_vec()),
        Some(AngularProfile::uniform(PL_Y.to_vec())),
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

/// 000-E1: document 000 eq 8 as printed integrates over φ ∈ [0, 2π]: the marginal cdf of θ. As
/// the conditional cdf of θ given φ_m (normalized to 1 at π/2) it is wrong; eq 9's form (no φ
/// integral, factor 2π) is right. Oracle: the conditional cdf from D by quadrature.
fn e000_1() -> Result<Shown, String> {
    let m = pl()?;
    let (phi, theta) = (0.3f64, 0.5f64);
    Ok(Shown::new(
        document000::eq8_theta_cdf_printed(&m, theta),
        m.cdf_theta(theta, phi),
        ratio(
            theta_mass(&m, phi, 0.0, theta),
            theta_mass(&m, phi, 0.0, FRAC_PI_2),
        ),
        &ERRATUM,
    ))
}

/// 000-E2: document 000 text after eq 9: the segment integral ∫ (A θ + B) cos θ sin θ dθ with
/// B^aniso = cos²φ D_y(0) b^x + sin²φ D_x(0) b^x (printed) or … b^y (Algorithm 2, line 2),
/// against the mass of D on the segment by quadrature.
fn e000_2() -> Result<Shown, String> {
    let m = pl()?;
    let (phi, k) = (0.9f64, 1);
    let (t0, t1) = (m.breakpoints()[k], m.breakpoints()[k + 1]);
    Ok(Shown::new(
        document000::b_aniso_segment_printed(&m, phi, k),
        document000::b_aniso_segment_corrected(&m, phi, k),
        theta_mass(&m, phi, t0, t1),
        &ERRATUM,
    ))
}

/// 000-E4: document 000 eq 9 summed Σ_{i=1}^k ∫_{θᵢ}^{θᵢ₊₁} read with eq 4's θ₀ = 0 omits the first
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

/// 000-E5: document 000 eq 23, partial segment ∫_{θ_k}^{E} (aθ + b) sin²θ dθ with cos 2φ_o (the
/// extracted y line) and cos 2θ_o (right), against quadrature.
fn e000_5() -> Result<Shown, String> {
    let (a, b, tk, theta_o, phi_o) = (0.7f64, 0.4f64, 0.2f64, 0.9f64, 0.3f64);
    let e = FRAC_PI_2 - theta_o;
    Ok(Shown::new(
        document000::eq23_partial_segment_printed(a, b, tk, theta_o, phi_o),
        document000::eq23_partial_segment_corrected(a, b, tk, theta_o),
        integrate(&|t: f64| (a * t + b) * t.sin().powi(2), tk, e, acc()),
        &ERRATUM,
    ))
}

/// Smith Λ of the piecewise model by the harness oracle (back-facing projected area).
fn pl_lambda_oracle(w: Vec3) -> Result<(Box<dyn Model>, Estimate), String> {
    let spec = pl_spec();
    let m = build(spec.clone())?;
    let o = lambda_oracle(&Subject::borrowed(m.as_ref()), w);
    Ok((m, o))
}

/// 000-E7: document 000 eq 32 with the lower limit −∞: (1/μ)∫(q − μ)P₂ dq = (E[q] − μ)/μ, and
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

/// 000-E8: document 000 eq 31 with p, q the slopes of the fixed frame: the printed P₂ is the one
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

/// 000-E9: document 000 eq 33, G = 1/(1 + Λ(i) + Λ(o)) without χ⁺: for a back-facing microfacet G₂
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

/// The domain-split Λ of document 000 (eq 34) with the remaining integral by `remaining`.
fn split(theta: f64, phi: f64, remaining: Remaining) -> Result<f64, String> {
    Ok(domain_split(&pl()?, theta, (2.0 * phi).cos(), remaining).lambda)
}

/// 000-E10: document 000 eq 28, the trapezoid rule, against Λ by quadrature (θ_o = 0.3, where
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

/// 000-E11: document 000 eq 34 with eq 16's I₁ (= I₁₁ + cos θ_o/2) for the display: Λ is ½ too large.
fn e000_11() -> Result<Shown, String> {
    let (theta, phi) = (0.3f64, 0.7f64);
    let (_, o) = pl_lambda_oracle(from_spherical(theta, phi))?;
    let ds = domain_split(&pl()?, theta, (2.0 * phi).cos(), Remaining::Adaptive);
    Ok(Shown::new(
        document000::eq34_lambda_printed(theta, ds.i11, ds.i2_1, ds.i2_2),
        document000::eq34_lambda_corrected(theta, ds.i11, ds.i2_1, ds.i2_2),
        o,
        &ERRATUM,
    ))
}

/// 000-E12: document 000 eq 27 calls the remaining integral "Λ": taken as Smith's Λ it is wrong.
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

/// 000-E14: document 000 eq 2 defines c as ∫∫ D cos θ sin θ dθ dφ with the normalized D of eq 1,
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
    let spec = m.spec();
    let kinks = spec.theta_kinks();
    let at_kinks = |_: f64| kinks.clone();
    let cuts = || {
        Some(crate::oracle::quadrature::Cuts {
            theta: &at_kinks,
            phi: &[],
        })
    };
    // 1e-10: the corrected c must meet the oracle to ERRATUM's 1e-8 (margin 100); the printed
    // value misses it by 0.53 (1e-12 cost about twice the evaluations).
    let accuracy = Accuracy::relative(1e-10);
    let printed = integrate_hemisphere(&|v| m.d(v) * v[2], 0.5, cuts(), accuracy).value;
    Ok(Shown::new(
        printed,
        c,
        integrate_hemisphere(&blend, 0.5, cuts(), accuracy),
        &ERRATUM,
    ))
}

/// 000-E15: document 000 eq 18, the front-facing condition with cos φ_m (φ_o = 0 assumed) for
/// cos(φ_m − φ_o): ∫ χ (o·m) D dm with the printed χ, against cos θ_o (1 + Λ(o)) (Λ by the
/// back-facing oracle).
fn e000_15() -> Result<Shown, String> {
    let (theta, phi) = (0.3f64, 0.7f64);
    let o = from_spherical(theta, phi);
    let (m, lam) = pl_lambda_oracle(o)?;
    let (so, co) = theta.sin_cos();
    let spec = pl_spec();
    let spec: ModelSpec = serde_json::from_value(spec).map_err(|e| e.to_string())?;
    let kinks = spec.theta_kinks();
    let projected = |printed: bool| {
        // Cut each polar integral at the kinks of D and where the indicator switches
        // (so sin θ cos δ + co cos θ = 0, tan θ = co/(so·(−cos δ)) for cos δ < 0): the
        // integrand is smooth between cuts (uncut, the indicator's jump cost 30 s in the audit).
        let terminator = |pm: f64| {
            let cosd = if printed { pm.cos() } else { (pm - phi).cos() };
            let mut at = kinks.clone();
            if cosd < 0.0 {
                at.push((co / (so * -cosd)).atan());
            }
            at
        };
        let cuts = crate::oracle::quadrature::Cuts {
            theta: &terminator,
            phi: &[],
        };
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
            Some(cuts),
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

/// 000-E16: document 000 eq 20, the sin²θ_m lines of I₂¹ with cos θ_o for sin θ_o and D_y(0) for
/// D_x(0), against I₂¹ = ∫₀^E ∫_{φ_o+π/2}^{φ_o+3π/2} (o·m) D sin θ_m dφ_m dθ_m (eq 19) by nested
/// harness quadrature with the breakpoints as cuts.
fn e000_16() -> Result<Shown, String> {
    let m = pl()?;
    let (theta_o, phi_o) = (0.9f64, 0.3f64);
    let o = from_spherical(theta_o, phi_o);
    let e = FRAC_PI_2 - theta_o;
    let mut cuts = vec![0.0];
    cuts.extend(
        m.breakpoints()
            .iter()
            .copied()
            .filter(|&t| t > 0.0 && t < e),
    );
    cuts.push(e);
    let evaluations = std::cell::Cell::new(0u64);
    let outer = integrate_pieces(
        &|t: f64| {
            let inner = integrate(
                &|p: f64| {
                    let v = from_spherical(t, p);
                    dot(o, v) * m.d(v) * t.sin()
                },
                phi_o + FRAC_PI_2,
                phi_o + 1.5 * PI,
                Accuracy::relative(1e-13),
            );
            evaluations.set(evaluations.get() + inner.evaluations);
            inner.value
        },
        &cuts,
        acc(),
    );
    Ok(Shown::new(
        document000::i21_eq20_printed(&m, theta_o, phi_o),
        document000::i21_eq20_corrected(&m, theta_o, phi_o),
        Estimate {
            evaluations: outer.evaluations + evaluations.get(),
            ..outer
        },
        &ERRATUM,
    ))
}

/// 000-E17: document 000 eq 25, last line: −(cos θ_o/4)(∫_{θ_{k+1}}^{π/2} 2π D_x(θ) D_x(0) cos sin/c
/// plus twice ∫_E^{θ_{k+1}} 2π D_y D_x(0) cos sin/c) as printed, against −(cos θ_o/4) ∫_E^{π/2}
/// 2π D_y D_x(0) cos θ sin θ/c dθ by harness quadrature (θ_o = 0.9).
fn e000_17() -> Result<Shown, String> {
    let m = pl()?;
    let theta_o = 0.9f64;
    let e = FRAC_PI_2 - theta_o;
    let (dx0, dy0) = (m.d_x(0.0), m.d_y(0.0));
    let c = 0.5 * (dx0 + dy0);
    let mut cuts = vec![e];
    cuts.extend(m.breakpoints().iter().copied().filter(|&t| t > e));
    let q = integrate_pieces(&|t: f64| m.d_y(t) * t.cos() * t.sin(), &cuts, acc());
    let k = -theta_o.cos() / 4.0 * TAU * dx0 / c;
    Ok(Shown::new(
        document000::i22_y_term_eq25_printed(&m, theta_o),
        document000::i22_y_term_eq25_corrected(&m, theta_o),
        Estimate {
            value: k * q.value,
            error_bound: k.abs() * q.error_bound,
            evaluations: q.evaluations,
        },
        &ERRATUM,
    ))
}

/// 000-U1: document 000 Algorithm 1 as printed in the zero case D_x(0) = D_y(0) = 0 (ξ₁ = 0.3,
/// 10⁴ iterations): line 18's (D_y(0) − D_x(0))/(D_y(0) + D_x(0)) is 0/0, `value` is NaN, the
/// exit |value| < 1e-5 never holds (printed: the NaN left after the bound). Guarded as the
/// reference does (k_x = k_y = 1: φ uniform): 2πξ₁, the inverse of the cdf φ/2π.
fn e000_u1() -> Result<Shown, String> {
    let xi = 0.3;
    let printed = document000::algorithm1_printed(0.0, 0.0, xi, 10_000);
    let guarded = document000::algorithm1_corrected(0.0, 0.0, xi, 10_000);
    if printed.converged || !guarded.converged {
        return Err(format!("unexpected runs: {printed:?}, {guarded:?}"));
    }
    Ok(Shown::new(
        printed.value,
        guarded.value,
        exact(TAU * xi),
        &ERRATUM,
    ))
}

/// 000-U2: document 000 eq 27/28's C = arccos(−1/(tan θ_o tan θ_m)) at θ_m = E = π/2 − θ_o, where the
/// trapezoid rule of eq 28 evaluates it: the argument is −1 − 4e-16 in double precision at
/// θ_o = 0.3 and C is NaN (so is Λ); clamped to [−1, 1] as the reference does, C = π, its
/// exact value.
fn e000_u2() -> Result<Shown, String> {
    let theta_o = 0.3f64;
    let e = FRAC_PI_2 - theta_o;
    Ok(Shown::new(
        document000::c_printed(theta_o, e),
        document000::c_corrected(theta_o, e),
        exact(PI),
        &ERRATUM,
    ))
}

/// The demonstrations of this document's errata.
pub(super) fn demos() -> Vec<Demo> {
    let d = Demo;
    vec![
        d(
            "000-E1",
            Concern::new(PIECEWISE, &[Effect::SampleNormals]),
            "seed 000 eq 8",
            vec![covers("piecewise_linear", "cdf_theta", "default")],
            pl_spec(),
            json!({"phi": 0.3, "theta": 0.5}),
            e000_1,
        ),
        d(
            "000-E2",
            Concern::new(PIECEWISE, &[Effect::SampleNormals]),
            "seed 000 text after eq 9; Algorithm 2 line 2",
            vec![],
            pl_spec(),
            json!({"phi": 0.9, "segment": 1}),
            e000_2,
        ),
        d(
            "000-E4",
            Concern::new(PIECEWISE, &[Effect::SampleNormals]),
            "seed 000 eq 4, eq 9",
            vec![],
            pl_spec(),
            json!({"phi": 0.4}),
            e000_4,
        ),
        d(
            "000-E5",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 23, y line",
            vec![],
            Value::Null,
            json!({"a": 0.7, "b": 0.4, "theta_k": 0.2, "theta_o": 0.9, "phi_o": 0.3}),
            e000_5,
        ),
        d(
            "000-E7",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 32",
            vec![covers("piecewise_linear", "lambda", "slope_space")],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7}),
            e000_7,
        ),
        d(
            "000-E8",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 31",
            vec![covers("piecewise_linear", "p2", "default")],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.0}),
            e000_8,
        ),
        d(
            "000-E9",
            Concern::new(PIECEWISE, &[Effect::Masking]),
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
            Concern::new(PIECEWISE, &[Effect::Masking]),
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
            Concern::new(PIECEWISE, &[Effect::Masking]),
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
            Concern::new(PIECEWISE, &[Effect::Masking]),
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
            Concern::new(PIECEWISE, &[Effect::SampleNormals]),
            "seed 000 Algorithms 1–2",
            vec![covers("piecewise_linear", "sample_wm", "default")],
            pl_spec(),
            json!({"phi": 0.4, "xi": [0.05, 0.2, 0.37, 0.5, 0.63, 0.81, 0.95], "printed_tolerance": 1e-5, "quantity": "½ + max |cdf(θ(ξ)) − ξ|"}),
            e000_13,
        ),
        d(
            "000-E14",
            Concern::new(&["piecewise_linear", "blend"], &[]),
            "seed 000 eq 2–3",
            vec![covers("piecewise_linear", "d", "default")],
            pl_spec(),
            json!({"quantity": "c"}),
            e000_14,
        ),
        d(
            "000-E15",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 18–19",
            vec![covers("piecewise_linear", "d", "default")],
            pl_spec(),
            json!({"theta": 0.3, "phi": 0.7, "quantity": "∫ χ (o·m) D dm"}),
            e000_15,
        ),
        d(
            "000-E16",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 20 (I₂¹), eq 22",
            vec![],
            pl_spec(),
            json!({"theta_o": 0.9, "phi_o": 0.3, "quantity": "I₂¹"}),
            e000_16,
        ),
        d(
            "000-E17",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 25 last line, eq 26",
            vec![],
            pl_spec(),
            json!({"theta_o": 0.9, "quantity": "−(cos θ_o/4) ∫_E^{π/2} 2π D_y D_x(0) cos sin / c"}),
            e000_17,
        ),
        d(
            "000-U1",
            Concern::new(PIECEWISE, &[Effect::SampleNormals]),
            "seed 000 Algorithm 1, line 18",
            vec![],
            Value::Null,
            json!({"D_x(0)": 0.0, "D_y(0)": 0.0, "xi1": 0.3, "max_iterations": 10_000, "quantity": "φ_m"}),
            e000_u1,
        ),
        d(
            "000-U2",
            Concern::new(PIECEWISE, &[Effect::Masking]),
            "seed 000 eq 18, 27, 28",
            vec![],
            Value::Null,
            json!({"theta_o": 0.3, "theta_m": "E = π/2 − θ_o", "quantity": "C",
                   "printed_nan_fraction": "84 % of θ_o on a uniform grid of 10⁵ (reference test)"}),
            e000_u2,
        ),
    ]
}
