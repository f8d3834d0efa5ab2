//! What the closed-form benchmarks share (`closed_forms.rs`, `other_documents.rs`): the swept
//! inputs, groups with per-element throughput, the sweep loop and the default settings.
#![allow(dead_code)] // each benchmark binary uses a part of it

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, SamplingMode, Throughput};
use mfh_reference::geometry::from_spherical;
use mfh_reference::ndf::{AngularProfile, Beckmann, Ggx, PiecewiseLinear};
use mfh_reference::{Ndf, Vec3};
use std::f64::consts::FRAC_PI_2;
use std::hint::black_box;
use std::time::Duration;

/// Inputs per iteration of the fast benchmarks.
pub const N: usize = 64;

/// θ of the swept directions: four near the ends (1e-6, 1e-3, π/2 − 1e-3, π/2 − 1e-6) and 60
/// evenly spread over (0, π/2).
pub fn thetas() -> [f64; N] {
    let mut t = [0.0; N];
    for (i, ti) in t.iter_mut().enumerate().take(N - 4) {
        *ti = (i as f64 + 0.5) / (N - 4) as f64 * FRAC_PI_2;
    }
    t[N - 4] = 1e-6;
    t[N - 3] = 1e-3;
    t[N - 2] = FRAC_PI_2 - 1e-3;
    t[N - 1] = FRAC_PI_2 - 1e-6;
    t
}

/// The fractional part of 0.1 + i/φ (φ the golden ratio): well spread over [0, 1).
pub fn golden(i: usize) -> f64 {
    (0.1 + i as f64 * 0.618_033_988_749_894_9).fract()
}

/// The swept directions: θ from `thetas`, φ by the golden-ratio sequence over [0, 2π).
pub fn directions() -> [Vec3; N] {
    let t = thetas();
    std::array::from_fn(|i| from_spherical(t[i], golden(i) * std::f64::consts::TAU))
}

/// A group whose benchmarks each sweep `n` inputs (criterion reports time per element).
pub fn group<'a>(c: &'a mut Criterion, name: &str, n: usize) -> BenchmarkGroup<'a, WallTime> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(n as u64));
    g
}

/// A group for slow (quadrature) routes: 10 flat samples.
pub fn slow_group<'a>(c: &'a mut Criterion, name: &str, n: usize) -> BenchmarkGroup<'a, WallTime> {
    let mut g = group(c, name, n);
    g.sample_size(10).sampling_mode(SamplingMode::Flat);
    g
}

/// Benchmarks `f` over the inputs `xs` (one iteration = one sweep).
pub fn over<T: Copy>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    id: &str,
    xs: &[T],
    f: impl Fn(T) -> f64,
) {
    g.bench_function(id, |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for x in black_box(xs) {
                acc += f(black_box(*x));
            }
            acc
        })
    });
}

/// A short default run: 20 samples, `measurement` of measurement and `warm_up` of warm-up per
/// benchmark (command-line options such as `--quick`, `--measurement-time` override these).
pub fn config(measurement: Duration, warm_up: Duration) -> Criterion {
    Criterion::default()
        .sample_size(20)
        .measurement_time(measurement)
        .warm_up_time(warm_up)
        .configure_from_args()
}

/// The piecewise-linear model of the benchmarks: the anisotropic blend (eq 1 of document 000) of
/// GGX α = 0.2 along x and Beckmann α = 0.4 along y, each discretized at 32 breakpoints.
pub fn piecewise_model() -> PiecewiseLinear {
    let ggx = Ggx::new(0.2, 0.2).expect("valid");
    let beckmann = Beckmann::new(0.4, 0.4).expect("valid");
    let x = AngularProfile::discretize(&|t| ggx.d(from_spherical(t, 0.0)), 32);
    let y = AngularProfile::discretize(&|t| beckmann.d(from_spherical(t, 0.0)), 32);
    PiecewiseLinear::new(x, Some(y)).expect("valid profiles")
}
