//! `mfh selftest`: the harness proves its own power and calibration.
//!
//! Power: every mutant of [`catalog::CATALOG`] — a reference model behind a wrapper with one
//! defect ([`mutant::Mutated`]) — is audited through the public gate ([`crate::Audit`]) at a
//! profile, for each of several seeds; a mutant is killed at a seed when a record fails. The
//! kill matrix (mutant × the checks that caught it, per seed) is the report. Each unmutated
//! base is audited the same way as a control: a control that fails would make its mutants'
//! kills meaningless, and fails the self-test. An `unexpected_pass` among a mutant's records
//! (an expected failure that stops failing under the mutant) is listed.
//!
//! Calibration ([`calibrate`]): seeded chi-square and KS runs of correct samplers; the
//! rejection fraction must lie in the 99 % binomial interval of α and the p-values must be
//! uniform.

pub mod calibrate;
pub mod catalog;
pub mod mutant;
pub mod power;

use crate::audit::{run_plan, AuditOptions};
use crate::check::Profile;
use crate::gate::Audit;
use crate::oracle::chi2::DEFAULT_SEED;
use crate::record::{CheckRecord, Verdict};
use crate::subject::{lobe_width, theta_kinks, Hints};
use catalog::{Entry, Route, CATALOG};
use mfh_reference::{Model, ModelSpec};
use mutant::Mutated;
use serde::Serialize;
use serde_json::Value;
use std::sync::Arc;
use std::time::Instant;

/// The schema version of the self-test report.
pub const SCHEMA_VERSION: u32 = 1;

/// Which mutants run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Subset {
    /// The representative subset CI runs ([`Entry::ci`]).
    Ci,
    /// Every mutant.
    All,
}

/// How to run the self-test.
#[derive(Debug, Clone)]
pub struct SelftestOptions {
    /// The audit profile of every mutant.
    pub profile: Profile,
    /// The audit seeds (each mutant is audited once per seed).
    pub seeds: Vec<u64>,
    /// Which mutants.
    pub subset: Subset,
    /// Only the mutants whose id contains this (None: all of the subset).
    pub filter: Option<String>,
}

impl SelftestOptions {
    /// `n` seeds derived from the default audit seed: DEFAULT_SEED + i.
    pub fn seeds(n: usize) -> Vec<u64> {
        (0..n as u64)
            .map(|i| DEFAULT_SEED.wrapping_add(i))
            .collect()
    }
}

/// One audit of one mutant at one seed.
#[derive(Debug, Clone, Serialize)]
pub struct KillRun {
    /// The audit seed.
    pub seed: u64,
    /// Whether a record failed.
    pub killed: bool,
    /// The check ids with a failing record (sorted).
    pub killers: Vec<String>,
    /// Whether one of the expected check ids is among the killers.
    pub expected_hit: bool,
    /// Records whose expected failure stopped failing under the mutant (check and case).
    pub unexpected_passes: Vec<String>,
    /// Records audited.
    pub records: usize,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// A mutant's row of the kill matrix.
#[derive(Debug, Clone, Serialize)]
pub struct MutantResult {
    /// The mutant's id.
    pub id: String,
    /// What is wrong.
    pub description: String,
    /// The base model's spec.
    pub base: Value,
    /// The defect.
    pub defect: mutant::Defect,
    /// The check ids expected to kill it.
    pub expected: Vec<String>,
    /// How it was audited.
    pub route: Route,
    /// One run per seed.
    pub runs: Vec<KillRun>,
}

impl MutantResult {
    /// Killed at every seed, by an expected check each time.
    pub fn caught(&self) -> bool {
        !self.runs.is_empty() && self.runs.iter().all(|r| r.killed && r.expected_hit)
    }
}

/// An unmutated base audited as a control: it must pass.
#[derive(Debug, Clone, Serialize)]
pub struct ControlRun {
    /// The base model's spec.
    pub base: Value,
    /// How it was audited.
    pub route: Route,
    /// The audit seed.
    pub seed: u64,
    /// Whether every record passed.
    pub passed: bool,
    /// The failing records (check and case).
    pub failures: Vec<String>,
}

/// The result of `mfh selftest`.
#[derive(Debug, Clone, Serialize)]
pub struct SelftestReport {
    /// The report schema version ([`SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// mfh's version.
    pub mfh_version: &'static str,
    /// The profile.
    pub profile: Profile,
    /// The seeds.
    pub seeds: Vec<u64>,
    /// The subset.
    pub subset: Subset,
    /// The mutants in the catalog (all of them, whatever the subset).
    pub catalog_size: usize,
    /// The kill matrix: one row per mutant run.
    pub mutants: Vec<MutantResult>,
    /// The controls: each base unmutated, per seed.
    pub controls: Vec<ControlRun>,
    /// The false-alarm calibration, when run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration: Option<calibrate::Calibration>,
    /// The detectable sampler distortion per sampler, when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power: Option<Vec<power::Detectable>>,
    /// Wall time, seconds.
    pub wall_seconds: f64,
}

impl SelftestReport {
    /// A report with no mutant run (e.g. for a calibration alone).
    pub fn empty(options: &SelftestOptions) -> Self {
        Self {
            schema_version: SCHEMA_VERSION,
            mfh_version: env!("CARGO_PKG_VERSION"),
            profile: options.profile,
            seeds: options.seeds.clone(),
            subset: options.subset,
            catalog_size: CATALOG.len(),
            mutants: Vec::new(),
            controls: Vec::new(),
            calibration: None,
            power: None,
            wall_seconds: 0.0,
        }
    }

    /// Every mutant caught at every seed by an expected check, every control passed, and the
    /// calibration (if run) within its bounds.
    pub fn passed(&self) -> bool {
        self.mutants.iter().all(MutantResult::caught)
            && self.controls.iter().all(|c| c.passed)
            && self.calibration.as_ref().is_none_or(|c| c.passed())
    }

    /// The mutants not caught at some seed, with why.
    pub fn survivors(&self) -> Vec<String> {
        let mut out = Vec::new();
        for m in &self.mutants {
            for r in &m.runs {
                if !r.killed {
                    out.push(format!("{} survived seed {}", m.id, r.seed));
                } else if !r.expected_hit {
                    out.push(format!(
                        "{} at seed {} was killed by {:?}, none of the expected {:?}",
                        m.id, r.seed, r.killers, m.expected
                    ));
                }
            }
        }
        out
    }
}

/// What to call after each audit (a line for the terminal); never changes a result.
pub type Progress<'p> = &'p (dyn Fn(&str) + Sync);

/// The hints a reference spec implies (as `Subject` derives them for reference models): they
/// only speed the oracles up.
fn hints_of(base: &Value) -> Hints {
    Hints {
        lobe_width: Some(lobe_width(base)),
        theta_kinks: theta_kinks(base),
        anisotropic: None,
    }
}

/// Audits `model` by `route` at `seed`: the records.
fn audit(
    model: Arc<Mutated>,
    name: &str,
    base: &Value,
    route: Route,
    profile: Profile,
    seed: u64,
) -> Vec<CheckRecord> {
    match route {
        Route::Gate { slope_moments } => {
            Audit::of(model.as_ref())
                .name(name)
                .hint(hints_of(base))
                .profile(profile)
                .seed(seed)
                .slope_moments(slope_moments)
                .run()
                .records
        }
        Route::VisibleMoments => {
            let model: Arc<dyn Model> = model;
            let plan = crate::check::ds::plan(
                model,
                profile,
                std::f64::consts::FRAC_PI_2,
                &format!("selftest mutant `{name}`"),
            );
            let options = AuditOptions {
                profile,
                seed,
                out: None,
                progress: None,
            };
            run_plan(&plan, &options).0
        }
    }
}

fn describe(r: &CheckRecord) -> String {
    format!("{} {}", r.check, r.case)
}

fn kill_run(records: &[CheckRecord], expected: &[&str], seed: u64, seconds: f64) -> KillRun {
    let mut killers: Vec<String> = records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .map(|r| r.check.clone())
        .collect();
    killers.sort_unstable();
    killers.dedup();
    KillRun {
        seed,
        killed: !killers.is_empty(),
        expected_hit: killers.iter().any(|k| expected.contains(&k.as_str())),
        unexpected_passes: records
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::UnexpectedPass { .. }))
            .map(describe)
            .collect(),
        killers,
        records: records.len(),
        seconds,
    }
}

/// The catalog entries the options select.
pub fn selected(options: &SelftestOptions) -> Vec<&'static Entry> {
    CATALOG
        .iter()
        .filter(|e| options.subset == Subset::All || e.ci)
        .filter(|e| options.filter.as_ref().is_none_or(|f| e.id.contains(f)))
        .collect()
}

/// A spec of the catalog (the catalog's unit test parses them all).
fn spec_of(entry: &Entry) -> Result<(ModelSpec, Value), String> {
    let spec: ModelSpec = serde_json::from_str(entry.base)
        .map_err(|e| format!("mutant {}: base spec: {e}", entry.id))?;
    let value = serde_json::to_value(&spec).map_err(|e| e.to_string())?;
    Ok((spec, value))
}

/// Runs the self-test: the controls, then every selected mutant at every seed.
pub fn run(options: &SelftestOptions, progress: Option<Progress<'_>>) -> SelftestReport {
    let t = Instant::now();
    let entries = selected(options);
    let say = |line: String| {
        if let Some(p) = progress {
            p(&line);
        }
    };
    // Controls: each (base, route) once per seed.
    let mut bases: Vec<(&str, Route)> = Vec::new();
    for e in &entries {
        if !bases.contains(&(e.base, e.route)) {
            bases.push((e.base, e.route));
        }
    }
    let mut controls = Vec::new();
    for &(base, route) in &bases {
        let entry = Entry {
            id: "control",
            description: "",
            base,
            defect: mutant::Defect::DScale { e: 0.0 },
            expected: &[],
            route,
            ci: true,
        };
        for &seed in &options.seeds {
            let (passed, failures, value) = match spec_of(&entry).and_then(|(s, v)| {
                Mutated::new(&s, entry.defect)
                    .map(|m| (m, v))
                    .map_err(|e| e.to_string())
            }) {
                Ok((m, value)) => {
                    let records =
                        audit(Arc::new(m), "control", &value, route, options.profile, seed);
                    let failures: Vec<String> = records
                        .iter()
                        .filter(|r| r.verdict.is_failure())
                        .map(describe)
                        .collect();
                    (failures.is_empty(), failures, value)
                }
                Err(e) => (false, vec![e], Value::String(base.to_string())),
            };
            say(format!(
                "control {} seed {seed:#x}: {}",
                value,
                if passed { "pass" } else { "FAIL" }
            ));
            controls.push(ControlRun {
                base: value,
                route,
                seed,
                passed,
                failures,
            });
        }
    }
    let mut mutants = Vec::new();
    for e in entries {
        let (runs, value) = match spec_of(e) {
            Ok((spec, value)) => {
                let runs = options
                    .seeds
                    .iter()
                    .map(|&seed| {
                        let t = Instant::now();
                        let records = match Mutated::new(&spec, e.defect) {
                            Ok(m) => {
                                audit(Arc::new(m), e.id, &value, e.route, options.profile, seed)
                            }
                            Err(_) => Vec::new(),
                        };
                        let run = kill_run(&records, e.expected, seed, t.elapsed().as_secs_f64());
                        say(format!(
                            "{} seed {seed:#x}: {} by {:?} ({:.1} s)",
                            e.id,
                            if run.killed { "killed" } else { "SURVIVED" },
                            run.killers,
                            run.seconds
                        ));
                        run
                    })
                    .collect();
                (runs, value)
            }
            Err(_) => (Vec::new(), Value::Null),
        };
        mutants.push(MutantResult {
            id: e.id.to_string(),
            description: e.description.to_string(),
            base: value,
            defect: e.defect,
            expected: e.expected.iter().map(|s| s.to_string()).collect(),
            route: e.route,
            runs,
        });
    }
    SelftestReport {
        mutants,
        controls,
        wall_seconds: t.elapsed().as_secs_f64(),
        ..SelftestReport::empty(options)
    }
}
