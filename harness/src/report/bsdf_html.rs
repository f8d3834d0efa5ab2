//! The BSDF section of `report.html`, per BSDF audited: the `bsdf.chi2` heat maps of
//! both hemispheres — reflection (wo on wi's side) and transmission, observed / expected /
//! (O − E)/√E — grouped by incidence; the albedo against incidence (`bsdf.albedo`: the
//! quadrature with its bound, the Monte Carlo mean weight with its standard error, reflected,
//! transmitted and total, and the line albedo = 1 that `bsdf.energy` holds where it is a law);
//! the sample-consistency and failure-rate table; the reciprocity table; `bsdf.against` where
//! the audit has one. Every number is a record's: this file only lays them out.

use super::artefacts::{case_name, chi2_heat_maps, hemispheres, model_name};
use super::page::{escape, fmt_num, img, measured_text, verdict_text};
use super::plot::{panels_svg, Corner, ErrorBars, LinePlot, Panel, PlotError, Series};
use crate::record::{CheckRecord, Measured, RecordData};
use serde_json::Value;
use std::fmt::Write as _;

/// Whether a record belongs to the BSDF section.
pub(crate) fn is_bsdf(check: &str) -> bool {
    check.starts_with("bsdf.")
}

/// The BSDFs of the report, in plan order: (model, its `bsdf.*` records). A model whose only
/// records are `bsdf.stability` (a stressed variant of a spec) is not one: its records go to the
/// section's stability table.
fn bsdfs(records: &[CheckRecord]) -> Vec<(&Value, Vec<&CheckRecord>)> {
    let mut out: Vec<(&Value, Vec<&CheckRecord>)> = Vec::new();
    for r in records.iter().filter(|r| is_bsdf(&r.check)) {
        match out.iter_mut().find(|(m, _)| **m == r.model) {
            Some((_, v)) => v.push(r),
            None => out.push((&r.model, vec![r])),
        }
    }
    out.retain(|(_, v)| v.iter().any(|r| r.check != "bsdf.stability"));
    out
}

/// The anchor of the BSDF section's part for `model`, if the report has one.
pub(crate) fn anchor(records: &[CheckRecord], model: &Value) -> Option<String> {
    bsdfs(records)
        .iter()
        .position(|(m, _)| *m == model)
        .map(|i| format!("bsdf-{i}"))
}

fn case_str<'r>(r: &'r CheckRecord, key: &str) -> Option<&'r str> {
    r.case.get(key).and_then(Value::as_str)
}

fn case_num(v: &Value, key: &str) -> Option<f64> {
    v.get(key).and_then(Value::as_f64)
}

/// cos θi of a record's incidence (negative from inside).
fn cos_theta_i(r: &CheckRecord) -> Option<f64> {
    case_num(&r.case, "cos_theta_i")
}

/// An incidence as people read it: its name and θi in radians on its side.
fn incidence_label(r: &CheckRecord) -> String {
    let name = case_str(r, "incidence")
        .unwrap_or("?")
        .replace("total_internal_reflection", "total internal reflection");
    match cos_theta_i(r) {
        Some(c) => format!(
            "{name} (θi = {:.3} rad {})",
            c.abs().min(1.0).acos(),
            if c < 0.0 {
                "from inside"
            } else {
                "from outside"
            }
        ),
        None => name,
    }
}

fn num_or_dash(x: Option<f64>) -> String {
    x.map(fmt_num).unwrap_or_else(|| "—".into())
}

/// A count of the case (samples, failed samples, pairs) as an integer.
fn count(v: &Value, key: &str) -> String {
    v.get(key)
        .and_then(Value::as_u64)
        .map_or_else(|| "—".into(), |n| n.to_string())
}

/// A direction with three decimals.
fn direction(v: Option<&Value>) -> String {
    match v.and_then(Value::as_array) {
        Some(a) => format!(
            "({})",
            a.iter()
                .map(|x| x.as_f64().map_or("?".into(), |x| format!("{x:.3}")))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        None => "—".into(),
    }
}

fn tolerance_text(r: &CheckRecord) -> String {
    r.tolerance
        .as_ref()
        .map(|t| format!("{} = {}", t.name, fmt_num(t.value)))
        .unwrap_or_else(|| "—".into())
}

fn p_value_text(r: &CheckRecord) -> String {
    match r.measured {
        Some(Measured::PValue { p, statistic, .. }) => {
            format!("z = {}, p = {}", fmt_num(statistic), fmt_num(p))
        }
        _ => "—".into(),
    }
}

/// The heat maps of one `bsdf.chi2` record: a row of reflection maps and a row of transmission
/// maps (left out, with a note, where the hemisphere has neither samples nor expected counts).
fn chi2_maps(r: &CheckRecord) -> Result<String, PlotError> {
    let Some(
        data @ RecordData::SphereChi2Table {
            rows,
            columns,
            samples,
            ..
        },
    ) = &r.data
    else {
        return Ok(
            "<p class=note>No table in this record (read back from report.json?): \
                   the counts are in its chi2/ artefacts.</p>"
                .into(),
        );
    };
    let upper_reflects = cos_theta_i(r).is_none_or(|c| c > 0.0);
    let mut sides = hemispheres(data);
    if !upper_reflects {
        sides.reverse();
    }
    let incidence = case_str(r, "incidence").unwrap_or("?").replace('_', " ");
    let mut h = String::new();
    for (hemisphere, what) in sides.into_iter().zip(["reflection", "transmission"]) {
        let (side, observed, expected) =
            (hemisphere.side, hemisphere.observed, hemisphere.expected);
        let empty = observed.iter().all(|&o| o == 0) && expected.iter().all(|&e| e == 0.0);
        if empty {
            let _ = write!(
                h,
                "<p class=note>{what}, {side}: no sample and no expected count (nothing goes \
                 there).</p>"
            );
            continue;
        }
        let title = format!("{incidence} · {what}, {side}");
        let edges = (hemisphere.z_edges, hemisphere.phi_edges);
        let maps = chi2_heat_maps(
            &title,
            (*rows, *columns),
            edges,
            *samples,
            observed,
            expected,
        )?;
        h.push_str("<div class=\"plots maps\">");
        for (name, svg) in &maps {
            h.push_str(&img(svg, &format!("bsdf.chi2 {incidence} {what} {name}")));
        }
        h.push_str("</div>");
    }
    Ok(h)
}

/// The albedo records' points: (θi in radians, cos θi, the record), from outside first.
fn albedo_points<'r>(albedo: &[&'r CheckRecord]) -> Vec<(f64, f64, &'r CheckRecord)> {
    let mut points: Vec<(f64, f64, &CheckRecord)> = albedo
        .iter()
        .filter_map(|r| {
            let c = cos_theta_i(r)?;
            Some((c.abs().min(1.0).acos(), c, *r))
        })
        .collect();
    // From outside first, then from inside; by θi within each.
    points.sort_by(|a, b| (a.1 < 0.0).cmp(&(b.1 < 0.0)).then(a.0.total_cmp(&b.0)));
    points
}

/// The albedo against θi: one panel from outside, one from inside (where there are inside
/// incidences). Lines: the quadrature (bars: its error bound); markers: the Monte Carlo mean
/// weight (bars: ± 2 standard errors); reflected and transmitted parts where the records carry
/// them and something is transmitted; the dashed line albedo = 1.
fn albedo_plot(albedo: &[&CheckRecord]) -> Result<Option<String>, PlotError> {
    let points = albedo_points(albedo);
    if points.is_empty() {
        return Ok(None);
    }
    let transmits = points.iter().any(|(_, _, r)| {
        r.case
            .get("transmission")
            .is_some_and(|t| case_num(t, "albedo").unwrap_or(0.0) > 0.0)
    });
    let mut panels: Vec<(LinePlot, Vec<ErrorBars>)> = Vec::new();
    for (inside, side) in [(false, "from outside"), (true, "from inside")] {
        let here: Vec<_> = points.iter().filter(|p| (p.1 < 0.0) == inside).collect();
        if here.is_empty() {
            continue;
        }
        let mut series = Vec::new();
        let mut bars = Vec::new();
        let mut parts: Vec<(&str, Option<&str>)> = vec![("total", None)];
        if transmits {
            parts.push(("reflection", Some("reflection")));
            parts.push(("transmission", Some("transmission")));
        }
        for (label, key) in parts {
            // (θ, quadrature, its bound, mean weight, its standard error)
            let values: Vec<(f64, f64, f64, f64, f64)> = here
                .iter()
                .filter_map(|&&(theta, _, r)| match key {
                    None => Some((
                        theta,
                        r.oracle?.value,
                        r.oracle?.uncertainty,
                        r.value?,
                        case_num(&r.case, "standard_error")?,
                    )),
                    Some(k) => {
                        let part = r.case.get(k)?;
                        Some((
                            theta,
                            case_num(part, "albedo")?,
                            case_num(part, "error_bound")?,
                            case_num(part, "mean_weight")?,
                            case_num(part, "standard_error")?,
                        ))
                    }
                })
                .collect();
            if values.is_empty() {
                continue;
            }
            bars.push(ErrorBars {
                series: series.len(),
                half_widths: values.iter().map(|v| v.2).collect(),
            });
            series.push(Series {
                label: format!("{label}: ∫ eval (quadrature)"),
                points: values.iter().map(|v| (v.0, v.1)).collect(),
                markers: false,
                line: true,
                emphasis: false,
            });
            bars.push(ErrorBars {
                series: series.len(),
                half_widths: values.iter().map(|v| 2.0 * v.4).collect(),
            });
            series.push(Series {
                label: format!("{label}: mean weight (Monte Carlo)"),
                points: values.iter().map(|v| (v.0, v.3)).collect(),
                markers: true,
                line: false,
                emphasis: false,
            });
        }
        panels.push((
            LinePlot {
                title: format!("albedo {side} (bars: quadrature bound, ± 2 s.e.)"),
                x_label: "θi (radians)".into(),
                y_label: "albedo".into(),
                x_log: false,
                y_log: false,
                series,
                h_lines: vec![(1.0, "albedo = 1 (energy conservation)".into())],
                legend: Corner::UpperRight,
            },
            bars,
        ));
    }
    // θi over [0, π/2] in both panels: the incidences from inside stop short of grazing,
    // which leaves the legend its corner.
    let refs: Vec<Panel<'_>> = panels
        .iter()
        .map(|(plot, bars)| Panel {
            plot,
            bars,
            x_range: Some((0.0, std::f64::consts::FRAC_PI_2)),
        })
        .collect();
    Ok(Some(img(
        &panels_svg(&refs, 400)?,
        "bsdf.albedo against incidence",
    )))
}

fn albedo_table(albedo: &[&CheckRecord], energy: &[&CheckRecord]) -> String {
    let mut t = String::from(
        "<table><tr><th>incidence</th><th>∫ eval (quadrature ± bound)</th>\
         <th>mean weight ± s.e. (Monte Carlo)</th><th>reflection: ∫ eval / mean weight</th>\
         <th>transmission: ∫ eval / mean weight</th><th>measured</th><th>verdict</th>\
         <th>energy: ∫ eval ≤ 1</th></tr>",
    );
    for (_, _, r) in albedo_points(albedo) {
        let part = |k: &str| {
            r.case.get(k).map_or("—".to_string(), |p| {
                format!(
                    "{} ± {} / {} ± {}",
                    num_or_dash(case_num(p, "albedo")),
                    num_or_dash(case_num(p, "error_bound")),
                    num_or_dash(case_num(p, "mean_weight")),
                    num_or_dash(case_num(p, "standard_error"))
                )
            })
        };
        let energy = energy
            .iter()
            .find(|e| case_str(e, "incidence") == case_str(r, "incidence"))
            .map_or(
                "not a law here (radiance carried into the thinner medium)".to_string(),
                |e| format!("{} ({})", verdict_text(&e.verdict), measured_text(e)),
            );
        let _ = write!(
            t,
            "<tr><td>{}</td><td class=num>{} ± {}</td><td class=num>{} ± {}</td>\
             <td class=num>{}</td><td class=num>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&incidence_label(r)),
            num_or_dash(r.oracle.map(|o| o.value)),
            num_or_dash(r.oracle.map(|o| o.uncertainty)),
            num_or_dash(r.value),
            num_or_dash(case_num(&r.case, "standard_error")),
            escape(&part("reflection")),
            escape(&part("transmission")),
            escape(&p_value_text(r)),
            escape(&verdict_text(&r.verdict)),
            escape(&energy)
        );
    }
    t.push_str("</table>");
    t
}

fn consistency_table(consistency: &[&CheckRecord], rate: &[&CheckRecord]) -> String {
    let mut t = String::from(
        "<table><tr><th>incidence</th><th>samples</th><th>worst pdf relative error</th>\
         <th>worst weight relative error</th><th>tolerance</th><th>verdict</th>\
         <th>failed-sample rate</th><th>1 − ∫ pdf (± bound)</th><th>measured</th>\
         <th>verdict</th></tr>",
    );
    let mut names: Vec<&str> = Vec::new();
    for r in consistency.iter().chain(rate) {
        let n = case_str(r, "incidence").unwrap_or("?");
        if !names.contains(&n) {
            names.push(n);
        }
    }
    for name in names {
        let c = consistency
            .iter()
            .find(|r| case_str(r, "incidence") == Some(name));
        let f = rate.iter().find(|r| case_str(r, "incidence") == Some(name));
        let label = c.or(f).map(|r| incidence_label(r)).unwrap_or_default();
        let _ = write!(t, "<tr><td>{}</td>", escape(&label));
        match c {
            Some(c) => {
                let _ = write!(
                    t,
                    "<td class=num>{}</td><td class=num>{}</td><td class=num>{}</td><td>{}</td>\
                     <td>{}</td>",
                    count(&c.case, "samples"),
                    num_or_dash(case_num(&c.case, "worst_pdf_error")),
                    num_or_dash(case_num(&c.case, "worst_weight_error")),
                    escape(&tolerance_text(c)),
                    escape(&verdict_text(&c.verdict))
                );
            }
            None => t.push_str("<td colspan=5>—</td>"),
        }
        match f {
            Some(f) => {
                let _ = write!(
                    t,
                    "<td class=num>{} ({} of {})</td><td class=num>{} ± {}</td><td>{}</td>\
                     <td>{}</td>",
                    num_or_dash(f.value),
                    count(&f.case, "failed_samples"),
                    count(&f.case, "samples"),
                    num_or_dash(f.oracle.map(|o| o.value)),
                    num_or_dash(f.oracle.map(|o| o.uncertainty)),
                    escape(&p_value_text(f)),
                    escape(&verdict_text(&f.verdict))
                );
            }
            None => t.push_str("<td colspan=4>—</td>"),
        }
        t.push_str("</tr>");
    }
    t.push_str("</table>");
    t
}

/// The worst-case tables (`bsdf.reciprocity`, `bsdf.against`): one row a record, its worst
/// relative error and where.
fn worst_table(records: &[&CheckRecord]) -> String {
    let mut t = String::from(
        "<table><tr><th>check</th><th>grid</th><th>worst relative error</th><th>where</th>\
         <th>tolerance</th><th>verdict</th></tr>",
    );
    for r in records {
        let grid = match r.check.as_str() {
            "bsdf.reciprocity" => format!(
                "{} direction pairs, transport {}, η = {}",
                count(&r.case, "pairs"),
                case_str(r, "transport").unwrap_or("?"),
                r.case
                    .get("eta")
                    .and_then(Value::as_f64)
                    .map_or("— (no transmission)".into(), fmt_num)
            ),
            "bsdf.ndf_consistency" => format!(
                "{}: {} direction pairs, G2 {} ({})",
                case_str(r, "relation").unwrap_or("?"),
                count(&r.case, "pairs"),
                r.case["g2"]["masking"].as_str().unwrap_or("?"),
                if r.case["g2"]["declared"] == true {
                    "declared"
                } else {
                    "fitted"
                }
            ),
            _ => format!(
                "{} against the reference",
                case_str(r, "quantity").unwrap_or("?")
            ),
        };
        let at = r.case.get("worst");
        let place = match at {
            Some(w) if w.is_object() => {
                let mut p = format!(
                    "wi = {}, wo = {}",
                    direction(w.get("wi")),
                    direction(w.get("wo"))
                );
                for (key, what) in [
                    ("f_wi_wo", "f(wi, wo)"),
                    ("f_wo_wi", "f(wo, wi)"),
                    ("value", "value"),
                    ("reference", "reference"),
                    ("expected", "expected"),
                    ("cos_wi_h", "|wi·h|"),
                ] {
                    if let Some(x) = case_num(w, key) {
                        let _ = write!(p, ", {what} = {}", fmt_num(x));
                    }
                }
                if let Some(u) = w.get("u") {
                    let _ = write!(p, ", u = {u}");
                }
                p
            }
            _ => case_name(&r.case),
        };
        let _ = write!(
            t,
            "<tr><td>{}</td><td>{}</td><td class=num>{}</td><td>{}</td><td>{}</td><td>{}</td>\
             </tr>",
            escape(&r.check),
            escape(&grid),
            num_or_dash(r.value),
            escape(&place),
            escape(&tolerance_text(r)),
            escape(&verdict_text(&r.verdict))
        );
    }
    t.push_str("</table>");
    t
}

/// The section: `<h2 id=bsdf>`, then per BSDF its maps, albedo, consistency and reciprocity;
/// `records_table` renders the "every record" table (the page's own).
pub(crate) fn bsdf_section(
    records: &[CheckRecord],
    records_table: impl Fn(&[&CheckRecord]) -> String,
) -> Result<String, PlotError> {
    let mut h = String::from("<h2 id=bsdf>BSDFs</h2>\n");
    let all = bsdfs(records);
    if all.is_empty() {
        h.push_str("<p class=note>No BSDF in this audit.</p>\n");
        return Ok(h);
    }
    for (i, (model, rs)) in all.iter().enumerate() {
        let name = model_name(model);
        let of = |id: &str| -> Vec<&CheckRecord> {
            rs.iter().copied().filter(|r| r.check == id).collect()
        };
        let bad = rs.iter().filter(|r| r.verdict.is_failure()).count();
        let _ = writeln!(
            h,
            "<h3 id=bsdf-{i}>{} <span class=note>({}, {} failing)</span></h3>",
            escape(&name),
            super::text::count(rs.len(), "record", "records"),
            bad
        );
        let chi2 = of("bsdf.chi2");
        if !chi2.is_empty() {
            let _ = writeln!(
                h,
                "<h4>Sampled directions against the pdf over the whole sphere (bsdf.chi2)</h4>\n\
                 <p class=note>Per incidence, the reflected hemisphere (wo on wi's side) above, \
                 the transmitted one below: the observed density, the expected density (the \
                 pdf's cell masses by cubature) and (O − E)/√E. The hemisphere below the surface \
                 is mirrored (θ from −z). Failed samples fall in no cell. {}</p>",
                escape(super::artefacts::CHI2_MAPS_NOTE)
            );
        }
        for r in &chi2 {
            let _ = writeln!(
                h,
                "<p><b>{}</b> · {} · failed samples {} of {}, ∫ pdf = {} · {}</p>",
                escape(&incidence_label(r)),
                escape(&measured_text(r)),
                count(&r.case, "failed_samples"),
                count(&r.case, "samples"),
                num_or_dash(case_num(&r.case, "pdf_mass")),
                escape(&verdict_text(&r.verdict))
            );
            h.push_str(&chi2_maps(r)?);
            h.push('\n');
        }
        let albedo = of("bsdf.albedo");
        if !albedo.is_empty() {
            h.push_str(
                "<h4>Albedo against incidence (bsdf.albedo, bsdf.energy)</h4>\n<p class=note>\
                 ∫ eval dωo by cubature (with its error bound) against the mean sampled weight \
                 (a failed sample weighs 0; with its standard error), reflected, transmitted and \
                 in total. Energy conservation (∫ eval ≤ 1, the dashed line) is a law for \
                 reflection and for transmission into the denser medium or of importance; \
                 radiance carried into the thinner medium may exceed it.</p>\n",
            );
            if let Some(p) = albedo_plot(&albedo)? {
                let _ = writeln!(h, "<div class=plots>{p}</div>");
            }
            h.push_str(&albedo_table(&albedo, &of("bsdf.energy")));
            h.push('\n');
        }
        let (consistency, rate) = (of("bsdf.sample_consistency"), of("bsdf.failure_rate"));
        if !consistency.is_empty() || !rate.is_empty() {
            h.push_str(
                "<h4>Sample consistency (bsdf.sample_consistency, bsdf.failure_rate)</h4>\n\
                 <p class=note>At every sampled direction, the sample's pdf against pdf(wi, wo) \
                 and its weight against eval/pdf (worst relative errors); the rate of failed \
                 samples against 1 − ∫ pdf dωo (a sampler that loses mass fails).</p>\n",
            );
            h.push_str(&consistency_table(&consistency, &rate));
            h.push('\n');
        }
        let worst: Vec<&CheckRecord> = rs
            .iter()
            .copied()
            .filter(|r| {
                matches!(
                    r.check.as_str(),
                    "bsdf.reciprocity" | "bsdf.against" | "bsdf.ndf_consistency"
                )
            })
            .collect();
        if !worst.is_empty() {
            h.push_str(
                "<h4>Reciprocity (bsdf.reciprocity)</h4>\n<p class=note>f(wi, wo) against \
                 f(wo, wi) with the transport's η² on a grid of direction pairs (normal, \
                 grazing and, for a transmitting BSDF, near-critical directions on both \
                 sides); bsdf.against: the BSDF value by value against a reference; \
                 bsdf.ndf_consistency: the Fresnel factors (and a visible-normal pdf) left by \
                 Walter's eq 20/21 with the BSDF's own NDF.</p>\n",
            );
            h.push_str(&worst_table(&worst));
            h.push('\n');
        }
        let _ = writeln!(
            h,
            "<details><summary>every record of this BSDF</summary>{}</details>",
            records_table(rs)
        );
    }
    let variants: Vec<&CheckRecord> = records
        .iter()
        .filter(|r| r.check == "bsdf.stability" && !all.iter().any(|(m, _)| **m == r.model))
        .collect();
    if !variants.is_empty() {
        let _ = writeln!(
            h,
            "<details><summary>bsdf.stability of {} stressed variants (parameters at the \
             ends of their domains)</summary>{}</details>",
            variants.len(),
            records_table(&variants)
        );
    }
    Ok(h)
}
