//! Reading `report.json` back (for `mfh merge` and `--baseline`): the schema-version gate and
//! the parse into an `AuditReport` (the serde helpers the record types need to read back what
//! they write are in `record_serde.rs`).

use crate::record::SCHEMA_VERSION;
use crate::run::AuditReport;
use std::path::Path;

/// Why a report could not be read back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("cannot read {path}: {message}")]
    Unreadable {
        /// The path.
        path: String,
        /// The I/O error.
        message: String,
    },
    /// The JSON is malformed or does not have the shape of a report.
    #[error("{path}: not an mfh report: {message}")]
    Malformed {
        /// The path.
        path: String,
        /// serde's message (with line and column where it has them).
        message: String,
    },
    /// The report was written with another record schema.
    #[error("{path}: schema_version {found}, but this mfh reads schema_version {expected} only (re-run the audit with this mfh)")]
    SchemaVersion {
        /// The path.
        path: String,
        /// The version in the file (`None`: the field is missing or not an integer).
        found: String,
        /// The version this mfh writes and reads.
        expected: u32,
    },
}

/// Reads `path` (a `report.json`, or a folder holding one) as an [`AuditReport`], refusing any
/// schema version other than [`SCHEMA_VERSION`].
pub fn read_report(path: &Path) -> Result<AuditReport, ReadError> {
    let file = if path.is_dir() {
        path.join("report.json")
    } else {
        path.to_path_buf()
    };
    let name = file.display().to_string();
    let text = std::fs::read_to_string(&file).map_err(|e| ReadError::Unreadable {
        path: name.clone(),
        message: e.to_string(),
    })?;
    parse_report(&text, &name)
}

/// Parses report text; `origin` names it in errors.
pub fn parse_report(text: &str, origin: &str) -> Result<AuditReport, ReadError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| ReadError::Malformed {
            path: origin.to_string(),
            message: e.to_string(),
        })?;
    match value
        .get("schema_version")
        .and_then(serde_json::Value::as_u64)
    {
        Some(v) if v == u64::from(SCHEMA_VERSION) => {}
        other => {
            return Err(ReadError::SchemaVersion {
                path: origin.to_string(),
                found: other.map_or_else(|| "missing".to_string(), |v| v.to_string()),
                expected: SCHEMA_VERSION,
            })
        }
    }
    serde_json::from_value(value).map_err(|e| ReadError::Malformed {
        path: origin.to_string(),
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interning_returns_one_allocation_per_string() {
        let a = crate::record_serde::intern(&String::from("closed_form"));
        let b = crate::record_serde::intern("closed_form");
        assert!(std::ptr::eq(a, b));
        assert_eq!(a, "closed_form");
    }

    #[test]
    fn other_schema_versions_are_refused_by_name() {
        let e = parse_report(r#"{"schema_version": 2}"#, "old/report.json").unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("old/report.json")
                && text.contains("schema_version 2")
                && text.contains("reads schema_version 1"),
            "{text}"
        );
        let e = parse_report(r#"{"records": []}"#, "r.json").unwrap_err();
        assert!(e.to_string().contains("schema_version missing"), "{e}");
        let e = parse_report("{", "r.json").unwrap_err();
        assert!(matches!(e, ReadError::Malformed { .. }), "{e:?}");
    }
}
