//! The terminal summary of an audit: counts by verdict, the failures, the worst error per
//! family, time per check family, the seed and the command that reproduces the run.

use super::text;
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
        "{} in {:.1} s: {}",
        text::count(report.records.len(), "record", "records"),
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
    let worst = text::worst_passing(&report.records);
    let _ = writeln!(
        o,
        "\nby check (worst error of the passing records, in its unit):"
    );
    let _ = writeln!(
        o,
        "  {:<32} {:>7} {:>6} {:>9} {:>9}  worst passing error",
        "check", "records", "fail", "expected", "cpu s"
    );
    for (id, c) in &s.by_check {
        let _ = writeln!(
            o,
            "  {:<32} {:>7} {:>6} {:>9} {:>9.2}  {}",
            id,
            c.records,
            c.failures,
            c.expected_failures,
            c.seconds,
            text::worst_text_of(&report.records, &worst, id)
        );
    }
    let _ = writeln!(o, "\nworst error per family (passing records):");
    for (family, by_unit) in text::worst_passing_by_family(&report.records) {
        for (unit, (e, r)) in by_unit {
            let _ = writeln!(
                o,
                "  {family:<24} {:<18} ({} {})",
                unit.show(e),
                r.check,
                text::case_name_cut(&r.case, 60)
            );
        }
    }
    let failures: Vec<_> = report
        .records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .collect();
    if !failures.is_empty() {
        let _ = writeln!(o, "\nfailures ({}):", failures.len());
        for r in failures.iter().take(max_failures) {
            o.push_str(&text::block(r, "  "));
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
