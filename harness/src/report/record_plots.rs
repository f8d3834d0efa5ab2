//! The plots of `report.html` drawn from records: a record's own data (chi-square heat maps,
//! KS marginals), Λ and G1 of a material against the oracle with the relative error below,
//! and the γ → ∞ convergence. The page (`html.rs`) decides where each goes.

use super::artefacts::{case_name, chi2_heat_maps, model_name};
use super::page::img;
use super::plot::{line_svg, stacked_svg, Corner, LinePlot, PlotError, Series};
use crate::record::{CheckRecord, Measured, RecordData, Verdict};
use serde_json::Value;
use std::collections::BTreeMap;

/// The plots of one record's data (heat maps, KS marginal), as `<img>` tags.
pub(crate) fn data_plots(r: &CheckRecord) -> Result<String, PlotError> {
    let title = format!("{} · {}", model_name(&r.model), case_name(&r.case));
    match &r.data {
        Some(RecordData::Chi2Table {
            rows,
            columns,
            observed,
            expected,
            z_edges,
            phi_edges,
            samples,
            ..
        }) => {
            let maps = chi2_heat_maps(
                &title,
                (*rows, *columns),
                (z_edges, phi_edges),
                *samples,
                observed,
                expected,
            )?;
            let mut tags: String = maps
                .iter()
                .map(|(name, svg)| img(svg, &format!("{} {name}", r.check)))
                .collect();
            tags.push_str(&maps_note());
            Ok(tags)
        }
        Some(
            data @ RecordData::SphereChi2Table {
                rows,
                columns,
                samples,
                ..
            },
        ) => {
            let mut tags = String::new();
            for h in super::artefacts::hemispheres(data) {
                let maps = chi2_heat_maps(
                    &format!("{title} · {}", h.side),
                    (*rows, *columns),
                    (h.z_edges, h.phi_edges),
                    *samples,
                    h.observed,
                    h.expected,
                )?;
                for (name, svg) in &maps {
                    tags.push_str(&img(svg, &format!("{} {} {name}", r.check, h.side)));
                }
            }
            tags.push_str(&maps_note());
            Ok(tags)
        }
        Some(RecordData::KsMarginal {
            marginal,
            x,
            model_cdf,
            empirical_cdf,
            samples,
            ..
        }) => {
            // The marginal's own variable: φ in radians, or cos θ (no unit).
            let unit = match marginal.as_str() {
                "phi" => "φ (radians)",
                "cos_theta" => "cos θ",
                _ => "θ (radians)",
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
                        emphasis: false,
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
                        emphasis: false,
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
                    emphasis: false,
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
            // A curve of positive values over decades (an error against incidence, swept
            // log-spaced near the normal) on log axes.
            let decades = |v: &[f64]| {
                let (lo, hi) = v
                    .iter()
                    .filter(|v| v.is_finite())
                    .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
                v.iter().all(|v| *v > 0.0) && hi > 100.0 * lo
            };
            let plot = LinePlot {
                title: format!("{label} · {title}"),
                x_label: if label.contains("θi") {
                    "θi (rad)"
                } else {
                    "x"
                }
                .into(),
                y_label: "y".into(),
                x_log: decades(x),
                y_log: decades(y),
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

/// The note under chi-square heat maps: they show densities over unequal cells.
fn maps_note() -> String {
    format!(
        "<p class=note>{}</p>",
        super::page::escape(super::artefacts::CHI2_MAPS_NOTE)
    )
}

pub(crate) fn case_f64(r: &CheckRecord, key: &str) -> Option<f64> {
    r.case.get(key).and_then(Value::as_f64)
}

/// How many θ the curves of Λ and G1 are drawn at ([`model_curve`]).
const CURVE_POINTS: usize = 240;

/// Λ by `route` at azimuth `phi` on a dense θ grid over `range`, from the model itself (built
/// from the record's spec): a curve where the records hold a few points. None where the model
/// is not one the registry builds (a user's model is named, not specified) or has no Smith Λ;
/// θ where the route refuses are left out. Drawing only: the records' values and the oracle's
/// are what the checks judged, and the plots mark them.
fn model_curve(model: &Value, route: &str, phi: f64, range: (f64, f64)) -> Option<Vec<(f64, f64)>> {
    let spec: mfh_reference::ModelSpec = serde_json::from_value(model.clone()).ok()?;
    let built = spec.build().ok()?;
    let smith = built.as_smith()?;
    let step = (range.1 - range.0) / (CURVE_POINTS - 1) as f64;
    let points: Vec<(f64, f64)> = (0..CURVE_POINTS)
        .filter_map(|k| {
            let theta = range.0 + step * k as f64;
            let value = match crate::check::smith::route_answer(smith, route, theta, phi) {
                Ok(Some(v)) => v,
                Ok(None) => smith.lambda(mfh_reference::geometry::from_spherical(theta, phi)),
                Err(_) => return None,
            };
            value.is_finite().then_some((theta, value))
        })
        .collect();
    (points.len() > 1).then_some(points)
}

/// One `smith.lambda_route` point: θ, the value, the oracle's, and the verdict's kind.
struct LambdaPoint {
    theta: f64,
    value: f64,
    oracle: f64,
    /// "expected failure", "FAIL" or None (pass).
    mark: Option<&'static str>,
}

/// Λ of the model against the oracle over θ (one series per route and φ), with the relative
/// error on a log axis below; then G1 = 1/(1 + Λ) (document 001 eq 16) of the same records,
/// likewise. Each route is a curve on a dense θ grid ([`model_curve`]; the records' points
/// joined where the model cannot be built), the oracle's values are dots at the records' θ,
/// and in the error panel the records that failed, or failed as expected, are crosses of
/// their own legend entry (an expected failure sits above the tolerance line of a passing
/// report, and says so). None when the material has no `smith.lambda_route` records.
///
/// `routes`: only these routes (a material drawn for its expected failures shows the routes
/// that fail, not the passing ones, which the first material of the report already shows).
pub(crate) fn smith_plots(
    records: &[&CheckRecord],
    material: &str,
    routes: Option<&std::collections::BTreeSet<String>>,
) -> Result<Option<String>, PlotError> {
    // series key → (route, φ, points)
    let mut series: BTreeMap<String, (String, f64, Vec<LambdaPoint>)> = BTreeMap::new();
    let mut tolerance: Option<(f64, &str)> = None;
    let model = records.first().map(|r| &r.model);
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
            format!("{route}, φ = {}", super::text::num(phi))
        };
        let mark = match r.verdict {
            Verdict::ExpectedFailure { .. } => Some("expected failure"),
            ref v if v.is_failure() => Some("FAIL"),
            _ => None,
        };
        series
            .entry(key)
            .or_insert_with(|| (route.to_string(), phi, Vec::new()))
            .2
            .push(LambdaPoint {
                theta,
                value: v,
                oracle: o.value,
                mark,
            });
        if let Some(t) = &r.tolerance {
            if tolerance.is_none_or(|(v, _)| t.value < v) {
                tolerance = Some((t.value, t.name));
            }
        }
    }
    if series.is_empty() {
        return Ok(None);
    }
    for (_, _, v) in series.values_mut() {
        v.sort_by(|a, b| a.theta.total_cmp(&b.theta));
    }
    // On Λ's log axis the model's curve reaches down only a decade below the smallest
    // positive value the records hold: near normal incidence Λ of a Beckmann-like lobe falls
    // to 1e-300 and would squeeze every record into the top of the plot.
    let floor = series
        .values()
        .flat_map(|(_, _, points)| points.iter().flat_map(|p| [p.value, p.oracle]))
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold(f64::INFINITY, f64::min)
        / 10.0;
    let mut html = String::new();
    for (name, f) in [
        ("Λ", (|l: f64| l) as fn(f64) -> f64),
        ("G1 = 1/(1 + Λ)", |l: f64| 1.0 / (1.0 + l)),
    ] {
        let mut values: Vec<Series> = Vec::new();
        let mut oracles: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        let mut errors: Vec<Series> = Vec::new();
        let mut marked: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        for (key, (route, phi, points)) in &series {
            let range = (points[0].theta, points[points.len() - 1].theta);
            let curve = model
                .and_then(|m| model_curve(m, route, *phi, range))
                .map(|c| {
                    c.into_iter()
                        .filter(|&(_, l)| name != "Λ" || l >= floor)
                        .map(|(t, l)| (t, f(l)))
                        .collect()
                })
                .unwrap_or_else(|| points.iter().map(|p| (p.theta, f(p.value))).collect());
            values.push(Series {
                label: key.clone(),
                points: curve,
                markers: false,
                line: true,
                emphasis: false,
            });
            let okey = key
                .split_once(", ")
                .map(|(_, phi)| format!("oracle, {phi}"))
                .unwrap_or_else(|| "oracle".into());
            oracles
                .entry(okey)
                .or_insert_with(|| points.iter().map(|p| (p.theta, f(p.oracle))).collect());
            let error = |p: &LambdaPoint| {
                (
                    p.theta,
                    crate::record::relative_error(f(p.value), f(p.oracle)),
                )
            };
            errors.push(Series::new(key.clone(), points.iter().map(error).collect()));
            // Marked where the log axis can show the point (an exact zero has no place on it,
            // and a legend entry without a cross would mislead).
            for p in points {
                let e = error(p);
                if let (Some(mark), true) = (p.mark, e.1 > 0.0 && e.1.is_finite()) {
                    marked.entry(format!("{key}: {mark}")).or_default().push(e);
                }
            }
        }
        for (key, points) in oracles {
            values.push(Series {
                label: key,
                points,
                markers: true,
                line: false,
                emphasis: false,
            });
        }
        for (label, points) in marked {
            errors.push(Series {
                label,
                points,
                markers: true,
                line: false,
                emphasis: true,
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
            title: format!("relative error of {name} at the records' θ (exact zeros left out)"),
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
pub(crate) fn limit_plot(r: &CheckRecord) -> Result<Option<String>, PlotError> {
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
        emphasis: false,
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
                emphasis: false,
            });
            series.push(Series {
                label: format!("expected rate γ^{expected}"),
                points: line(expected),
                markers: false,
                line: true,
                emphasis: false,
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
pub(crate) fn plot_policy(
    r: &CheckRecord,
    plotted: &mut std::collections::BTreeSet<String>,
) -> bool {
    if r.verdict.is_failure() {
        return false;
    }
    matches!(r.verdict, Verdict::ExpectedFailure { .. }) || plotted.insert(r.check.clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::{AppliedTolerance, OracleValue};
    use base64::Engine as _;
    use serde_json::json;

    /// The SVG texts of the `<img>` tags of `html`.
    fn svgs(html: &str) -> Vec<String> {
        html.split("base64,")
            .skip(1)
            .map(|rest| {
                let b64 = &rest[..rest.find('"').unwrap_or(rest.len())];
                let bytes = base64::engine::general_purpose::STANDARD
                    .decode(b64)
                    .unwrap();
                String::from_utf8(bytes).unwrap()
            })
            .collect()
    }

    /// Λ and G1 are curves (the model evaluated on a dense grid), not the records' few points
    /// joined, and an expected failure is a cross with its own legend entry.
    #[test]
    fn lambda_is_a_curve_and_an_expected_failure_is_marked() {
        let model = json!({"family": "ggx", "alpha": 0.3});
        let records: Vec<CheckRecord> = [0.2, 0.8, 1.4]
            .iter()
            .enumerate()
            .map(|(i, &theta)| {
                let mut r = CheckRecord::new(
                    "smith.lambda_route",
                    model.clone(),
                    json!({"route": "default", "theta": theta, "phi": 0.0}),
                    "s",
                );
                r.value = Some(1e-9 * theta);
                r.oracle = Some(OracleValue {
                    value: 1e-9 * theta * if i == 2 { 1.01 } else { 1.0 },
                    uncertainty: 1e-15,
                    kind: "error_bound",
                    noise_floor: None,
                });
                r.tolerance = Some(AppliedTolerance {
                    name: "closed_form",
                    value: 1e-10,
                    reason: "r",
                });
                r.verdict = if i == 2 {
                    Verdict::ExpectedFailure {
                        reason: "outside its domain".into(),
                    }
                } else {
                    Verdict::Pass
                };
                r
            })
            .collect();
        let refs: Vec<&CheckRecord> = records.iter().collect();
        let html = smith_plots(&refs, "ggx alpha=0.3", None).unwrap().unwrap();
        let plots = svgs(&html);
        assert_eq!(plots.len(), 2);
        let lambda = &plots[0];
        assert!(lambda.contains("default: expected failure"), "{lambda}");
        // The longest polyline is the route's curve: the dense grid, not the 3 records.
        let longest = lambda
            .split("points=\"")
            .skip(1)
            .map(|p| p[..p.find('"').unwrap()].split_whitespace().count())
            .max()
            .unwrap();
        assert!(longest >= CURVE_POINTS - 1, "{longest} vertices");
    }
}
