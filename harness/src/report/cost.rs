//! Sinks of `mfh cost`: `cost.json`, one Pareto plot per quantity (`cost/<quantity>.svg`),
//! `cost.html`, the terminal table and the generated markdown report
//! (`reports/accuracy-versus-time.md`). The markdown's error section is deterministic (fixed
//! inputs and seeds) and compared by a test with what the code measures today; its timing
//! section is machine-dependent and never compared.

use super::ReportError;
use crate::cost::{CostReport, RouteCost};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The markers around the deterministic part of the markdown report.
pub const ERRORS_BEGIN: &str = "<!-- BEGIN errors (deterministic; checked by a test) -->";
/// See [`ERRORS_BEGIN`].
pub const ERRORS_END: &str = "<!-- END errors -->";

/// The file name of the generated markdown report.
pub const MARKDOWN_FILE: &str = "accuracy-versus-time.md";

/// An error as two significant digits (what the markdown and the terminal show; stable across
/// machines whose libm differ in the last bit), "—" when not measured, "non-finite (n)" when
/// the route answered NaN or ±∞.
pub fn error_text(r: &RouteCost) -> String {
    if r.status == "refused" {
        return "refused".into();
    }
    if r.non_finite > 0 {
        return format!("non-finite at {} input(s)", r.non_finite);
    }
    match r.max_error {
        Some(0.0) => "0".into(),
        Some(e) => format!("{e:.1e}"),
        None => "—".into(),
    }
}

/// Seconds as ns / µs / ms / s with three significant digits.
pub fn seconds_text(s: Option<f64>) -> String {
    match s {
        None => "—".into(),
        Some(s) if s < 1e-6 => format!("{:.3} ns", s * 1e9),
        Some(s) if s < 1e-3 => format!("{:.3} µs", s * 1e6),
        Some(s) if s < 1.0 => format!("{:.3} ms", s * 1e3),
        Some(s) => format!("{s:.3} s"),
    }
}

/// A file name for a quantity: its name's ASCII letters and digits, `_` elsewhere.
pub fn slug(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    while s.contains("__") {
        s = s.replace("__", "_");
    }
    s.trim_matches('_').to_string()
}

/// The Pareto plot of a quantity (routes that were refused or not timed are left out).
#[cfg(feature = "html")]
pub fn pareto_svg(q: &crate::cost::Quantity) -> String {
    let points: Vec<(String, f64, f64)> = q
        .routes
        .iter()
        .filter_map(|r| Some((r.route.clone(), r.seconds_per_eval?, r.max_error?)))
        .collect();
    super::plot::pareto_svg(&q.name, &points)
}

/// The terminal table: per quantity, each route's max error, time and whether it is on the
/// frontier.
pub fn terminal(report: &CostReport) -> String {
    let mut t = String::new();
    for q in &report.quantities {
        let _ = writeln!(t, "{}  [error: {}]", q.name, q.error);
        let width = q
            .routes
            .iter()
            .map(|r| r.route.chars().count())
            .max()
            .unwrap_or(5);
        for r in &q.routes {
            let pad = width - r.route.chars().count();
            let _ = writeln!(
                t,
                "  {}{}  {:>26}  {:>12}{}",
                r.route,
                " ".repeat(pad),
                error_text(r),
                seconds_text(r.seconds_per_eval),
                if q.frontier.contains(&r.route) {
                    "  *frontier"
                } else {
                    ""
                }
            );
        }
    }
    if report.timed {
        t.push_str(
            "time: median seconds per evaluation over repeated batches (machine-dependent)\n",
        );
    }
    t
}

fn escape_md(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The deterministic part of the markdown report: per quantity, its reference, inputs and each
/// route's max error (with refusals and notes).
pub fn markdown_errors(report: &CostReport) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "{ERRORS_BEGIN}\n");
    for q in &report.quantities {
        let _ = writeln!(
            m,
            "### {}\n\nReference: {}. Error: {}. Inputs: {}.\n\n| route | max error | inputs \
             measured | inputs refused | note |\n|---|---:|---:|---:|---|",
            q.name, q.reference, q.error, q.inputs
        );
        for r in &q.routes {
            let note = [r.reason.as_deref(), r.note.as_deref()]
                .into_iter()
                .flatten()
                .collect::<Vec<_>>()
                .join("; ");
            let _ = writeln!(
                m,
                "| {} | {} | {} | {} | {} |",
                escape_md(&r.route),
                error_text(r),
                r.evaluated,
                r.refused_inputs,
                escape_md(&note)
            );
        }
        m.push('\n');
    }
    let _ = writeln!(m, "{ERRORS_END}");
    m
}

/// The machine-dependent part: each route's median time per evaluation with its spread, and
/// the Pareto frontier per quantity.
pub fn markdown_timings(report: &CostReport) -> String {
    let mut m = String::from(
        "## Timings (machine-dependent: not compared by any test)\n\n\
         Median seconds per evaluation over repeated batches (fastest – slowest batch in\n\
         brackets), on the machine and load of the run that wrote this file. The frontier: the\n\
         routes no other route beats in both time and error, fastest first.\n\n",
    );
    if !report.timed {
        m.push_str("Not timed in this run.\n");
        return m;
    }
    for q in &report.quantities {
        let _ = writeln!(
            m,
            "**{}** — frontier: {}\n\n| route | time per evaluation | spread |\n|---|---:|---|",
            q.name,
            if q.frontier.is_empty() {
                "—".to_string()
            } else {
                q.frontier.join(" → ")
            }
        );
        for r in &q.routes {
            let spread = r
                .timing
                .map(|t| {
                    format!(
                        "{} – {} ({} batches)",
                        seconds_text(Some(t.min)),
                        seconds_text(Some(t.max)),
                        t.batches
                    )
                })
                .unwrap_or_else(|| "—".into());
            let _ = writeln!(
                m,
                "| {} | {} | {} |",
                escape_md(&r.route),
                seconds_text(r.seconds_per_eval),
                spread
            );
        }
        m.push('\n');
    }
    m
}

/// The whole markdown report.
pub fn markdown(report: &CostReport) -> String {
    format!(
        "# Accuracy versus time\n\n\
         Generated by `mfh cost --markdown reports/` (do not edit by hand: the test\n\
         `cost_markdown_is_current` regenerates the error section and fails if this file is\n\
         stale). mfh {}, cost.json schema {}{}. For each quantity with more than one route (or an\n\
         oracle with a knob): the largest error of every route against an independent\n\
         high-precision reference on the same inputs, then the time per evaluation.\n\n\
         ## Errors (deterministic)\n\n{}\n{}",
        report.mfh_version,
        report.schema_version,
        if report.quick { ", quick run" } else { "" },
        markdown_errors(report),
        markdown_timings(report)
    )
}

/// The error section of a markdown report's text (between the markers), if it has one.
pub fn errors_section(text: &str) -> Option<&str> {
    let start = text.find(ERRORS_BEGIN)?;
    let end = text[start..].find(ERRORS_END)? + start + ERRORS_END.len();
    Some(&text[start..end])
}

/// Writes `cost.json` (first), then (feature `html`) the Pareto plots into `cost/` and
/// `cost.html` into `dir` (created if needed). Returns the paths written.
pub fn write_all(report: &CostReport, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::CreateFolder {
        path: dir.to_path_buf(),
        source,
    })?;
    let write = |path: PathBuf, text: &str| {
        std::fs::write(&path, text)
            .map(|_| path.clone())
            .map_err(|source| ReportError::Write { path, source })
    };
    let json = serde_json::to_string_pretty(report).expect("a cost report serializes") + "\n";
    let written = vec![write(dir.join("cost.json"), &json)?];
    #[cfg(feature = "html")]
    let written = [written, write_plots(report, dir, &json)?].concat();
    Ok(written)
}

/// The Pareto plots (`cost/<quantity>.svg`) and `cost.html` (feature `html`: plotters).
#[cfg(feature = "html")]
fn write_plots(report: &CostReport, dir: &Path, json: &str) -> Result<Vec<PathBuf>, ReportError> {
    let write = |path: PathBuf, text: &str| {
        std::fs::write(&path, text)
            .map(|_| path.clone())
            .map_err(|source| ReportError::Write { path, source })
    };
    let mut written = Vec::new();
    let plots = dir.join("cost");
    std::fs::create_dir_all(&plots).map_err(|source| ReportError::CreateFolder {
        path: plots.clone(),
        source,
    })?;
    for q in &report.quantities {
        written.push(write(
            plots.join(format!("{}.svg", slug(&q.name))),
            &pareto_svg(q),
        )?);
    }
    written.push(write(
        dir.join("cost.html"),
        &super::cost_html::cost_page(json),
    )?);
    Ok(written)
}

/// Writes the markdown report into `dir` (which must exist). Returns its path.
pub fn write_markdown(report: &CostReport, dir: &Path) -> Result<PathBuf, ReportError> {
    let path = dir.join(MARKDOWN_FILE);
    std::fs::write(&path, markdown(report))
        .map(|_| path.clone())
        .map_err(|source| ReportError::Write { path, source })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slugs_and_numbers_read_well() {
        assert_eq!(slug("STD Λ, γ = 3.5"), "std_3_5");
        assert_eq!(seconds_text(Some(2.5e-8)), "25.000 ns");
        assert_eq!(seconds_text(Some(0.0125)), "12.500 ms");
        let text = format!("a\n{ERRORS_BEGIN}\nx\n{ERRORS_END}\nb");
        assert_eq!(errors_section(&text), Some(&text[2..text.len() - 2]));
    }
}
