//! `report.json`: the whole audit (schema version, scene, profile, seed, reproduce command,
//! summary, every record), for machines.

use crate::audit::AuditReport;
use std::path::Path;

/// Serializes the report as pretty JSON. Non-finite numbers (an infinite error) become null.
pub fn to_string(report: &AuditReport) -> String {
    serde_json::to_string_pretty(report).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

/// Writes `report.json`.
pub fn write(report: &AuditReport, path: &Path) -> std::io::Result<()> {
    std::fs::write(path, to_string(report) + "\n")
}
