//! The BSDF rows of `mfh selftest`: every [`BsdfDefect`] audited through the public gate
//! ([`Audit::of_bsdf`]) at each seed, and the unmutated bases as controls. They run with
//! `--subset all` or `--only` naming them (`--only bsdf`): a BSDF audit at the ci profile
//! takes seconds, 13 mutants × 3 seeds about four minutes on 2 cores.

use super::bsdf_mutant::{BsdfDefect, MutatedBsdf};
use super::{kill_run, KillRun, Progress, SelftestOptions, Subset};
use crate::audit::Audit;
use serde::Serialize;
use serde_json::Value;
use std::time::Instant;

/// A BSDF mutant's row of the kill matrix.
#[derive(Debug, Clone, Serialize)]
pub struct BsdfMutantResult {
    /// The mutant's id.
    pub id: String,
    /// The defect.
    pub defect: String,
    /// The base BSDF's spec.
    pub base: Value,
    /// The check ids expected to kill it.
    pub expected: Vec<String>,
    /// One run per seed.
    pub runs: Vec<KillRun>,
}

impl BsdfMutantResult {
    /// Killed at every seed, by an expected check each time.
    pub fn caught(&self) -> bool {
        !self.runs.is_empty() && self.runs.iter().all(|r| r.killed && r.expected_hit)
    }
}

/// An unmutated base BSDF audited as a control: it must pass.
#[derive(Debug, Clone, Serialize)]
pub struct BsdfControl {
    /// The base BSDF's spec.
    pub base: Value,
    /// The audit seed.
    pub seed: u64,
    /// The failing checks (none for a pass).
    pub failures: Vec<String>,
}

/// Whether the options select the BSDF mutant `defect`.
fn selected(options: &SelftestOptions, defect: BsdfDefect) -> bool {
    match &options.filter {
        Some(f) => defect.id().contains(f.as_str()),
        None => options.subset == Subset::All,
    }
}

/// Whether the options select any BSDF mutant.
pub fn any_selected(options: &SelftestOptions) -> bool {
    BsdfDefect::ALL.into_iter().any(|d| selected(options, d))
}

/// Runs the selected BSDF mutants and their bases' controls.
pub fn run(
    options: &SelftestOptions,
    progress: Option<Progress<'_>>,
) -> (Vec<BsdfMutantResult>, Vec<BsdfControl>) {
    let defects: Vec<BsdfDefect> = BsdfDefect::ALL
        .into_iter()
        .filter(|d| selected(options, *d))
        .collect();
    let mut bases: Vec<mfh_reference::bsdf::BsdfSpec> = Vec::new();
    for d in &defects {
        if !bases.contains(&d.base()) {
            bases.push(d.base());
        }
    }
    let mut controls = Vec::new();
    for base in &bases {
        let Ok(bsdf) = base.build() else { continue };
        for &seed in &options.seeds {
            let report = Audit::of_bsdf(&bsdf)
                .name("control")
                .profile(options.profile)
                .seed(seed)
                .control(options.control())
                .run();
            controls.push(BsdfControl {
                base: serde_json::to_value(base).unwrap_or(Value::Null),
                seed,
                failures: super::killers(&report.records),
            });
        }
    }
    let mut mutants = Vec::new();
    for defect in defects {
        let m = MutatedBsdf::new(defect);
        let runs = options
            .seeds
            .iter()
            .map(|&seed| {
                let t = Instant::now();
                let report = Audit::of_bsdf(&m)
                    .name(defect.id())
                    .profile(options.profile)
                    .seed(seed)
                    .control(options.control())
                    .run();
                let run = kill_run(
                    &report.records,
                    defect.killers(),
                    seed,
                    t.elapsed().as_secs_f64(),
                );
                if let Some(p) = progress {
                    p(&format!(
                        "{} seed {seed}: killed by {:?} ({:.1} s)",
                        defect.id(),
                        run.killers,
                        run.seconds
                    ));
                }
                run
            })
            .collect();
        mutants.push(BsdfMutantResult {
            id: defect.id().to_string(),
            defect: format!("{defect:?}"),
            base: serde_json::to_value(defect.base()).unwrap_or(Value::Null),
            expected: defect.killers().iter().map(|s| s.to_string()).collect(),
            runs,
        });
    }
    (mutants, controls)
}
