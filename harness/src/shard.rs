//! `mfh audit --shard i/n`: a deterministic, cost-balanced i-th part of a plan, run on one
//! machine of a job matrix (CI matrix, Slurm array, Kubernetes indexed Job); `mfh merge`
//! ([`crate::merge`]) puts the parts back together exactly.
//!
//! Partition: longest-processing-time-first greedy over [`estimated_cost`] — checks sorted by
//! decreasing estimated cost (ties: plan order), each to the shard with the least estimated
//! load so far (ties: the lowest shard). It depends only on the plan (whose cases carry the
//! profile's sample counts) and n, so every machine computes the same partition without
//! talking to the others. Per-check seeds
//! do not depend on plan order ([`crate::run::check_seed`]), so a check's record is the same
//! whichever shard runs it.
//!
//! A shard's statistical verdicts are taken at the Šidák level of the whole plan's planned
//! statistical checks (at least as strict as the final level, which counts only those that
//! produced a p-value); `mfh merge` re-judges over the whole family.

use crate::check::Planned;
use crate::estimate::estimated_cost;
use crate::plan::plan;
use crate::record::SCHEMA_VERSION;
use crate::record_trust::Identity;
use crate::run::sidak_alpha;
use crate::run::{
    fnv1a, judge_at, reproduce_command, run_plan, summarize, AuditOptions, AuditReport,
};
use crate::scene::Scene;
use crate::tolerance::STATISTICAL_ALPHA;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The largest number of shards accepted.
pub const MAX_SHARDS: usize = 10_000;

/// The file a shard writes beside its `report.json`.
pub const SHARD_FILE: &str = "shard.json";

/// Which part: shard `index` (1-based) of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShardSpec {
    /// 1 ≤ index ≤ count.
    pub index: usize,
    /// 1 ≤ count ≤ [`MAX_SHARDS`].
    pub count: usize,
}

impl std::str::FromStr for ShardSpec {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let bad =
            || format!("--shard {text:?}: expected i/n with 1 ≤ i ≤ n ≤ {MAX_SHARDS} (e.g. 2/7)");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count || count > MAX_SHARDS {
            return Err(bad());
        }
        Ok(ShardSpec { index, count })
    }
}

impl std::fmt::Display for ShardSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What a shard ran, written to `shard.json` beside its report: enough for `mfh merge` to
/// check that the shards belong to one plan and to put the records back in plan order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardInfo {
    /// The record schema version.
    pub schema_version: u32,
    /// 1-based shard index.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
    /// Checks in the whole plan.
    pub plan_checks: usize,
    /// FNV-1a of every planned `check|model|case`, in order (hex): shards of one plan agree.
    pub plan_fingerprint: String,
    /// The plan indices this shard ran, ascending (its records are in this order).
    pub indices: Vec<usize>,
    /// The planned check at each of those indices: `mfh merge` checks that they make up the
    /// plan's fingerprint and that each record is its planned check's
    /// (`record_trust::identity_mismatch`).
    pub planned: Vec<crate::record_trust::Identity>,
    /// The shard's estimated cost (seconds, [`estimated_cost`]).
    pub estimated_seconds: f64,
    /// The command that reproduces the unsharded audit.
    pub unsharded_command: String,
}

/// The shard (0-based) of every planned check, by the greedy of the module doc.
pub fn assign(plan: &[Planned], count: usize) -> Vec<usize> {
    let costs: Vec<f64> = plan.iter().map(estimated_cost).collect();
    let mut order: Vec<usize> = (0..plan.len()).collect();
    order.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
    let mut load = vec![0.0f64; count.max(1)];
    let mut shard = vec![0usize; plan.len()];
    for i in order {
        let (best, _) = load
            .iter()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |(bi, bl), (j, &l)| {
                    if l < bl {
                        (j, l)
                    } else {
                        (bi, bl)
                    }
                },
            );
        shard[i] = best;
        load[best] += costs[i];
    }
    shard
}

/// The fingerprint of a plan (hex FNV-1a of its `check|model|case` lines).
pub fn fingerprint(plan: &[Planned]) -> String {
    fingerprint_of(plan.iter().map(Identity::of))
}

/// The fingerprint of the planned checks `identities`, in plan order ([`fingerprint`]).
pub fn fingerprint_of(identities: impl Iterator<Item = Identity>) -> String {
    let text: Vec<String> = identities.map(|i| i.line()).collect();
    format!("{:016x}", fnv1a(&text.join("\n")))
}

/// Runs shard `spec` of a scene's plan: the report of its checks (statistical verdicts at the
/// whole plan's Šidák level, the reproduce command with `--shard`) and its [`ShardInfo`].
pub fn audit_shard(
    scene: &Scene,
    scene_path: Option<&str>,
    options: &AuditOptions,
    spec: ShardSpec,
) -> (AuditReport, ShardInfo) {
    let t = Instant::now();
    let planned = plan(scene, options.profile);
    let plan_checks = planned.len();
    let planned_statistical = planned.iter().filter(|p| p.statistical).count();
    let plan_fingerprint = fingerprint(&planned);
    let shard_of = assign(&planned, spec.count);
    let mut estimated_seconds = 0.0;
    let mut indices = Vec::new();
    let mut identities = Vec::new();
    let mut mine = Vec::new();
    for (i, p) in planned.into_iter().enumerate() {
        if shard_of[i] == spec.index - 1 {
            estimated_seconds += estimated_cost(&p);
            indices.push(i);
            identities.push(Identity::of(&p));
            mine.push(p);
        }
    }
    let (mut records, k, _) = run_plan(&mine, options);
    let alpha = sidak_alpha(STATISTICAL_ALPHA.value, planned_statistical.max(k));
    judge_at(&mut records, alpha);
    let summary = summarize(&records, (k, alpha), t.elapsed().as_secs_f64());
    let unsharded_command = reproduce_command(scene_path, options);
    let report = AuditReport {
        schema_version: SCHEMA_VERSION,
        mfh_version: env!("CARGO_PKG_VERSION"),
        scene: scene.name.clone(),
        profile: options.profile,
        seed: options.seed,
        command: format!("{unsharded_command} --shard {spec}"),
        summary,
        records,
        not_audited: scene.not_audited.clone(),
    };
    let info = ShardInfo {
        schema_version: SCHEMA_VERSION,
        index: spec.index,
        count: spec.count,
        plan_checks,
        plan_fingerprint,
        indices,
        planned: identities,
        estimated_seconds,
        unsharded_command,
    };
    (report, info)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Profile;

    #[test]
    fn shard_specs_parse_and_refuse_with_the_limit() {
        assert_eq!(
            "2/7".parse::<ShardSpec>(),
            Ok(ShardSpec { index: 2, count: 7 })
        );
        for bad in ["0/3", "4/3", "1", "a/b", "1/0", "1/10001"] {
            let e = bad.parse::<ShardSpec>().unwrap_err();
            assert!(e.contains("1 ≤ i ≤ n ≤ 10000"), "{bad}: {e}");
        }
    }

    /// The estimates follow the measured sampler costs and the case's sample count: in the
    /// default scene's thorough plan, Beckmann's visible chi-square (634 ns a sample) is
    /// estimated 45× GGX's (14 ns), and the piecewise Monte Carlo Λ at its own 10⁸ samples (not
    /// the KS checks' 10⁶ for a slow sampler).
    #[test]
    fn estimates_follow_the_measured_costs_and_the_sample_counts() {
        let planned = plan(&Scene::default_scene(), Profile::Thorough);
        let cost_of = |check: &str, family: &str| {
            let costs: Vec<f64> = planned
                .iter()
                .filter(|p| p.check == check && p.model["family"] == family)
                .map(estimated_cost)
                .collect();
            assert!(!costs.is_empty(), "no {check} for {family}");
            costs[0]
        };
        let near = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b;
        let beckmann = cost_of("sampling.chi2_visible", "beckmann");
        let ggx = cost_of("sampling.chi2_visible", "ggx");
        assert!(near(beckmann, 0.2 + 1e8 * 634e-9), "{beckmann}");
        assert!(near(ggx, 0.2 + 1e8 * 14e-9), "{ggx}");
        let mc = cost_of("sampling.lambda_monte_carlo", "piecewise_linear");
        assert!(near(mc, 1e8 * 578e-9), "{mc}");
        let ks = cost_of("sampling.ks_marginals", "piecewise_linear");
        assert!(near(ks, 1e6 * 638e-9), "{ks}");
        assert!(near(cost_of("smith.white_furnace", "ggx"), 0.05));
    }

    /// The cost model reads a sampling check's sample count from its case: every sampling
    /// check that draws samples states them, in every profile's plan of the default scene.
    #[test]
    fn every_sampling_check_states_its_samples() {
        for profile in [
            Profile::Ci,
            Profile::Quick,
            Profile::Standard,
            Profile::Thorough,
        ] {
            for p in plan(&Scene::default_scene(), profile) {
                let draws = [
                    "sampling.chi2",
                    "sampling.chi2_visible",
                    "sampling.chi2_pseudo_vnis",
                    "sampling.ks_marginals",
                    "sampling.lambda_monte_carlo",
                    "sampling.pseudo_vnis",
                ]
                .contains(&p.check.as_str());
                if draws {
                    assert!(
                        p.case.get("samples").and_then(|n| n.as_u64()) > Some(0),
                        "{profile:?} {} {}: {}",
                        p.check,
                        p.model,
                        p.case
                    );
                }
            }
        }
    }

    #[test]
    fn the_partition_covers_the_plan_once_and_balances_estimated_cost() {
        let scene = Scene::default_scene();
        let planned = plan(&scene, Profile::Quick);
        for n in [1, 3, 7] {
            let shard = assign(&planned, n);
            assert_eq!(shard, assign(&planned, n), "deterministic");
            let mut load = vec![0.0; n];
            for (i, p) in planned.iter().enumerate() {
                assert!(shard[i] < n);
                load[shard[i]] += estimated_cost(p);
            }
            let total: f64 = load.iter().sum();
            let max = load.iter().cloned().fold(0.0, f64::max);
            let biggest = planned
                .iter()
                .map(|p| estimated_cost(p))
                .fold(0.0, f64::max);
            // LPT: the heaviest shard is within one check of the mean.
            assert!(
                max <= total / n as f64 + biggest + 1e-9,
                "n {n}: max {max} total {total}"
            );
        }
    }
}
