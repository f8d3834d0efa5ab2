//! `report.jsonl`: the records of an audit appended one JSON line each as its checks finish
//! (written straight to the file, one `write` per line, so that an audit killed by SIGKILL, a
//! CI timeout or Ctrl-C leaves every finished record on disk), and read back by `--resume`.
//!
//! The first line is a [`Header`] (`{"header": {...}}`) naming the run: what was audited, the
//! profile, the seed, the plan's fingerprint; every further line is one [`CheckRecord`] in the
//! serialization of `report.json`'s records, plus its `data` (the tables and curves that
//! `report.json` moves to artefact files), so that a resumed audit writes the same artefacts.
//! Records are written as their checks finish (not in plan order) and before the Šidák
//! correction re-judges the statistical ones over the whole audit (report.json has the
//! corrected verdicts).

use crate::record::CheckRecord;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The file's name in the output folder.
pub const FILE: &str = "report.jsonl";

/// The format of the file (the header's `format`); a different one is refused by `--resume`.
pub const FORMAT: u32 = 1;

/// What run a `report.jsonl` belongs to: `--resume` refuses a file whose header differs from
/// the resumed run's in any field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The file format ([`FORMAT`]).
    pub format: u32,
    /// The record schema version.
    pub schema_version: u32,
    /// mfh's version.
    pub mfh_version: String,
    /// The command: `audit` or `audit-external`.
    pub command: String,
    /// What was audited: the scene file (`<default scene>` for the embedded one), or the
    /// external child's command line.
    pub subject: String,
    /// The external audit's `--against` spec, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub against: Option<String>,
    /// The profile's name.
    pub profile: String,
    /// The audit seed.
    pub seed: u64,
    /// The plan's fingerprint (`shard::fingerprint`, the CLI's) and its number of checks, where
    /// the plan is known before the run (`mfh audit`; an external child's plan follows from its
    /// `describe` answer, and its records name the child's command, parameters and
    /// capabilities, so a record of a changed child matches no planned check and is not used).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plan: Option<(String, usize)>,
}

impl Header {
    /// The fields in which `stored` (a file's header) differs from `self` (this run's), each
    /// as "FIELD: STORED in the file, THIS in this run".
    pub fn differences(&self, stored: &Header) -> Vec<String> {
        let (a, b) = (
            serde_json::to_value(stored).unwrap_or_default(),
            serde_json::to_value(self).unwrap_or_default(),
        );
        let keys = [
            "format",
            "schema_version",
            "mfh_version",
            "command",
            "subject",
        ]
        .into_iter()
        .chain(["against", "profile", "seed", "plan"]);
        keys.filter_map(|k| {
            let (x, y) = (a.get(k), b.get(k));
            (x != y).then(|| {
                let show = |v: Option<&serde_json::Value>| {
                    v.map(|v| v.to_string()).unwrap_or_else(|| "none".into())
                };
                format!("{k}: {} in the file, {} in this run", show(x), show(y))
            })
        })
        .collect()
    }
}

/// The header line as it is written.
#[derive(Serialize, Deserialize)]
struct HeaderLine {
    header: Header,
}

/// Why a `report.jsonl` could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum JsonlError {
    /// The file could not be read, created or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The first line is not a header.
    #[error("{path}: line 1 is not a report.jsonl header ({reason})")]
    Header {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A complete line (one ending in a newline) is not a record.
    #[error("{path}: line {line} is not a record ({reason})")]
    Record {
        /// The file.
        path: PathBuf,
        /// The line number (1-based).
        line: usize,
        /// Why.
        reason: String,
    },
}

/// A `report.jsonl` read back.
#[derive(Debug, Clone)]
pub struct Stream {
    /// Its header.
    pub header: Header,
    /// Its records by the key of their planned check (the last, if a key repeats).
    pub records: std::collections::HashMap<String, CheckRecord>,
    /// The lines of those records as written (without their newlines).
    pub lines: Vec<String>,
    /// Whether a last line without its newline (a write cut short by a kill) was dropped.
    pub dropped_partial_line: bool,
}

/// Reads `path`: the header, then every complete line as a record. A last line that does not
/// end in a newline was cut short (the run was killed while writing it) and is dropped; any
/// other line that is not a record is an error naming its number.
pub fn read(path: &Path) -> Result<Stream, JsonlError> {
    let text = std::fs::read_to_string(path).map_err(|source| JsonlError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let complete = match text.rfind('\n') {
        Some(end) => &text[..end + 1],
        None => "",
    };
    let dropped_partial_line = complete.len() < text.len();
    let mut lines = complete.lines();
    let header = match lines.next() {
        Some(first) => {
            serde_json::from_str::<HeaderLine>(first)
                .map_err(|e| JsonlError::Header {
                    path: path.to_path_buf(),
                    reason: crate::messages::json_error_message(&e),
                })?
                .header
        }
        None => {
            return Err(JsonlError::Header {
                path: path.to_path_buf(),
                reason: "the file has no complete line".into(),
            })
        }
    };
    #[derive(Deserialize)]
    struct Key {
        planned: String,
    }
    let (mut records, mut kept) = (std::collections::HashMap::new(), Vec::new());
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let error = |e: serde_json::Error| JsonlError::Record {
            path: path.to_path_buf(),
            line: i + 2,
            reason: crate::messages::json_error_message(&e),
        };
        let key: Key = serde_json::from_str(line).map_err(error)?;
        let record: CheckRecord = serde_json::from_str(line).map_err(error)?;
        records.insert(key.planned, record);
        kept.push(line.to_string());
    }
    Ok(Stream {
        header,
        records,
        lines: kept,
        dropped_partial_line,
    })
}

/// The open `report.jsonl` of a running audit: [`Sink::append`] writes one record per line,
/// from any thread. The first write error is kept ([`Sink::error`]) and later records are not
/// written (the audit goes on; the command reports the error at the end).
#[derive(Debug)]
pub struct Sink {
    path: PathBuf,
    file: Mutex<Result<std::fs::File, String>>,
}

impl Sink {
    /// Creates `dir/report.jsonl` with `header` and then `kept` (the record lines of a resumed
    /// run, as read), replacing the file atomically (written beside it, then renamed), so that
    /// a resume that reads and rewrites the same folder cannot lose the records it read.
    pub fn create(dir: &Path, header: &Header, kept: &[String]) -> Result<Self, JsonlError> {
        let path = dir.join(FILE);
        let partial = dir.join(format!("{FILE}.partial"));
        let io = |p: &Path| {
            let p = p.to_path_buf();
            move |source| JsonlError::Io { path: p, source }
        };
        let mut text = serde_json::to_string(&HeaderLine {
            header: header.clone(),
        })
        .unwrap_or_default();
        text.push('\n');
        for line in kept {
            text.push_str(line);
            text.push('\n');
        }
        std::fs::write(&partial, text).map_err(io(&partial))?;
        std::fs::rename(&partial, &path).map_err(io(&path))?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(io(&path))?;
        Ok(Self {
            path,
            file: Mutex::new(Ok(file)),
        })
    }

    /// Appends `record` (with its data) of the planned check with the key `planned` as one
    /// line, in one write (unbuffered: it is in the file when this returns, whatever happens to
    /// the process afterwards).
    pub fn append(&self, planned: &str, record: &CheckRecord) {
        let mut file = self.file.lock().unwrap_or_else(|p| p.into_inner());
        let Ok(f) = file.as_mut() else { return };
        let line = match serde_json::to_string(record) {
            // The record's object with the key first: `{"planned":"…",` + the record's fields.
            Ok(text) => format!("{{\"planned\":\"{planned}\",{}\n", &text[1..]),
            Err(e) => {
                *file = Err(format!(
                    "cannot serialize a record of {}: {e}",
                    record.check
                ));
                return;
            }
        };
        if let Err(e) = f.write_all(line.as_bytes()) {
            *file = Err(format!("cannot write {}: {e}", self.path.display()));
        }
    }

    /// The first error, if a record could not be written.
    pub fn error(&self) -> Option<String> {
        match &*self.file.lock().unwrap_or_else(|p| p.into_inner()) {
            Ok(_) => None,
            Err(e) => Some(e.clone()),
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
