//! Test-only conformance checks shared by every NDF's unit tests: each closed form against an
//! independent numerical integral of its definition (test_support quadrature), and sampling
//! inversions against their densities.

use crate::geometry::{dot, from_spherical, Vec3};
use crate::model::{NormalSampler, SlopeDistribution, Smith, VisibleNormalSampler};
use crate::test_support::{integrate, integrate_line, integrate_tail, rel_err};
use std::f64::consts::PI;

/// ∫ D(m) (m·n) dm over the hemisphere, in slope-radius coordinates r = tan θ along each
/// azimuth (dm = sin θ dθ dφ, cos θ sin θ dθ = r dr/(1 + r²)²); `radial_scale(φ)` is the slope
/// width along φ, used only to place the quadrature nodes.
pub fn normalization(d: &dyn Fn(Vec3) -> f64, radial_scale: &dyn Fn(f64) -> f64) -> f64 {
    let inner = |phi: f64| {
        let (s, c) = phi.sin_cos();
        let f = |r: f64| {
            let z = 1.0 / (1.0 + r * r).sqrt();
            d([r * z * c, r * z * s, z]) * r * z.powi(4)
        };
        integrate_tail(&f, 0.0, radial_scale(phi), 1e-13)
    };
    // Four quarter-periods: the integrand is smooth and periodic in φ.
    (0..4)
        .map(|k| {
            let a = k as f64 * PI / 2.0;
            integrate(&inner, a, a + PI / 2.0, 1e-13, 0.0).0
        })
        .sum()
}

/// ∫ D(m) (m·n) dm for an isotropic D: 2π times the radial integral at φ = 0.
pub fn normalization_isotropic(d: &dyn Fn(Vec3) -> f64, radial_scale: f64) -> f64 {
    let f = |r: f64| {
        let z = 1.0 / (1.0 + r * r).sqrt();
        d([r * z, 0.0, z]) * r * z.powi(4)
    };
    2.0 * PI * integrate_tail(&f, 0.0, radial_scale, 1e-13)
}

/// P2(q) along azimuth φ as the marginal ∫ P22 dp of the rotated slope (q along φ, p across).
pub fn p2_marginal(slopes: &dyn SlopeDistribution, q: f64, phi: f64, scale: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let f = |p: f64| slopes.p22(q * c - p * s, q * s + p * c);
    integrate_line(&f, scale, 1e-13)
}

/// Smith Λ(w) from its definition (document 001 eq 17): (1/μ) ∫_μ^∞ (q − μ) P2(q) dq, μ = cot θ,
/// with P2 along the azimuth of w.
pub fn lambda_integral(slopes: &dyn SlopeDistribution, w: Vec3, scale: f64) -> f64 {
    let sin_theta = (w[0] * w[0] + w[1] * w[1]).sqrt();
    let mu = w[2] / sin_theta;
    let phi = w[1].atan2(w[0]);
    let f = |q: f64| (q - mu) * slopes.p2(q, phi);
    integrate_tail(&f, mu, scale, 1e-14) / mu
}

/// The slope moment ν₂ₖ = ∫ q^{2k} P2(q) dq along φ.
pub fn moment_integral(slopes: &dyn SlopeDistribution, k: u32, phi: f64, scale: f64) -> f64 {
    integrate_line(&|q| q.powi(2 * k as i32) * slopes.p2(q, phi), scale, 1e-13)
}

/// Asserts Λ against its integral at every θ of `thetas` and φ of `phis`; returns the max
/// relative error.
pub fn assert_lambda(
    smith: &dyn Smith,
    slopes: &dyn SlopeDistribution,
    scale: f64,
    thetas: &[f64],
    phis: &[f64],
    tol: f64,
    label: &str,
) -> f64 {
    let mut worst: f64 = 0.0;
    for &theta in thetas {
        for &phi in phis {
            let w = from_spherical(theta, phi);
            let got = smith.lambda(w);
            let want = lambda_integral(slopes, w, scale);
            let e = rel_err(got, want);
            // Values below 1e-290 are at the edge of f64: compare absolutely there.
            let ok = e <= tol || (want.abs() < 1e-290 && got.abs() < 1e-290);
            assert!(
                ok,
                "{label}: Λ(θ={theta}, φ={phi}) = {got:e}, integral {want:e}, rel err {e:e} > {tol:e}"
            );
            if want.abs() >= 1e-290 {
                worst = worst.max(e);
            }
            // Λ(−w) = −1 − Λ(w) and G1 in [0, 1].
            let below = smith.lambda([-w[0], -w[1], -w[2]]);
            assert!(
                (below + 1.0 + got).abs() <= 1e-12 * (1.0 + got.abs()),
                "{label}: Λ(−w)"
            );
            let g1 = smith.g1(w, [0.0, 0.0, 1.0]);
            assert!((0.0..=1.0).contains(&g1), "{label}: G1 = {g1}");
        }
    }
    eprintln!("{label}: max rel err of Λ against its integral: {worst:.2e}");
    worst
}

/// Checks a normal sampler: the Jacobian of u ↦ m (solid angle per unit area of u, by central
/// differences) is 1/pdf_wm(m), and the samples lie on the unit upper hemisphere. Returns the
/// max relative error.
pub fn assert_sampler_density(sampler: &dyn NormalSampler, tol: f64, label: &str) -> f64 {
    assert_density(
        &|u| sampler.sample_wm(u),
        &|m| sampler.pdf_wm(m),
        tol,
        label,
    )
}

/// [`assert_sampler_density`] for any map `sample` from [0, 1)² to the unit upper hemisphere
/// with density `pdf`.
pub fn assert_density(
    sample: &dyn Fn([f64; 2]) -> Vec3,
    pdf_of: &dyn Fn(Vec3) -> f64,
    tol: f64,
    label: &str,
) -> f64 {
    let mut worst: f64 = 0.0;
    let h = 1e-6;
    for i in 1..12 {
        for j in 1..12 {
            let u = [i as f64 / 12.0 + 0.013, j as f64 / 12.0 * 0.97];
            let m = sample(u);
            assert!(
                (dot(m, m) - 1.0).abs() < 1e-12 && m[2] >= 0.0,
                "{label}: m = {m:?}"
            );
            let d1 = diff(sample, u, [h, 0.0]);
            let d2 = diff(sample, u, [0.0, h]);
            let cross = [
                d1[1] * d2[2] - d1[2] * d2[1],
                d1[2] * d2[0] - d1[0] * d2[2],
                d1[0] * d2[1] - d1[1] * d2[0],
            ];
            let area = dot(cross, cross).sqrt();
            let pdf = pdf_of(m);
            if pdf < 1e-8 || m[2] < 1e-4 {
                continue; // the finite differences are meaningless where m is on the horizon
            }
            let e = rel_err(1.0 / area, pdf);
            assert!(
                e <= tol,
                "{label}: u = {u:?}: 1/|J| = {}, pdf = {pdf}, rel err {e:e}",
                1.0 / area
            );
            worst = worst.max(e);
        }
    }
    eprintln!("{label}: max rel err of the sampler's Jacobian against its pdf: {worst:.2e}");
    worst
}

fn diff(sample: &dyn Fn([f64; 2]) -> Vec3, u: [f64; 2], h: [f64; 2]) -> Vec3 {
    let a = sample([u[0] + h[0], u[1] + h[1]]);
    let b = sample([u[0] - h[0], u[1] - h[1]]);
    let n = 2.0 * (h[0] + h[1]);
    [(a[0] - b[0]) / n, (a[1] - b[1]) / n, (a[2] - b[2]) / n]
}

/// ∫ pdf(m) dm over the upper hemisphere for a density peaked at the normal with angular width
/// `width`, with the polar integral cut at `kinks(φ)` (e.g. the terminator of ⟨wi·m⟩⁺) and the
/// azimuthal one at `phi_kinks` (e.g. where the terminator enters the hemisphere).
pub fn hemisphere_integral(
    pdf: &dyn Fn(Vec3) -> f64,
    width: f64,
    kinks: &dyn Fn(f64) -> Vec<f64>,
    phi_kinks: &[f64],
) -> f64 {
    let half = PI / 2.0;
    let inner = |phi: f64| {
        let (s, c) = phi.sin_cos();
        let mut cuts = vec![0.0, half];
        for k in [0.1, 0.3, 1.0, 3.0, 10.0] {
            if width * k < half {
                cuts.push(width * k);
            }
        }
        cuts.extend(kinks(phi).into_iter().filter(|t| *t > 0.0 && *t < half));
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let f = |theta: f64| {
            let (st, ct) = theta.sin_cos();
            pdf([st * c, st * s, ct]) * st
        };
        cuts.windows(2)
            .map(|w| integrate(&f, w[0], w[1], 1e-12, 1e-15).0)
            .sum::<f64>()
    };
    let mut cuts: Vec<f64> = (0..=8).map(|k| k as f64 * PI / 4.0).collect();
    cuts.extend(phi_kinks.iter().map(|p| p.rem_euclid(2.0 * PI)));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts.windows(2)
        .map(|w| integrate(&inner, w[0], w[1], 1e-11, 1e-14).0)
        .sum()
}

/// The azimuths of m where the terminator of ⟨wi·m⟩⁺ meets the normal (φi ± π/2).
pub fn terminator_azimuths(wi: Vec3) -> [f64; 2] {
    let phi = wi[1].atan2(wi[0]);
    [phi + PI / 2.0, phi - PI / 2.0]
}

/// The polar angle of the terminator of ⟨wi·m⟩⁺ along azimuth φ of m, if it is above the
/// horizon: cos θ wi_z + sin θ (wi_x cos φ + wi_y sin φ) = 0.
pub fn terminator(wi: Vec3, phi: f64) -> Vec<f64> {
    let k = wi[0] * phi.cos() + wi[1] * phi.sin();
    if k < 0.0 {
        vec![PI / 2.0 + k.atan2(wi[2])]
    } else {
        Vec::new()
    }
}

/// Checks a visible-normal sampler at several incidences: ∫ pdf_wm_visible(wi, m) dm = 1 by
/// quadrature, the Jacobian of u ↦ m against 1/pdf_wm_visible, every sample facing `wi`, and at
/// normal incidence pdf_wm_visible(n, m) = D(m)(m·n). `width` is the smallest roughness, used
/// to place quadrature nodes.
pub fn assert_visible_sampler(model: &dyn VisibleNormalSampler, width: f64, label: &str) {
    for &(theta, phi) in &[
        (0.0, 0.0),
        (1e-3, 0.4),
        (0.5, 0.0),
        (0.5, 2.2),
        (1.3, 0.7),
        (1.55, 4.0),
    ] {
        let wi = from_spherical(theta, phi);
        let n = hemisphere_integral(
            &|m| model.pdf_wm_visible(wi, m),
            width.atan(),
            &|p| terminator(wi, p),
            &terminator_azimuths(wi),
        );
        assert!(
            (n - 1.0).abs() < 1e-8,
            "{label}: θi = {theta}: ∫ D_wi = {n}"
        );
        let here = format!("{label} θi={theta} φi={phi}");
        assert_density(
            &|u| model.sample_wm_visible(wi, u),
            &|m| model.pdf_wm_visible(wi, m),
            1e-5,
            &here,
        );
        for i in 0..400 {
            let u = [
                (i as f64 + 0.5) / 400.0,
                (i as f64 * 0.618_033_988_749_895).fract(),
            ];
            let m = model.sample_wm_visible(wi, u);
            assert!(
                dot(wi, m) >= -1e-12,
                "{here}: u = {u:?}: wi·m = {}",
                dot(wi, m)
            );
        }
    }
    let n = [0.0, 0.0, 1.0];
    for &(theta, phi) in &[(0.2, 0.1), (0.9, 3.0)] {
        let m = from_spherical(theta, phi);
        let want = model.d(m) * m[2];
        assert!(rel_err(model.pdf_wm_visible(n, m), want) < 1e-14, "{label}");
    }
    // Outside the domain: NaN samples and zero density, no panic.
    for wi in [
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [f64::NAN, 0.0, 1.0],
        [0.0, 0.0, 2.0],
    ] {
        assert!(
            model.sample_wm_visible(wi, [0.3, 0.4])[0].is_nan(),
            "{label}"
        );
        assert_eq!(model.pdf_wm_visible(wi, n), 0.0, "{label}");
    }
}

/// The conformance suite of an elliptic NDF with a closed-form Smith Λ, P2 and sampler, at
/// roughness `(alpha_x, alpha_y)`: normalization, P2 as the marginal of P22, D = P22/cos⁴θ,
/// Λ against its defining integral (and Λ(−w), G1 ∈ [0, 1]), the sampler's Jacobian, and
/// the slope moments that exist against their integrals. `width` is the slope width used to
/// place quadrature nodes. Returns the worst relative errors (normalization, P2, Λ, moments).
pub fn assert_elliptic_model<M>(model: &M, alpha: (f64, f64), width: f64, label: &str) -> [f64; 4]
where
    M: Smith + NormalSampler + SlopeDistribution,
{
    let (ax, ay) = alpha;
    let radial = |phi: f64| {
        let (s, c) = phi.sin_cos();
        width / ((c / ax).powi(2) + (s / ay).powi(2)).sqrt()
    };
    let n = normalization(&|w| model.d(w), &radial);
    assert!((n - 1.0).abs() < 1e-10, "{label}: ∫ D cos θ dω = {n}");
    let mut worst_p2: f64 = 0.0;
    for &phi in &[0.0f64, 0.7, 2.0] {
        let s = (ax * phi.cos()).hypot(ay * phi.sin());
        for &q in &[0.0, 0.4 * s, 3.0 * s] {
            let want = p2_marginal(model, q, phi, s * width);
            let e = rel_err(model.p2(q, phi), want);
            assert!(e < 1e-10, "{label}: P2({q}, {phi}) rel err {e:e}");
            worst_p2 = worst_p2.max(e);
        }
    }
    for &(theta, phi) in &[(0.0, 0.0), (0.4, 0.3), (1.2, 2.5), (1.5, 4.0)] {
        let w = from_spherical(theta, phi);
        let want = model.p22(w[0] / w[2], w[1] / w[2]) / w[2].powi(4);
        assert!(rel_err(model.d(w), want) < 1e-12, "{label}: D vs P22/cos⁴θ");
    }
    let thetas = [1e-3, 0.05, 0.3, 0.8, 1.2, 1.5, 1.57];
    let phis: &[f64] = if ax == ay { &[0.0] } else { &[0.0, 0.9, 2.0] };
    let worst_lambda = assert_lambda(
        model,
        model,
        ax.max(ay) * width,
        &thetas,
        phis,
        1e-10,
        label,
    );
    assert_sampler_density(model, 1e-6, label);
    let mut worst_moment: f64 = 0.0;
    for k in 1..=3 {
        for &phi in &[0.0f64, 1.1] {
            let s = (ax * phi.cos()).hypot(ay * phi.sin());
            if let Some(v) = model.slope_moment(k, phi) {
                let want = moment_integral(model, k, phi, s * width);
                let e = rel_err(v, want);
                assert!(e < 1e-10, "{label}: ν{} rel err {e:e}", 2 * k);
                worst_moment = worst_moment.max(e);
            }
        }
    }
    eprintln!("{label}: |∫D cos − 1| = {:.1e}, P2 {worst_p2:.1e}, Λ {worst_lambda:.1e}, moments {worst_moment:.1e}", (n - 1.0).abs());
    [(n - 1.0).abs(), worst_p2, worst_lambda, worst_moment]
}

/// The azimuth of a normal in [0, 2π).
pub fn azimuth(m: Vec3) -> f64 {
    m[1].atan2(m[0]).rem_euclid(std::f64::consts::TAU)
}
