//! `report.html`: one self-contained page (plots embedded as SVG `data:` URIs, no scripts, no
//! network) read top to bottom: verdict and counts, how to reproduce the run, the failures with
//! their plots, per material Λ and G1 against the oracle with the relative error below, the
//! chi-square heat maps and KS marginals of every sampling check, the γ → ∞ convergence, the
//! stability sweep, the errata and claims tables, accuracy versus time (`cost.json`), and the
//! time per check.

use super::artefacts::{case_name, chi2_heat_maps, model_name, record_title};
use super::plot::{line_svg, stacked_svg, Corner, LinePlot, PlotError, Series};
use crate::audit::AuditReport;
use crate::record::{CheckRecord, Measured, RecordData, Verdict};
use base64::Engine as _;
use serde_json::Value;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Escapes text for HTML element content and attribute values.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// An `<img>` of an SVG as a base64 `data:` URI (so that the page is one file and the browser
/// reports the image's natural size).
pub(crate) fn img(svg: &str, alt: &str) -> String {
    format!(
        "<img alt=\"{}\" src=\"data:image/svg+xml;base64,{}\">",
        escape(alt),
        base64::engine::general_purpose::STANDARD.encode(svg)
    )
}

pub(crate) const STYLE: &str =
    "body{font-family:sans-serif;max-width:1340px;margin:1em auto;padding:0 1em;\
color:#222;line-height:1.4}h1{margin-bottom:.2em}h2{border-bottom:2px solid #ccc;margin-top:1.6em}\
.verdict{font-size:1.4em;font-weight:bold;padding:.4em .8em;border-radius:6px;display:inline-block}\
.pass{background:#d8f0dc;color:#145c24}.fail{background:#f8d7da;color:#842029}\
table{border-collapse:collapse;margin:.5em 0;font-size:.9em}td,th{border:1px solid #ccc;\
padding:3px 6px;text-align:left;vertical-align:top}th{background:#f2f2f2}\
code{background:#f4f4f4;padding:1px 4px;border-radius:3px}.plots img{margin:4px;\
border:1px solid #ddd;vertical-align:top;max-width:100%}.failure{border-left:4px solid #c0392b;\
padding-left:.8em;margin:1em 0}.num{text-align:right;font-variant-numeric:tabular-nums}\
nav a{margin-right:1em}details{margin:.4em 0}.note{color:#555;font-size:.9em}";

pub(crate) fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if !x.is_finite() {
        format!("{x}")
    } else if x.abs() >= 1e4 || x.abs() < 1e-3 {
        format!("{x:.3e}")
    } else {
        format!("{x:.6}")
    }
}

/// The measured discrepancy against the tolerance, as one line of text.
pub fn measured_text(r: &CheckRecord) -> String {
    let tol = r
        .tolerance
        .as_ref()
        .map(|t| format!(" against {} = {}", t.name, fmt_num(t.value)))
        .unwrap_or_default();
    match r.measured {
        Some(Measured::Absolute { error }) => format!("absolute error {}{tol}", fmt_num(error)),
        Some(Measured::Relative { error }) => format!("relative error {}{tol}", fmt_num(error)),
        Some(Measured::PValue {
            p,
            statistic,
            dof,
            alpha,
        }) => format!(
            "p = {} (statistic {}, dof {dof}) at α = {}",
            fmt_num(p),
            fmt_num(statistic),
            fmt_num(alpha)
        ),
        Some(Measured::Rate { exponent, expected }) => format!(
            "rate {} (expected {}){tol}",
            fmt_num(exponent),
            fmt_num(expected)
        ),
        None => "not measured".into(),
    }
}

fn verdict_text(v: &Verdict) -> String {
    match v {
        Verdict::Pass => "pass".into(),
        Verdict::Fail => "FAIL".into(),
        Verdict::ExpectedFailure { reason } => format!("expected failure: {reason}"),
        Verdict::Skipped { reason } => format!("skipped: {reason}"),
        Verdict::Error { message } => format!("ERROR: {message}"),
        Verdict::UnexpectedPass { reason } => format!("UNEXPECTED PASS: {reason}"),
    }
}

/// The plots of one record's data (heat maps, KS marginal), as `<img>` tags.
fn data_plots(r: &CheckRecord) -> Result<String, PlotError> {
    let title = format!("{} · {}", model_name(&r.model), case_name(&r.case));
    match &r.data {
        Some(RecordData::Chi2Table {
            rows,
            columns,
            observed,
            expected,
            ..
        }) => {
            let maps = chi2_heat_maps(&title, *rows, *columns, observed, expected)?;
            Ok(maps
                .iter()
                .map(|(name, svg)| img(svg, &format!("{} {name}", r.check)))
                .collect())
        }
        Some(RecordData::KsMarginal {
            marginal,
            x,
            model_cdf,
            empirical_cdf,
            samples,
            ..
        }) => {
            let unit = if marginal == "phi" {
                "φ (radians)"
            } else {
                "θ (radians)"
            };
            let plot = LinePlot {
                title: format!(
                    "KS {marginal} marginal · {} · {samples} samples",
                    model_name(&r.model)
                ),
                x_label: unit.into(),
                y_label: "CDF".into(),
                x_log: false,
                y_log: false,
                series: vec![
                    Series {
                        label: "model CDF (oracle table)".into(),
                        points: x.iter().copied().zip(model_cdf.iter().copied()).collect(),
                        markers: false,
                        line: true,
                    },
                    Series {
                        label: format!("empirical CDF, {samples} samples"),
                        points: x
                            .iter()
                            .copied()
                            .zip(empirical_cdf.iter().copied())
                            .collect(),
                        markers: false,
                        line: true,
                    },
                ],
                h_lines: vec![],
                legend: Corner::LowerRight,
            };
            let diff = LinePlot {
                title: "empirical − model CDF (D_N is the largest |difference| over all samples)"
                    .into(),
                x_label: unit.into(),
                y_label: "difference".into(),
                x_log: false,
                y_log: false,
                series: vec![Series {
                    label: "F_N − F".into(),
                    points: x
                        .iter()
                        .zip(empirical_cdf.iter().zip(model_cdf))
                        .map(|(&t, (e, m))| (t, e - m))
                        .collect(),
                    markers: false,
                    line: true,
                }],
                h_lines: r
                    .value
                    .map(|d| vec![(d, "+D_N".to_string()), (-d, "−D_N".to_string())])
                    .unwrap_or_default(),
                legend: Corner::UpperRight,
            };
            Ok(img(&stacked_svg(&plot, &diff)?, &format!("{} KS", r.check)))
        }
        Some(RecordData::Curve { label, x, y }) => {
            let plot = LinePlot {
                title: format!("{label} · {title}"),
                x_label: "x".into(),
                y_label: "y".into(),
                x_log: false,
                y_log: false,
                series: vec![Series::new(
                    label.clone(),
                    x.iter().copied().zip(y.iter().copied()).collect(),
                )],
                h_lines: vec![],
                legend: Corner::UpperRight,
            };
            Ok(img(&line_svg(&plot)?, label))
        }
        None => Ok(String::new()),
    }
}

fn case_f64(r: &CheckRecord, key: &str) -> Option<f64> {
    r.case.get(key).and_then(Value::as_f64)
}

/// Λ of the model against the oracle over θ (one series per route and φ), with the relative
/// error on a log axis below; then G1 = 1/(1 + Λ) (seed 001 eq 16) of the same records,
/// likewise. None when the material has no `smith.lambda_route` records.
///
/// `routes`: only these routes (a material drawn for its expected failures shows the routes
/// that fail, not the passing ones, which the first material of the report already shows).
fn smith_plots(
    records: &[&CheckRecord],
    material: &str,
    routes: Option<&std::collections::BTreeSet<String>>,
) -> Result<Option<String>, PlotError> {
    // series key → (θ, value, oracle)
    let mut series: BTreeMap<String, Vec<(f64, f64, f64)>> = BTreeMap::new();
    let mut tolerance: Option<(f64, &str)> = None;
    for r in records.iter().filter(|r| {
        r.check == "smith.lambda_route"
            && routes.is_none_or(|set| {
                set.contains(r.case.get("route").and_then(Value::as_str).unwrap_or("?"))
            })
    }) {
        let (Some(theta), Some(phi), Some(v), Some(o)) =
            (case_f64(r, "theta"), case_f64(r, "phi"), r.value, r.oracle)
        else {
            continue;
        };
        let route = r.case.get("route").and_then(Value::as_str).unwrap_or("?");
        let key = if phi == 0.0 {
            route.to_string()
        } else {
            format!("{route}, φ = {phi}")
        };
        series.entry(key).or_default().push((theta, v, o.value));
        if let Some(t) = &r.tolerance {
            if tolerance.is_none_or(|(v, _)| t.value < v) {
                tolerance = Some((t.value, t.name));
            }
        }
    }
    if series.is_empty() {
        return Ok(None);
    }
    for v in series.values_mut() {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let mut html = String::new();
    for (name, f) in [
        ("Λ", (|l: f64| l) as fn(f64) -> f64),
        ("G1 = 1/(1 + Λ)", |l: f64| 1.0 / (1.0 + l)),
    ] {
        let mut values: Vec<Series> = Vec::new();
        let mut oracles: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        let mut errors: Vec<Series> = Vec::new();
        for (key, points) in &series {
            // Lines only: the routes' values coincide with the oracle's at plot scale (the
            // error panel below has the markers); a marker per point doubled the page.
            values.push(Series {
                label: key.clone(),
                points: points.iter().map(|&(t, v, _)| (t, f(v))).collect(),
                markers: false,
                line: true,
            });
            let okey = key
                .split_once(", ")
                .map(|(_, phi)| format!("oracle, {phi}"))
                .unwrap_or_else(|| "oracle".into());
            oracles
                .entry(okey)
                .or_insert_with(|| points.iter().map(|&(t, _, o)| (t, f(o))).collect());
            errors.push(Series::new(
                key.clone(),
                points
                    .iter()
                    .map(|&(t, v, o)| (t, crate::record::relative_error(f(v), f(o))))
                    .collect(),
            ));
        }
        for (key, points) in oracles {
            values.push(Series {
                label: key,
                points,
                markers: false,
                line: true,
            });
        }
        let top = LinePlot {
            title: format!("{name} of {material} against the oracle"),
            x_label: "θ (radians)".into(),
            y_label: name.split(' ').next().unwrap_or(name).into(),
            x_log: false,
            y_log: name == "Λ",
            series: values,
            h_lines: vec![],
            legend: if name == "Λ" {
                Corner::UpperLeft
            } else {
                Corner::LowerLeft
            },
        };
        let bottom = LinePlot {
            title: format!("relative error of {name} (exact zeros left out)"),
            x_label: "θ (radians)".into(),
            y_label: "relative error".into(),
            x_log: false,
            y_log: true,
            series: errors,
            h_lines: tolerance
                .filter(|_| name == "Λ")
                .map(|(v, n)| vec![(v, format!("tolerance {n}"))])
                .unwrap_or_default(),
            legend: Corner::UpperRight,
        };
        html.push_str(&img(&stacked_svg(&top, &bottom)?, &top.title));
    }
    Ok(Some(html))
}

/// The γ → ∞ convergence of a `limits.*` record on log–log axes: the relative error against
/// γ, with the fitted rate's line through the points' geometric mean.
fn limit_plot(r: &CheckRecord) -> Result<Option<String>, PlotError> {
    let (Some(gammas), Some(errors)) = (
        r.case.get("gammas").and_then(Value::as_array),
        r.case.get("relative_errors").and_then(Value::as_array),
    ) else {
        return Ok(None);
    };
    let points: Vec<(f64, f64)> = gammas
        .iter()
        .zip(errors)
        .filter_map(|(g, e)| Some((g.as_f64()?, e.as_f64()?)))
        .collect();
    let mut series = vec![Series {
        label: "|STD − Beckmann| / Beckmann".into(),
        points: points.clone(),
        markers: true,
        line: false,
    }];
    if let Some(Measured::Rate { exponent, expected }) = r.measured {
        let logs: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.0 > 0.0 && p.1 > 0.0)
            .map(|p| (p.0.ln(), p.1.ln()))
            .collect();
        if !logs.is_empty() {
            let n = logs.len() as f64;
            let (mx, my) = (
                logs.iter().map(|p| p.0).sum::<f64>() / n,
                logs.iter().map(|p| p.1).sum::<f64>() / n,
            );
            let line = |slope: f64| -> Vec<(f64, f64)> {
                logs.iter()
                    .map(|p| (p.0.exp(), (my + slope * (p.0 - mx)).exp()))
                    .collect()
            };
            series.push(Series {
                label: format!("fitted rate γ^{exponent:.4}"),
                points: line(exponent),
                markers: false,
                line: true,
            });
            series.push(Series {
                label: format!("expected rate γ^{expected}"),
                points: line(expected),
                markers: false,
                line: true,
            });
        }
    }
    let plot = LinePlot {
        title: format!(
            "γ → ∞ · {} · {}",
            model_name(&r.model),
            r.case
                .get("quantity")
                .and_then(Value::as_str)
                .unwrap_or("?")
        ),
        x_label: "γ".into(),
        y_label: "relative error".into(),
        x_log: true,
        y_log: true,
        series,
        h_lines: vec![],
        legend: Corner::UpperRight,
    };
    Ok(Some(img(&line_svg(&plot)?, &plot.title)))
}

/// Whether a record with data gets its plots under its material: an expected failure always,
/// a failure never (its plots are in the failures section above), a passing record when it is
/// the first of its check family (`plotted` remembers the families drawn).
fn plot_policy(r: &CheckRecord, plotted: &mut std::collections::BTreeSet<String>) -> bool {
    if r.verdict.is_failure() {
        return false;
    }
    matches!(r.verdict, Verdict::ExpectedFailure { .. }) || plotted.insert(r.check.clone())
}

/// The checks that have their own section (not under the materials).
fn own_section(check: &str) -> bool {
    ["errata.", "claims.", "limits.", "stability."]
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
        "<p><span class=\"verdict {}\">{}</span> &nbsp; {} records: {}</p>\n\
         <table><tr><th>reproduce</th><td><code>{}</code></td></tr>\
         <tr><th>seed</th><td>{}</td></tr><tr><th>profile</th><td>{}</td></tr>\
         <tr><th>versions</th><td>mfh {}, record schema {}</td></tr>\
         <tr><th>scene</th><td>{}</td></tr>\
         <tr><th>statistical checks</th><td>{} at Šidák level {} each (family-wise α = {})</td></tr>\
         <tr><th>wall time</th><td>{:.1} s</td></tr></table>\n",
        if passed { "pass" } else { "fail" },
        if passed { "PASS" } else { "FAIL" },
        report.records.len(),
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
         <a href=#limits>γ → ∞</a><a href=#stability>stability</a><a href=#errata>errata</a>\
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
        let _ = write!(
            h,
            "<div class=failure><h3>{}</h3><p>{} · value {} · oracle {} · {}</p><p>source: {}</p>",
            escape(&record_title(r)),
            escape(&verdict_text(&r.verdict)),
            r.value.map(fmt_num).unwrap_or("—".into()),
            r.oracle
                .map(|o| format!("{} ± {}", fmt_num(o.value), fmt_num(o.uncertainty)))
                .unwrap_or("—".into()),
            escape(&measured_text(r)),
            escape(&r.source)
        );
        let plots = data_plots(r)?;
        if !plots.is_empty() {
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
            "<h3 id=material-{i}>{} <span class=note>({} records, {} failing)</span></h3>",
            escape(&name),
            records.len(),
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
         <th>expected failures</th><th>CPU seconds</th><th>worst passing error</th></tr>",
    );
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
            fmt_num(c.worst_passing_error)
        );
    }
    h.push_str(
        "</table>\n<p class=note>report.json beside this page holds every record; \
                chi2/ and ks/ hold the tables behind the plots.</p>\n</body></html>\n",
    );
    Ok(h)
}
