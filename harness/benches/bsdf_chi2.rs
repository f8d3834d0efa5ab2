//! Criterion benchmark of the BSDF chi-square's sampling and binning (the target: the
//! BSDF chi-square of the reference GGX dielectric, visible normals, within 2× of the NDF
//! chi-square's samples/s): samples/s of
//!
//! - `bsdf_chi2/dielectric_ggx_0.3`: `observe_sphere` of the rough dielectric (η 1.5, GGX
//!   α 0.3, visible normals, θi = 1 rad from outside) into the cells `mfh chi2 --bsdf …
//!   --resolution 32` bins into (each hemisphere's rows and columns at its lobe's quantiles);
//! - `bsdf_chi2/ndf_ggx_0.3`: `observe_batch` of GGX α 0.3's normal sampler into its 64 × 32
//!   lobe cells (`mfh chi2 --resolution 32`), the rate the target compares with;
//!
//! on every thread of the machine; and, in the group `bsdf_stages`, each stage of the BSDF's
//! loop alone on 1 thread: per block of 1024 samples, the uniforms (three a sample) and the
//! dielectric's `sample_wo_batch`; and `observe_sphere`'s binning of those directions over
//! 2²² samples (a sampler that copies them). Run: `cargo bench -p mfh-harness --bench bsdf_chi2` (`--
//! --quick` for a fast pass).

use criterion::{black_box, Criterion, Throughput};
use mfh_harness::oracle::chi2::sphere::{chi2_masses, observe_sphere, SphereMasses};
use mfh_harness::oracle::chi2::sphere_finder::SphereFinder;
use mfh_harness::oracle::chi2::{cells, observe_batch};
use mfh_harness::oracle::hemisphere_grid::CellFinder;
use mfh_harness::random::stream;
use mfh_reference::bsdf::microfacet::{Microfacet, Sampling};
use mfh_reference::bsdf::spec::BsdfSpec;
use mfh_reference::bsdf::{Bsdf, Directions};
use mfh_reference::geometry::Vec3;
use mfh_reference::model::Masking;
use mfh_reference::ndf::Ggx;
use mfh_reference::NormalSampler;
use std::sync::Arc;

/// 2²² samples: 64 chunks, enough for two threads to share evenly.
const SAMPLES: u64 = 1 << 22;
/// The block size of `draw_chunks`.
const BLOCK: usize = 1024;
/// The incidence, θi in radians from the normal (φi = 0), from outside.
const THETA_I: f64 = 1.0;

fn dielectric() -> Arc<dyn Bsdf> {
    let spec: BsdfSpec = serde_json::from_str(
        r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},
            "sampling":"visible_normals"}"#,
    )
    .expect("a valid spec");
    spec.build().expect("a valid BSDF")
}

fn wi() -> Vec3 {
    [THETA_I.sin(), 0.0, THETA_I.cos()]
}

/// Both hemispheres' lobe cells at resolution 32 (and their masses, unused here).
fn sphere_cells(bsdf: &dyn Bsdf) -> SphereMasses {
    let wi = wi();
    chi2_masses(
        &|wo: &[Vec3], out: &mut [f64]| bsdf.pdf_batch(&vec![wi; wo.len()], wo, out),
        32,
        SAMPLES,
    )
}

fn bsdf_against_ndf(c: &mut Criterion) {
    let bsdf = dielectric();
    let masses = sphere_cells(bsdf.as_ref());
    let grids = (masses.upper_grid, masses.lower_grid);
    let ggx = Ggx::new(0.3, 0.3).expect("valid roughness");
    let lobe = mfh_harness::oracle::lobe::measure_density(&|m| ggx.pdf_wm(m));
    let pdf = |m: &[Vec3], out: &mut [f64]| {
        for (o, &m) in out.iter_mut().zip(m) {
            *o = ggx.pdf_wm(m);
        }
    };
    let (grid, _) = cells::layout(&pdf, &lobe, 32, &[], cells::Layout::FollowLobe);
    let wi = wi();
    let mut group = c.benchmark_group("bsdf_chi2");
    group.throughput(Throughput::Elements(SAMPLES));
    group.sample_size(10);
    group.measurement_time(std::time::Duration::from_secs(3));
    group.warm_up_time(std::time::Duration::from_secs(1));
    group.bench_function("dielectric_ggx_0.3", |b| {
        b.iter(|| {
            black_box(observe_sphere(
                &|u: &[[f64; 3]], out: &mut Directions| bsdf.sample_wo_batch(wi, u, out),
                grids.clone(),
                SAMPLES,
                1,
            ))
        })
    });
    group.bench_function("ndf_ggx_0.3", |b| {
        b.iter(|| {
            black_box(observe_batch(
                &|u: &[[f64; 2]], m: &mut [Vec3]| ggx.sample_wm_batch(u, m),
                grid.clone(),
                SAMPLES,
                1,
            ))
        })
    });
    group.finish();
}

/// Each stage of the BSDF chi-square's loop alone, on one thread.
fn bsdf_stages(c: &mut Criterion) {
    let bsdf = dielectric();
    let masses = sphere_cells(bsdf.as_ref());
    let grids = (masses.upper_grid, masses.lower_grid);
    let wi = wi();
    let mut rng = stream(1, 0);
    let mut pairs = vec![[0.0; 2]; 3 * BLOCK / 2];
    rng.fill_pairs(&mut pairs);
    let flat: Vec<f64> = pairs.iter().flatten().copied().collect();
    let u: Vec<[f64; 3]> = flat.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let mut out = Directions::new(BLOCK);
    bsdf.sample_wo_batch(wi, &u, &mut out);
    let sampled = out.clone();
    let mut group = c.benchmark_group("bsdf_stages");
    group.throughput(Throughput::Elements(BLOCK as u64));
    group.measurement_time(std::time::Duration::from_secs(2));
    group.warm_up_time(std::time::Duration::from_millis(500));
    group.bench_function("uniforms", |b| {
        b.iter(|| rng.fill_pairs(black_box(&mut pairs)))
    });
    // The normals alone (the visible-normal sampler and the side tests), for the share of
    // the scatter.
    let ggx: Arc<dyn mfh_reference::Ndf> = Arc::new(Ggx::new(0.3, 0.3).expect("valid roughness"));
    let microfacet = Microfacet::new(
        ggx,
        "ggx",
        Masking::HeightCorrelated,
        Sampling::VisibleNormals,
    )
    .expect("GGX has Λ and a visible-normal sampler");
    let ggx_model = Ggx::new(0.3, 0.3).expect("valid roughness");
    let pairs3: Vec<[f64; 2]> = u.iter().map(|u| [u[1], u[2]]).collect();
    let mut normals = vec![[0.0; 3]; BLOCK];
    group.bench_function("ggx_visible_batch", |b| {
        b.iter(|| {
            mfh_reference::VisibleNormalSampler::sample_wm_visible_batch(
                &ggx_model,
                wi,
                black_box(&pairs3),
                black_box(&mut normals),
            )
        })
    });
    let mut normals_out = vec![None; BLOCK];
    group.bench_function("microfacet_sample_m_batch", |b| {
        b.iter(|| microfacet.sample_m_batch(wi, black_box(&u), black_box(&mut normals_out)))
    });
    group.bench_function("dielectric_sample_wo_batch", |b| {
        b.iter(|| bsdf.sample_wo_batch(wi, black_box(&u), black_box(&mut out)))
    });
    // The transmission hemisphere's cell finder alone, on the block's transmitted directions
    // (mirrored, as observe_sphere hands them).
    let lower: Vec<Vec3> = sampled
        .iter()
        .flatten()
        .filter(|w| w[2] < 0.0)
        .map(|w| [w[0], w[1], -w[2]])
        .collect();
    let finder = CellFinder::new(grids.1.clone());
    let mut cells = vec![0usize; lower.len()];
    group.throughput(Throughput::Elements(lower.len() as u64));
    group.bench_function("lower_cell_finder", |b| {
        b.iter(|| finder.cells_of(black_box(&lower), black_box(&mut cells)))
    });
    // Both hemispheres' finder on the whole block, as observe_sphere bins it.
    let sphere = SphereFinder::new(grids.0.clone(), grids.1.clone());
    let mut sphere_cells = vec![0usize; sampled.len()];
    group.throughput(Throughput::Elements(sampled.len() as u64));
    group.bench_function("sphere_cell_finder", |b| {
        b.iter(|| sphere.cells_of(black_box(&sampled), black_box(&mut sphere_cells)))
    });
    // observe_sphere on this thread with a sampler that copies the block sampled above: the
    // split into hemispheres, the two cell finders and the counting (and the finders' tables,
    // built once a run).
    group.throughput(Throughput::Elements(SAMPLES));
    group.sample_size(10);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    group.bench_function("binning", |b| {
        b.iter(|| {
            pool.install(|| {
                black_box(observe_sphere(
                    &|_: &[[f64; 3]], out: &mut Directions| {
                        let ([x, y, z], flags) = sampled.components();
                        for c in out.as_mut().chunks(BLOCK) {
                            let n = c.len();
                            let [cx, cy, cz] = c.xyz;
                            cx.copy_from_slice(&x[..n]);
                            cy.copy_from_slice(&y[..n]);
                            cz.copy_from_slice(&z[..n]);
                            c.sampled.copy_from_slice(&flags[..n]);
                        }
                    },
                    grids.clone(),
                    SAMPLES,
                    1,
                ))
            })
        })
    });
    group.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bsdf_stages(&mut c);
    bsdf_against_ndf(&mut c);
    c.final_summary();
}
