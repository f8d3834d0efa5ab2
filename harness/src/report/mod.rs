//! Sinks of an audit report: the terminal summary, `report.json`, JUnit XML, the artefact
//! files of records that carry data (chi-square tables and heat maps, KS curves) and the
//! self-contained `report.html`. Checks do no I/O: everything written is written here.
//!
//! **One concept per file.** `terminal.rs` the summary; `json.rs` `report.json`
//! (schema-versioned; read back by `crate::readback`); `jsonl.rs` `report.jsonl` (each record
//! appended as its check finishes, read back by `--resume`); `junit.rs` `junit.xml`;
//! `artefacts.rs` the tables and SVG heat maps that records carry as `RecordData`; `plan_table.rs`
//! `mfh plan`'s table; `cost.rs` `mfh cost`'s files. With the `html` feature: `html.rs` the audit
//! page, `bsdf_html.rs` its BSDF section, `record_plots.rs` the plots of records, `plot.rs` the
//! drawing (plotters), `bitmap.rs` a heat map's cells as the image its SVG embeds, `colour.rs`
//! its colour scales, `page.rs` what every page shares (escaping, images, style, a record's
//! error and verdict), `cost_html.rs` and `selftest_html.rs` the pages of `mfh cost` and
//! `mfh selftest`. No circle of imports between these files (`harness/tests/layers.rs`).

pub mod artefacts;
#[cfg(feature = "html")]
pub mod bitmap;
#[cfg(feature = "html")]
pub mod bsdf_html;
#[cfg(feature = "html")]
pub mod colour;
pub mod cost;
#[cfg(feature = "html")]
pub mod cost_html;
#[cfg(feature = "html")]
pub mod heat_map;
#[cfg(feature = "html")]
pub mod html;
pub mod json;
pub mod jsonl;
pub mod junit;
#[cfg(feature = "html")]
pub mod page;
pub mod plan_table;
#[cfg(feature = "html")]
pub mod plot;
#[cfg(feature = "html")]
pub mod record_plots;
#[cfg(feature = "html")]
pub mod selftest_html;
pub mod terminal;
/// The one text layout of a record (a leaf module, below the runner, whose `assert_pass`
/// prints it too).
pub use crate::record_text as text;

use crate::run::AuditReport;
use std::path::{Path, PathBuf};

/// Why the report could not be written; names the path (or the plot) and the cause.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The output folder could not be created.
    #[error("cannot create the output folder {path}: {source}")]
    CreateFolder {
        /// The folder.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// An artefact (a record's tables or heat maps) could not be written or drawn.
    #[error("artefacts of {record}: {source}")]
    Artefact {
        /// The record (check, model, case).
        record: String,
        /// The error.
        source: artefacts::ArtefactError,
    },
    /// The HTML report could not be rendered (report.json was written before).
    #[cfg(feature = "html")]
    #[error("cannot render report.html: {0}")]
    Render(#[from] plot::PlotError),
}

/// The report as `report.json` holds it: each record with data gets the paths of its artefact
/// files (in `dir`) and loses the data itself (large tables live in those files).
pub fn on_disk(report: &AuditReport, dir: &Path) -> AuditReport {
    let mut out = report.clone();
    for r in &mut out.records {
        if let (Some(folder), Some(data)) = (artefacts::relative_folder(r), r.data.as_ref()) {
            r.artefacts.extend(
                artefacts::file_names(data)
                    .iter()
                    .map(|name| dir.join(&folder).join(name).display().to_string()),
            );
        }
        r.data = None;
    }
    out
}

/// Writes every file sink into `dir` (created if needed), in order: `report.json` first (so
/// that nothing measured is lost if a later sink fails), then `junit.xml`, the artefact files
/// of records that carry data (listed in report.json), and `report.html` (which also shows
/// `cost.json` if `dir` holds one). Returns the files and artefact folders written (not every
/// artefact file: report.json lists those).
pub fn write_all(report: &AuditReport, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::CreateFolder {
        path: dir.to_path_buf(),
        source,
    })?;
    let write = |path: PathBuf, text: String| {
        std::fs::write(&path, text)
            .map(|_| path.clone())
            .map_err(|source| ReportError::Write { path, source })
    };
    let mut written = vec![write(
        dir.join("report.json"),
        json::to_string(&on_disk(report, dir)) + "\n",
    )?];
    written.push(write(dir.join("junit.xml"), junit::render(report))?);
    for r in &report.records {
        if let (Some(folder), Some(data)) = (artefacts::relative_folder(r), r.data.as_ref()) {
            let paths = artefacts::write_record_data(
                &dir.join(folder),
                &artefacts::record_title(r),
                "mfh audit",
                data,
            )
            .map_err(|source| ReportError::Artefact {
                record: artefacts::record_title(r),
                source,
            })?;
            if let Some(top) = paths
                .first()
                .and_then(|p| p.strip_prefix(dir).ok())
                .and_then(|p| p.components().next())
                .map(|c| dir.join(c))
            {
                if !written.contains(&top) {
                    written.push(top);
                }
            }
        }
    }
    // report.html (and cost.json shown in it) only with the `html` feature (plotters).
    #[cfg(feature = "html")]
    {
        let cost = std::fs::read_to_string(dir.join("cost.json")).ok();
        let page = html::render(report, cost.as_deref())?;
        written.push(write(dir.join("report.html"), page)?);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use crate::record::{CheckRecord, NoiseFloor, OracleValue, Verdict};
    use crate::run::{AuditOptions, AuditReport};
    use serde_json::Value;

    /// A failing record whose oracle stopped at a float32 rounding floor says so in every
    /// sink a person reads: the terminal summary, JUnit's failure text and the HTML report.
    #[test]
    fn a_failure_at_a_rounding_floor_says_so_in_every_sink() {
        let mut r = CheckRecord::new("smith.white_furnace", Value::Null, Value::Null, "s");
        r.verdict = Verdict::Fail;
        r.oracle = Some(OracleValue {
            value: 1.0,
            uncertainty: 2.1e-7,
            kind: "error_bound",
            noise_floor: Some(NoiseFloor {
                noise: 1.2e-7,
                floor: 3.8e-6,
            }),
        });
        let report = AuditReport::from_records(
            "s".into(),
            &AuditOptions::default(),
            "mfh".into(),
            vec![r],
            (0, 0.001),
            0.0,
        );
        let want = "integrand noise 1.2e-7 relative, floor 3.8e-6";
        assert!(super::terminal::render(&report, 5).contains(want));
        assert!(super::junit::render(&report).contains(want));
        #[cfg(feature = "html")]
        assert!(super::html::render(&report, None).is_ok_and(|h| h.contains(want)));
    }
}
