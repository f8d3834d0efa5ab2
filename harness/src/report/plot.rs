//! Plots as SVG text, drawn with `plotters` (its SVG backend writes text as `<text>` elements,
//! so the viewer draws the glyphs: no fonts and no system libraries are needed here). Generic:
//! line plots with optional log axes (stacked in pairs: a quantity over the relative error
//! below), heat maps of a (φ, θ) grid with a colour bar, and accuracy-versus-time scatter plots
//! with the Pareto frontier highlighted ([`pareto_svg`], which `mfh cost` calls).
//!
//! Log axes are drawn as linear axes over log10 of the data with tick labels `10^k`: one
//! coordinate type for every plot, and non-positive or non-finite values are left out (and
//! counted in the caption) instead of breaking the scale.

pub use super::colour::{colour, ColourScale, INFINITE_COLOUR, NAN_COLOUR};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::fmt::Write as _;

/// Why a plot could not be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cannot draw the plot \"{title}\": {message}")]
pub struct PlotError {
    /// The plot's title.
    pub title: String,
    /// What went wrong (the drawing backend's error).
    pub message: String,
}

/// One curve (or set of points) of a line plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The legend entry.
    pub label: String,
    /// The points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Draw markers at the points (and no line when `line` is false).
    pub markers: bool,
    /// Join the points with a line.
    pub line: bool,
    /// Mark the points with large crosses instead of dots (points that failed, or failed as
    /// expected, drawn over the passing ones).
    pub emphasis: bool,
}

impl Series {
    /// A line with markers.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            markers: true,
            line: true,
            emphasis: false,
        }
    }
}

/// A line plot.
#[derive(Debug, Clone, PartialEq)]
pub struct LinePlot {
    /// The caption.
    pub title: String,
    /// The x axis' label.
    pub x_label: String,
    /// The y axis' label.
    pub y_label: String,
    /// log10 x axis.
    pub x_log: bool,
    /// log10 y axis.
    pub y_log: bool,
    /// The curves.
    pub series: Vec<Series>,
    /// Horizontal reference lines (y, label), e.g. a tolerance.
    pub h_lines: Vec<(f64, String)>,
    /// Where the legend goes (the corner the curves leave free).
    pub legend: Corner,
}

/// Vertical error bars on the points of one series of a [`LinePlot`]: ±`half_widths[k]` about
/// its k-th point (drawn only for a series short enough not to be decimated).
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorBars {
    /// The index of the series in [`LinePlot::series`].
    pub series: usize,
    /// The half-width of each point's bar (non-finite or ≤ 0: no bar).
    pub half_widths: Vec<f64>,
}

/// One panel of [`panels_svg`]: a line plot, error bars on its series, and an x range (the
/// padded range of the points when None).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel<'a> {
    /// The plot.
    pub plot: &'a LinePlot,
    /// Error bars on its series.
    pub bars: &'a [ErrorBars],
    /// The x axis' range.
    pub x_range: Option<(f64, f64)>,
}

/// A corner of a plot, for its legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Corner {
    /// Upper left.
    UpperLeft,
    /// Upper right.
    #[default]
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
}

impl Corner {
    fn position(self) -> SeriesLabelPosition {
        match self {
            Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
            Corner::UpperRight => SeriesLabelPosition::UpperRight,
            Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
            Corner::LowerRight => SeriesLabelPosition::LowerRight,
        }
    }
}

/// Size of one plot, pixels.
pub const WIDTH: u32 = 640;
/// Height of one line plot, pixels.
pub const HEIGHT: u32 = 300;

/// Series colours (colour-blind-safe palette of Okabe and Ito).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

pub(super) fn plot_error<E: std::fmt::Debug>(title: &str) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError {
        title: title.to_string(),
        message: format!("{e:?}"),
    }
}

/// The data coordinate of a value on an axis (log10 on a log axis; None where it cannot be
/// drawn).
fn axis_value(v: f64, log: bool) -> Option<f64> {
    if !v.is_finite() || (log && v <= 0.0) {
        None
    } else if log {
        Some(v.log10())
    } else {
        Some(v)
    }
}

/// A range around the values, padded; a unit range where there are none.
fn padded_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !(lo <= hi) {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else if log {
        0.5
    } else {
        0.5 * lo.abs().max(1e-300)
    };
    (lo - pad, hi + pad)
}

pub(super) fn tick_label(v: f64, log: bool) -> String {
    if log {
        let k = v.round();
        if (v - k).abs() < 1e-9 {
            format!("1e{k}")
        } else {
            format!("{:.1e}", 10f64.powf(v))
        }
    } else if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e4 || v.abs() < 1e-3 {
        format!("{v:.1e}")
    } else {
        format!("{}", (v * 1e4).round() / 1e4)
    }
}

/// The most points a series is drawn with: a 640-pixel-wide plot cannot show more, and every
/// point is a path vertex (or a marker) in the SVG.
pub const MAX_DRAWN_POINTS: usize = 320;

/// At most [`MAX_DRAWN_POINTS`] of a series' points, evenly by index, the first and the last
/// kept, and the point of largest y of each stride (so that a spike, e.g. the largest error,
/// is never decimated away).
pub fn decimate(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    if points.len() <= MAX_DRAWN_POINTS {
        return points.to_vec();
    }
    let stride = points.len().div_ceil(MAX_DRAWN_POINTS - 1);
    let mut out: Vec<(f64, f64)> = points
        .chunks(stride)
        .map(|c| {
            *c.iter()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .expect("chunks are non-empty")
        })
        .collect();
    if out.first() != points.first() {
        out.insert(0, points[0]);
    }
    if out.last() != points.last() {
        out.push(points[points.len() - 1]);
    }
    out
}

/// The bars' segments in axis coordinates: (x, y_low, y_high) per bar, clipped on a log axis
/// to the smallest positive value of the plot.
fn bar_segments(plot: &LinePlot, bars: &[ErrorBars]) -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    for b in bars {
        let Some(s) = plot.series.get(b.series) else {
            continue;
        };
        if s.points.len() > MAX_DRAWN_POINTS {
            continue;
        }
        for (&(x, y), &e) in s.points.iter().zip(&b.half_widths) {
            if !(e.is_finite() && e > 0.0) {
                continue;
            }
            let low = if plot.y_log && y - e <= 0.0 {
                y * 1e-3
            } else {
                y - e
            };
            if let (Some(x), Some(lo), Some(hi)) = (
                axis_value(x, plot.x_log),
                axis_value(low, plot.y_log),
                axis_value(y + e, plot.y_log),
            ) {
                out.push((x, lo, hi));
            }
        }
    }
    out
}

/// Draws a line plot into an area.
fn draw_lines(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    plot: &LinePlot,
    bars: &[ErrorBars],
    x_range: Option<(f64, f64)>,
) -> Result<(), PlotError> {
    let err = plot_error(&plot.title);
    let segments = bar_segments(plot, bars);
    let mut dropped = 0usize;
    let series: Vec<Vec<(f64, f64)>> = plot
        .series
        .iter()
        .map(|s| {
            decimate(&s.points)
                .into_iter()
                .filter_map(|(x, y)| {
                    let p = axis_value(x, plot.x_log).zip(axis_value(y, plot.y_log));
                    if p.is_none() {
                        dropped += 1;
                    }
                    p
                })
                .collect()
        })
        .collect();
    let h_lines: Vec<(f64, &str)> = plot
        .h_lines
        .iter()
        .filter_map(|(y, l)| axis_value(*y, plot.y_log).map(|y| (y, l.as_str())))
        .collect();
    let x_range = x_range
        .and_then(|(a, b)| axis_value(a, plot.x_log).zip(axis_value(b, plot.x_log)))
        .filter(|(a, b)| a < b)
        .unwrap_or_else(|| padded_range(series.iter().flatten().map(|p| p.0), plot.x_log));
    let y_range = padded_range(
        series
            .iter()
            .flatten()
            .map(|p| p.1)
            .chain(h_lines.iter().map(|h| h.0))
            .chain(segments.iter().flat_map(|b| [b.1, b.2])),
        plot.y_log,
    );
    let caption = if dropped > 0 {
        format!(
            "{} ({dropped} point(s) ≤ 0 or not finite left out)",
            plot.title
        )
    } else {
        plot.title.clone()
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(&err)?;
    let (x_log, y_log) = (plot.x_log, plot.y_log);
    chart
        .configure_mesh()
        .x_desc(plot.x_label.as_str())
        .y_desc(plot.y_label.as_str())
        .x_label_formatter(&|v| tick_label(*v, x_log))
        .y_label_formatter(&|v| tick_label(*v, y_log))
        .light_line_style(RGBColor(235, 235, 235))
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(&err)?;
    for (i, (s, points)) in plot.series.iter().zip(&series).enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        if s.line {
            chart
                .draw_series(LineSeries::new(points.iter().copied(), style))
                .map_err(&err)?
                .label(s.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
        }
        if s.markers && s.emphasis {
            let style = ShapeStyle::from(&colour).stroke_width(2);
            let anno = chart
                .draw_series(points.iter().map(|&p| Cross::new(p, 6, style)))
                .map_err(&err)?;
            if !s.line {
                anno.label(s.label.as_str())
                    .legend(move |(x, y)| Cross::new((x + 9, y), 6, style));
            }
        } else if s.markers {
            let anno = chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(&err)?;
            if !s.line {
                anno.label(s.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 9, y), 3, colour.filled()));
            }
        }
    }
    for b in bars {
        let colour = PALETTE[b.series % PALETTE.len()];
        let style = ShapeStyle::from(&colour).stroke_width(1);
        let cap = 0.006 * (x_range.1 - x_range.0);
        let mine = bar_segments(plot, std::slice::from_ref(b));
        chart
            .draw_series(mine.iter().flat_map(|&(x, lo, hi)| {
                [
                    PathElement::new(vec![(x, lo), (x, hi)], style),
                    PathElement::new(vec![(x - cap, lo), (x + cap, lo)], style),
                    PathElement::new(vec![(x - cap, hi), (x + cap, hi)], style),
                ]
            }))
            .map_err(&err)?;
    }
    for (y, label) in &h_lines {
        let style = ShapeStyle::from(&RGBColor(200, 0, 0)).stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x_range.0, *y), (x_range.1, *y)],
                6,
                4,
                style,
            ))
            .map_err(&err)?
            .label(*label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
    }
    if !plot.series.is_empty() || !h_lines.is_empty() {
        chart
            .configure_series_labels()
            .position(plot.legend.position())
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(&err)?;
    }
    Ok(())
}

/// A line plot as SVG.
pub fn line_svg(plot: &LinePlot) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error(&plot.title))?;
        draw_lines(&root, plot, &[], None)?;
        root.present().map_err(plot_error(&plot.title))?;
    }
    Ok(svg)
}

/// Two line plots stacked in one SVG (e.g. Λ against the oracle above, the relative error on a
/// log axis below).
pub fn stacked_svg(top: &LinePlot, bottom: &LinePlot) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 2 * HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error(&top.title))?;
        let (a, b) = root.split_vertically(HEIGHT);
        draw_lines(&a, top, &[], None)?;
        draw_lines(&b, bottom, &[], None)?;
        root.present().map_err(plot_error(&top.title))?;
    }
    Ok(svg)
}

/// Line plots with error bars, stacked in one SVG, each `height` pixels high (e.g. a BSDF's
/// albedo against incidence from outside above, from inside below).
pub fn panels_svg(panels: &[Panel<'_>], height: u32) -> Result<String, PlotError> {
    let title = panels.first().map_or("", |p| p.plot.title.as_str());
    let mut svg = String::new();
    {
        let n = panels.len().max(1) as u32;
        let root = SVGBackend::with_string(&mut svg, (WIDTH, n * height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error(title))?;
        for (area, p) in root
            .split_evenly((panels.len().max(1), 1))
            .iter()
            .zip(panels)
        {
            draw_lines(area, p.plot, p.bars, p.x_range)?;
        }
        root.present().map_err(plot_error(title))?;
    }
    Ok(svg)
}

/// The indices of the Pareto frontier of (time, error) points ([`crate::cost::frontier`]).
pub fn pareto_frontier(points: &[(f64, f64)]) -> Vec<usize> {
    crate::cost::frontier::pareto_frontier(points)
}

/// Accuracy against time: every route a point (time per evaluation on x, max error on y, both
/// log10), labelled with its route; the Pareto frontier (no route both faster and more
/// accurate) joined and drawn in red. Always returns an SVG: if drawing fails, one that says
/// why. Errors of exactly 0 are drawn at the smallest positive error (or 1e-17) and marked "=0".
pub fn pareto_svg(title: &str, points: &[(String, f64, f64)]) -> String {
    match try_pareto(title, points) {
        Ok(svg) => svg,
        Err(e) => {
            let mut svg = String::new();
            let _ = write!(
                svg,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"40\">\
                 <text x=\"8\" y=\"24\" font-family=\"sans-serif\" font-size=\"13\">{}</text></svg>",
                super::page::escape(&e.to_string())
            );
            svg
        }
    }
}

fn try_pareto(title: &str, points: &[(String, f64, f64)]) -> Result<String, PlotError> {
    let err = plot_error(title);
    let floor = points
        .iter()
        .map(|p| p.2)
        .filter(|e| *e > 0.0 && e.is_finite())
        .fold(f64::INFINITY, f64::min);
    let floor = if floor.is_finite() { floor } else { 1e-17 };
    let shown: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.1, if p.2 == 0.0 { floor } else { p.2 }))
        .collect();
    let front = pareto_frontier(&shown);
    let logged: Vec<Option<(f64, f64)>> = shown
        .iter()
        .map(|&(t, e)| axis_value(t, true).zip(axis_value(e, true)))
        .collect();
    let x_range = padded_range(logged.iter().flatten().map(|p| p.0), true);
    let y_range = padded_range(logged.iter().flatten().map(|p| p.1), true);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 380)).into_drawing_area();
        root.fill(&WHITE).map_err(&err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 15))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
            .map_err(&err)?;
        chart
            .configure_mesh()
            .x_desc("seconds per evaluation")
            .y_desc("max error")
            .x_label_formatter(&|v| tick_label(*v, true))
            .y_label_formatter(&|v| tick_label(*v, true))
            .light_line_style(RGBColor(235, 235, 235))
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(&err)?;
        let red = RGBColor(200, 0, 0);
        let front_points: Vec<(f64, f64)> = front.iter().filter_map(|&i| logged[i]).collect();
        chart
            .draw_series(LineSeries::new(
                front_points.iter().copied(),
                ShapeStyle::from(&red).stroke_width(2),
            ))
            .map_err(&err)?
            .label("Pareto frontier")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], red));
        for (i, p) in logged.iter().enumerate() {
            let Some(p) = *p else { continue };
            let on = front.contains(&i);
            let c = if on { red } else { RGBColor(90, 90, 90) };
            let mut label = points[i].0.clone();
            if points[i].2 == 0.0 {
                label.push_str(" (=0)");
            }
            chart
                .draw_series([EmptyElement::at(p)
                    + Circle::new((0, 0), 4, c.filled())
                    + Text::new(label, (6, -12), ("sans-serif", 11).into_font().color(&c))])
                .map_err(&err)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .draw()
            .map_err(&err)?;
        root.present().map_err(&err)?;
    }
    Ok(svg)
}

#[cfg(test)]
/// Whether an SVG has a text line `tick` (plotters writes a label's text on its own line).
pub(crate) fn plot_svg_has_tick(svg: &str, tick: &str) -> bool {
    svg.lines().any(|l| l.trim() == tick)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_are_svg_with_their_titles_and_every_point() {
        let svg = pareto_svg(
            "STD Λ",
            &[
                ("stable".into(), 1e-7, 1e-15),
                ("2f1".into(), 1e-6, 1e-13),
                ("table1".into(), 5e-8, 0.0),
            ],
        );
        assert!(svg.starts_with("<svg") && svg.contains("STD Λ"), "{svg}");
        for route in ["stable", "2f1", "table1 (=0)", "Pareto frontier"] {
            assert!(svg.contains(route), "{route}");
        }
        let plot = LinePlot {
            title: "Λ".into(),
            x_label: "θ".into(),
            y_label: "relative error".into(),
            x_log: false,
            y_log: true,
            series: vec![Series::new(
                "route a",
                vec![(0.1, 1e-16), (0.5, 0.0), (1.0, 1e-12)],
            )],
            h_lines: vec![(1e-10, "tolerance".into())],
            legend: Corner::UpperLeft,
        };
        let svg = line_svg(&plot).unwrap();
        assert!(
            svg.contains("1 point(s) ≤ 0 or not finite left out"),
            "{svg}"
        );
        assert!(svg.contains("route a") && svg.contains("tolerance"));
    }

    #[test]
    fn error_bars_widen_the_range_and_are_drawn_per_point() {
        let plot = LinePlot {
            title: "albedo from outside".into(),
            x_label: "θi".into(),
            y_label: "albedo".into(),
            x_log: false,
            y_log: false,
            series: vec![Series::new("mean weight", vec![(0.0, 0.5), (60.0, 0.4)])],
            h_lines: vec![],
            legend: Corner::UpperRight,
        };
        let bars = [ErrorBars {
            series: 0,
            half_widths: vec![0.3, f64::NAN],
        }];
        // One bar (the NaN half-width has none), from 0.2 to 0.8.
        assert_eq!(bar_segments(&plot, &bars), vec![(0.0, 0.2, 0.8)]);
        let panel = |bars| Panel {
            plot: &plot,
            bars,
            x_range: Some((0.0, 90.0)),
        };
        let with = panels_svg(&[panel(&bars), panel(&[])], 400).unwrap();
        let without = panels_svg(&[panel(&[]), panel(&[])], 400).unwrap();
        assert!(with.starts_with("<svg") && with.contains("height=\"800\""));
        // A bar is three thin paths in its series' colour (the bar and its caps); the x axis
        // reaches 90 (its range).
        let bar_paths = |svg: &str| svg.matches("stroke=\"#0072B2\" stroke-width=\"1\"").count();
        assert_eq!((bar_paths(&with), bar_paths(&without)), (3, 0), "{with}");
        assert!(plot_svg_has_tick(&with, "90"), "{with}");
        assert!(!plot_svg_has_tick(&line_svg(&plot).unwrap(), "90"));
    }

    #[test]
    fn colours_follow_their_scales() {
        let s = ColourScale::Sequential { min: 0.0, max: 2.0 };
        assert_eq!(colour(0.0, s), RGBColor(68, 1, 84));
        assert_eq!(colour(2.0, s), RGBColor(253, 231, 37));
        assert_eq!(colour(5.0, s), RGBColor(253, 231, 37));
        let d = ColourScale::Diverging { limit: 4.0 };
        assert_eq!(colour(0.0, d), RGBColor(247, 247, 247));
        assert_eq!(colour(-4.0, d), RGBColor(33, 102, 172));
        assert_eq!(colour(9.0, d), RGBColor(178, 24, 43));
        assert_eq!(colour(f64::NAN, d), NAN_COLOUR);
        assert_eq!(colour(f64::NEG_INFINITY, d), INFINITE_COLOUR);
    }
}
