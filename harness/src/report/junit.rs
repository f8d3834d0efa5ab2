//! JUnit XML for CI systems: one test suite per check id, one test case per record; failures
//! and errors carry the measured error and tolerance, expected failures and skips are skipped
//! cases with their reason.

use crate::record::{CheckRecord, Verdict};
use crate::run::AuditReport;
use std::collections::BTreeMap;

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A failing record's text ([`super::text::fields`], the layout every sink prints), one field
/// a line.
fn detail(r: &CheckRecord) -> String {
    super::text::fields(r)
        .iter()
        .map(|(label, text)| format!("{label}: {text}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Renders the report as JUnit XML.
pub fn render(report: &AuditReport) -> String {
    let mut suites: BTreeMap<&str, Vec<&CheckRecord>> = BTreeMap::new();
    for r in &report.records {
        suites.entry(r.check.as_str()).or_default().push(r);
    }
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let failures = report
        .records
        .iter()
        .filter(|r| matches!(r.verdict, Verdict::Fail | Verdict::UnexpectedPass { .. }))
        .count();
    let errors = report
        .records
        .iter()
        .filter(|r| matches!(r.verdict, Verdict::Error { .. }))
        .count();
    out.push_str(&format!(
        "<testsuites name=\"mfh audit: {}\" tests=\"{}\" failures=\"{failures}\" errors=\"{errors}\" time=\"{:.3}\">\n",
        escape(&report.scene),
        report.records.len(),
        report.summary.wall_seconds
    ));
    for (check, records) in suites {
        let f = records
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::Fail | Verdict::UnexpectedPass { .. }))
            .count();
        let e = records
            .iter()
            .filter(|r| matches!(r.verdict, Verdict::Error { .. }))
            .count();
        let s = records
            .iter()
            .filter(|r| {
                matches!(
                    r.verdict,
                    Verdict::Skipped { .. } | Verdict::ExpectedFailure { .. }
                )
            })
            .count();
        out.push_str(&format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{f}\" errors=\"{e}\" skipped=\"{s}\">\n",
            escape(check),
            records.len()
        ));
        for r in records {
            let name = format!("{} {}", r.model, r.case);
            out.push_str(&format!(
                "    <testcase classname=\"{}\" name=\"{}\" time=\"{:.6}\"",
                escape(check),
                escape(&name),
                r.cost.wall_seconds
            ));
            match &r.verdict {
                Verdict::Pass => out.push_str("/>\n"),
                Verdict::Fail => out.push_str(&format!(
                    ">\n      <failure message=\"{}\">{}</failure>\n    </testcase>\n",
                    escape(&super::text::measured_against(r)),
                    escape(&detail(r))
                )),
                Verdict::Error { message } => out.push_str(&format!(
                    ">\n      <error message=\"{}\"/>\n    </testcase>\n",
                    escape(message)
                )),
                Verdict::UnexpectedPass { reason } => out.push_str(&format!(
                    ">\n      <failure message=\"unexpected pass: {}\">{}</failure>\n    </testcase>\n",
                    escape(reason),
                    escape(&detail(r))
                )),
                Verdict::ExpectedFailure { reason } => out.push_str(&format!(
                    ">\n      <skipped message=\"expected failure: {}\"/>\n    </testcase>\n",
                    escape(reason)
                )),
                Verdict::Skipped { reason } => out.push_str(&format!(
                    ">\n      <skipped message=\"{}\"/>\n    </testcase>\n",
                    escape(reason)
                )),
            }
        }
        out.push_str("  </testsuite>\n");
    }
    out.push_str("</testsuites>\n");
    out
}
