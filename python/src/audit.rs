//! `audit_bsdf` and `audit_ndf`: the Python callables wrapped as the capability traits
//! ([`crate::model`]), audited by `Audit::of_bsdf` / `Audit::of` (the same plan as a Rust model's),
//! run by `run::run_plan` on a thread of the audit's own while the calling (main) thread waits
//! without the GIL and checks for Ctrl-C every [`POLL`].

// The Python functions take their keyword arguments one by one (`mfh.audit_bsdf`'s signature);
// PyO3's wrappers of them have as many.
#![allow(clippy::too_many_arguments)]

use crate::caller::Caller;
use crate::model::{PyBsdf, PyNdf};
use crate::report::Report;
use mfh_harness::check::{PlannedCheck, Profile};
use mfh_harness::cli::progress::{Bar, Lines};
use mfh_harness::record::{CheckRecord, Verdict};
use mfh_harness::run::{
    judge_at, run_plan, sidak_alpha, AuditOptions, AuditReport, CheckEvent, CheckEventFn, Progress,
    ProgressFn, RunControl,
};
use mfh_harness::tolerance::STATISTICAL_ALPHA;
use mfh_harness::{Audit, Precision, Sampling};
use mfh_reference::bsdf::dielectric::{ETA_MAX, ETA_MIN, ETA_MIN_GAP};
use mfh_reference::bsdf::Transport;
use mfh_reference::Masking;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde_json::json;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often the waiting main thread looks for Ctrl-C (Python's signal handlers run only on
/// the main thread, between bytecodes: it must come back to Python to see one).
const POLL: Duration = Duration::from_millis(50);

/// What every audit takes besides the model.
struct Settings {
    profile: Profile,
    precision: Precision,
    seed: u64,
    name: String,
    against: Option<String>,
    checks: Option<Vec<String>>,
    quiet: bool,
    command: String,
    /// The progress lines' label ("audit_bsdf", "audit_ndf").
    label: &'static str,
}

fn settings(
    label: &'static str,
    profile: &str,
    precision: &str,
    seed: u64,
    name: String,
    against: Option<String>,
    checks: Option<Vec<String>>,
    quiet: bool,
    command: String,
) -> PyResult<Settings> {
    let profile = Profile::from_name(profile).ok_or_else(|| {
        PyValueError::new_err(format!(
            "profile = {profile:?} is not one of \"ci\", \"quick\", \"standard\", \"thorough\""
        ))
    })?;
    let precision = precision
        .parse::<Precision>()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(Settings {
        profile,
        precision,
        seed,
        name,
        against,
        checks,
        quiet,
        command,
        label,
    })
}

fn parse<T: serde::de::DeserializeOwned>(field: &str, value: &str, allowed: &str) -> PyResult<T> {
    serde_json::from_value(json!(value))
        .map_err(|_| PyValueError::new_err(format!("{field} = {value:?} is not one of {allowed}")))
}

/// The relative index against the reference dielectric's limits, as the external protocol
/// checks a child's `eta`.
fn check_eta(eta: f64) -> PyResult<f64> {
    if !(ETA_MIN..=ETA_MAX).contains(&eta) {
        return Err(PyValueError::new_err(format!(
            "eta = {eta} is outside [{ETA_MIN}, {ETA_MAX}] (η inside / η outside)"
        )));
    }
    if !((eta - 1.0).abs() >= ETA_MIN_GAP) {
        return Err(PyValueError::new_err(format!(
            "eta = {eta} is less than {ETA_MIN_GAP:e} away from 1 (at η = 1 refraction is a \
             delta, wo = −wi, which no density-based check resolves)"
        )));
    }
    Ok(eta)
}

/// Audits a BSDF given as Python callables (see `mfh.audit_bsdf`, which validates the
/// arguments and documents them).
#[pyfunction]
#[pyo3(signature = (eval, pdf, sample, eta, transport, precision, profile, against, seed, name,
                    checks, quiet, command, ndf_d, ndf_lambda, ndf_masking, ndf_visible_normals))]
pub fn audit_bsdf(
    py: Python<'_>,
    eval: PyObject,
    pdf: PyObject,
    sample: PyObject,
    eta: Option<f64>,
    transport: &str,
    precision: &str,
    profile: &str,
    against: Option<String>,
    seed: u64,
    name: String,
    checks: Option<Vec<String>>,
    quiet: bool,
    command: String,
    ndf_d: Option<PyObject>,
    ndf_lambda: Option<PyObject>,
    ndf_masking: Option<String>,
    ndf_visible_normals: bool,
) -> PyResult<Report> {
    let s = settings(
        "audit_bsdf",
        profile,
        precision,
        seed,
        name,
        against,
        checks,
        quiet,
        command,
    )?;
    let transport: Transport = parse("transport", transport, "\"radiance\", \"importance\"")?;
    let eta = eta.map(check_eta).transpose()?;
    let masking: Option<Masking> = ndf_masking
        .as_deref()
        .map(|m| parse("masking", m, "\"uncorrelated\", \"height_correlated\""))
        .transpose()?;
    let caller = Arc::new(Caller::new(py)?);
    let bsdf = PyBsdf {
        eval,
        pdf,
        sample,
        eta,
        transport,
        caller: caller.clone(),
    };
    let ndf = ndf_d.map(|d| PyNdf {
        d,
        lambda: ndf_lambda,
        sample_wm: None,
        pdf_wm: None,
        sample_wm_visible: None,
        pdf_wm_visible: None,
        caller: caller.clone(),
    });
    let build = || {
        let mut audit = Audit::of_bsdf(&bsdf).name(&s.name);
        if let Some(ndf) = &ndf {
            audit = audit.ndf(ndf).masking(masking);
            if ndf_visible_normals {
                audit = audit.sampling(Some(Sampling::VisibleNormals));
            }
        }
        audit
    };
    run(py, &caller, build, &s)
}

/// Audits an NDF given as Python callables (see `mfh.audit_ndf`).
#[pyfunction]
#[pyo3(signature = (d, lambda_, sample_wm, pdf_wm, sample_wm_visible, pdf_wm_visible, precision,
                    profile, against, seed, name, checks, quiet, command, masking, sampling,
                    theta_max))]
pub fn audit_ndf(
    py: Python<'_>,
    d: PyObject,
    lambda_: Option<PyObject>,
    sample_wm: Option<PyObject>,
    pdf_wm: Option<PyObject>,
    sample_wm_visible: Option<PyObject>,
    pdf_wm_visible: Option<PyObject>,
    precision: &str,
    profile: &str,
    against: Option<String>,
    seed: u64,
    name: String,
    checks: Option<Vec<String>>,
    quiet: bool,
    command: String,
    masking: Option<String>,
    sampling: Option<String>,
    theta_max: Option<f64>,
) -> PyResult<Report> {
    let s = settings(
        "audit_ndf",
        profile,
        precision,
        seed,
        name,
        against,
        checks,
        quiet,
        command,
    )?;
    // "none": the renderer does not mask / sample; absent: what the capabilities allow.
    let masking: Option<Option<Masking>> = match masking.as_deref() {
        None => None,
        Some("none") => Some(None),
        Some(m) => Some(Some(parse(
            "masking",
            m,
            "\"uncorrelated\", \"height_correlated\", \"none\"",
        )?)),
    };
    let sampling: Option<Option<Sampling>> = match sampling.as_deref() {
        None => None,
        Some("none") => Some(None),
        Some(m) => Some(Some(parse(
            "sampling",
            m,
            "\"normals\", \"visible_normals\", \"none\"",
        )?)),
    };
    let caller = Arc::new(Caller::new(py)?);
    let ndf = PyNdf {
        d,
        lambda: lambda_,
        sample_wm,
        pdf_wm,
        sample_wm_visible,
        pdf_wm_visible,
        caller: caller.clone(),
    };
    let build = || {
        // A call crosses into Python: checks whose oracle accuracy is a cost trade-off take the
        // looser of their two stated tolerances, as for a child of the external protocol.
        let mut audit = Audit::of(&ndf).name(&s.name).remote();
        if ndf.sample_wm.is_none()
            && ndf.lambda.is_none()
            && ndf.sample_wm_visible.is_none()
        {
            // The callables given are the capabilities: `d=` alone states that D is all.
            audit = audit.d_only();
        }
        if let Some(m) = masking {
            audit = audit.masking(m);
        }
        if let Some(m) = sampling {
            audit = audit.sampling(m);
        }
        if let Some(t) = theta_max {
            audit = audit.theta_max(t);
        }
        audit
    };
    run(py, &caller, build, &s)
}

/// Plans and runs the audit `build` makes on a thread of its own; the calling thread waits
/// without the GIL (the checks' threads take it for each call) and turns Ctrl-C into stopped
/// calls, waits for the checks to end (quickly: every call then answers NaN at once), and
/// raises the `KeyboardInterrupt`.
fn run<'a>(
    py: Python<'_>,
    caller: &Arc<Caller>,
    build: impl FnOnce() -> Audit<'a> + Send,
    s: &Settings,
) -> PyResult<Report> {
    let mut interrupt: Option<PyErr> = None;
    let result = std::thread::scope(|scope| {
        let handle = scope.spawn(|| plan_and_run(build(), caller, s));
        while !handle.is_finished() {
            py.allow_threads(|| std::thread::sleep(POLL));
            if interrupt.is_none() {
                if let Err(e) = py.check_signals() {
                    caller.interrupt();
                    eprintln!("mfh {}: interrupted; stopping the running checks", s.label);
                    interrupt = Some(e);
                }
            }
        }
        handle.join()
    });
    if let Some(e) = interrupt {
        return Err(e);
    }
    match result {
        Ok(Ok(report)) => Ok(Report::new(report, caller.counts())),
        Ok(Err(message)) => Err(PyValueError::new_err(message)),
        Err(_) => Err(PyValueError::new_err(
            "mfh: the audit panicked outside a check (a bug of mfh: please report it)",
        )),
    }
}

/// The audit's plan, the checks `s.checks` keeps of it, run with progress on stderr; the report
/// with the `python.call` record of the first error the callables met.
fn plan_and_run(
    audit: Audit<'_>,
    caller: &Arc<Caller>,
    s: &Settings,
) -> Result<AuditReport, String> {
    let t = Instant::now();
    let audit = audit.profile(s.profile).seed(s.seed).precision(s.precision);
    let audit = match &s.against {
        Some(spec) => audit.against(spec),
        None => audit,
    };
    let (plan, mut errors) = audit.plan();
    // The Šidák level is the whole plan's, so that the checks kept give the records the
    // whole audit gives them (as a shard's do).
    let k_all = plan.iter().filter(|p| p.statistical).count();
    let plan = match &s.checks {
        None => plan,
        Some(keep) => {
            let mut ids: Vec<String> = plan.iter().map(|p| p.check.clone()).collect();
            ids.sort_unstable();
            ids.dedup();
            if let Some(unknown) = keep.iter().find(|c| !ids.contains(c)) {
                return Err(format!(
                    "checks: {unknown:?} is not planned for this model; planned: {}",
                    ids.join(", ")
                ));
            }
            plan.into_iter()
                .filter(|p| keep.contains(&p.check))
                .collect()
        }
    };
    let plan: Vec<_> = plan
        .into_iter()
        .map(|p| not_after_a_stop(p, caller.clone()))
        .collect();
    let lines = Lines::start(s.label, s.quiet).map(Arc::new);
    let l = lines.clone();
    let on_check = CheckEventFn(Arc::new(move |event: CheckEvent<'_>| {
        let Some(l) = &l else { return };
        match event {
            CheckEvent::Plan { checks, resumed, .. } => l.plan(checks, resumed),
            CheckEvent::Started { index, planned } => {
                l.started(index, format!("{} {}", planned.check, planned.case))
            }
            CheckEvent::Finished { index, record, .. } => {
                l.finished(index, record.verdict.is_failure())
            }
        }
    }));
    let bar = Arc::new(Bar::new(plan.len() as u64, "checks", s.quiet));
    let b = bar.clone();
    let options = AuditOptions {
        profile: s.profile,
        seed: s.seed,
        out: None,
        progress: bar.enabled().then(|| {
            ProgressFn(Arc::new(move |p: Progress| {
                b.update(p.done as u64, format!(", {} failed", p.failures))
            }))
        }),
        control: RunControl {
            on_check: Some(on_check),
            ..RunControl::default()
        },
    };
    let (mut records, mut k, mut alpha) = run_plan(&plan, &options);
    drop(plan);
    bar.finish();
    if let Some(l) = &lines {
        l.finish();
    }
    if s.checks.is_some() {
        k = k_all;
        alpha = sidak_alpha(STATISTICAL_ALPHA.value, k_all);
        judge_at(&mut records, alpha);
    }
    records.append(&mut errors);
    if let Some(message) = caller.first_error() {
        let mut r = CheckRecord::new(
            "python.call",
            json!({ "name": s.name }),
            json!({}),
            "the Python callables' answers (an exception, a wrong shape or a NaN)",
        );
        r.verdict = Verdict::Error { message };
        r.precision = s.precision;
        records.push(r);
    }
    Ok(AuditReport::from_records(
        s.name.clone(),
        &options,
        s.command.clone(),
        records,
        (k, alpha),
        t.elapsed().as_secs_f64(),
    ))
}

/// `planned`, which once the calls have stopped (an error, Ctrl-C) is not started: its record
/// is an error that says why, so an interrupted or broken audit ends with the checks running.
fn not_after_a_stop<'a>(mut planned: PlannedCheck<'a>, caller: Arc<Caller>) -> PlannedCheck<'a> {
    let run = std::mem::replace(&mut planned.run, Box::new(|_| unreachable_record()));
    let (check, model, case) = (
        planned.check.clone(),
        planned.model.clone(),
        planned.case.clone(),
    );
    planned.run = Box::new(move |ctx| match caller.stop_reason() {
        None => run(ctx),
        Some(reason) => {
            let mut r = CheckRecord::new(&check, model.clone(), case.clone(), "");
            r.verdict = Verdict::Error {
                message: reason.into(),
            };
            r
        }
    });
    planned
}

/// The placeholder runner while a planned check's runner is wrapped (never run).
fn unreachable_record() -> CheckRecord {
    let mut r = CheckRecord::new("python.call", json!(null), json!({}), "");
    r.verdict = Verdict::Error {
        message: "a placeholder runner ran".into(),
    };
    r
}
