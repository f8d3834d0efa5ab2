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
//!
//! **One concept per file.** `catalog.rs` the mutants (id, base spec, `Defect`, the checks
//! expected to kill it); `mutant.rs` the defect wrappers; this file the kill matrix;
//! `bsdf_mutant.rs` the BSDF mutants (`BsdfDefect`) and `bsdf.rs` their rows of the matrix;
//! `power.rs` the smallest sampler distortion each profile detects; `calibrate.rs` the
//! false-alarm calibration. Everything returns data: the CLI and the sinks
//! (`report/selftest_html.rs`) write it.

pub mod bsdf;
pub mod bsdf_mutant;
pub mod calibrate;
pub mod catalog;
pub mod mutant;
pub mod power;

use crate::audit::Audit;
use crate::check::Profile;
use crate::record::{CheckRecord, Verdict};
use crate::run::DEFAULT_SEED;
use crate::run::{run_plan, AuditOptions, CheckEventFn, RunControl};
use crate::subject::{spec_width, Hints};
use catalog::{Entry, Route, CATALOG};
use mfh_reference::family::FamilySpec;
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
    /// Told of each check of the mutants' and controls' audits as it starts and finishes (the
    /// CLI prints these under `MFH_TRACE`); None: nothing is told.
    pub on_check: Option<CheckEventFn>,
}

impl SelftestOptions {
    /// The run control of every audit of the self-test: its check events go to
    /// [`SelftestOptions::on_check`].
    fn control(&self) -> RunControl {
        RunControl {
            on_check: self.on_check.clone(),
            ..Default::default()
        }
    }

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
    /// The BSDF mutants' kill matrix ([`bsdf`]; with `--subset all` or `--only bsdf`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bsdf_mutants: Vec<bsdf::BsdfMutantResult>,
    /// The BSDF controls: each base BSDF unmutated, per seed.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bsdf_controls: Vec<bsdf::BsdfControl>,
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
            bsdf_mutants: Vec::new(),
            bsdf_controls: Vec::new(),
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
            && self.bsdf_mutants.iter().all(bsdf::BsdfMutantResult::caught)
            && self.bsdf_controls.iter().all(|c| c.failures.is_empty())
            && self.calibration.as_ref().is_none_or(|c| c.passed())
    }

    /// The mutants not caught at some seed, with why.
    pub fn survivors(&self) -> Vec<String> {
        let mut out = Vec::new();
        let rows = self.mutants.iter().map(|m| (&m.id, &m.runs, &m.expected));
        let bsdf_rows = self
            .bsdf_mutants
            .iter()
            .map(|m| (&m.id, &m.runs, &m.expected));
        for (id, runs, expected) in rows.chain(bsdf_rows) {
            for r in runs {
                if !r.killed {
                    out.push(format!("{id} survived seed {}", r.seed));
                } else if !r.expected_hit {
                    out.push(format!(
                        "{id} at seed {} was killed by {:?}, none of the expected {expected:?}",
                        r.seed, r.killers
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
pub(crate) fn hints_of(base: &Value) -> Hints {
    let Ok(spec) = serde_json::from_value::<mfh_reference::ModelSpec>(base.clone()) else {
        return Hints::default();
    };
    Hints {
        lobe_width: Some(spec_width(&spec)),
        theta_kinks: spec.theta_kinks(),
        anisotropic: None,
    }
}

/// The sharpness of the lobe pairs the SG product is checked at (per profile: the quick
/// grids span three decades, like the SG checks' own).
fn sg_sharpness(profile: Profile) -> &'static [f64] {
    match profile {
        Profile::Ci | Profile::Quick => &[1.0, 30.0, 1000.0],
        Profile::Standard | Profile::Thorough => &[0.1, 1.0, 10.0, 100.0, 1000.0, 1e4],
    }
}

/// The `sg.product` records of a product with `defect`: one per sharpness, lobes a (axis n,
/// amplitude 1.7) and b (axis 0.3 rad away, sharpness λ/2 + 0.3, amplitude 0.6).
fn sg_records(defect: mutant::Defect, profile: Profile) -> Vec<CheckRecord> {
    use mfh_reference::sg::Sg;
    let src = "seed 003 §1: G₁⊗G₂ = G(p_m/‖p_m‖, λ_m‖p_m‖, μ₁μ₂e^{λ_m(‖p_m‖−1)})";
    sg_sharpness(profile)
        .iter()
        .map(|&lambda| {
            let case = serde_json::json!({"sharpness": [lambda, 0.5 * lambda + 0.3]});
            let mut r = CheckRecord::new("sg.product", Value::Null, case, src);
            let b_axis = [0.3f64.sin(), 0.0, 0.3f64.cos()];
            match (
                Sg::new([0.0, 0.0, 1.0], lambda, 1.7),
                Sg::new(b_axis, 0.5 * lambda + 0.3, 0.6),
            ) {
                (Ok(a), Ok(b)) => crate::check::sg::product_check(&mut r, &a, &b, &|a, b| {
                    mutant::sg_product(a, b, defect)
                }),
                (a, b) => {
                    r.verdict = Verdict::Error {
                        message: format!("invalid lobes: {:?} {:?}", a.err(), b.err()),
                    }
                }
            }
            r
        })
        .collect()
}

/// Audits the model of `base` with `defect` by `route` at `seed` under `control`: the records.
fn audit(
    base: &str,
    defect: mutant::Defect,
    name: &str,
    route: Route,
    profile: Profile,
    seed: u64,
    control: RunControl,
) -> Result<Vec<CheckRecord>, String> {
    if route == Route::SgProduct {
        return Ok(sg_records(defect, profile));
    }
    let spec: ModelSpec =
        serde_json::from_str(base).map_err(|e| format!("mutant {name}: base spec: {e}"))?;
    let value = serde_json::to_value(&spec).map_err(|e| e.to_string())?;
    let model = Arc::new(Mutated::new(&spec, defect).map_err(|e| format!("{name}: {e}"))?);
    Ok(match route {
        Route::Gate { slope_moments } => {
            Audit::of(model.as_ref())
                .name(name)
                .hint(hints_of(&value))
                .profile(profile)
                .seed(seed)
                .slope_moments(slope_moments)
                .control(control)
                .run()
                .records
        }
        Route::VisibleMoments | Route::SgProduct => {
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
                control,
                ..Default::default()
            };
            run_plan(&plan, &options).0
        }
    })
}

/// A base spec as JSON (the empty object for the SG mutants).
fn base_value(base: &str) -> Value {
    serde_json::from_str::<ModelSpec>(base)
        .ok()
        .and_then(|s| serde_json::to_value(s).ok())
        .unwrap_or_else(|| serde_json::from_str(base).unwrap_or(Value::Null))
}

fn describe(r: &CheckRecord) -> String {
    format!("{} {}", r.check, r.case)
}

/// The ids of the checks that failed, sorted, each once.
pub(crate) fn killers(records: &[CheckRecord]) -> Vec<String> {
    let mut killers: Vec<String> = records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .map(|r| r.check.clone())
        .collect();
    killers.sort_unstable();
    killers.dedup();
    killers
}

pub(crate) fn kill_run(
    records: &[CheckRecord],
    expected: &[&str],
    seed: u64,
    seconds: f64,
) -> KillRun {
    let killers = killers(records);
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

/// Runs the self-test: the controls, then every selected mutant at every seed.
pub fn run(options: &SelftestOptions, progress: Option<Progress<'_>>) -> SelftestReport {
    let t = Instant::now();
    let entries = selected(options);
    let say = |line: String| {
        if let Some(p) = progress {
            p(&line);
        }
    };
    // Controls: each (base, route) once per seed, with the identity defect.
    let mut bases: Vec<(&str, Route)> = Vec::new();
    for e in &entries {
        if !bases.contains(&(e.base, e.route)) {
            bases.push((e.base, e.route));
        }
    }
    let mut controls = Vec::new();
    for &(base, route) in &bases {
        let identity = match route {
            Route::SgProduct => mutant::Defect::SgProductAmplitude { e: 0.0 },
            _ => mutant::Defect::DScale { e: 0.0 },
        };
        for &seed in &options.seeds {
            let (passed, failures) = match audit(
                base,
                identity,
                "control",
                route,
                options.profile,
                seed,
                options.control(),
            ) {
                Ok(records) => {
                    let failures: Vec<String> = records
                        .iter()
                        .filter(|r| r.verdict.is_failure())
                        .map(describe)
                        .collect();
                    (failures.is_empty() && !records.is_empty(), failures)
                }
                Err(e) => (false, vec![e]),
            };
            say(format!(
                "control {base} seed {seed:#x}: {}",
                if passed { "pass" } else { "FAIL" }
            ));
            controls.push(ControlRun {
                base: base_value(base),
                route,
                seed,
                passed,
                failures,
            });
        }
    }
    let mut mutants = Vec::new();
    for e in entries {
        let runs = options
            .seeds
            .iter()
            .map(|&seed| {
                let t = Instant::now();
                let (records, error) = match audit(
                    e.base,
                    e.defect,
                    e.id,
                    e.route,
                    options.profile,
                    seed,
                    options.control(),
                ) {
                    Ok(r) => (r, None),
                    Err(err) => (Vec::new(), Some(err)),
                };
                let run = kill_run(&records, e.expected, seed, t.elapsed().as_secs_f64());
                say(format!(
                    "{} seed {seed:#x}: {} by {:?} ({:.1} s){}",
                    e.id,
                    if run.killed { "killed" } else { "SURVIVED" },
                    run.killers,
                    run.seconds,
                    error.map(|e| format!(" error: {e}")).unwrap_or_default()
                ));
                run
            })
            .collect();
        mutants.push(MutantResult {
            id: e.id.to_string(),
            description: e.description.to_string(),
            base: base_value(e.base),
            defect: e.defect,
            expected: e.expected.iter().map(|s| s.to_string()).collect(),
            route: e.route,
            runs,
        });
    }
    let (bsdf_mutants, bsdf_controls) = bsdf::run(options, progress);
    SelftestReport {
        mutants,
        controls,
        bsdf_mutants,
        bsdf_controls,
        wall_seconds: t.elapsed().as_secs_f64(),
        ..SelftestReport::empty(options)
    }
}
