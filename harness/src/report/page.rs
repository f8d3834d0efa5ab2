//! The pieces every HTML page of mfh shares (`report.html`, `cost.html`, `selftest.html`):
//! escaping, SVG images as `data:` URIs, the style sheet, number formatting and a record's
//! measured error and verdict as text. A leaf of
//! `report/`: it imports no other sink, so the pages and the plots can all use it.

use crate::record::{CheckRecord, Measured, Verdict};
use base64::Engine as _;

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

/// The style sheet of every page.
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
.maps img{width:calc(33.3% - 12px)}nav a{margin-right:1em}details{margin:.4em 0}.note{color:#555;font-size:.9em}";

/// A number for a table cell: fixed below 10⁴ and above 10⁻³, scientific otherwise.
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
    let text = measured_only(r);
    match &r.region {
        Some(region) => format!("{text}; {}", region.text),
        None => text,
    }
}

/// [`measured_text`] without the region.
fn measured_only(r: &CheckRecord) -> String {
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

pub(crate) fn verdict_text(v: &Verdict) -> String {
    match v {
        Verdict::Pass => "pass".into(),
        Verdict::Fail => "FAIL".into(),
        Verdict::ExpectedFailure { reason } => format!("expected failure: {reason}"),
        Verdict::Skipped { reason } => format!("skipped: {reason}"),
        Verdict::Error { message } => format!("ERROR: {message}"),
        Verdict::UnexpectedPass { reason } => format!("UNEXPECTED PASS: {reason}"),
    }
}
