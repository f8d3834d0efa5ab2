//! `mfh audit --shard i/n`: a deterministic, cost-balanced i-th part of a plan, run on one
//! machine of a job matrix (CI matrix, Slurm array, Kubernetes indexed Job); `mfh merge`
//! ([`crate::merge`]) puts the parts back together exactly.
//!
//! Partition: longest-processing-time-first greedy over [`estimated_cost`] — checks sorted by
//! decreasing estimated cost (ties: plan order), each to the shard with the least estimated
//! load so far (ties: the lowest shard). It depends only on the plan, the profile and n, so
//! every machine computes the same partition without talking to the others. Per-check seeds
//! do not depend on plan order ([`crate::audit::check_seed`]), so a check's record is the same
//! whichever shard runs it.
//!
//! A shard's statistical verdicts are taken at the Šidák level of the whole plan's planned
//! statistical checks (at least as strict as the final level, which counts only those that
//! produced a p-value); `mfh merge` re-judges over the whole family.

use crate::audit::{
    fnv1a, judge_at, reproduce_command, run_plan, summarize, AuditOptions, AuditReport,
};
use crate::check::{Planned, PlannedCheck, Profile};
use crate::oracle::chi2::sidak_alpha;
use crate::plan::plan;
use crate::record::SCHEMA_VERSION;
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
    /// The shard's estimated cost (seconds, [`estimated_cost`]).
    pub estimated_seconds: f64,
    /// The command that reproduces the unsharded audit.
    pub unsharded_command: String,
}

/// The estimated cost of a planned check, in seconds on one core — a model, not a
/// measurement, used only to balance shards (a wrong estimate unbalances them; it cannot
/// change a record):
/// - sampling checks draw the profile's samples at ~0.1 µs each (`sampling.chi2*`: chi-square
///   samples plus ~0.2 s of expected-count cubature; `sampling.ks_marginals`, the Monte Carlo
///   Λ and the pseudo-VNIS bias: the profile's KS samples); slow samplers
///   (the registry's `slow_sampler` families, ~30 µs a sample) cost 300× a sample;
/// - quadrature-heavy checks (`precise.*`, `smith.*`, `ds.*`, errata demonstrations, claims)
///   0.05 s; everything else 0.01 s.
pub fn estimated_cost(planned: &PlannedCheck<'_>, profile: Profile) -> f64 {
    let family = planned
        .model
        .get("family")
        .and_then(|f| f.as_str())
        .unwrap_or("");
    let slow = mfh_reference::registry::by_name(family).is_some_and(|f| f.slow_sampler);
    let per_sample = if slow { 3e-5 } else { 1e-7 };
    let id = planned.check.as_str();
    if id.starts_with("sampling.chi2") {
        0.2 + profile.chi2_samples() as f64 * per_sample
    } else if id.starts_with("sampling.") && planned.statistical
        || id == "sampling.lambda_monte_carlo"
        || id == "sampling.pseudo_vnis"
    {
        profile.ks_samples(slow) as f64 * per_sample
    } else if ["precise.", "smith.", "ds.", "errata.", "claims."]
        .iter()
        .any(|p| id.starts_with(p))
    {
        0.05
    } else {
        0.01
    }
}

/// The shard (0-based) of every planned check, by the greedy of the module doc.
pub fn assign(plan: &[Planned], profile: Profile, count: usize) -> Vec<usize> {
    let costs: Vec<f64> = plan.iter().map(|p| estimated_cost(p, profile)).collect();
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
    let text: Vec<String> = plan
        .iter()
        .map(|p| format!("{}|{}|{}", p.check, p.model, p.case))
        .collect();
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
    let shard_of = assign(&planned, options.profile, spec.count);
    let mut estimated_seconds = 0.0;
    let mut indices = Vec::new();
    let mut mine = Vec::new();
    for (i, p) in planned.into_iter().enumerate() {
        if shard_of[i] == spec.index - 1 {
            estimated_seconds += estimated_cost(&p, options.profile);
            indices.push(i);
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
        estimated_seconds,
        unsharded_command,
    };
    (report, info)
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn the_partition_covers_the_plan_once_and_balances_estimated_cost() {
        let scene = Scene::default_scene();
        let planned = plan(&scene, Profile::Quick);
        for n in [1, 3, 7] {
            let shard = assign(&planned, Profile::Quick, n);
            assert_eq!(shard, assign(&planned, Profile::Quick, n), "deterministic");
            let mut load = vec![0.0; n];
            for (i, p) in planned.iter().enumerate() {
                assert!(shard[i] < n);
                load[shard[i]] += estimated_cost(p, Profile::Quick);
            }
            let total: f64 = load.iter().sum();
            let max = load.iter().cloned().fold(0.0, f64::max);
            let biggest = planned
                .iter()
                .map(|p| estimated_cost(p, Profile::Quick))
                .fold(0.0, f64::max);
            // LPT: the heaviest shard is within one check of the mean.
            assert!(
                max <= total / n as f64 + biggest + 1e-9,
                "n {n}: max {max} total {total}"
            );
        }
    }
}
