//! The report of an audit, as Python sees it through `mfh.Report` (`python/mfh/_report.py`,
//! which gives it its properties and repr): the harness's `AuditReport` and what the sinks of
//! the CLI make of it.

use mfh_harness::report;
use mfh_harness::run::{failure_table, AuditReport};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// An audit's report (`AuditReport`), and the calls its callables answered.
#[pyclass(frozen, module = "mfh._mfh", name = "_Report")]
pub struct Report {
    inner: AuditReport,
    calls: (u64, u64),
}

impl Report {
    /// The report of a run whose callables answered `calls` (calls, items).
    pub fn new(inner: AuditReport, calls: (u64, u64)) -> Self {
        Self { inner, calls }
    }
}

#[pymethods]
impl Report {
    /// Whether no record failed or errored (expected failures pass).
    fn passed(&self) -> bool {
        self.inner.passed()
    }

    /// Every record as JSON (an array, in plan order; a record's tables and heat maps are left
    /// out, as in report.json, which lists their files instead).
    fn records_json(&self) -> String {
        let records: Vec<_> = self
            .inner
            .records
            .iter()
            .map(|r| {
                let mut r = r.clone();
                r.data = None;
                r
            })
            .collect();
        serde_json::to_string(&records).unwrap_or_else(|_| "[]".into())
    }

    /// The summary (counts by verdict, worst errors, per-check totals, wall time) as JSON.
    fn summary_json(&self) -> String {
        serde_json::to_string(&self.inner.summary).unwrap_or_else(|_| "{}".into())
    }

    /// The table of failures (check, case, measured against the oracle, tolerance and why) and
    /// the line that reproduces the run; as `AuditReport::assert_pass` panics with.
    fn failure_table(&self) -> String {
        failure_table(&self.inner)
    }

    /// The CLI's terminal summary.
    fn terminal(&self) -> String {
        report::terminal::render(&self.inner, 20)
    }

    /// The line that reproduces the run.
    #[getter]
    fn command(&self) -> String {
        self.inner.command.clone()
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.scene.clone()
    }

    /// The profile's name.
    #[getter]
    fn profile(&self) -> &'static str {
        self.inner.profile.name()
    }

    /// The audit seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }

    /// The audit's wall time, seconds.
    #[getter]
    fn wall_seconds(&self) -> f64 {
        self.inner.summary.wall_seconds
    }

    /// Calls of the Python callables and items they answered.
    #[getter]
    fn calls(&self) -> (u64, u64) {
        self.calls
    }

    /// Writes report.json, junit.xml, the records' artefacts and report.html into `out_dir`, as
    /// `mfh audit --out` writes them; the paths written.
    fn write(&self, py: Python<'_>, out_dir: PathBuf) -> PyResult<Vec<String>> {
        let written = py
            .allow_threads(|| report::write_all(&self.inner, &out_dir))
            .map_err(|e| PyOSError::new_err(e.to_string()))?;
        Ok(written.iter().map(|p| p.display().to_string()).collect())
    }
}
