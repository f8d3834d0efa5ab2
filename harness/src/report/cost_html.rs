//! The accuracy-versus-time section of the HTML report and `cost.html` (rendered from
//! cost.json): one Pareto plot and one table per quantity.

use super::page::{escape, fmt_num, img, STYLE};
use serde_json::Value;
use std::fmt::Write as _;

/// The `cost.json` section: one Pareto plot and one table per quantity, or how to produce it.
pub(crate) fn cost_section(cost: Option<&str>) -> String {
    let mut h = String::from(
        "<!-- BEGIN accuracy-versus-time (rendered from cost.json in the output folder) -->\n\
         <h2 id=cost>Accuracy versus time</h2>\n",
    );
    let parsed = cost.map(serde_json::from_str::<Value>);
    match parsed {
        None => h.push_str(
            "<p class=note>No <code>cost.json</code> in the output folder. Produce it with \
             <code>mfh cost --out DIR</code> into the same folder as this report, then run the \
             audit again (or <code>mfh audit --out DIR</code> after it): this section then shows \
             time per evaluation against the error of every route, with the Pareto frontier.</p>\n",
        ),
        Some(Err(e)) => {
            let _ = writeln!(
                h,
                "<p class=fail>cost.json is not valid JSON: {}</p>",
                escape(&e.to_string())
            );
        }
        Some(Ok(v)) => {
            let quantities = v
                .get("quantities")
                .and_then(Value::as_array)
                .cloned()
                .unwrap_or_default();
            if quantities.is_empty() {
                h.push_str("<p class=note>cost.json lists no quantities.</p>\n");
            }
            for q in quantities {
                h.push_str(&cost_quantity(&q));
            }
        }
    }
    h.push_str("<!-- END accuracy-versus-time -->\n");
    h
}

/// One quantity of `cost.json`: its Pareto plot (routes with a time and a finite error) and a
/// table of every route (refused ones with their reason).
fn cost_quantity(q: &Value) -> String {
    let text = |v: &Value, k: &str| v.get(k).and_then(Value::as_str).unwrap_or("").to_string();
    let num = |v: &Value, k: &str| v.get(k).and_then(Value::as_f64);
    let name = q.get("name").and_then(Value::as_str).unwrap_or("?");
    let routes = q
        .get("routes")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let frontier: Vec<String> = q
        .get("frontier")
        .and_then(Value::as_array)
        .map(|f| {
            f.iter()
                .filter_map(|r| r.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let points: Vec<(String, f64, f64)> = routes
        .iter()
        .filter_map(|r| {
            Some((
                text(r, "route"),
                num(r, "seconds_per_eval")?,
                num(r, "max_error")?,
            ))
        })
        .collect();
    let mut h = String::new();
    let _ = write!(
        h,
        "<h3>{}</h3><p class=note>reference: {} · error: {} · inputs: {}</p>",
        escape(name),
        escape(&text(q, "reference")),
        escape(&text(q, "error")),
        escape(&text(q, "inputs"))
    );
    if points.is_empty() {
        h.push_str("<p class=note>No timed route with a finite error: no plot.</p>");
    } else {
        let _ = write!(
            h,
            "<div class=plots>{}</div>",
            img(&super::plot::pareto_svg(name, &points), name)
        );
    }
    h.push_str(
        "<table><tr><th>route</th><th>max error</th><th>seconds per evaluation (median)</th>\
         <th>spread (fastest – slowest batch)</th><th>frontier</th><th>note</th></tr>",
    );
    for r in &routes {
        let route = text(r, "route");
        let error = if text(r, "status") == "refused" {
            "refused".to_string()
        } else if r.get("non_finite").and_then(Value::as_u64).unwrap_or(0) > 0 {
            "non-finite".to_string()
        } else {
            num(r, "max_error")
                .map(fmt_num)
                .unwrap_or_else(|| "—".into())
        };
        let spread = r
            .get("timing")
            .map(|t| {
                format!(
                    "{} – {}",
                    num(t, "min").map(fmt_num).unwrap_or_default(),
                    num(t, "max").map(fmt_num).unwrap_or_default()
                )
            })
            .unwrap_or_default();
        let note = [text(r, "reason"), text(r, "note")]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join("; ");
        let _ = write!(
            h,
            "<tr><td>{}</td><td class=num>{}</td><td class=num>{}</td><td class=num>{}</td>\
             <td>{}</td><td>{}</td></tr>",
            escape(&route),
            escape(&error),
            num(r, "seconds_per_eval")
                .map(fmt_num)
                .unwrap_or_else(|| "—".into()),
            escape(&spread),
            if frontier.contains(&route) { "yes" } else { "" },
            escape(&note)
        );
    }
    h.push_str("</table>\n");
    h
}

/// `cost.html`: the accuracy-versus-time section of the report as a page of its own (what
/// `mfh cost --out DIR` writes beside cost.json).
pub fn cost_page(cost_json: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>mfh cost</title>\
         <style>{STYLE}</style></head><body>\n<h1>mfh cost — what accuracy costs in time</h1>\n\
         <p class=note>Timings are medians of repeated batches on the machine and load of this \
         run; errors are against independent high-precision references (deterministic).</p>\n\
         {}</body></html>\n",
        cost_section(Some(cost_json))
    )
}
