//! `report.json`: the whole audit (schema version, scene, profile, seed, reproduce command,
//! summary, every record), for machines.

use crate::run::AuditReport;
use std::path::Path;

/// Serializes the report as pretty JSON, without the records' data (tables and curves go to
/// artefact files, see [`super::on_disk`]). Non-finite numbers (an infinite error) become null.
pub fn to_string(report: &AuditReport) -> String {
    let result = if report.records.iter().any(|r| r.data.is_some()) {
        let mut lean = report.clone();
        for r in &mut lean.records {
            r.data = None;
        }
        serde_json::to_string_pretty(&lean)
    } else {
        serde_json::to_string_pretty(report)
    };
    result.unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

/// Writes `report.json`.
pub fn write(report: &AuditReport, path: &Path) -> std::io::Result<()> {
    std::fs::write(path, to_string(report) + "\n")
}

/// `report.json` of `mfh selftest`: the self-test report (kill matrix, controls, calibration)
/// under a `selftest` key, beside the schema and mfh versions.
pub fn selftest_to_string(report: &crate::selftest::SelftestReport) -> String {
    let doc = serde_json::json!({
        "schema_version": report.schema_version,
        "mfh_version": report.mfh_version,
        "selftest": report,
    });
    serde_json::to_string_pretty(&doc).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}
