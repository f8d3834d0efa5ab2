//! The page of `mfh selftest` (`report.html` in its `--out`): the kill matrix, the controls,
//! unexpected passes, the false-alarm calibration (tables, p-value histograms and QQ plots) and
//! the detectable sampler distortion. Shares the audit page's style and helpers.

use super::artefacts::model_name;
use super::page::{escape, fmt_num, img, STYLE};
use super::plot::{line_svg, Corner, LinePlot, PlotError, Series};
use std::fmt::Write as _;

/// The page of `mfh selftest`: the verdict, the kill matrix (mutant × seed: the checks that
/// killed it; survivors and misses marked), the controls, unexpected passes, and the
/// calibration (rejection counts against their binomial intervals; a p-value histogram and QQ
/// plot per test).
pub fn render_selftest(report: &crate::selftest::SelftestReport) -> Result<String, PlotError> {
    let passed = report.passed();
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>mfh selftest</title>\
         <style>{STYLE}</style></head><body>\n<h1>mfh selftest</h1>\n\
         <p><span class=\"verdict {}\">{}</span> &nbsp; {} mutants of {} in the catalog, \
         profile {}, seeds {:?}, mfh {}, schema {}, {:.1} s</p>\n",
        if passed { "pass" } else { "fail" },
        if passed { "PASS" } else { "FAIL" },
        report.mutants.len(),
        report.catalog_size,
        report.profile.name(),
        report.seeds,
        escape(report.mfh_version),
        report.schema_version,
        report.wall_seconds
    );
    if !report.mutants.is_empty() {
        h.push_str("<h2 id=kills>Kill matrix</h2>\n<table><tr><th>mutant</th><th>defect</th><th>expected</th>");
        for s in &report.seeds {
            let _ = write!(h, "<th>seed {s:#x}</th>");
        }
        h.push_str("</tr>\n");
        for m in &report.mutants {
            let _ = write!(
                h,
                "<tr><td><code>{}</code></td><td>{}</td><td>{}</td>",
                escape(&m.id),
                escape(&m.description),
                escape(&m.expected.join(", "))
            );
            for r in &m.runs {
                let class = if r.killed && r.expected_hit {
                    "pass"
                } else {
                    "fail"
                };
                let text = if r.killed {
                    r.killers.join(", ")
                } else {
                    "SURVIVED".into()
                };
                let _ = write!(h, "<td class={class}>{}</td>", escape(&text));
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</table>\n");
        let failed: Vec<_> = report.controls.iter().filter(|c| !c.passed).collect();
        let _ = writeln!(
            h,
            "<h2 id=controls>Controls</h2><p>{} unmutated audits, {} failed.</p>",
            report.controls.len(),
            failed.len()
        );
        for c in failed {
            let _ = writeln!(
                h,
                "<p class=fail>{} seed {:#x}: {}</p>",
                escape(&model_name(&c.base)),
                c.seed,
                escape(&c.failures.join("; "))
            );
        }
        let unexpected: Vec<String> = report
            .mutants
            .iter()
            .flat_map(|m| {
                m.runs.iter().flat_map(move |r| {
                    r.unexpected_passes
                        .iter()
                        .map(move |u| format!("{} seed {:#x}: {u}", m.id, r.seed))
                })
            })
            .collect();
        let _ = writeln!(
            h,
            "<h2 id=unexpected>Expected failures that passed under a mutant</h2><p>{}</p>",
            if unexpected.is_empty() {
                "None.".to_string()
            } else {
                escape(&unexpected.join("; "))
            }
        );
    }
    if let Some(cal) = &report.calibration {
        let _ = writeln!(
            h,
            "<h2 id=calibration>False-alarm calibration</h2><p>Correct samplers, seeded runs at \
             the {} profile's sample counts: the rejections at each α must lie in the 99 % \
             binomial interval, and the p-values must be uniform (KS p ≥ {}).</p>\
             <table><tr><th>model</th><th>test</th><th>runs</th><th>samples</th>\
             <th>rejections (interval) at α</th><th>KS uniformity D, p</th><th>time</th></tr>",
            cal.profile.name(),
            crate::selftest::calibrate::UNIFORMITY_LEVEL
        );
        let mut plots = String::new();
        for t in &cal.tests {
            let levels: Vec<String> = t
                .levels
                .iter()
                .map(|l| {
                    format!(
                        "α={}: {} [{}, {}]",
                        l.alpha, l.rejections, l.interval[0], l.interval[1]
                    )
                })
                .collect();
            let _ = write!(
                h,
                "<tr class={}><td>{}</td><td>{}</td><td class=num>{}</td><td class=num>{}</td>\
                 <td>{}</td><td>{}, {}</td><td class=num>{:.1} s</td></tr>",
                if t.passed() { "pass" } else { "fail" },
                escape(&model_name(&t.model)),
                escape(&t.test),
                t.runs,
                t.samples,
                escape(&levels.join("; ")),
                fmt_num(t.uniformity_statistic),
                fmt_num(t.uniformity_p_value),
                t.seconds
            );
            let n = t.p_values.len().max(1) as f64;
            let bins = 20;
            let mut counts = vec![0usize; bins];
            for &p in &t.p_values {
                counts[((p * bins as f64) as usize).min(bins - 1)] += 1;
            }
            let hist: Vec<(f64, f64)> = counts
                .iter()
                .enumerate()
                .flat_map(|(i, &c)| {
                    let y = c as f64 / n * bins as f64;
                    [
                        (i as f64 / bins as f64, y),
                        ((i + 1) as f64 / bins as f64, y),
                    ]
                })
                .collect();
            let mut sorted = t.p_values.clone();
            sorted.sort_by(f64::total_cmp);
            let qq: Vec<(f64, f64)> = sorted
                .iter()
                .enumerate()
                .map(|(i, &p)| ((i as f64 + 0.5) / n, p))
                .collect();
            let title = format!("{} {}", model_name(&t.model), t.test);
            let hist_plot = LinePlot {
                title: format!("{title}: p-value density ({} runs)", t.p_values.len()),
                x_label: "p".into(),
                y_label: "density".into(),
                x_log: false,
                y_log: false,
                series: vec![Series {
                    markers: false,
                    ..Series::new("p-values", hist)
                }],
                h_lines: vec![(1.0, "uniform".into())],
                legend: Corner::UpperRight,
            };
            let qq_plot = LinePlot {
                title: format!("{title}: QQ against U(0, 1)"),
                x_label: "uniform quantile".into(),
                y_label: "p-value".into(),
                x_log: false,
                y_log: false,
                series: vec![
                    Series {
                        line: false,
                        emphasis: false,
                        ..Series::new("sorted p-values", qq)
                    },
                    Series {
                        markers: false,
                        ..Series::new("y = x", vec![(0.0, 0.0), (1.0, 1.0)])
                    },
                ],
                h_lines: Vec::new(),
                legend: Corner::UpperLeft,
            };
            plots.push_str(&img(&line_svg(&hist_plot)?, &hist_plot.title));
            plots.push_str(&img(&line_svg(&qq_plot)?, &qq_plot.title));
        }
        let _ = writeln!(h, "</table><div class=plots>{plots}</div>");
    }
    if let Some(power) = &report.power {
        h.push_str(
            "<h2 id=power>Detectable sampler distortion</h2>\n<table><tr><th>sampler</th>\
                    <th>distortion: seeds caught</th><th>smallest caught at every seed</th></tr>",
        );
        for d in power {
            let mut cells = Vec::new();
            for e in crate::selftest::power::DISTORTIONS {
                let runs: Vec<_> = d.runs.iter().filter(|r| r.distortion == e).collect();
                let caught = runs.iter().filter(|r| !r.killers.is_empty()).count();
                cells.push(format!("{}%: {caught}/{}", e * 100.0, runs.len()));
            }
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&model_name(&d.model)),
                escape(&cells.join(", ")),
                d.smallest
                    .map_or("—".into(), |e| format!("{} %", e * 100.0))
            );
        }
        h.push_str("</table>\n");
    }
    h.push_str("</body></html>\n");
    Ok(h)
}
