//! The estimated cost in seconds of a planned check, before it runs: the runner starts the
//! longest checks first by it, and shards balance their loads by it. Below both (the planner's
//! layer), so that neither imports the other for it.

use crate::check::PlannedCheck;

pub mod sampler_cost;

/// The estimated cost of a planned check, in seconds of audit wall time — a model, not a
/// measurement, used only to balance shards (a wrong estimate unbalances them; it cannot
/// change a record). Fitted to the records of the default scene's thorough audit on a 2-core
/// Zen 4 (2026-12-02), whose sampling checks are nine tenths of its time:
/// - a sampling check costs its sample count (its case's `samples`) times
///   the family's measured cost per sample ([`sampler_cost::SamplerCost`]: 11 ns for GGX's
///   normals, 634 ns for Beckmann's visible normals, 568 ns for the piecewise-linear sampler)
///   plus what the check adds per sample: the KS tests' sort and CDF table 70 ns, the Monte
///   Carlo Λ 10 ns, the pseudo-VNIS bias (a Λ per sample) 250 ns, its chi-square 25 ns; the
///   chi-square checks add 0.2 s of expected-count cubature;
/// - quadrature-heavy checks (`precise.*`, `smith.*`, `ds.*`, `sg.*`, `normalization.*`,
///   errata demonstrations, claims) 0.05 s; everything else 0.01 s.
///
/// A family outside the registry (a user's model) is taken at [`sampler_cost::UNKNOWN_SAMPLER`]. Splitting
/// the default scene's plan into 4 shards by these estimates and summing its records' measured
/// costs per shard, the longest shard is 1.09× the ideal (total / 4) for the thorough, standard
/// and ci profiles alike (1.05× for ci); the previous model (one per-sample cost for every
/// family, 300× for the slow sampler, the KS sample count for the Monte Carlo Λ) gave 1.74×,
/// 1.38× and 1.23×.
pub fn estimated_cost(planned: &PlannedCheck<'_>) -> f64 {
    let family = planned
        .model
        .get("family")
        .and_then(|f| f.as_str())
        .unwrap_or("");
    let cost = sampler_cost::for_family(family);
    let id = planned.check.as_str();
    // Every sampling check states its sample count in its case (the test
    // `every_sampling_check_states_its_samples`).
    let samples = planned
        .case
        .get("samples")
        .and_then(|n| n.as_u64())
        .unwrap_or(0) as f64;
    if let Some(seconds) = bsdf_cost(id, samples) {
        return seconds;
    }
    let per_sample_ns = match id {
        "sampling.chi2" => cost.normal_ns,
        "sampling.chi2_visible" => cost.visible_ns,
        "sampling.chi2_pseudo_vnis" => cost.normal_ns + 25.0,
        "sampling.ks_marginals" => cost.normal_ns + 70.0,
        "sampling.lambda_monte_carlo" => cost.normal_ns + 10.0,
        "sampling.pseudo_vnis" => cost.normal_ns + 250.0,
        _ if [
            "precise.",
            "smith.",
            "ds.",
            "sg.",
            "normalization.",
            "errata.",
            "claims.",
        ]
        .iter()
        .any(|p| id.starts_with(p)) =>
        {
            return 0.05;
        }
        _ => return 0.01,
    };
    let cubature = if id.starts_with("sampling.chi2") {
        0.2
    } else {
        0.0
    };
    cubature + samples * per_sample_ns * 1e-9
}

/// The estimated cost of a BSDF check (`bsdf.*`), None for any other: per sample of its case
/// plus a fixed part, fitted to the records of a reference GGX dielectric (visible normals,
/// α 0.3, η 1.5) and a Beckmann conductor (α 0.1) audited at the quick (2·10⁵ chi-square
/// samples) and ci (10⁶) profiles on the 2-core Zen 4 (2026-12-06, `mfh audit --scene` of both,
/// mean record `wall_seconds` per check): `bsdf.chi2` 0.58 s and 1.64 s, so 1.3 µs a sample
/// (sample, bin, the pdf of the sampled direction) and 0.3 s of cell-mass cubature;
/// `bsdf.albedo` 0.43 s and 2.1 s, 2.1 µs a sample (its cubature grows with the sample count's
/// bound); `bsdf.sample_consistency` 0.30–0.36 s and `bsdf.failure_rate` 0.18–0.23 s at 10⁵
/// samples, 3.3 µs and 2 µs a sample; `bsdf.energy` 0.06–0.10 s, no samples; the deterministic
/// checks (reciprocity, stability, ndf_consistency, against) below 1 ms. A BSDF behind the
/// external protocol costs more per call, but in the same proportions between its checks.
fn bsdf_cost(id: &str, samples: f64) -> Option<f64> {
    let (per_sample_ns, fixed) = match id {
        "bsdf.chi2" => (1300.0, 0.3),
        "bsdf.albedo" => (2100.0, 0.0),
        "bsdf.sample_consistency" => (3300.0, 0.0),
        "bsdf.failure_rate" => (2000.0, 0.0),
        "bsdf.energy" => (0.0, 0.08),
        _ if id.starts_with("bsdf.") => (0.0, 0.001),
        _ => return None,
    };
    Some(fixed + samples * per_sample_ns * 1e-9)
}

#[cfg(test)]
mod tests {
    use super::bsdf_cost;

    #[test]
    fn the_bsdf_chi_square_is_estimated_as_the_costliest_bsdf_check() {
        let chi2 = bsdf_cost("bsdf.chi2", 1e6).unwrap();
        assert!((chi2 - 1.6).abs() < 1e-12, "{chi2}");
        for other in ["bsdf.reciprocity", "bsdf.stability", "bsdf.energy"] {
            assert!(bsdf_cost(other, 0.0).unwrap() < chi2 / 10.0, "{other}");
        }
        assert!(bsdf_cost("sampling.chi2", 1e6).is_none());
    }
}
