//! The terminal summary of an audit: counts by verdict, the failures, the worst error per
//! family, time per check family, the seed and the command that reproduces the run.

use crate::run::AuditReport;
use std::fmt::Write;

/// Renders the summary (at most `max_failures` failures listed).
pub fn render(report: &AuditReport, max_failures: usize) -> String {
    let s = &report.summary;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "mfh audit — scene \"{}\", profile {}, seed {}",
        report.scene,
        report.profile.name(),
        report.seed
    );
    let counts: Vec<String> = s.counts.iter().map(|(k, v)| format!("{k} {v}")).collect();
    let _ = writeln!(
        o,
        "{} records in {:.1} s: {}",
        report.records.len(),
        s.wall_seconds,
        counts.join(", ")
    );
    let _ = writeln!(
        o,
        "statistical checks: {} at Šidák level {:.3e} each (family-wise α = {})",
        s.statistical.0,
        s.statistical.1,
        crate::tolerance::STATISTICAL_ALPHA.value
    );
    let _ = writeln!(o, "\nby check:");
    let _ = writeln!(
        o,
        "  {:<32} {:>7} {:>6} {:>9} {:>9} {:>12}",
        "check", "records", "fail", "expected", "cpu s", "worst pass"
    );
    for (id, c) in &s.by_check {
        let _ = writeln!(
            o,
            "  {:<32} {:>7} {:>6} {:>9} {:>9.2} {:>12.2e}",
            id, c.records, c.failures, c.expected_failures, c.seconds, c.worst_passing_error
        );
    }
    let _ = writeln!(o, "\nworst error per family (passing records):");
    for (family, (e, at)) in &s.worst_error {
        let _ = writeln!(o, "  {family:<24} {e:.2e}  ({at})");
    }
    let failures: Vec<_> = report
        .records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .collect();
    if !failures.is_empty() {
        let _ = writeln!(o, "\nfailures ({}):", failures.len());
        for r in failures.iter().take(max_failures) {
            let _ = writeln!(
                o,
                "  {} {} {} — value {:?}, oracle {:?}, measured {:?}, {:?}",
                r.check,
                r.model,
                r.case,
                r.value,
                r.oracle.map(|x| x.value),
                r.measured,
                r.verdict
            );
            if let Some(region) = &r.region {
                let _ = writeln!(o, "    region: {}", region.text);
            }
            if let Some(note) = r.oracle.and_then(|o| o.noise_note()) {
                let _ = writeln!(o, "    ({note})");
            }
        }
        if failures.len() > max_failures {
            let _ = writeln!(
                o,
                "  … and {} more (report.json)",
                failures.len() - max_failures
            );
        }
    }
    let _ = writeln!(
        o,
        "\n{} — reproduce: {}",
        if report.passed() { "PASS" } else { "FAIL" },
        report.command
    );
    o
}
