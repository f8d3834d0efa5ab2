//! Criterion benchmark of the chi-square oracle: samples/s of GGX α = 0.3 normal sampling and
//! binning into the 128 × 64-cell (φ × cos θ) grid, against the bare sampling loop.

use criterion::{black_box, Criterion, Throughput};
use mfh_harness::oracle::chi2::{observe, stream};
use mfh_harness::oracle::domain::HemisphereGrid;
use mfh_reference::ndf::Ggx;
use mfh_reference::NormalSampler;
use rand_core::RngCore;

const SAMPLES: u64 = 1 << 20;

fn uniform(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn chi2_sampling(c: &mut Criterion) {
    let ggx = Ggx::new(0.3, 0.3).expect("valid roughness");
    let grid = HemisphereGrid::new(64).expect("resolution ≥ 1");
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let mut group = c.benchmark_group("chi2_ggx_0.3");
    group.throughput(Throughput::Elements(SAMPLES));
    group.sample_size(10);
    group.bench_function("bare_sampling_1_thread", |b| {
        b.iter(|| {
            let mut rng = stream(1, 0);
            let mut sum = 0.0;
            for _ in 0..SAMPLES {
                let m = ggx.sample_wm([uniform(&mut rng), uniform(&mut rng)]);
                sum += m[2];
            }
            black_box(sum)
        })
    });
    group.bench_function("sample_and_bin_128x64_1_thread", |b| {
        b.iter(|| single.install(|| black_box(observe(&|u| ggx.sample_wm(u), grid, SAMPLES, 1))))
    });
    group.bench_function("sample_and_bin_128x64_all_threads", |b| {
        b.iter(|| black_box(observe(&|u| ggx.sample_wm(u), grid, SAMPLES, 1)))
    });
    group.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    chi2_sampling(&mut c);
    c.final_summary();
}
