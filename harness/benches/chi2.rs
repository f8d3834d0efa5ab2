//! Criterion benchmark of the chi-square oracle's observed counts (the
//! harness-overhead target: sampling + binning ≤ 1.15 × the bare sampler loop): samples/s of
//! GGX α = 0.3 normal sampling binned by `observe_batch` into the 128 × 64 cells (φ × cos θ)
//! that `mfh chi2 --resolution 64` bins into (rows at the lobe's cos θ quantiles,
//! `oracle::chi2::cells`), against the bare
//! loop — the same chunks, the same random streams drawn in the same blocks, the same sampler,
//! no binning — for
//!
//! - `vectorized`: the reference `Ggx`, whose `sample_wm_batch` is vectorized;
//! - `scalar_user`: a wrapper that implements only `sample_wm` (a renderer's own sampler),
//!   drawn through the default `sample_wm_batch` (a loop over the scalar method);
//!
//! each on 1 thread and on every thread of the machine; and, in the group `chi2_stages`, each
//! stage of the loop alone on 1 thread, per block of 256 samples (the uniforms, GGX's batch
//! sampler, GGX's batch visible-normal sampler at θi = 1 rad — the BSDF chi-square's — the
//! cell finder, the counting), so that the loop's time can be apportioned. Run:
//! `cargo bench -p mfh-harness --bench chi2` (`-- --quick` for a fast pass).

use criterion::{black_box, Criterion, Throughput};
use mfh_harness::oracle::chi2::{cells, observe_batch, CHUNK};
use mfh_harness::oracle::hemisphere_grid::{CellFinder, HemisphereGrid};
use mfh_harness::random::stream;
use mfh_reference::geometry::Vec3;
use mfh_reference::ndf::Ggx;
use mfh_reference::{Ndf, NormalSampler, VisibleNormalSampler};
use rayon::prelude::*;

/// 2²² samples: 64 chunks, enough for two threads to share evenly.
const SAMPLES: u64 = 1 << 22;
/// The block size of `observe_batch`.
const BATCH: usize = 256;

/// A sampler with only the scalar method: what a renderer author plugs in.
struct ScalarUser(Ggx);

impl Ndf for ScalarUser {
    fn d(&self, m: Vec3) -> f64 {
        self.0.d(m)
    }
}

impl NormalSampler for ScalarUser {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        self.0.sample_wm(u)
    }
}

/// The bare loop: `observe_batch`'s chunks, streams and blocks, summing m_z instead of binning.
fn bare(sampler: &dyn NormalSampler, samples: u64, seed: u64) -> f64 {
    (0..samples.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let mut rng = stream(seed, chunk);
            let (mut u, mut m) = ([[0.0; 2]; BATCH], [[0.0; 3]; BATCH]);
            let end = ((chunk + 1) * CHUNK).min(samples);
            let mut first = chunk * CHUNK;
            let mut sum = 0.0;
            while first < end {
                let n = (end - first).min(BATCH as u64) as usize;
                rng.fill_pairs(&mut u[..n]);
                sampler.sample_wm_batch(&u[..n], &mut m[..n]);
                sum += m[..n].iter().map(|m| m[2]).sum::<f64>();
                first += n as u64;
            }
            sum
        })
        .sum()
}

/// The cells `mfh chi2 --resolution 64` bins GGX α = 0.3 into: rows at its cos θ quantiles.
fn lobe_grid(ggx: &Ggx) -> HemisphereGrid {
    let lobe = mfh_harness::oracle::lobe::measure_density(&|m| ggx.pdf_wm(m));
    let pdf = |m: &[Vec3], out: &mut [f64]| {
        for (o, &m) in out.iter_mut().zip(m) {
            *o = ggx.pdf_wm(m);
        }
    };
    let (grid, _) = cells::layout(&pdf, &lobe, 64, &[], cells::Layout::FollowLobe);
    assert!(!grid.is_equal_area(), "the lobe's rows");
    grid
}

fn chi2_sampling(c: &mut Criterion) {
    let ggx = Ggx::new(0.3, 0.3).expect("valid roughness");
    let user = ScalarUser(ggx.clone());
    let grid = lobe_grid(&ggx);
    let threads = rayon::current_num_threads();
    let pools: Vec<(usize, rayon::ThreadPool)> = [1, threads]
        .into_iter()
        .map(|n| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("thread pool");
            (n, pool)
        })
        .collect();
    let mut group = c.benchmark_group("chi2_ggx_0.3");
    group.throughput(Throughput::Elements(SAMPLES));
    group.sample_size(10);
    group.measurement_time(std::time::Duration::from_secs(3));
    group.warm_up_time(std::time::Duration::from_secs(1));
    let samplers: [(&str, &dyn NormalSampler); 2] = [("vectorized", &ggx), ("scalar_user", &user)];
    for (name, sampler) in samplers {
        for (n, pool) in &pools {
            group.bench_function(format!("{name}/bare_{n}_threads"), |b| {
                b.iter(|| pool.install(|| black_box(bare(sampler, SAMPLES, 1))))
            });
            group.bench_function(format!("{name}/sample_and_bin_128x64_{n}_threads"), |b| {
                b.iter(|| {
                    pool.install(|| {
                        black_box(observe_batch(
                            &|u: &[[f64; 2]], m: &mut [Vec3]| sampler.sample_wm_batch(u, m),
                            grid.clone(),
                            SAMPLES,
                            1,
                        ))
                    })
                })
            });
        }
    }
    group.finish();
}

/// Each stage of `observe_batch`'s loop alone, on one block of [`BATCH`] samples of GGX
/// α = 0.3 (the blocks of the other stages made once, beforehand).
fn chi2_stages(c: &mut Criterion) {
    let ggx = Ggx::new(0.3, 0.3).expect("valid roughness");
    let finder = CellFinder::new(lobe_grid(&ggx));
    let mut rng = stream(1, 0);
    let (mut u, mut m, mut cells) = ([[0.0; 2]; BATCH], [[0.0; 3]; BATCH], [0usize; BATCH]);
    rng.fill_pairs(&mut u);
    ggx.sample_wm_batch(&u, &mut m);
    assert!(
        finder.cells_of(&m, &mut cells),
        "GGX samples are in the domain"
    );
    let mut counts = vec![0u64; finder.grid().cells()];
    let mut group = c.benchmark_group("chi2_stages");
    group.throughput(Throughput::Elements(BATCH as u64));
    group.measurement_time(std::time::Duration::from_secs(2));
    group.warm_up_time(std::time::Duration::from_millis(500));
    group.bench_function("uniforms", |b| b.iter(|| rng.fill_pairs(black_box(&mut u))));
    group.bench_function("ggx_sampler", |b| {
        b.iter(|| ggx.sample_wm_batch(black_box(&u), black_box(&mut m)))
    });
    let wi = mfh_reference::geometry::from_spherical(1.0, 0.0);
    let mut mv = [[0.0; 3]; BATCH];
    group.bench_function("ggx_visible_sampler", |b| {
        b.iter(|| ggx.sample_wm_visible_batch(black_box(wi), black_box(&u), black_box(&mut mv)))
    });
    group.bench_function("cell_finder", |b| {
        b.iter(|| finder.cells_of(black_box(&m), black_box(&mut cells)))
    });
    group.bench_function("counting", |b| {
        b.iter(|| {
            for &cell in black_box(&cells).iter() {
                counts[cell] += 1;
            }
        })
    });
    group.finish();
    black_box(counts);
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    chi2_stages(&mut c);
    chi2_sampling(&mut c);
    c.final_summary();
}
