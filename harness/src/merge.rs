//! `mfh merge DIR…`: combines the reports of `mfh audit --shard i/n` into the report of the
//! unsharded audit — records back in plan order, statistical verdicts re-judged at the Šidák
//! level of the whole family, counts and per-check totals recomputed from the records — so
//! that the merged `report.json` equals the unsharded run's, timings aside (the merged wall
//! time is the longest shard's: the shards ran in parallel).
//!
//! Every stored verdict is re-judged from the record's own numbers (measured error, tolerance,
//! oracle uncertainty: [`CheckRecord::verdict_contradicts_measurement`], the rule
//! `check::compare` passes by): a shard's report is a file anyone can edit, and a record that
//! claims pass at an error of 1.0 against a tolerance of 1e-10 merges as the failure it is. The
//! corrections are listed ([`Merged::corrected`]) for the CLI to print.
//!
//! Refused, with the shard folder named: a missing or duplicated shard, shards of different
//! plans (fingerprint), seeds, profiles, scenes or mfh versions, another schema version; a
//! record that is not the check planned at its index (`record_trust::identity_mismatch`:
//! another check id, model or case — a renamed check, an edited case, records moved), and
//! planned checks that do not make up the plan's fingerprint (indices swapped in a
//! `shard.json`).

use crate::readback::{read_report, ReadError};
use crate::record::{CheckRecord, SCHEMA_VERSION};
use crate::record_trust::{identity_mismatch, Identity};
use crate::run::{judge_statistical, summarize, AuditReport};
use crate::shard::{fingerprint_of, ShardInfo, SHARD_FILE};
use std::path::{Path, PathBuf};

/// Why shard reports could not be merged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MergeError {
    /// A report could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// `shard.json` is missing or malformed.
    #[error("{path}: {message}")]
    ShardFile {
        /// The path.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The shards do not make up one plan.
    #[error("{0}")]
    Inconsistent(String),
}

/// One shard's output folder, read back.
#[derive(Debug, Clone)]
pub struct ShardReport {
    /// The folder.
    pub dir: PathBuf,
    /// Its `report.json`.
    pub report: AuditReport,
    /// Its `shard.json`.
    pub info: ShardInfo,
}

/// The merged report and the stored verdicts merge corrected.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The unsharded report.
    pub report: AuditReport,
    /// One line per record whose stored verdict its numbers contradicted (now `fail`): the
    /// shard folder, the plan index, the check, the stored verdict and the numbers.
    pub corrected: Vec<String>,
}

/// Re-judges a record read from `dir` at plan index `index` (`record_trust::rejudge`: a
/// verdict its numbers contradict becomes `fail`); returns the line that says so.
fn rejudge(record: &mut CheckRecord, dir: &Path, index: usize) -> Option<String> {
    let check = record.check.clone();
    crate::record_trust::rejudge(record)
        .map(|line| format!("{}: plan index {index} ({check}): {line}", dir.display()))
}

/// Reads `dir/report.json` and `dir/shard.json`.
pub fn read_shard(dir: &Path) -> Result<ShardReport, MergeError> {
    let report = read_report(&dir.join("report.json"))?;
    let path = dir.join(SHARD_FILE);
    let shard_error = |message: String| MergeError::ShardFile {
        path: path.display().to_string(),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| {
        shard_error(format!(
            "cannot read it ({e}): is {} the output of `mfh audit --shard i/n`?",
            dir.display()
        ))
    })?;
    let info: ShardInfo = serde_json::from_str(&text).map_err(|e| shard_error(e.to_string()))?;
    if info.schema_version != SCHEMA_VERSION {
        return Err(shard_error(format!(
            "schema_version {}, but this mfh reads schema_version {SCHEMA_VERSION} only",
            info.schema_version
        )));
    }
    if info.indices.len() != report.records.len() || info.planned.len() != info.indices.len() {
        return Err(shard_error(format!(
            "lists {} plan indices and {} planned checks but report.json has {} records",
            info.indices.len(),
            info.planned.len(),
            report.records.len()
        )));
    }
    Ok(ShardReport {
        dir: dir.to_path_buf(),
        report,
        info,
    })
}

/// Merges shard reports (any order) into the unsharded report, re-judging every stored verdict.
pub fn merge(shards: Vec<ShardReport>) -> Result<Merged, MergeError> {
    let bad = |m: String| Err(MergeError::Inconsistent(m));
    let Some(first) = shards.first() else {
        return bad("no shard folders given".to_string());
    };
    let n = first.info.count;
    let plan_checks = first.info.plan_checks;
    for s in &shards {
        let (a, b) = (&first, s);
        let differs = [
            (
                "shard count",
                a.info.count.to_string(),
                b.info.count.to_string(),
            ),
            (
                "plan fingerprint",
                a.info.plan_fingerprint.clone(),
                b.info.plan_fingerprint.clone(),
            ),
            (
                "plan size",
                a.info.plan_checks.to_string(),
                b.info.plan_checks.to_string(),
            ),
            ("seed", a.report.seed.to_string(), b.report.seed.to_string()),
            (
                "profile",
                a.report.profile.name().to_string(),
                b.report.profile.name().to_string(),
            ),
            ("scene", a.report.scene.clone(), b.report.scene.clone()),
            (
                "mfh version",
                a.report.mfh_version.to_string(),
                b.report.mfh_version.to_string(),
            ),
            (
                "not-audited list",
                format!("{:?}", a.report.not_audited),
                format!("{:?}", b.report.not_audited),
            ),
        ]
        .into_iter()
        .find(|(_, x, y)| x != y);
        if let Some((what, x, y)) = differs {
            return bad(format!(
                "{} and {} are not shards of one audit: {what} {x} ≠ {y}",
                a.dir.display(),
                b.dir.display()
            ));
        }
    }
    let mut seen = vec![None::<&Path>; n];
    for s in &shards {
        match seen.get_mut(s.info.index.wrapping_sub(1)) {
            Some(Some(other)) => {
                return bad(format!(
                    "shard {}/{n} given twice: {} and {}",
                    s.info.index,
                    other.display(),
                    s.dir.display()
                ))
            }
            Some(slot) => *slot = Some(&s.dir),
            None => {
                return bad(format!(
                    "{}: shard index {} of {n}",
                    s.dir.display(),
                    s.info.index
                ))
            }
        }
    }
    let missing: Vec<String> = (1..=n)
        .filter(|i| seen[i - 1].is_none())
        .map(|i| format!("{i}/{n}"))
        .collect();
    if !missing.is_empty() {
        return bad(format!("missing shard(s) {}", missing.join(", ")));
    }
    let mut slots: Vec<Option<CheckRecord>> = vec![None; plan_checks];
    let mut identities: Vec<Option<&Identity>> = vec![None; plan_checks];
    let mut wall: f64 = 0.0;
    let mut corrected = Vec::new();
    for s in &shards {
        wall = wall.max(s.report.summary.wall_seconds);
        let listed = s.info.indices.iter().zip(&s.info.planned);
        for ((&i, planned), r) in listed.zip(&s.report.records) {
            match slots.get_mut(i) {
                Some(slot @ None) => {
                    if let Some(why) = identity_mismatch(planned, r) {
                        return bad(format!(
                            "{}: the record at plan index {i} is not the planned check's \
                             ({why}): report.json or shard.json was edited",
                            s.dir.display()
                        ));
                    }
                    let mut r = r.clone();
                    corrected.extend(rejudge(&mut r, &s.dir, i));
                    *slot = Some(r);
                    identities[i] = Some(planned);
                }
                _ => {
                    return bad(format!(
                        "{}: plan index {i} is out of range or run by two shards",
                        s.dir.display()
                    ))
                }
            }
        }
    }
    // The planned checks, in plan order, must be the plan the shards name: indices moved
    // between records, or a planned check edited in a shard.json, change the fingerprint.
    if identities.iter().all(Option::is_some) {
        let made = fingerprint_of(identities.iter().flatten().map(|i| (*i).clone()));
        if made != first.info.plan_fingerprint {
            return bad(format!(
                "the planned checks listed in the shard.json files, in plan-index order, have \
                 the fingerprint {made}, not the plan's {}: a shard.json was edited (indices \
                 or planned checks)",
                first.info.plan_fingerprint
            ));
        }
    }
    let mut records: Vec<CheckRecord> = Vec::with_capacity(plan_checks);
    for (i, slot) in slots.into_iter().enumerate() {
        match slot {
            Some(r) => records.push(r),
            None => return bad(format!("no shard ran plan index {i}")),
        }
    }
    let statistical = judge_statistical(&mut records);
    let summary = summarize(&records, statistical, wall);
    let first = &shards[0];
    let report = AuditReport {
        schema_version: SCHEMA_VERSION,
        mfh_version: first.report.mfh_version,
        scene: first.report.scene.clone(),
        profile: first.report.profile,
        seed: first.report.seed,
        command: first.info.unsharded_command.clone(),
        summary,
        records,
        not_audited: first.report.not_audited.clone(),
    };
    Ok(Merged { report, corrected })
}

/// Reads and merges shard folders.
pub fn merge_dirs(dirs: &[PathBuf]) -> Result<Merged, MergeError> {
    let shards = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<Vec<_>, _>>()?;
    merge(shards)
}
