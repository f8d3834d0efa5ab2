//! The CI profile's cost: `Audit::of(model).profile(Profile::Ci)` on one isotropic model with
//! D, Λ and normal sampling (reference GGX α = 0.3, checked against its own spec). Target:
//! ≤ 10 s on 2 cores. `cargo bench -p mfh-harness --bench gate`.

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{criterion_group, criterion_main, Criterion};
use mfh_harness::{Audit, Profile};
use mfh_reference::ndf::Ggx;

fn ci_profile(c: &mut Criterion) {
    let ggx = Ggx::new(0.3, 0.3).expect("valid");
    let mut group = c.benchmark_group("gate");
    group.sample_size(10);
    group.bench_function("ci_profile_ggx_0.3", |b| {
        b.iter(|| {
            let report = Audit::of(&ggx)
                .profile(Profile::Ci)
                .against(r#"{"family":"ggx","alpha":0.3}"#)
                .run();
            assert!(report.passed());
            report.records.len()
        })
    });
    group.finish();
}

criterion_group!(benches, ci_profile);
criterion_main!(benches);
