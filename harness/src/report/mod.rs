//! Sinks of an audit report: the terminal summary, `report.json`, JUnit XML.

pub mod json;
pub mod junit;
pub mod terminal;

use crate::audit::AuditReport;
use std::path::{Path, PathBuf};

/// Writes every file sink into `dir` (created if needed); returns the paths written.
pub fn write_all(report: &AuditReport, dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let json_path = dir.join("report.json");
    json::write(report, &json_path)?;
    let junit_path = dir.join("junit.xml");
    std::fs::write(&junit_path, junit::render(report))?;
    Ok(vec![json_path, junit_path])
}
