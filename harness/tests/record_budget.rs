//! Each record has a wall-clock budget (`check/budget.rs`): a check of a slow model is stopped
//! at its next checkpoint (a request to a child, a step or chunk of an oracle) once the budget has passed, and its record is an `error`
//! naming the budget — not a verdict on the model —, left out of `report.jsonl` so that
//! `--resume` runs it again; the records that finish within the budget are the unbudgeted
//! run's. Times are printed, not asserted.

use mfh_harness::record::Verdict;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mfh-budget-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The GGX child that pauses 0.2 s before every answer, audited at ci with a budget of 1 s a
/// record: the checks that need more than a few round trips are stopped.
#[test]
fn a_check_past_its_budget_is_an_error_naming_it_and_resume_runs_it_again() {
    let out = temp("slow");
    let child = format!(
        "python3 {}/tests/external/slow_ggx.py 0.2",
        env!("CARGO_MANIFEST_DIR")
    );
    let t = Instant::now();
    let (code, _, err) = mfh_harness::cli::run_captured(&[
        "audit-external",
        "--cmd",
        &child,
        "--profile",
        "ci",
        "--record-budget",
        "1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    eprintln!(
        "slow child, budget 1 s: exit {code} in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(
        code, 1,
        "an audit with records past their budget fails: {err}"
    );
    let report = read(&out.join("report.json"));
    let records = report["records"].as_array().unwrap();
    let over: Vec<&Value> = records
        .iter()
        .filter(|r| {
            r["verdict"] == "error"
                && r["message"]
                    .as_str()
                    .unwrap_or("")
                    .contains("ran past its wall-clock budget of 1 s")
        })
        .collect();
    assert!(!over.is_empty(), "some check needs more than 5 round trips");
    for r in &over {
        let message = r["message"].as_str().unwrap();
        assert!(message.contains("no verdict on the model"), "{message}");
        eprintln!(
            "  {} stopped after {:.2} s",
            r["check"],
            r["cost"]["wall_seconds"].as_f64().unwrap()
        );
    }
    // Not a protocol failure: the child served every other check after the stops.
    assert!(
        !records.iter().any(|r| r["check"] == "external.protocol"),
        "{report}"
    );
    // The stopped records are not kept for --resume.
    let text = std::fs::read_to_string(out.join("report.jsonl")).unwrap();
    let kept = text.lines().count() - 1;
    let planned = records
        .iter()
        .filter(|r| !r["check"].as_str().unwrap().starts_with("audit."))
        .count();
    assert!(kept < planned, "{kept} kept of {planned}");
    assert!(
        !text.contains("wall-clock budget"),
        "no over-budget record in report.jsonl"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// Within its budget a record is the unbudgeted run's: the in-process GGX at ci under its
/// profile's budget and under a budget of a year give the same records, timings aside.
#[test]
fn records_within_the_budget_do_not_depend_on_it() {
    use mfh_harness::run::RunControl;
    use mfh_harness::{Audit, Profile};
    let ggx = mfh_reference::ndf::Ggx::new(0.3, 0.3).unwrap();
    let run = |budget: Option<std::time::Duration>| {
        let mut records = Audit::of(&ggx)
            .profile(Profile::Ci)
            .seed(11)
            .control(RunControl {
                record_budget: budget,
                ..RunControl::default()
            })
            .run()
            .records;
        for r in &mut records {
            r.cost.wall_seconds = 0.0;
            assert!(
                !matches!(&r.verdict, Verdict::Error { message } if message.contains("budget")),
                "{r:?}"
            );
        }
        records
    };
    assert_eq!(
        run(None),
        run(Some(std::time::Duration::from_secs(365 * 86_400)))
    );
}

/// GGX whose D takes at least a millisecond (a tabulated or measured D in a renderer's own
/// code, in-process), counting its calls.
struct SlowD {
    ggx: mfh_reference::ndf::Ggx,
    pause: std::time::Duration,
    calls: std::sync::atomic::AtomicU64,
}

impl mfh_harness::model::Ndf for SlowD {
    fn d(&self, m: [f64; 3]) -> f64 {
        self.calls
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        std::thread::sleep(self.pause);
        self.ggx.d(m)
    }
}

/// An in-process model is stopped at its budget too (at the oracles' checkpoints: each step of
/// an adaptive quadrature or cubature, each chunk of a sample loop), not only at a child's
/// requests: the audit of a D that takes 1 ms a call, under a budget of 0.3 s a record, makes
/// under a tenth of the calls the whole audit makes (counted on the same D without the pause),
/// and its stopped records are errors naming the budget.
#[test]
fn an_in_process_model_is_stopped_at_its_budget() {
    use mfh_harness::run::RunControl;
    use mfh_harness::{Audit, Profile};
    let slow = |pause: u64| SlowD {
        ggx: mfh_reference::ndf::Ggx::new(0.3, 0.3).unwrap(),
        pause: std::time::Duration::from_millis(pause),
        calls: std::sync::atomic::AtomicU64::new(0),
    };
    let whole = slow(0);
    let unbudgeted = Audit::of(&whole)
        .d_only()
        .profile(Profile::Ci)
        .seed(3)
        .run();
    let whole = whole.calls.into_inner();
    let paused = slow(1);
    let t = Instant::now();
    let budgeted = Audit::of(&paused)
        .d_only()
        .profile(Profile::Ci)
        .seed(3)
        .control(RunControl {
            record_budget: Some(std::time::Duration::from_millis(300)),
            ..RunControl::default()
        })
        .run();
    let calls = paused.calls.into_inner();
    eprintln!(
        "D of 1 ms, budget 0.3 s: {calls} calls of the whole audit's {whole}, {:.1} s",
        t.elapsed().as_secs_f64()
    );
    let stopped: Vec<_> = budgeted
        .records
        .iter()
        .filter(|r| mfh_harness::check::budget::is_over_budget(&r.verdict))
        .collect();
    assert!(!stopped.is_empty(), "{:#?}", budgeted.records);
    for r in &stopped {
        eprintln!("  {} stopped after {:.2} s", r.check, r.cost.wall_seconds);
    }
    assert!(
        calls * 10 < whole,
        "{calls} calls of {whole}: the stopped checks ran on"
    );
    // The records that finished are the unbudgeted run's.
    for r in budgeted.records.iter().filter(|r| !stopped.contains(r)) {
        let same = unbudgeted
            .records
            .iter()
            .find(|u| u.check == r.check && u.case == r.case)
            .expect("the same plan");
        assert_eq!(same.verdict, r.verdict, "{}", r.check);
        assert_eq!(same.measured, r.measured, "{}", r.check);
    }
}
