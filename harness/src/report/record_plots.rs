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
            ..
        }) => {
            let maps = chi2_heat_maps(
                &title,
                (*rows, *columns),
                (z_edges, phi_edges),
                observed,
                expected,
            )?;
            Ok(maps
                .iter()
                .map(|(name, svg)| img(svg, &format!("{} {name}", r.check)))
                .collect())
        }
        Some(data @ RecordData::SphereChi2Table { rows, columns, .. }) => {
            let mut tags = String::new();
            for h in super::artefacts::hemispheres(data) {
                let maps = chi2_heat_maps(
                    &format!("{title} · {}", h.side),
                    (*rows, *columns),
                    (h.z_edges, h.phi_edges),
                    h.observed,
                    h.expected,
                )?;
                for (name, svg) in &maps {
                    tags.push_str(&img(svg, &format!("{} {} {name}", r.check, h.side)));
                }
            }
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

pub(crate) fn case_f64(r: &CheckRecord, key: &str) -> Option<f64> {
    r.case.get(key).and_then(Value::as_f64)
}

/// Λ of the model against the oracle over θ (one series per route and φ), with the relative
/// error on a log axis below; then G1 = 1/(1 + Λ) (seed 001 eq 16) of the same records,
/// likewise. None when the material has no `smith.lambda_route` records.
///
/// `routes`: only these routes (a material drawn for its expected failures shows the routes
/// that fail, not the passing ones, which the first material of the report already shows).
pub(crate) fn smith_plots(
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
pub(crate) fn plot_policy(
    r: &CheckRecord,
    plotted: &mut std::collections::BTreeSet<String>,
) -> bool {
    if r.verdict.is_failure() {
        return false;
    }
    matches!(r.verdict, Verdict::ExpectedFailure { .. }) || plotted.insert(r.check.clone())
}
