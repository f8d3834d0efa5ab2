//! The whole-sphere BSDF chi-square's detection power alone (`bsdf.chi2`'s test, no albedo or
//! consistency check): the reference GGX dielectric (η = 1.5, visible normals) whose sampler
//! draws its normals from α(1 + ε) while its pdf is α's, at the oblique incidence of the audit
//! (θi = 1.0 rad from outside), R = 16 (`bsdf.chi2`'s), 10⁶ samples (the ci profile's), level
//! `STATISTICAL_ALPHA` (10⁻³), seeds 1–3. For α ∈ {0.01, 0.3, 1}, the smallest ε caught at
//! every seed (and every larger one tried), by the test's p-value (the statistic split into
//! the cos θ marginal's smooth components and the rest, `oracle/chi2/components.rs`) and by
//! Q(dof/2, χ²/2) of the whole table (the test before the split), from the same counts.
//!
//! ```text
//! cargo run --release -p mfh-harness --example bsdf_chi2_power [-- SAMPLES]
//! ```

use mfh_harness::oracle::chi2::sphere::sphere_chi2;
use mfh_harness::oracle::chi2::Chi2Config;
use mfh_harness::tolerance::STATISTICAL_ALPHA;
use mfh_reference::bsdf::{Bsdf, BsdfSpec, Directions};
use mfh_reference::geometry::Vec3;

/// The distortions tried (relative errors).
const ERRORS: [f64; 10] = [
    0.001, 0.002, 0.003, 0.005, 0.0075, 0.01, 0.015, 0.02, 0.03, 0.05,
];
/// The roughnesses.
const ALPHAS: [f64; 3] = [0.01, 0.3, 1.0];
/// The seeds.
const SEEDS: [u64; 3] = [1, 2, 3];

fn dielectric(alpha: f64) -> std::sync::Arc<dyn Bsdf> {
    let spec: BsdfSpec = serde_json::from_str(&format!(
        r#"{{"bsdf":"dielectric","eta":1.5,"ndf":{{"family":"ggx","alpha":{alpha}}},"sampling":"visible_normals"}}"#
    ))
    .expect("spec");
    spec.build().expect("bsdf")
}

/// The smallest error from which on every larger one is caught at every seed.
fn smallest(caught: &[bool]) -> String {
    (0..ERRORS.len())
        .find(|&i| caught[i..].iter().all(|&c| c))
        .map_or("> 5 %".to_string(), |i| format!("{} %", ERRORS[i] * 100.0))
}

fn main() {
    let samples: u64 = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().expect("SAMPLES"));
    let level = STATISTICAL_ALPHA.value;
    let wi: Vec3 = [1f64.sin(), 0.0, 1f64.cos()];
    println!("samples {samples}, resolution 16, θi = 1 rad, level {level}");
    println!();
    println!("| GGX α | whole table (before) | split statistic (now) | p now (seeds 1, 2, 3) per error |");
    println!("|---|---|---|---|");
    for alpha in ALPHAS {
        let reference = dielectric(alpha);
        let (mut now, mut before, mut detail) = (Vec::new(), Vec::new(), Vec::new());
        for e in ERRORS {
            let distorted = dielectric(alpha * (1.0 + e));
            let (mut all_now, mut all_before, mut ps) = (true, true, Vec::new());
            for seed in SEEDS {
                let config = Chi2Config {
                    resolution: 16,
                    samples,
                    seed,
                    alpha: level,
                };
                let r = sphere_chi2(
                    &|u: &[[f64; 3]], out: &mut Directions| distorted.sample_wo_batch(wi, u, out),
                    &|wo: &[Vec3], out: &mut [f64]| {
                        reference.pdf_batch(&vec![wi; wo.len()], wo, out)
                    },
                    &config,
                );
                let whole = statrs::function::gamma::checked_gamma_ur(
                    0.5 * r.dof as f64,
                    0.5 * r.statistic,
                )
                .unwrap_or(f64::NAN);
                all_now &= r.p_value < level;
                all_before &= whole < level;
                ps.push(format!("{:.0e}", r.p_value));
            }
            now.push(all_now);
            before.push(all_before);
            detail.push(format!("{e}: {}", ps.join(" ")));
        }
        println!(
            "| {alpha} | {} | {} | {} |",
            smallest(&before),
            smallest(&now),
            detail.join("; ")
        );
    }
}
