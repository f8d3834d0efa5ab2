//! The chi-square test's detection power alone (no KS, no Jacobian): for GGX α ∈ {0.01, 0.3,
//! 1}, the smallest roughness error ε (the sampler draws from α(1 + ε), the pdf is α's) and the
//! smallest slope-exponent error e (the sampled tan²θ raised to 1 + e about α,
//! `Defect::SamplerExponent`) that `chi2_test_batch_in` rejects at level
//! `STATISTICAL_ALPHA` (10⁻³) at every one of 3 seeds, at 10⁶ samples (the ci profile's) and
//! resolution 16 (the default audit's).
//!
//! ```text
//! cargo run --release -p mfh-harness --example chi2_power [-- SAMPLES RESOLUTION LAYOUT]
//! ```
//!
//! LAYOUT is `lobe` (the default: cells at the pdf's marginal quantiles) or `equal` (the
//! equal-area grid, the layout before the lobe-quantile cells: the "before" column of the table).
//!
//! Prints a Markdown table (docs/chi2.md, "Detection power"): per α and distortion kind, the
//! smallest error caught at all seeds (with every larger one tried also caught), and the
//! p-values of every run.

use mfh_harness::oracle::chi2::{chi2_test_batch_layout, Chi2Config, Layout, TestOutcome};
use mfh_harness::selftest::mutant::{Defect, Mutated};
use mfh_harness::tolerance::{CELL_RELATIVE_TOLERANCE, STATISTICAL_ALPHA};
use mfh_reference::geometry::Vec3;
use mfh_reference::ModelSpec;
use mfh_reference::{Ndf, NormalSampler};

/// The distortions tried (relative errors).
const ERRORS: [f64; 10] = [
    0.001, 0.002, 0.003, 0.005, 0.0075, 0.01, 0.015, 0.02, 0.03, 0.05,
];
/// The roughnesses.
const ALPHAS: [f64; 3] = [0.01, 0.3, 1.0];
/// The seeds.
const SEEDS: [u64; 3] = [1, 2, 3];

fn ggx(alpha: f64) -> ModelSpec {
    serde_json::from_str(&format!(r#"{{"family":"ggx","alpha":{alpha}}}"#)).expect("spec")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let samples: u64 = args
        .get(1)
        .map_or(1_000_000, |s| s.parse().expect("SAMPLES"));
    let resolution: usize = args.get(2).map_or(16, |s| s.parse().expect("RESOLUTION"));
    let layout = match args.get(3).map_or("lobe", String::as_str) {
        "lobe" => Layout::FollowLobe,
        "equal" => Layout::EqualArea,
        other => panic!("LAYOUT is lobe or equal, not {other}"),
    };
    println!(
        "samples {samples}, resolution {resolution}, layout {layout:?}, α_test {}",
        STATISTICAL_ALPHA.value
    );
    println!();
    println!(
        "| GGX α | distortion | smallest caught (3 seeds) | p-values (seed 1, 2, 3) per error |"
    );
    println!("|---|---|---|---|");
    for alpha in ALPHAS {
        let base = ggx(alpha).build().expect("model");
        let pdf_model = base.as_sampler().expect("sampler");
        for kind in ["roughness", "exponent"] {
            let mut caught_all = Vec::new();
            let mut detail = Vec::new();
            for e in ERRORS {
                let rough;
                let mutated;
                let sampler: &dyn NormalSampler = if kind == "roughness" {
                    rough = ggx(alpha * (1.0 + e)).build().expect("model");
                    rough.as_sampler().expect("sampler")
                } else {
                    mutated =
                        Mutated::new(&ggx(alpha), Defect::SamplerExponent { scale: alpha, e })
                            .expect("mutant");
                    mutated.as_sampler().expect("sampler")
                };
                let mut ps = Vec::new();
                let mut all = true;
                for seed in SEEDS {
                    let config = Chi2Config {
                        resolution,
                        samples,
                        seed,
                        alpha: STATISTICAL_ALPHA.value,
                    };
                    let r = chi2_test_batch_layout(
                        &|u: &[[f64; 2]], m: &mut [Vec3]| sampler.sample_wm_batch(u, m),
                        &|m| pdf_model.pdf_wm(m),
                        &config,
                        (CELL_RELATIVE_TOLERANCE, None, &[]),
                        layout,
                    );
                    all &= r.verdict == TestOutcome::Fail;
                    ps.push(format!("{:.0e}", r.p_value));
                }
                caught_all.push(all);
                detail.push(format!("{e}: {}", ps.join(" ")));
            }
            // The smallest error from which on every larger one is caught at every seed.
            let smallest = (0..ERRORS.len())
                .find(|&i| caught_all[i..].iter().all(|&c| c))
                .map_or("> 5 %".to_string(), |i| format!("{} %", ERRORS[i] * 100.0));
            println!("| {alpha} | {kind} | {smallest} | {} |", detail.join("; "));
        }
    }
}
