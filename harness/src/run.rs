//! The audit: runs a plan in parallel with per-check seeds, applies the Šidák correction across
//! its statistical checks, and summarizes. This is also the public API a renderer's own tests
//! call as a CI gate (`audit_scene(..)?.assert_pass()`).
//!
//! **Seeds.** A check's seed is the audit seed ([`DEFAULT_SEED`] unless `--seed` or `MFH_SEED`
//! gives one) mixed with the check's id, model and case ([`check_seed`]): independent of plan
//! order, thread count and shard. A panic inside a model or a check is caught into an error
//! record; the other checks still run. The statistical verdicts are judged at the Šidák level
//! of the whole plan ([`sidak_alpha`]). [`RunControl`] sends each check's start and finish
//! (with its record) to a callback, takes the records of an interrupted run (by [`plan_key`])
//! and stops starting checks after a time limit; this module writes no file.

use crate::check::{budget, PlannedCheck, Profile, RunContext};
use crate::plan::plan;
use crate::random::splitmix64;
use crate::record::{CheckRecord, Measured, Verdict, SCHEMA_VERSION};
use crate::scene::Scene;
use crate::tolerance::STATISTICAL_ALPHA;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The default audit seed (overridable everywhere a seed is taken: `--seed`, `MFH_SEED`, the
/// options): every check's random stream derives from it and the check's id, model and case.
pub const DEFAULT_SEED: u64 = 0x6d66_6800_0000_0001;

/// The Šidák-corrected level for each of `k` independent tests so that the family-wise level
/// is `alpha`: 1 − (1 − α)^{1/k} (computed as −expm1(ln(1 − α)/k), exact for small α).
pub fn sidak_alpha(alpha: f64, k: usize) -> f64 {
    if k <= 1 {
        return alpha;
    }
    -((-alpha).ln_1p() / k as f64).exp_m1()
}

/// How to run an audit.
#[derive(Debug, Clone)]
pub struct AuditOptions {
    /// The profile.
    pub profile: Profile,
    /// The audit seed (every check's stream derives from it).
    pub seed: u64,
    /// Where artefacts go (None: none are written).
    pub out: Option<PathBuf>,
    /// Called after each check (from worker threads); None: no progress is reported.
    pub progress: Option<ProgressFn>,
    /// Streaming, resuming and the time limit ([`RunControl`]).
    pub control: RunControl,
}

impl Default for AuditOptions {
    fn default() -> Self {
        Self {
            profile: Profile::Quick,
            seed: DEFAULT_SEED,
            out: None,
            progress: None,
            control: RunControl::default(),
        }
    }
}

/// What an audit does beyond running its plan: tell a sink about each check as it starts and
/// finishes (the CLI appends each record to `report.jsonl` and prints progress lines from
/// these events; the library itself writes nothing), take the records of an interrupted run
/// instead of running their checks again, and stop starting checks after a time limit.
#[derive(Debug, Clone, Default)]
pub struct RunControl {
    /// Told when a check starts and when it finishes, from the worker threads.
    pub on_check: Option<CheckEventFn>,
    /// Records of an earlier run of the same plan (read back from `report.jsonl`), by the
    /// [`plan_key`] of the planned check that made each: a planned check with a record here is
    /// not run again, its record is taken. Records do not depend on the order or the thread a
    /// check runs on ([`check_seed`]), so a resumed audit has the records of an uninterrupted
    /// one. (The key is the planned check's, not the record's identity: some checks refine
    /// the case they record.) The file can be edited, so a record is taken only if it is the
    /// planned check's (`record_trust::identity_mismatch`: else the check runs again), and
    /// re-judged from its numbers as `mfh merge` re-judges (`record_trust::rejudge`); each
    /// is told in [`CheckEvent::Plan`]'s `distrusted`.
    pub resume: Option<Arc<std::collections::HashMap<String, CheckRecord>>>,
    /// The wall-time limit from the start of [`run_plan`]: a check not started when it has
    /// passed is not run and gets an `error` record naming the limit ([`not_run_message`]);
    /// checks already running finish (a check cannot be cancelled midway).
    pub max_time: Option<Duration>,
    /// The wall-clock budget of each record (`None`: the profile's,
    /// [`crate::check::budget::record_budget`]): a check that runs past it ends as an `error`
    /// record naming the budget ([`crate::check::budget`]).
    pub record_budget: Option<Duration>,
}

/// What happened to one planned check ([`RunControl::on_check`]).
#[derive(Debug)]
pub enum CheckEvent<'e> {
    /// The run begins: `checks` planned, of which `resumed` were taken from
    /// [`RunControl::resume`] and will not run. Sent once, before any other event.
    Plan {
        /// Checks planned.
        checks: usize,
        /// Checks whose records were taken from the earlier run.
        resumed: usize,
        /// One line per resumed record not taken as it was stored: a record that is not its
        /// plan key's planned check's (not taken: the check runs again), or whose verdict its
        /// numbers contradict (taken re-judged as `fail`) — [`crate::record_trust`].
        distrusted: &'e [String],
    },
    /// Check `index` of the plan has started.
    Started {
        /// Its index in the plan.
        index: usize,
        /// The planned check.
        planned: &'e PlannedCheck<'e>,
    },
    /// Check `index` of the plan has finished with `record` (before the Šidák correction
    /// re-judges the statistical records over the whole audit). Not sent for records taken
    /// from [`RunControl::resume`] nor for checks not run because of the time limit.
    Finished {
        /// Its index in the plan.
        index: usize,
        /// The planned check (its [`plan_key`] identifies the record for
        /// [`RunControl::resume`]).
        planned: &'e PlannedCheck<'e>,
        /// Its record (with its `data`, if any).
        record: &'e CheckRecord,
    },
}

/// A check-event callback; it never changes a result.
#[derive(Clone)]
pub struct CheckEventFn(pub Arc<dyn Fn(CheckEvent<'_>) + Send + Sync>);

impl std::fmt::Debug for CheckEventFn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("CheckEventFn")
    }
}

/// The key of a planned check for [`RunControl::resume`]: the hex FNV-1a of its
/// `check|model|case` (the model and case as compact JSON, as [`check_seed`] and the shard
/// fingerprint spell them).
pub fn plan_key(planned: &PlannedCheck<'_>) -> String {
    format!(
        "{:016x}",
        fnv1a(&format!(
            "{}|{}|{}",
            planned.check, planned.model, planned.case
        ))
    )
}

/// The message of the `error` record of a check that was not run because the time limit
/// `limit` had passed.
pub fn not_run_message(limit: Duration) -> String {
    format!(
        "not run: the audit's time limit of {} s (max_time, `--max-time`) had passed before \
         this check could start",
        limit.as_secs_f64()
    )
}

/// How far an audit has got: checks done of those planned, and failures so far (before the
/// Šidák correction re-judges the statistical checks).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Checks done.
    pub done: usize,
    /// Checks planned.
    pub planned: usize,
    /// Checks failed or errored so far.
    pub failures: usize,
}

/// A progress callback; it never changes a result.
#[derive(Clone)]
pub struct ProgressFn(pub std::sync::Arc<dyn Fn(Progress) + Send + Sync>);

impl std::fmt::Debug for ProgressFn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressFn")
    }
}

/// Counts and extremes of an audit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Records by verdict name.
    pub counts: BTreeMap<String, usize>,
    /// The worst measured error (relative or absolute) per model family, with its check.
    pub worst_error: BTreeMap<String, (f64, String)>,
    /// Records, time (s) and worst error per check id.
    pub by_check: BTreeMap<String, CheckSummary>,
    /// The Šidák level each statistical check was judged at, and how many there were.
    pub statistical: (usize, f64),
    /// Wall time of the whole audit, seconds.
    pub wall_seconds: f64,
}

/// Per-check-id totals.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CheckSummary {
    /// Records.
    pub records: usize,
    /// Failing records (fail or error).
    pub failures: usize,
    /// Expected failures.
    pub expected_failures: usize,
    /// Summed wall time of its records (CPU-parallel, so it can exceed the audit's wall time).
    pub seconds: f64,
    /// The worst measured error among passing records.
    pub worst_passing_error: f64,
}

/// The result of an audit, as written to `report.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AuditReport {
    /// The record schema version.
    pub schema_version: u32,
    /// mfh's version.
    #[serde(deserialize_with = "crate::record_serde::interned")]
    pub mfh_version: crate::record_serde::StaticStr,
    /// The scene's name.
    pub scene: String,
    /// The profile.
    #[serde(deserialize_with = "crate::check::deserialize_profile")]
    pub profile: Profile,
    /// The audit seed.
    pub seed: u64,
    /// The command that reproduces the run.
    pub command: String,
    /// The summary.
    pub summary: Summary,
    /// Every record, in plan order.
    pub records: Vec<CheckRecord>,
    /// What the scene file holds that was not audited, and why (Mitsuba scenes).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_audited: Vec<crate::scene::NotAudited>,
}

impl AuditReport {
    /// Whether the audit passes: no record failed or errored (expected failures pass).
    pub fn passed(&self) -> bool {
        !self.records.iter().any(|r| r.verdict.is_failure())
    }

    /// The CI gate: Ok when the audit passes, else the table of failures ([`failure_table`]).
    pub fn check_pass(&self) -> Result<(), String> {
        if self.passed() {
            Ok(())
        } else {
            Err(failure_table(self))
        }
    }

    /// The CI gate for a test: panics with the table of failures (check, case, measured
    /// against the oracle, tolerance and why, the seed and the command that reproduces the
    /// run) unless the audit passes.
    #[track_caller]
    pub fn assert_pass(&self) {
        if let Err(table) = self.check_pass() {
            panic!("{table}");
        }
    }

    /// The records of one check id.
    pub fn records_of<'r>(&'r self, check: &'r str) -> impl Iterator<Item = &'r CheckRecord> {
        self.records.iter().filter(move |r| r.check == check)
    }

    /// The ids of the checks with a failing record, sorted and unique.
    pub fn failed_checks(&self) -> Vec<&str> {
        let mut ids: Vec<&str> = self
            .records
            .iter()
            .filter(|r| r.verdict.is_failure())
            .map(|r| r.check.as_str())
            .collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

/// A readable table of an audit's failures: per failing record its check, model and case, the
/// value against the oracle, the measured error and the tolerance and why, and the verdict, as
/// every sink prints a record (`record_text::block`); then the seed and the command that
/// reproduces the run.
pub fn failure_table(report: &AuditReport) -> String {
    use std::fmt::Write;
    let failures: Vec<&CheckRecord> = report
        .records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .collect();
    let mut out = format!(
        "mfh: {} of {} check record(s) failed ({}, profile {}, seed {})\n",
        failures.len(),
        report.records.len(),
        report.scene,
        report.profile.name(),
        report.seed
    );
    for r in failures {
        out.push('\n');
        out.push_str(&crate::record_text::block(r, "  "));
    }
    let _ = write!(out, "\nreproduce: {}", report.command);
    out
}

impl AuditReport {
    /// Assembles a report from a run's records.
    pub fn from_records(
        scene: String,
        options: &AuditOptions,
        command: String,
        records: Vec<CheckRecord>,
        statistical: (usize, f64),
        wall_seconds: f64,
    ) -> Self {
        let summary = summarize(&records, statistical, wall_seconds);
        AuditReport {
            schema_version: SCHEMA_VERSION,
            mfh_version: env!("CARGO_PKG_VERSION"),
            scene,
            profile: options.profile,
            seed: options.seed,
            command,
            summary,
            records,
            not_audited: Vec::new(),
        }
    }
}

/// FNV-1a of a string: a stable key for seeding (std's hasher may change between releases).
pub fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The seed of one planned check: the audit seed mixed with its id, model and case, so that
/// neither plan order nor thread count changes any stream.
pub fn check_seed(seed: u64, planned: &PlannedCheck<'_>) -> u64 {
    splitmix64(
        seed ^ fnv1a(&format!(
            "{}|{}|{}",
            planned.check, planned.model, planned.case
        )),
    )
}

/// Runs a plan: every check in parallel, records in plan order, statistical verdicts at the
/// Šidák-corrected level. Prints nothing: each check's start and finish go to
/// `options.control.on_check` (the CLI prints them under `MFH_TRACE`).
///
/// Scheduling: the checks are started longest first by [`crate::estimate::estimated_cost`]
/// (ties in plan order), each thread taking the next from one queue, so that a long check does
/// not start last and run alone while the other threads are idle (rayon's split of the plan
/// into contiguous halves did that). Records do not depend on the order: each check has its
/// own seed ([`check_seed`]).
///
/// `options.control` ([`RunControl`]): each check's start and finish are told to `on_check`;
/// the checks with a record in `resume` are not run (their records are taken); once `max_time`
/// has passed no check is started, and each one not run gets an `error` record naming the limit.
pub fn run_plan(
    plan: &[PlannedCheck<'_>],
    options: &AuditOptions,
) -> (Vec<CheckRecord>, usize, f64) {
    let start = Instant::now();
    let control = &options.control;
    let deadline = control.max_time.map(|limit| start + limit);
    let record_budget = control
        .record_budget
        .unwrap_or_else(|| budget::record_budget(options.profile));
    let slots: Vec<std::sync::OnceLock<CheckRecord>> =
        plan.iter().map(|_| std::sync::OnceLock::new()).collect();
    let mut resumed = 0;
    let mut distrusted = Vec::new();
    if let Some(previous) = &control.resume {
        for (index, (slot, p)) in slots.iter().zip(plan).enumerate() {
            let key = plan_key(p);
            let Some(r) = previous.get(&key) else {
                continue;
            };
            let identity = crate::record_trust::Identity::of(p);
            if let Some(why) = crate::record_trust::identity_mismatch(&identity, r) {
                distrusted.push(format!(
                    "the record under plan key {key} (plan index {index}) is not that planned \
                     check's: {why}; not taken, the check runs again"
                ));
                continue;
            }
            let mut r = r.clone();
            if let Some(line) = crate::record_trust::rejudge(&mut r) {
                distrusted.push(format!(
                    "plan key {key} (plan index {index}, {}): {line}",
                    r.check
                ));
            }
            let _ = slot.set(r);
            resumed += 1;
        }
    }
    if let Some(f) = &control.on_check {
        (f.0)(CheckEvent::Plan {
            checks: plan.len(),
            resumed,
            distrusted: &distrusted,
        });
    }
    let (done, failures) = (AtomicUsize::new(resumed), AtomicUsize::new(0));
    let costs: Vec<f64> = plan.iter().map(crate::estimate::estimated_cost).collect();
    let mut order: Vec<usize> = (0..plan.len())
        .filter(|&i| slots[i].get().is_none())
        .collect();
    order.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]));
    let next = AtomicUsize::new(0);
    let run_one = |index: usize, p: &PlannedCheck<'_>| {
        if let Some(f) = &control.on_check {
            (f.0)(CheckEvent::Started { index, planned: p });
        }
        let ctx = RunContext {
            seed: check_seed(options.seed, p),
        };
        let started = Instant::now();
        let error = |message: String| {
            let mut r = CheckRecord::new(&p.check, p.model.clone(), p.case.clone(), "");
            r.verdict = Verdict::Error { message };
            r.cost.wall_seconds = started.elapsed().as_secs_f64();
            r
        };
        let over_budget = || {
            error(budget::over_budget_message(
                record_budget,
                started.elapsed().as_secs_f64(),
            ))
        };
        let mut r = match budget::run_within(Some(record_budget), started, || (p.run)(&ctx)) {
            budget::Outcome::Done(_) if started.elapsed() > record_budget => over_budget(),
            budget::Outcome::Done(r) => r,
            budget::Outcome::OverBudget => over_budget(),
            budget::Outcome::Panicked(e) => {
                let message = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                error(format!(
                    "a panic inside the check or the model's methods: {message}"
                ))
            }
        };
        if r.covers.is_empty() {
            r.covers = p.covers.clone();
        }
        crate::record_trust::keep_planned_case(&mut r.case, &p.case);
        if let Some(f) = &control.on_check {
            (f.0)(CheckEvent::Finished {
                index,
                planned: p,
                record: &r,
            });
        }
        if let Some(f) = &options.progress {
            let failed = failures.fetch_add(usize::from(r.verdict.is_failure()), Relaxed);
            (f.0)(Progress {
                done: done.fetch_add(1, Relaxed) + 1,
                planned: plan.len(),
                failures: failed + usize::from(r.verdict.is_failure()),
            });
        }
        r
    };
    (0..rayon::current_num_threads().max(1))
        .into_par_iter()
        .for_each(|_| loop {
            if deadline.is_some_and(|d| Instant::now() >= d) {
                break;
            }
            let at = next.fetch_add(1, Relaxed);
            let Some(&i) = order.get(at) else { break };
            let _ = slots[i].set(run_one(i, &plan[i]));
        });
    let mut records: Vec<CheckRecord> = slots
        .into_iter()
        .zip(plan)
        .map(|(s, p)| {
            // Without a time limit every index is taken from the queue once, and an empty slot
            // is not reached; with one, the checks not started in time are empty.
            s.into_inner().unwrap_or_else(|| {
                let mut r = CheckRecord::new(&p.check, p.model.clone(), p.case.clone(), "");
                r.verdict = Verdict::Error {
                    message: match control.max_time {
                        Some(limit) => not_run_message(limit),
                        None => "the check was not run".into(),
                    },
                };
                r
            })
        })
        .collect();
    let (k, alpha) = judge_statistical(&mut records);
    (records, k, alpha)
}

/// Judges the statistical records (those with a p-value) at the Šidák level of their number
/// k, in place: each gets that α, and a pass/fail verdict from p ≥ α (errors stay errors).
/// Returns (k, α). Idempotent, so a merge of shard reports re-judges over the whole family.
pub fn judge_statistical(records: &mut [CheckRecord]) -> (usize, f64) {
    let k = records.iter().filter(|r| r.is_statistical()).count();
    let alpha = sidak_alpha(STATISTICAL_ALPHA.value, k);
    judge_at(records, alpha);
    (k, alpha)
}

/// Judges the statistical records at the level `alpha` (see [`judge_statistical`]).
pub fn judge_at(records: &mut [CheckRecord], alpha: f64) {
    for r in records.iter_mut() {
        if let Some(Measured::PValue {
            p, statistic, dof, ..
        }) = r.measured
        {
            r.measured = Some(Measured::PValue {
                p,
                statistic,
                dof,
                alpha,
            });
            if matches!(r.verdict, Verdict::Pass | Verdict::Fail) {
                r.verdict = if p >= alpha {
                    Verdict::Pass
                } else {
                    Verdict::Fail
                };
            }
        }
    }
}

/// The family of a record's model (its `family` key), or the check's family for non-NDF checks.
fn family_of(r: &CheckRecord) -> String {
    r.model
        .get("family")
        .and_then(|f| f.as_str())
        .map(str::to_string)
        .unwrap_or_else(|| r.check.split('.').next().unwrap_or("").to_string())
}

/// Summarizes records.
pub fn summarize(records: &[CheckRecord], statistical: (usize, f64), wall_seconds: f64) -> Summary {
    let mut counts = BTreeMap::new();
    for name in [
        "pass",
        "fail",
        "expected_failure",
        "unexpected_pass",
        "skipped",
        "error",
    ] {
        counts.insert(name.to_string(), 0);
    }
    let mut worst_error: BTreeMap<String, (f64, String)> = BTreeMap::new();
    let mut by_check: BTreeMap<String, CheckSummary> = BTreeMap::new();
    for r in records {
        *counts.entry(r.verdict.name().to_string()).or_default() += 1;
        let c = by_check.entry(r.check.clone()).or_default();
        c.records += 1;
        c.seconds += r.cost.wall_seconds;
        if r.verdict.is_failure() {
            c.failures += 1;
        }
        if matches!(r.verdict, Verdict::ExpectedFailure { .. }) {
            c.expected_failures += 1;
        }
        if r.verdict == Verdict::Pass {
            if let Some(e) = r.measured.and_then(|m| m.error()) {
                c.worst_passing_error = c.worst_passing_error.max(e);
                if !matches!(r.measured, Some(Measured::Rate { .. })) {
                    let w = worst_error
                        .entry(family_of(r))
                        .or_insert((0.0, String::new()));
                    if e > w.0 {
                        *w = (e, format!("{} {}", r.check, r.case));
                    }
                }
            }
        }
    }
    Summary {
        counts,
        worst_error,
        by_check,
        statistical,
        wall_seconds,
    }
}

/// The command line that reproduces an audit.
pub fn reproduce_command(scene: Option<&str>, options: &AuditOptions) -> String {
    let mut c = format!(
        "mfh audit --profile {} --seed {}",
        options.profile.name(),
        options.seed
    );
    if let Some(s) = scene {
        c.push_str(&format!(" --scene {s}"));
    }
    c
}

/// Audits a scene: plans, runs, corrects, summarizes. `scene_path` only names the scene in
/// the reproduce command.
pub fn audit_scene(scene: &Scene, scene_path: Option<&str>, options: &AuditOptions) -> AuditReport {
    let t = Instant::now();
    let planned = plan(scene, options.profile);
    let (records, k, alpha) = run_plan(&planned, options);
    let mut report = AuditReport::from_records(
        scene.name.clone(),
        options,
        reproduce_command(scene_path, options),
        records,
        (k, alpha),
        t.elapsed().as_secs_f64(),
    );
    report.not_audited = scene.not_audited.clone();
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One test keeps its level; k tests share it so that the family-wise level is α.
    #[test]
    fn sidak_alpha_keeps_the_family_wise_level() {
        assert_eq!(sidak_alpha(0.01, 1), 0.01);
        let a = sidak_alpha(0.01, 10);
        assert!((1.0 - (1.0 - a).powi(10) - 0.01).abs() < 1e-15);
    }
}
