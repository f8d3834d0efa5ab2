//! Criterion benchmarks of the closed forms of documents 004 (GTR), 000 (piecewise-linear NDF and
//! blend), 002 (visible moments of Gaussian slopes) and 003 (spherical Gaussians, ASG, circular
//! Gaussians) at the level of each route: what `closed_forms.rs` does not already cover.
//!
//! `closed_forms.rs` measures D, Λ by every route at γ ∈ {1, 1.5, 2, 4}, `sample_wm` for GTR,
//! D / Λ / `sample_wm` of the piecewise-linear model and the blend, and the default visible
//! moments. This file adds: GTR Λ at γ = 0 and 3 and at α = 1e-4 and α → 1, G1 by every route
//! (`Gtr::g1_route`, the routes `implementation` and `spline` computing G1 directly), the spline
//! at γ > 4 (the clamp); the piecewise-linear samplers split into Algorithm 1 (φ) and Algorithm
//! 2 (θ | φ) and their cdfs (eq 7, 8–9), G1 by each Λ route; the blend's G1; every visible-moment
//! route of document 002 including near-singular covariance; and everything of document 003.
//!
//! Every benchmark sweeps a fixed set of inputs per iteration (64 unless the name says
//! otherwise; quadrature routes fewer); criterion's `time` is per sweep and its `thrpt` in
//! evaluations per second, so ns per evaluation = time / inputs. Names read
//! `quantity/family/parameters[/route]`.
//!
//! Run: `cargo bench -p mfh-harness --bench other_documents` (a few minutes), `-- --quick` for a
//! fast pass, or with a filter (`-- sg/`).

mod common;

use common::{config, directions, golden, group, over, piecewise_model, slow_group, thetas, N};
use criterion::Criterion;
use mfh_reference::geometry::from_spherical;
use mfh_reference::model::VisibleSlopeMoments;
use mfh_reference::ndf::gtr::Gtr;
use mfh_reference::ndf::{Beckmann, Blend, Ggx};
use mfh_reference::sg::circular::{self, CircularGaussian};
use mfh_reference::sg::{Asg, Sg};
use mfh_reference::slopes::gaussian::GaussianSlopes;
use mfh_reference::{Smith, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::time::Duration;

/// Directions over the whole sphere (for SG evaluation): cos θ evenly spread over (−1, 1).
fn sphere_directions() -> [Vec3; N] {
    std::array::from_fn(|i| {
        let z = -1.0 + (2.0 * i as f64 + 1.0) / N as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden(i) * std::f64::consts::TAU;
        [r * phi.cos(), r * phi.sin(), z]
    })
}

/// 64 numbers in [0, 1): u by the golden-ratio sequence, with 1e-9 and 1 − 1e-9 at the ends.
fn uniforms() -> [f64; N] {
    std::array::from_fn(|i| match i {
        0 => 1e-9,
        _ if i == N - 1 => 1.0 - 1e-9,
        _ => golden(i),
    })
}

/// GTR (document 004): Λ by every route at γ = 0 and 3 (closed_forms.rs has 1, 1.5, 2, 4), Λ at
/// the ends of the α range, G1 by every route, the spline at non-integer γ and past the γ > 4
/// clamp.
fn bench_gtr(c: &mut Criterion) {
    let dirs = directions();
    let mut g = group(c, "lambda/gtr", N);
    for (gamma, alpha) in [
        (0.0, 0.3),
        (3.0, 0.3),
        (2.0, 1e-4),
        (3.0, 1e-4),
        (3.0, 0.999),
    ] {
        let m = Gtr::new(gamma, alpha).expect("valid GTR");
        for route in m.lambda_routes() {
            if m.lambda_route(from_spherical(1.0, 0.0), route).is_err() {
                continue;
            }
            over(
                &mut g,
                &format!("gamma={gamma},alpha={alpha}/{route}"),
                &dirs,
                |w| m.lambda_route(w, route).expect("checked route"),
            );
        }
    }
    for gamma in [0.5, 2.5, 7.0, 10.0] {
        let m = Gtr::new(gamma, 0.3).expect("valid GTR");
        over(
            &mut g,
            &format!("gamma={gamma},alpha=0.3/spline"),
            &dirs,
            |w| {
                m.lambda_route(w, "spline")
                    .expect("spline applies to every γ")
            },
        );
    }
    g.finish();

    let mut g = group(c, "g1/gtr", N);
    for gamma in [0.0, 1.0, 2.0, 3.0, 4.0, 2.5, 7.0] {
        let m = Gtr::new(gamma, 0.3).expect("valid GTR");
        for route in m.lambda_routes() {
            if m.g1_route(from_spherical(1.0, 0.0), route).is_err() {
                continue;
            }
            over(
                &mut g,
                &format!("gamma={gamma},alpha=0.3/{route}"),
                &dirs,
                |w| m.g1_route(w, route).expect("checked route"),
            );
        }
    }
    g.finish();

    let us = uniforms();
    let pairs: Vec<[f64; 2]> = (0..N).map(|i| [golden(i + 7), us[i]]).collect();
    let mut g = group(c, "sample_wm/gtr", N);
    for (gamma, alpha) in [(0.0, 0.3), (1.0, 0.3), (3.0, 1e-4), (10.0, 0.999)] {
        let m = Gtr::new(gamma, alpha).expect("valid GTR");
        over(
            &mut g,
            &format!("gamma={gamma},alpha={alpha}"),
            &pairs,
            |u| {
                use mfh_reference::NormalSampler;
                m.sample_wm(u)[2]
            },
        );
    }
    g.finish();
}

/// Piecewise-linear (document 000): Algorithm 1 (φ), Algorithm 2 (θ | φ), the cdfs of eq 7 and
/// eq 8–9, and G1 by each Λ route.
fn bench_piecewise(c: &mut Criterion) {
    let m = piecewise_model();
    let us = uniforms();
    let phis: Vec<f64> = (0..N)
        .map(|i| golden(i + 3) * std::f64::consts::TAU)
        .collect();
    let pairs: Vec<(f64, f64)> = (0..N).map(|i| (us[i], phis[i])).collect();
    let params = "ggx0.2+beckmann0.4,n=32";
    let mut g = group(c, "sample/piecewise_linear", N);
    over(&mut g, &format!("{params}/algorithm1_phi"), &us, |u| {
        m.sample_phi(u)
    });
    over(
        &mut g,
        &format!("{params}/algorithm2_theta"),
        &pairs,
        |(u, phi)| m.sample_theta(u, phi),
    );
    over(&mut g, &format!("{params}/cdf_phi_eq7"), &phis, |phi| {
        m.cdf_phi(phi)
    });
    let tp: Vec<(f64, f64)> = thetas().iter().zip(&phis).map(|(&t, &p)| (t, p)).collect();
    over(
        &mut g,
        &format!("{params}/cdf_theta_eq8_9"),
        &tp,
        |(t, phi)| m.cdf_theta(t, phi),
    );
    g.finish();

    // G1 = 1/(1 + Λ) by each route over all 64 directions (ends included: since the
    // co-angle fix, `exact` and `slope_space` cost ~0.1 ms at θ = 1e-6 too).
    let dirs = directions();
    let mut g = slow_group(c, "g1/piecewise_linear", N);
    for route in [
        "exact",
        "domain_split",
        "domain_split_adaptive",
        "slope_space",
    ] {
        over(&mut g, &format!("{params}/{route}"), &dirs, |w| {
            1.0 / (1.0 + m.lambda_route(w, route).expect("listed route"))
        });
    }
    g.finish();

    let blend = Blend::new(
        Box::new(Ggx::new(0.2, 0.2).expect("valid")),
        Box::new(Beckmann::new(0.4, 0.4).expect("valid")),
    )
    .expect("valid blend");
    let mut g = slow_group(c, "g1/blend", N);
    over(&mut g, "ggx0.2+beckmann0.4/exact", &dirs, |w| {
        blend.g1(w, [0.0, 0.0, 1.0])
    });
    g.finish();
}

/// Gaussian slopes (document 002): the visible moments by every route, for a regular covariance,
/// a correlation of 1 − 1e-9 and a variance ratio of 1e-8.
fn bench_gaussian_slopes(c: &mut Criterion) {
    let dirs = directions();
    let cases = [
        (
            "mean=[0.1,-0.05],cov=[[0.04,0.01],[0.01,0.09]]",
            [0.1, -0.05],
            [[0.04, 0.01], [0.01, 0.09]],
        ),
        (
            "mean=[0.3,0.2],rho=1-1e-9",
            [0.3, 0.2],
            [[0.04, 0.04 * (1.0 - 1e-9)], [0.04 * (1.0 - 1e-9), 0.04]],
        ),
        (
            "mean=[0,0],cov=diag(0.25,2.5e-9)",
            [0.0, 0.0],
            [[0.25, 0.0], [0.0, 2.5e-9]],
        ),
    ];
    let mut g = group(c, "visible_moments/gaussian_slopes", N);
    for (params, mean, cov) in cases {
        let m = GaussianSlopes::new(mean, cov).expect("valid");
        for route in m.visible_moments_routes() {
            over(&mut g, &format!("{params}/{route}"), &dirs, |w| {
                let v = m.visible_moments_route(w, route).expect("upper hemisphere");
                v.mean[0] + v.cov[1][1]
            });
        }
    }
    g.finish();
}

/// A unit SG axis tilted θ from +z.
fn axis(theta: f64, phi: f64) -> Vec3 {
    from_spherical(theta, phi)
}

/// Spherical Gaussians (document 003 §1–2): evaluation, inner product (closed form, printed, and
/// quadrature) for sharpness 1 … 1e4, vector product, integral, cap integral and cap products,
/// clamped-cosine inner product, lobe warp.
fn bench_sg(c: &mut Criterion) {
    let sph = sphere_directions();
    let sharpnesses = [1.0, 100.0, 1e4];
    let mut g = group(c, "sg_eval/sg", N);
    for l in sharpnesses {
        let a = Sg::new(axis(0.4, 0.3), l, 1.5).expect("valid SG");
        over(&mut g, &format!("lambda={l}"), &sph, |v| a.eval(v));
    }
    g.finish();

    // Partner lobes: axes 64 directions over the sphere, sharpness fixed per benchmark.
    // The lobe of sharpness l and its partners of sharpness 0.7 l along the directions `sph`.
    let partners = |l: f64| {
        let a = Sg::new(axis(0.4, 0.3), l, 1.5).expect("valid SG");
        let bs: Vec<Sg> = sph
            .iter()
            .map(|&p| Sg::new(p, l * 0.7, 0.8).expect("valid SG"))
            .collect();
        (a, bs)
    };
    let mut g = group(c, "sg_inner/sg", N);
    for l in sharpnesses {
        let (a, bs) = partners(l);
        over(&mut g, &format!("lambda={l}/default"), &bs, |b| a.inner(&b));
        over(&mut g, &format!("lambda={l}/printed"), &bs, |b| {
            a.inner_printed(&b)
        });
    }
    g.finish();
    let mut g = group(c, "sg_product/sg", N);
    for l in sharpnesses {
        let (a, bs) = partners(l);
        over(&mut g, &format!("lambda={l}"), &bs, |b| {
            a.product(&b).amplitude()
        });
    }
    g.finish();

    // Sharpness spread log-uniformly over [1e-3, 1e4].
    let lobes: Vec<Sg> = (0..N)
        .map(|i| {
            let l = 10f64.powf(-3.0 + 7.0 * i as f64 / (N - 1) as f64);
            Sg::new(sph[i], l, 1.0).expect("valid SG")
        })
        .collect();
    let caps: Vec<(Sg, f64)> = lobes
        .iter()
        .enumerate()
        .map(|(i, &s)| (s, PI * golden(i + 11)))
        .collect();
    let n = [0.0, 0.0, 1.0];
    let mut g = group(c, "sg_integral/sg", N);
    over(&mut g, "lambda=1e-3..1e4/sphere", &lobes, |s| s.integral());
    over(&mut g, "lambda=1e-3..1e4/cap", &caps, |(s, t)| {
        s.cap_integral(t).expect("valid cap")
    });
    over(&mut g, "lambda=1e-3..1e4/cap_product", &caps, |(s, t)| {
        s.cap_product(t).expect("valid cap").amplitude()
    });
    over(
        &mut g,
        "lambda=1e-3..1e4/cap_product_matched",
        &caps,
        |(s, t)| s.cap_product_matched(t).expect("valid cap").amplitude(),
    );
    over(&mut g, "lambda=1e-3..1e4/clamped_cosine_fit", &lobes, |s| {
        s.clamped_cosine_inner(n).expect("unit n")
    });
    g.finish();
    let mut g = group(c, "sg_warp/sg", N);
    let views: Vec<(Sg, Vec3)> = lobes
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let p = axis(0.3 + 0.5 * golden(i), 0.0);
            let o = axis(0.6 * golden(i + 5), PI);
            (Sg::new(p, s.sharpness(), 1.0).expect("valid SG"), o)
        })
        .collect();
    over(&mut g, "lambda=1e-3..1e4", &views, |(s, o)| {
        s.warp(o).expect("p not ⊥ o").sharpness()
    });
    g.finish();

    // Quadrature (`_exact`) routes: 4 lobes (sharpness 1e-3, 1, 100, 1e4).
    let few: Vec<Sg> = [1e-3, 1.0, 100.0, 1e4]
        .iter()
        .map(|&l| Sg::new(axis(0.7, 0.2), l, 1.0).expect("valid SG"))
        .collect();
    let partner = |s: &Sg| Sg::new(axis(0.9, 1.0), s.sharpness(), 1.0).expect("valid SG");
    let mut g = slow_group(c, "sg_exact/sg", few.len());
    over(&mut g, "lambda=1e-3,1,100,1e4/integral_exact", &few, |s| {
        s.integral_exact()
    });
    over(&mut g, "lambda=1e-3,1,100,1e4/inner_exact", &few, |s| {
        s.inner_exact(&partner(&s))
    });
    over(
        &mut g,
        "lambda=1e-3,1,100,1e4/cap_integral_exact",
        &few,
        |s| s.cap_integral_exact(1.0).expect("valid cap"),
    );
    over(
        &mut g,
        "lambda=1e-3,1,100,1e4/clamped_cosine_exact",
        &few,
        |s| s.clamped_cosine_inner_exact(n).expect("unit n"),
    );
    g.finish();
}

/// An ASG with frame rotated about z by `angle` and tilted, bandwidths [λ, μ].
fn asg(bandwidths: [f64; 2], tilt: f64) -> Asg {
    let z = axis(tilt, 0.5);
    let x = axis(tilt + FRAC_PI_2, 0.5);
    let y = [
        z[1] * x[2] - z[2] * x[1],
        z[2] * x[0] - z[0] * x[2],
        z[0] * x[1] - z[1] * x[0],
    ];
    Asg::new(x, y, z, bandwidths, 1.3).expect("valid ASG")
}

/// Anisotropic SGs (document 003 §3): evaluation, the integral (approximation, large-bandwidth
/// form, exact), the product approximation, the ASG–SG convolution (approximation and exact).
fn bench_asg(c: &mut Criterion) {
    let sph = sphere_directions();
    let mut g = group(c, "asg_eval/asg", N);
    let a = asg([10.0, 2.0], 0.3);
    over(&mut g, "bandwidths=[10,2]", &sph, |v| a.eval(v));
    g.finish();

    // Bandwidths log-spread over [1e-2, 1e4] in both λ and μ.
    let spread: Vec<Asg> = (0..N)
        .map(|i| {
            let l = 10f64.powf(-2.0 + 6.0 * golden(i));
            let m = 10f64.powf(-2.0 + 6.0 * golden(i + 17));
            asg([l, m], 0.2)
        })
        .collect();
    let mut g = group(c, "asg_integral/asg", N);
    over(&mut g, "bandwidths=1e-2..1e4/default", &spread, |a| {
        a.integral().expect("bandwidths > 0")
    });
    over(
        &mut g,
        "bandwidths=1e-2..1e4/large_bandwidth",
        &spread,
        |a| a.integral_large_bandwidth().expect("bandwidths > 0"),
    );
    g.finish();
    let mut g = slow_group(c, "asg_integral/asg", 8);
    let eight: Vec<Asg> = spread[..8].to_vec();
    over(&mut g, "bandwidths=1e-2..1e4/exact", &eight, |a| {
        a.integral_exact()
    });
    g.finish();

    let mut g = group(c, "asg_product/asg", N);
    let pairs: Vec<(Asg, Asg)> = (0..N)
        .map(|i| {
            let b = 10f64.powf(3.0 * golden(i));
            (
                asg([b, 0.3 * b], 0.1),
                asg([0.5 * b, 2.0 * b], 0.1 + 0.4 * golden(i + 9)),
            )
        })
        .collect();
    over(&mut g, "bandwidths=1..1e3", &pairs, |(a, b)| {
        a.product(&b).map(|p| p.amplitude()).unwrap_or(0.0)
    });
    g.finish();

    let sgs: Vec<(Asg, Sg)> = (0..N)
        .map(|i| {
            let nu = 10f64.powf(-0.5 + 2.5 * golden(i + 4));
            let s = Sg::new(sph[(i * 7) % N], 2.0 * nu, 1.0).expect("valid SG");
            (asg([3.0, 1.5], 0.2), s)
        })
        .collect();
    let mut g = group(c, "asg_sg_convolution/asg", N);
    over(
        &mut g,
        "bandwidths=[3,1.5],nu=0.3..100/default",
        &sgs,
        |(a, s)| a.convolve_sg(&s).expect("valid"),
    );
    g.finish();
    let four: Vec<(Asg, Sg)> = [0.3, 3.0, 30.0, 100.0]
        .iter()
        .map(|&nu| {
            let s = Sg::new(axis(0.5, 1.0), 2.0 * nu, 1.0).expect("valid SG");
            (asg([3.0, 1.5], 0.2), s)
        })
        .collect();
    let mut g = slow_group(c, "asg_sg_convolution/asg", four.len());
    over(
        &mut g,
        "bandwidths=[3,1.5],nu=0.3,3,30,100/exact",
        &four,
        |(a, s)| a.convolve_sg_exact(&s),
    );
    g.finish();
}

/// Circular Gaussians and von Mises (document 003 §4): the scaled I₀, the von Mises integral, the
/// product, the period and interval integrals (erf route and quadrature), the SG decomposition.
fn bench_circular(c: &mut Criterion) {
    // κ log-spread over [1e-3, 1e4] (both branches of I₀: series below 20, asymptotic above).
    let kappas: Vec<f64> = (0..N)
        .map(|i| 10f64.powf(-3.0 + 7.0 * i as f64 / (N - 1) as f64))
        .collect();
    let mut g = group(c, "von_mises/circular", N);
    over(
        &mut g,
        "kappa=1e-3..1e4/bessel_i0_scaled",
        &kappas,
        circular::bessel_i0_scaled,
    );
    over(&mut g, "kappa=1e-3..1e4/integral_scaled", &kappas, |k| {
        circular::von_mises_integral_scaled(k)
    });
    over(&mut g, "kappa=1e-3..700/integral", &kappas, |k| {
        circular::von_mises_integral(k.min(700.0))
    });
    g.finish();

    let gs: Vec<CircularGaussian> = (0..N)
        .map(|i| {
            let sigma = 10f64.powf(-2.0 + 2.0 * golden(i));
            CircularGaussian::new(-1.4 + 2.8 * golden(i + 3), sigma).expect("valid")
        })
        .collect();
    let other = CircularGaussian::new(0.3, 0.2).expect("valid");
    let mut g = group(c, "circular_gaussian/circular", N);
    over(&mut g, "sigma=1e-2..1/eval", &gs, |cg| cg.eval(0.2));
    over(&mut g, "sigma=1e-2..1/product", &gs, |cg| {
        cg.product(&other).map(|(a, _)| a).unwrap_or(0.0)
    });
    over(&mut g, "sigma=1e-2..1/integral_period", &gs, |cg| {
        cg.integral_period()
    });
    over(&mut g, "sigma=1e-2..1/integral_interval_erf", &gs, |cg| {
        cg.integral_interval(-FRAC_PI_2, FRAC_PI_2)
    });
    let angles: Vec<(f64, f64)> = (0..N)
        .map(|i| (-1.5 + 3.0 * golden(i), -PI + 2.0 * PI * golden(i + 5)))
        .collect();
    over(&mut g, "sigma=0.3/decompose_sg", &angles, |(t, p)| {
        let (a, b) = circular::decompose_sg(t, p, 0.4, 0.1, 0.3).expect("inside (−π/2, π/2)");
        a * b
    });
    g.finish();
    let mut g = slow_group(c, "circular_gaussian/circular", 8);
    let eight: Vec<CircularGaussian> = gs[..8].to_vec();
    over(
        &mut g,
        "sigma=1e-2..1/integral_interval_exact",
        &eight,
        |cg| cg.integral_interval_exact(-FRAC_PI_2, FRAC_PI_2),
    );
    g.finish();
}

fn main() {
    let mut c = config(Duration::from_millis(500), Duration::from_millis(200));
    bench_gtr(&mut c);
    bench_piecewise(&mut c);
    bench_gaussian_slopes(&mut c);
    bench_sg(&mut c);
    bench_asg(&mut c);
    bench_circular(&mut c);
    c.final_summary();
}
