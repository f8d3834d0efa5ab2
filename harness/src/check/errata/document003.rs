//! Errata demonstrations of Document 003 (spherical Gaussians, Khungurn): each printed form and its correction against a
//! harness oracle (reference/ERRATA.md, section "Document 003").

use super::*;
use mfh_reference::errata::document003;

/// 003-E1: document 003 §2.1 Cook–Torrance Fresnel factor with g = √(η² − c² − 1) (printed) and
/// √(η² + c² − 1), against the mean of the s and p reflectances from Snell's law (η = 1.5,
/// c = 0.6).
fn e003_1() -> Result<Shown, String> {
    let (eta, c) = (1.5f64, 0.6f64);
    let sin_t = (1.0 - c * c).sqrt() / eta;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = ((c - eta * cos_t) / (c + eta * cos_t)).powi(2);
    let rp = ((eta * c - cos_t) / (eta * c + cos_t)).powi(2);
    Ok(Shown::new(
        document003::fresnel_printed(eta, c),
        document003::fresnel_corrected(eta, c),
        exact(0.5 * (rs + rp)),
        &ERRATUM,
    ))
}

/// ∫ f over the sphere by harness quadrature (a peak of angular width `width` at `axis`).
/// To 1e-10: ERRATUM asks 1e-8 of the corrected form (margin 100); the printed one misses by
/// 5e-2 (1e-12 cost about twice the evaluations).
fn sphere(f: &dyn Fn(Vec3) -> f64, axis: Vec3, width: f64) -> Estimate {
    integrate_cap(f, axis, PI, width, None, Accuracy::relative(1e-10))
}

/// 003-E2: document 003 §2.2 cap product G ⊗ V′ ≈ G(·; p, λ, μ f_h(θ_d, λ)/f_h(π/2, λ)); its
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
        Accuracy::relative(1e-10),
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

/// 003-E4: document 003 §3.2.3, ∫_{S²} e^{−A(v·x − a)² − B(v·y − b)²} dv ≈ π/√(AB) (printed) against
/// 2π/√(AB) (both hemispheres), A = B = 1e4, by harness quadrature. Centred (a = b = 0): off
/// centre each peak also carries the Jacobian 1/|v·z| = 1/√(1 − a² − b²) of dv = dv_x dv_y/|v_z|
/// (2.6 % at a = 0.2, b = 0.1), which neither form has.
fn e003_4() -> Result<Shown, String> {
    let (big_a, big_b, a, b) = (1e4f64, 1e4f64, 0.0f64, 0.0f64);
    let f = |v: Vec3| (-big_a * (v[0] - a).powi(2) - big_b * (v[1] - b).powi(2)).exp();
    let z = (1.0 - a * a - b * b).sqrt();
    // 1e-8: the corrected form holds to O(1/A) = 5e-5 against ERRATUM_ASYMPTOTIC's 1e-3; the
    // printed one is off by a factor 2.
    let accuracy = Accuracy::relative(1e-8);
    let upper = integrate_cap(&f, [a, b, z], 0.3, 0.01, None, accuracy);
    let lower = integrate_cap(&f, [a, b, -z], 0.3, 0.01, None, accuracy);
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

/// 003-E5: document 003 §3.2.3 "when λ, μ > 3, the L2-error is less than 0.2 %": the relative L2
/// error over the SG axis p (a 2-D grid of axes on the upper hemisphere, quadrature-weighted) at
/// λ = μ = 3.5, SG sharpness 2ν = 20, against the claim; corrected: the weaker 2.8 % bound at
/// SG sharpness 200, where it holds.
fn e003_5() -> Result<Shown, String> {
    let evaluations = std::cell::Cell::new(0u64);
    let l2 = |lambda: f64, nu: f64| -> Result<f64, String> {
        // λ = μ: the ASG exp(−λ((v·x)² + (v·y)²)) max(v·z, 0) is symmetric about z, so
        // ∫ ASG · SG_p depends on θ_p alone: the oracle is computed once per θ and serves the
        // four azimuths (the approximation is evaluated at every axis of the grid).
        let a = asg([lambda, lambda])?;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..6 {
            let theta = (i as f64 + 0.5) / 6.0 * 1.2;
            let axis = from_spherical(theta, 0.0);
            let sg = Sg::new(axis, 2.0 * nu, 1.0).map_err(|e| e.to_string())?;
            // Percent-level errors are measured: a relative error ≤ 1e-4 in each exact value
            // moves the L2 error by ≤ 1e-4, against the printed form's 4.3e-2, the claims'
            // 2e-3 and 2.8e-2 and the corrected form's 3.7e-4 (1e-9 and every azimuth cost
            // 42 s in the audit).
            let e = integrate_cap(
                &|v| a.eval(v) * sg.eval(v),
                axis,
                PI,
                1.0 / (2.0 * nu).sqrt(),
                None,
                Accuracy::relative(1e-4),
            );
            evaluations.set(evaluations.get() + e.evaluations);
            let exact = e.value;
            for j in 0..4 {
                let phi = (j as f64 + 0.5) / 4.0 * FRAC_PI_2;
                let p = from_spherical(theta, phi);
                let sg = Sg::new(p, 2.0 * nu, 1.0).map_err(|e| e.to_string())?;
                let approx = a.convolve_sg(&sg).map_err(|e| e.to_string())?;
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
        Estimate {
            evaluations: evaluations.get(),
            ..exact(0.0)
        },
        &crate::tolerance::SG_CONVOLUTION_L2,
    ))
}

/// 003-E6: document 003 §3.3.3, ∫ e^{2ν(i·p − 1)} V(i) di ≈ f_h(θ_d, ν) (printed) for a cap
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

/// 003-E8: document 003 §4.1, the third line of the derivation of ω·ξ − 1 (printed without − 1),
/// against ln(G(ω)/μ)/λ of the SG.
fn e003_8() -> Result<Shown, String> {
    let (t, p, t1, p1) = (0.3f64, 0.8f64, -0.2f64, 0.4f64);
    let xi = fiber_direction(t1, p1);
    let sg = Sg::new(xi, 4.0, 1.0).map_err(|e| e.to_string())?;
    let omega = fiber_direction(t, p);
    Ok(Shown::new(
        document003::eq_sec41_line3_printed(t, p, t1, p1),
        document003::eq_sec41_line3_corrected(t, p, t1, p1),
        exact(sg.eval(omega).ln() / 4.0),
        &ERRATUM,
    ))
}

/// 003-E9: document 003 §3.3.2, the ASG warp axis z_i = o (printed) against 2(o·z_h)z_h − o: the
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

/// The demonstrations of this document's errata.
pub(super) fn demos() -> Vec<Demo> {
    let d = Demo;
    vec![
        d(
            "003-E1",
            Concern::new(&[], &[Effect::SphericalGaussians]),
            "seed 003 §2.1",
            vec![],
            Value::Null,
            json!({"eta": 1.5, "c": 0.6}),
            e003_1,
        ),
        d(
            "003-E2",
            Concern::new(&[], &[Effect::SphericalGaussians]),
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
            "003-E4",
            Concern::new(&[], &[Effect::AnisotropicSphericalGaussians]),
            "seed 003 §3.2.3",
            vec![],
            Value::Null,
            json!({"A": 1e4, "B": 1e4, "a": 0.0, "b": 0.0}),
            e003_4,
        ),
        d(
            "003-E5",
            Concern::new(&[], &[Effect::AnisotropicSphericalGaussians]),
            "seed 003 §3.2.3",
            vec![covers("asg", "asg_sg_convolution", "default")],
            Value::Null,
            json!({"bandwidths": [3.5, 3.5], "sg_sharpness": 20.0, "axes": "6 × 4 grid, θ ≤ 1.2"}),
            e003_5,
        ),
        d(
            "003-E6",
            Concern::new(&[], &[Effect::SphericalGaussians]),
            "seed 003 §3.3.3",
            vec![],
            Value::Null,
            json!({"nu": 5.0, "theta_d": 1.0}),
            e003_6,
        ),
        d(
            "003-E8",
            Concern::new(&[], &[Effect::SphericalGaussians]),
            "seed 003 §4.1",
            vec![],
            Value::Null,
            json!({"theta": 0.3, "phi": 0.8, "theta_axis": -0.2, "phi_axis": 0.4}),
            e003_8,
        ),
        d(
            "003-E9",
            Concern::new(&[], &[Effect::AnisotropicSphericalGaussians]),
            "seed 003 §3.3.2",
            vec![],
            Value::Null,
            json!({"bandwidths": [40.0, 10.0], "o": [0.9, 2.0]}),
            e003_9,
        ),
    ]
}
