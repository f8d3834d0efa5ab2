//! `report.html`: one self-contained page (plots embedded as SVG `data:` URIs, no scripts, no
//! network) read top to bottom: verdict and counts, how to reproduce the run, the failures with
//! their plots, per material Λ and G1 against the oracle with the relative error below, the
//! chi-square heat maps and KS marginals of every sampling check, the BSDFs
//! (`bsdf_html.rs`: both hemispheres' heat maps per incidence, albedo against incidence, the
//! consistency and reciprocity tables), the γ → ∞ convergence, the
//! stability sweep, the errata and claims tables, accuracy versus time (`cost.json`), and the
//! time per check.

use super::artefacts::{case_name, model_name, record_title};
pub use super::page::measured_text;
use super::page::{escape, fmt_num, verdict_text, STYLE};
use super::plot::PlotError;
use super::record_plots::{data_plots, limit_plot, plot_policy, smith_plots};
use crate::record::{CheckRecord, Verdict};
use crate::run::AuditReport;
use serde_json::Value;
use std::fmt::Write as _;

/// The checks that have their own section (not under the materials).
fn own_section(check: &str) -> bool {
    ["errata.", "claims.", "limits.", "stability.", "bsdf."]
        .iter()
        .any(|p| check.starts_with(p))
}

fn records_table(records: &[&CheckRecord]) -> String {
    let mut t = String::from(
        "<table><tr><th>check</th><th>case</th><th>value</th><th>oracle</th>\
         <th>measured</th><th>verdict</th></tr>",
    );
    for r in records {
        let _ = write!(
            t,
            "<tr><td>{}</td><td>{}</td><td class=num>{}</td><td class=num>{}</td><td>{}</td>\
             <td>{}</td></tr>",
            escape(&r.check),
            escape(&case_name(&r.case)),
            r.value.map(fmt_num).unwrap_or_default(),
            r.oracle.map(|o| fmt_num(o.value)).unwrap_or_default(),
            escape(&measured_text(r)),
            escape(&verdict_text(&r.verdict))
        );
    }
    t.push_str("</table>");
    t
}

fn errata_section(records: &[CheckRecord]) -> String {
    let mut h = String::from(
        "<h2 id=errata>Errata</h2>\n<p class=note>Each erratum of reference/ERRATA.md for the \
         documents the scene draws on: the printed formula evaluated as printed against the \
         oracle (an expected failure when the printed form fails and the corrected one holds; \
         the corrected value is in the verdict).</p>\n<table><tr><th>id</th><th>document</th>\
         <th>equation / source</th><th>what</th><th>printed</th><th>oracle</th>\
         <th>error of the printed form</th><th>verdict (corrected form)</th></tr>",
    );
    for r in records.iter().filter(|r| r.check.starts_with("errata.")) {
        let id = r.case.get("erratum").and_then(Value::as_str).unwrap_or("?");
        let _ = write!(
            h,
            "<tr><td>{}</td><td>seed {}</td><td>{}</td><td>{}</td><td class=num>{}</td>\
             <td class=num>{}</td><td>{}</td><td>{}</td></tr>",
            escape(id),
            escape(id.get(..3).unwrap_or(id)),
            escape(&r.source),
            escape(crate::check::errata::description(id)),
            r.value.map(fmt_num).unwrap_or_default(),
            r.oracle.map(|o| fmt_num(o.value)).unwrap_or_default(),
            escape(&measured_text(r)),
            escape(&verdict_text(&r.verdict))
        );
    }
    h.push_str("</table>\n");
    h
}

fn claims_section(records: &[CheckRecord]) -> String {
    let mut h = String::from(
        "<h2 id=claims>Claims</h2>\n<p class=note>Each quantitative claim of the documents, \
         measured.</p>\n<table><tr><th>claim</th><th>case</th><th>source</th>\
         <th>measured</th><th>verdict</th></tr>",
    );
    for r in records.iter().filter(|r| r.check.starts_with("claims.")) {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&r.check),
            escape(&case_name(&r.case)),
            escape(&r.source),
            escape(&measured_text(r)),
            escape(&verdict_text(&r.verdict))
        );
    }
    h.push_str("</table>\n");
    h
}

/// Renders the page. `cost` is the text of `cost.json`, if there is one.
pub fn render(report: &AuditReport, cost: Option<&str>) -> Result<String, PlotError> {
    let s = &report.summary;
    let passed = report.passed();
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>mfh audit — {}</title>\
         <style>{STYLE}</style></head><body>\n<h1>mfh audit — {}</h1>\n",
        escape(&report.scene),
        escape(&report.scene)
    );
    let counts: Vec<String> = s.counts.iter().map(|(k, v)| format!("{k} {v}")).collect();
    let _ = write!(
        h,
        "<p><span class=\"verdict {}\">{}</span> &nbsp; {}: {}</p>\n\
         <table><tr><th>reproduce</th><td><code>{}</code></td></tr>\
         <tr><th>seed</th><td>{}</td></tr><tr><th>profile</th><td>{}</td></tr>\
         <tr><th>versions</th><td>mfh {}, record schema {}</td></tr>\
         <tr><th>scene</th><td>{}</td></tr>\
         <tr><th>statistical checks</th><td>{} at Šidák level {} each (family-wise α = {})</td></tr>\
         <tr><th>wall time</th><td>{:.1} s</td></tr></table>\n",
        if passed { "pass" } else { "fail" },
        if passed { "PASS" } else { "FAIL" },
        super::text::count(report.records.len(), "record", "records"),
        escape(&counts.join(", ")),
        escape(&report.command),
        report.seed,
        report.profile.name(),
        escape(report.mfh_version),
        report.schema_version,
        escape(&report.scene),
        s.statistical.0,
        fmt_num(s.statistical.1),
        crate::tolerance::STATISTICAL_ALPHA.value,
        s.wall_seconds
    );
    h.push_str(
        "<nav><a href=#failures>failures</a><a href=#materials>materials</a>\
         <a href=#bsdf>BSDFs</a><a href=#limits>γ → ∞</a><a href=#stability>stability</a><a href=#errata>errata</a>\
         <a href=#claims>claims</a><a href=#cost>accuracy vs time</a><a href=#checks>by check</a>\
         </nav>\n",
    );
    // Materials: records grouped by model, in plan order, with an anchor each.
    let mut materials: Vec<(String, Vec<&CheckRecord>)> = Vec::new();
    for r in report
        .records
        .iter()
        .filter(|r| r.model.is_object() && !own_section(&r.check))
    {
        let key = r.model.to_string();
        match materials.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(r),
            None => materials.push((key, vec![r])),
        }
    }
    let anchor = |model: &Value| {
        let key = model.to_string();
        materials
            .iter()
            .position(|(k, _)| *k == key)
            .map(|i| format!("material-{i}"))
    };
    // Failures first.
    let failures: Vec<&CheckRecord> = report
        .records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .collect();
    let _ = writeln!(h, "<h2 id=failures>Failures ({})</h2>", failures.len());
    if failures.is_empty() {
        h.push_str("<p>None: every check passed or failed as expected.</p>\n");
    }
    for r in &failures {
        // The fields every sink prints for a record (`text.rs`), as a table.
        let _ = write!(
            h,
            "<div class=failure><h3>{}</h3><table>",
            escape(&record_title(r))
        );
        for (label, text) in super::text::fields(r) {
            let _ = write!(h, "<tr><th>{label}</th><td>{}</td></tr>", escape(&text));
        }
        h.push_str("</table>");
        let bsdf = super::bsdf_html::is_bsdf(&r.check)
            .then(|| super::bsdf_html::anchor(&report.records, &r.model))
            .flatten();
        let plots = if bsdf.is_some() {
            String::new()
        } else {
            data_plots(r)?
        };
        if let Some(a) = bsdf {
            let _ = write!(
                h,
                "<p>Plots and tables: <a href=#{a}>this BSDF in the BSDF section</a>.</p>"
            );
        } else if !plots.is_empty() {
            let _ = write!(h, "<div class=plots>{plots}</div>");
        } else if let (true, Some(a)) = (r.check.starts_with("smith."), anchor(&r.model)) {
            let _ = write!(
                h,
                "<p>Plot: <a href=#{a}>Λ and G1 of this material</a>.</p>"
            );
        } else if r.check.starts_with("limits.") {
            if let Some(p) = limit_plot(r)? {
                let _ = write!(h, "<div class=plots>{p}</div>");
            }
        } else {
            h.push_str(
                "<p class=note>No plot for this check: the numbers above are all it measures.</p>",
            );
        }
        h.push_str("</div>\n");
    }
    h.push_str("<h2 id=materials>Materials</h2>\n");
    // Check families whose passing plot has been drawn (one each keeps the page small).
    let mut plotted: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    for (i, (_, records)) in materials.iter().enumerate() {
        let name = model_name(&records[0].model);
        let bad = records.iter().filter(|r| r.verdict.is_failure()).count();
        let _ = writeln!(
            h,
            "<h3 id=material-{i}>{} <span class=note>({}, {} failing)</span></h3>",
            escape(&name),
            super::text::count(records.len(), "record", "records"),
            bad
        );
        let mut plots = String::new();
        let mut left_out = 0usize;
        let has_smith = records.iter().any(|r| r.check == "smith.lambda_route");
        let failing_routes: std::collections::BTreeSet<String> = records
            .iter()
            .filter(|r| {
                r.check == "smith.lambda_route"
                    && (r.verdict.is_failure()
                        || matches!(r.verdict, Verdict::ExpectedFailure { .. }))
            })
            .map(|r| {
                r.case
                    .get("route")
                    .and_then(Value::as_str)
                    .unwrap_or("?")
                    .to_string()
            })
            .collect();
        if has_smith && plotted.insert("smith.lambda_route".to_string()) {
            if let Some(p) = smith_plots(records, &name, None)? {
                plots.push_str(&p);
            }
        } else if !failing_routes.is_empty()
            && plotted.insert(format!(
                "smith.lambda_route failing {}",
                failing_routes.iter().cloned().collect::<Vec<_>>().join(",")
            ))
        {
            // The first material failing (as expected) in this set of routes: Λ of those
            // routes (G1 = 1/(1 + Λ) adds nothing there); later materials with the same set
            // are table rows.
            if let Some(p) = smith_plots(records, &name, Some(&failing_routes))? {
                plots.push_str(
                    p.split("<img")
                        .nth(1)
                        .map(|i| format!("<img{i}"))
                        .as_deref()
                        .unwrap_or(&p),
                );
            }
        } else if has_smith {
            left_out += 2;
        }
        for r in records.iter().filter(|r| r.data.is_some()) {
            if plot_policy(r, &mut plotted) {
                plots.push_str(&data_plots(r)?);
            } else if !r.verdict.is_failure() {
                left_out += 1;
            }
        }
        if !plots.is_empty() {
            let _ = writeln!(h, "<div class=plots>{plots}</div>");
        }
        if left_out > 0 {
            let _ = writeln!(
                h,
                "<p class=note>{left_out} plot(s) of passing checks left out (one per check \
                 family is drawn in this report, failures and expected failures always): their \
                 measured errors are in the table below, their data in chi2/ and ks/.</p>"
            );
        }
        let _ = writeln!(
            h,
            "<details><summary>every record of this material</summary>{}</details>",
            records_table(records)
        );
    }
    h.push_str(&super::bsdf_html::bsdf_section(
        &report.records,
        records_table,
    )?);
    h.push_str("<h2 id=limits>γ → ∞ convergence</h2>\n<div class=plots>");
    let limits: Vec<&CheckRecord> = report
        .records
        .iter()
        .filter(|r| r.check.starts_with("limits."))
        .collect();
    for r in &limits {
        if let Some(p) = limit_plot(r)? {
            h.push_str(&p);
        }
    }
    h.push_str("</div>\n");
    if limits.is_empty() {
        h.push_str("<p class=note>No γ → ∞ checks in this scene (no Student-t material).</p>\n");
    } else {
        h.push_str(&records_table(&limits));
    }
    let stability: Vec<&CheckRecord> = report
        .records
        .iter()
        .filter(|r| r.check.starts_with("stability."))
        .collect();
    h.push_str(
        "<h2 id=stability>Stability sweep</h2>\n<p class=note>Each material's parameters pushed \
         to the ends of their domains, one at a time, evaluated from θ = 0 to θ = π/2 (finite, \
         in range, Λ monotone; problems listed in the case) and Λ at θ = 1 against the oracle \
         (the error column). The error against θ near 0 and π/2 of the unstressed models is in \
         the materials' relative-error plots above.</p>\n",
    );
    h.push_str("<table><tr><th>variant</th><th>case</th><th>measured</th><th>verdict</th></tr>");
    for r in &stability {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&model_name(&r.model)),
            escape(&case_name(&r.case)),
            escape(&measured_text(r)),
            escape(&verdict_text(&r.verdict))
        );
    }
    h.push_str("</table>\n");
    h.push_str(&errata_section(&report.records));
    h.push_str(&claims_section(&report.records));
    h.push_str(&super::cost_html::cost_section(cost));
    h.push_str(
        "<h2 id=checks>By check</h2>\n<table><tr><th>check</th><th>records</th><th>failing</th>\
         <th>expected failures</th><th>CPU seconds</th><th>worst passing error (its unit)</th></tr>",
    );
    let worst = super::text::worst_passing(&report.records);
    for (id, c) in &s.by_check {
        let _ = write!(
            h,
            "<tr><td>{}</td><td class=num>{}</td><td class=num>{}</td><td class=num>{}</td>\
             <td class=num>{:.2}</td><td class=num>{}</td></tr>",
            escape(id),
            c.records,
            c.failures,
            c.expected_failures,
            c.seconds,
            escape(&super::text::worst_text_of(&report.records, &worst, id))
        );
    }
    h.push_str(
        "</table>\n<p class=note>report.json beside this page holds every record; \
                chi2/ and ks/ hold the tables behind the plots.</p>\n</body></html>\n",
    );
    Ok(h)
}
