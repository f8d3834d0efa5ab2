//! Criterion benchmarks of the closed forms: ns per evaluation of D, Smith Λ by every route,
//! `sample_wm` (and the visible-slope moments of Gaussian slopes), for every family, and the raw
//! special functions behind Λ.
//!
//! Every benchmark sweeps a fixed set of 64 inputs per iteration (directions with θ spread over
//! (0, π/2), near-normal and near-grazing included; or 64 points u ∈ [0, 1)² for the samplers),
//! so that branch-dependent costs (series versus continued fraction, the regimes of the stable
//! Λ) are averaged; one slow input weighs in at 1/64 of its cost (the piecewise-linear `exact`
//! and `domain_split_adaptive` routes spend ~0.1 s at θ = 1e-6, 10–60 µs elsewhere). The
//! piecewise-linear `slope_space` route (nested quadrature: 1–100 ms per Λ, > 15 min at
//! θ = 1e-5) is swept over 8 of the directions only. The throughput is the number of inputs:
//! criterion's `time` is per sweep, its `thrpt` in evaluations per second. Names read
//! `quantity/family/parameters[/route]`, e.g. `lambda/std/gamma=2.5/stable`.
//!
//! How Λ is called: the default route through `Smith::lambda(w)` (what a renderer calls);
//! Beckmann's, GGX's and the piecewise-linear model's other routes through
//! `Smith::lambda_route(w, name)`; the other Student routes as the route function of
//! `student_lambda::route(name, γ)` (looked up once) applied to the standardized cotangent of
//! w, so that the string dispatch and the σ of `lambda_route` (an atan2, needed by one printed
//! route only) are not charged to the route.
//!
//! Run: `cargo bench -p mfh-harness --bench closed_forms` (about three minutes), or with
//! `-- --quick` for a fast pass, or with a filter (`-- lambda/std`).

mod common;

use common::{config, directions, golden, over, piecewise_model, thetas, N};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, SamplingMode, Throughput};
use mfh_reference::geometry::from_spherical;
use mfh_reference::model::VisibleSlopeMoments;
use mfh_reference::ndf::gtr::Gtr;
use mfh_reference::ndf::student::Member;
use mfh_reference::ndf::{student_lambda, Beckmann, Blend, Ggx, Student};
use mfh_reference::slopes::gaussian::GaussianSlopes;
use mfh_reference::special::{hyp2f1, student_tail};
use mfh_reference::{Ndf, NormalSampler, Smith, Vec3};
use std::hint::black_box;
use std::time::Duration;

/// The roughness of every benchmarked model (isotropic).
const ALPHA: f64 = 0.3;

/// The shapes of the Student Λ route sweep.
const GAMMAS: [f64; 8] = [2.0, 2.5, 3.0, 3.5, 4.0, 7.5, 20.0, 1e4];

/// The piecewise-linear Λ route that is benchmarked on 8 directions only (see `bench_routed`).
const SLOW_ROUTE: &str = "slope_space";

/// The shape of the single-γ benchmarks (D, sample_wm, the other Student members).
const GAMMA: f64 = 2.5;

/// The swept sampler inputs: u1 by the golden-ratio sequence, u2 evenly spread over (0, 1)
/// with 1e-9 and 1 − 1e-9 at the ends.
fn uniforms() -> [[f64; 2]; N] {
    std::array::from_fn(|i| {
        let u2 = match i {
            0 => 1e-9,
            _ if i == N - 1 => 1.0 - 1e-9,
            _ => i as f64 / N as f64,
        };
        [golden(i), u2]
    })
}

/// A group of benchmarks that each sweep the 64 inputs.
fn group<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    common::group(c, name, N)
}

/// Benchmarks `f` over the 64 directions.
fn over_directions(g: &mut BenchmarkGroup<'_, WallTime>, id: &str, f: impl Fn(Vec3) -> f64) {
    over(g, id, &directions(), f);
}

/// Benchmarks `f` over 64 precomputed arguments (raw special functions).
fn over_arguments(
    g: &mut BenchmarkGroup<'_, WallTime>,
    id: &str,
    args: [f64; N],
    f: impl Fn(f64) -> f64,
) {
    over(g, id, &args, f);
}

/// Benchmarks `sample_wm` over the 64 points u.
fn over_uniforms(g: &mut BenchmarkGroup<'_, WallTime>, id: &str, s: &dyn NormalSampler) {
    let us = uniforms();
    g.bench_function(id, |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for u in black_box(&us) {
                acc += s.sample_wm(black_box(*u))[2];
            }
            acc
        })
    });
}

fn std_model(member: Member, gamma: f64) -> Student {
    Student::new(member, gamma, ALPHA, ALPHA).expect("valid Student parameters")
}

/// The blend model of the benchmarks: GGX α = 0.2 along x, Beckmann α = 0.4 along y.
fn blend_model() -> Blend {
    Blend::new(
        Box::new(Ggx::new(0.2, 0.2).expect("valid")),
        Box::new(Beckmann::new(0.4, 0.4).expect("valid")),
    )
    .expect("valid blend")
}

/// D, every Λ route and `sample_wm` of a model whose Λ routes all go through
/// `Smith::lambda_route` (Beckmann, GGX, piecewise-linear).
fn bench_routed<M: Ndf + Smith + NormalSampler>(
    c: &mut Criterion,
    family: &str,
    params: &str,
    m: &M,
) {
    let mut g = group(c, &format!("d/{family}"));
    over_directions(&mut g, params, |w| m.d(w));
    g.finish();

    let mut g = group(c, &format!("lambda/{family}"));
    let routes = m.lambda_routes();
    for &route in &routes {
        let id = format!("{params}/{route}");
        if route == routes[0] {
            over_directions(&mut g, &id, |w| m.lambda(w));
        } else if route != SLOW_ROUTE {
            over_directions(&mut g, &id, |w| {
                m.lambda_route(w, route).expect("listed route")
            });
        }
    }
    g.finish();

    if routes.contains(&SLOW_ROUTE) {
        // Nested adaptive quadrature: 1–100 ms per Λ, > 15 min at θ = 1e-5. Eight of the
        // swept directions (θ from 0.09 to 1.37), ten flat samples.
        let dirs = directions();
        let few: Vec<Vec3> = (0..8).map(|k| dirs[3 + 7 * k]).collect();
        let mut g = c.benchmark_group(format!("lambda/{family}"));
        g.throughput(Throughput::Elements(few.len() as u64))
            .sample_size(10)
            .sampling_mode(SamplingMode::Flat);
        g.bench_function(format!("{params}/{SLOW_ROUTE}"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for w in black_box(&few) {
                    acc += m
                        .lambda_route(black_box(*w), SLOW_ROUTE)
                        .expect("listed route");
                }
                acc
            })
        });
        g.finish();
    }

    let mut g = group(c, &format!("sample_wm/{family}"));
    over_uniforms(&mut g, params, m);
    g.finish();
}

fn bench_beckmann_ggx(c: &mut Criterion) {
    let params = format!("alpha={ALPHA}");
    bench_routed(
        c,
        "beckmann",
        &params,
        &Beckmann::new(ALPHA, ALPHA).expect("valid"),
    );
    bench_routed(c, "ggx", &params, &Ggx::new(ALPHA, ALPHA).expect("valid"));
}

/// STD: D and sample_wm at γ = 2.5; Λ by every route of `student_lambda::ROUTES` at every γ of
/// the sweep where the route applies.
fn bench_std(c: &mut Criterion) {
    let m = std_model(Member::Std, GAMMA);
    let params = format!("gamma={GAMMA}");
    let mut g = group(c, "d/std");
    over_directions(&mut g, &params, |w| m.d(w));
    g.finish();
    let mut g = group(c, "sample_wm/std");
    over_uniforms(&mut g, &params, &m);
    g.finish();

    let mut g = group(c, "lambda/std");
    for gamma in GAMMAS {
        let m = std_model(Member::Std, gamma);
        // Isotropic: σ along every azimuth is α (the STD roughness).
        let sigma = m.scales().0 / (gamma - 1.0).sqrt();
        for &(name, _) in student_lambda::ROUTES {
            let Ok(f) = student_lambda::route(name, gamma) else {
                continue;
            };
            let id = format!("gamma={gamma}/{name}");
            if name == "stable" {
                over_directions(&mut g, &id, |w| m.lambda(w));
            } else {
                over_directions(&mut g, &id, |w| {
                    f(gamma, m.standardized_cotangent(w), sigma)
                });
            }
        }
    }
    g.finish();
}

/// The other Student members: D, the default Λ and sample_wm.
fn bench_student_members(c: &mut Criterion) {
    let members = [
        (
            "hyper_cauchy",
            std_model(Member::HyperCauchy, GAMMA),
            format!("gamma={GAMMA}"),
        ),
        (
            "student_fixed_variance",
            std_model(Member::FixedVariance, GAMMA),
            format!("gamma={GAMMA}"),
        ),
        (
            "student_general",
            Student::general(4.0, GAMMA).expect("valid"),
            format!("b=4,c={GAMMA}"),
        ),
    ];
    for (family, m, params) in &members {
        let mut g = group(c, &format!("d/{family}"));
        over_directions(&mut g, params, |w| m.d(w));
        g.finish();
        let mut g = group(c, &format!("lambda/{family}"));
        over_directions(&mut g, &format!("{params}/stable"), |w| m.lambda(w));
        g.finish();
        let mut g = group(c, &format!("sample_wm/{family}"));
        over_uniforms(&mut g, params, m);
        g.finish();
    }
}

fn bench_piecewise_blend(c: &mut Criterion) {
    bench_routed(
        c,
        "piecewise_linear",
        "ggx0.2+beckmann0.4,n=32",
        &piecewise_model(),
    );

    // The blend has no sampler: D and Λ (its single route, exact) only.
    let m = blend_model();
    let params = "ggx0.2+beckmann0.4";
    let mut g = group(c, "d/blend");
    over_directions(&mut g, params, |w| m.d(w));
    g.finish();
    let mut g = group(c, "lambda/blend");
    over_directions(&mut g, &format!("{params}/exact"), |w| m.lambda(w));
    g.finish();
}

/// GTR (document 004): D and sample_wm at γ = 1.5, Λ by every route of `gtr_lambda::ROUTES` at
/// γ ∈ {1, 1.5, 2, 4} where it applies.
fn bench_gtr(c: &mut Criterion) {
    let m = Gtr::new(1.5, ALPHA).expect("valid GTR");
    let params = format!("gamma=1.5,alpha={ALPHA}");
    let mut g = group(c, "d/gtr");
    over_directions(&mut g, &params, |w| m.d(w));
    g.finish();
    let mut g = group(c, "sample_wm/gtr");
    over_uniforms(&mut g, &params, &m);
    g.finish();
    let mut g = group(c, "lambda/gtr");
    for gamma in [1.0, 1.5, 2.0, 4.0] {
        let m = Gtr::new(gamma, ALPHA).expect("valid GTR");
        for route in m.lambda_routes() {
            let probe = from_spherical(1.0, 0.0);
            if m.lambda_route(probe, route).is_err() {
                continue;
            }
            let id = format!("gamma={gamma},alpha={ALPHA}/{route}");
            if route == "exact" {
                over_directions(&mut g, &id, |w| m.lambda(w));
            } else {
                over_directions(&mut g, &id, |w| {
                    m.lambda_route(w, route).expect("checked route")
                });
            }
        }
    }
    g.finish();
}

/// Gaussian slopes (document 002): D, Λ and the moments of the visible slopes D_s (no sampler).
fn bench_gaussian_slopes(c: &mut Criterion) {
    let m = GaussianSlopes::new([0.1, -0.05], [[0.04, 0.01], [0.01, 0.09]]).expect("valid");
    let params = "mean=[0.1,-0.05],cov=[[0.04,0.01],[0.01,0.09]]";
    let mut g = group(c, "d/gaussian_slopes");
    over_directions(&mut g, params, |w| m.d(w));
    g.finish();
    let mut g = group(c, "lambda/gaussian_slopes");
    over_directions(&mut g, &format!("{params}/default"), |w| m.lambda(w));
    g.finish();
    let mut g = group(c, "visible_moments/gaussian_slopes");
    over_directions(&mut g, &format!("{params}/default"), |w| {
        let v = VisibleSlopeMoments::visible_moments(&m, w).expect("upper hemisphere");
        v.mean[0] + v.cov[1][1]
    });
    g.finish();
}

/// The raw special functions, on the arguments the models above give them: x = cot θ / s with
/// s = α √(γ − 1) (STD, α = 0.3), z = −x² for ₂F₁, a = cot θ / α for Beckmann.
fn bench_special(c: &mut Criterion) {
    // x = cot θ / s for the swept θ.
    let cotangents = |s: f64| thetas().map(|t| 1.0 / (t.tan() * s));
    let mut g = group(c, "special/hyp2f1_lambda");
    for gamma in GAMMAS {
        let z = cotangents(ALPHA * (gamma - 1.0).sqrt()).map(|x| -x * x);
        over_arguments(&mut g, &format!("gamma={gamma}"), z, |z| {
            hyp2f1::hyp2f1_lambda(gamma, z)
        });
    }
    g.finish();
    let mut g = group(c, "special/student_lambda");
    for gamma in GAMMAS {
        let x = cotangents(ALPHA * (gamma - 1.0).sqrt());
        over_arguments(&mut g, &format!("gamma={gamma}"), x, |x| {
            student_tail::student_lambda(gamma, x)
        });
    }
    g.finish();
    let mut g = group(c, "special/beckmann_lambda");
    over_arguments(&mut g, &format!("alpha={ALPHA}"), cotangents(ALPHA), |a| {
        student_tail::beckmann_lambda(a)
    });
    g.finish();
}

fn main() {
    let mut c = config(Duration::from_secs(1), Duration::from_millis(300));
    bench_beckmann_ggx(&mut c);
    bench_std(&mut c);
    bench_student_members(&mut c);
    bench_piecewise_blend(&mut c);
    bench_gtr(&mut c);
    bench_gaussian_slopes(&mut c);
    bench_special(&mut c);
    c.final_summary();
}
