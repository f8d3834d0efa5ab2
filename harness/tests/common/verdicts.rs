//! What the float32 tests ask of a report (shared by `float32.rs` and `float32_bsdf.rs`).
#![allow(dead_code)] // each test binary uses its own part

use mfh_harness::record::Verdict;
use mfh_harness::run::AuditReport;
use mfh_harness::Precision;

/// The records that neither pass nor are skipped: check, case, verdict and measured error.
pub fn failing(report: &AuditReport) -> Vec<String> {
    report
        .records
        .iter()
        .filter(|r| !matches!(r.verdict, Verdict::Pass | Verdict::Skipped { .. }))
        .map(|r| format!("{} {} {:?} {:?}", r.check, r.case, r.verdict, r.measured))
        .collect()
}

/// A float32 implementation audited as f64: `audit.precision` is an error that says to declare
/// f32, the rest was judged at f32 (and says so), and nothing else fails.
pub fn assert_named_float32(report: &AuditReport) {
    let r = report
        .records
        .iter()
        .find(|r| r.check == "audit.precision")
        .expect("an audit.precision record");
    assert!(
        matches!(&r.verdict, Verdict::Error { message }
            if message.contains("float32 values; declare precision f32")),
        "{r:?}"
    );
    assert!(!report.passed());
    assert!(report.records.iter().all(|r| r.precision == Precision::F32));
    assert_eq!(failing(report).len(), 1, "{:#?}", failing(report));
}

/// Some failing record's check starts with `check` (and its line contains `detail`).
pub fn assert_fails_on(report: &AuditReport, check: &str, detail: &str) {
    let failed = failing(report);
    assert!(
        failed
            .iter()
            .any(|f| f.starts_with(check) && f.contains(detail)),
        "no failing {check} ({detail}): {failed:#?}"
    );
}
