//! Heat maps of the hemisphere's (φ, cos θ) grid as SVG: the cells as an embedded bitmap
//! (`bitmap.rs`), the axes, ticks in fractions of π and the colour bar drawn by `plotters` as in
//! every other plot of the report ([`super::plot`]).

use super::bitmap::{cells_bitmap, Cells};
use super::colour::{colour, ColourScale};
use super::plot::{plot_error, tick_label, PlotError, WIDTH};
use base64::Engine as _;
use plotters::prelude::*;

/// A heat map over the hemisphere's (φ, cos θ) grid: `rows` cos θ-rows (row 0 at the horizon,
/// cos θ ∈ [z_i, z_{i+1}), by default z_i = i/R) × `columns` φ-columns over [0, 2π) (by default
/// equal), row-major. Drawn with φ in radians across and θ in radians down (as every other plot
/// of the report), each cell where its edges put it (rows are uneven in θ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatMap<'a> {
    /// The caption's first line (name the model and the case).
    pub title: &'a str,
    /// The caption's second line: what the map shows.
    pub subtitle: &'a str,
    /// What the colours show (the colour bar's label).
    pub quantity: &'a str,
    /// cos θ-rows.
    pub rows: usize,
    /// φ-columns.
    pub columns: usize,
    /// The values (NaN grey, ±∞ magenta).
    pub values: &'a [f64],
    /// The colour scale.
    pub scale: ColourScale,
    /// The row edges z₀ = 0 < … < z_R = 1 (empty: i/R).
    pub z_edges: &'a [f64],
    /// The column edges φ₀ = 0 < … < φ_2R = 2π (empty: equal columns).
    pub phi_edges: &'a [f64],
}

/// Height of a heat map, pixels.
pub const HEAT_MAP_HEIGHT: u32 = 400;

/// The text size of a heat map's tick labels, pixels: the page shows three maps side by side,
/// each at about two thirds of its drawn width, so 18 px reads as 12 px.
const HEAT_MAP_LABEL_PX: u32 = 18;

/// A multiple of π/8 as a tick label: `0`, `π/8`, `π/4`, `3π/8`, `π/2`, `π`, `3π/2`, `2π`.
pub fn pi_label(v: f64) -> String {
    let eighths = (v / (std::f64::consts::PI / 8.0)).round() as i64;
    if eighths == 0 {
        return "0".into();
    }
    let g = gcd(eighths.unsigned_abs(), 8) as i64;
    let (n, d) = (eighths / g, 8 / g);
    let n = match n {
        1 => String::new(),
        -1 => "−".into(),
        n => n.to_string(),
    };
    if d == 1 {
        format!("{n}π")
    } else {
        format!("{n}π/{d}")
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// A heat map with axes in φ and θ (radians) and a colour bar, as SVG.
pub fn heat_map_svg(map: &HeatMap<'_>) -> Result<String, PlotError> {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let err = plot_error(map.title);
    if map.rows == 0 || map.columns == 0 || map.values.len() != map.rows * map.columns {
        return Err(PlotError {
            title: map.title.to_string(),
            message: format!(
                "{} values for a {} × {} grid",
                map.values.len(),
                map.rows,
                map.columns
            ),
        });
    }
    let mut svg = String::new();
    let cells_image: Option<String>;
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEAT_MAP_HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(&err)?;
        let root = root
            .titled(map.title, ("sans-serif", 16))
            .map_err(&err)?
            .titled(map.subtitle, ("sans-serif", HEAT_MAP_LABEL_PX))
            .map_err(&err)?;
        let (main, bar) = root.split_horizontally(WIDTH - 130);
        // The axes count φ in quarter turns (π/2) and θ in eighths of π, so that plotters'
        // ticks at whole numbers fall on π/2 and π/8 and are labelled as such.
        let (phi_unit, theta_unit) = (FRAC_PI_2, PI / 8.0);
        let mut chart = ChartBuilder::on(&main)
            .margin(8)
            .margin_right(20)
            .x_label_area_size(56)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..TAU / phi_unit, FRAC_PI_2 / theta_unit..0.0)
            .map_err(&err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("φ (radians)")
            .y_desc("θ (radians)")
            .x_labels(5)
            .y_labels(5)
            .x_label_formatter(&|v| pi_label(*v * phi_unit))
            .y_label_formatter(&|v| pi_label(*v * theta_unit))
            .label_style(("sans-serif", HEAT_MAP_LABEL_PX))
            .axis_desc_style(("sans-serif", HEAT_MAP_LABEL_PX))
            .draw()
            .map_err(&err)?;
        // The cells as one embedded bitmap stretched over the plotting area (one `<rect>` per
        // cell made a 32-row map ~250 kB): placed after drawing, under the axes' labels.
        let (x0, y0) = chart.backend_coord(&(0.0, 0.0));
        let (x1, y1) = chart.backend_coord(&(TAU / phi_unit, FRAC_PI_2 / theta_unit));
        cells_image = Some(format!(
            "<image x=\"{x0}\" y=\"{y0}\" width=\"{}\" height=\"{}\" \
             preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" \
             href=\"data:image/bmp;base64,{}\"/>",
            x1 - x0,
            y1 - y0,
            base64::engine::general_purpose::STANDARD.encode(cells_bitmap(&Cells {
                rows: map.rows,
                columns: map.columns,
                z_edges: map.z_edges,
                phi_edges: map.phi_edges,
                colour: &|cell| {
                    let RGBColor(r, g, b) = colour(map.values[cell], map.scale);
                    [r, g, b]
                },
            }))
        ));
        let (lo, hi) = match map.scale {
            ColourScale::Sequential { min, max } => (min, if max > min { max } else { min + 1.0 }),
            ColourScale::Diverging { limit } => {
                let l = if limit > 0.0 { limit } else { 1.0 };
                (-l, l)
            }
        };
        let mut scale_chart = ChartBuilder::on(&bar)
            .margin_top(8)
            .margin_bottom(64)
            .margin_right(8)
            .y_label_area_size(78)
            .caption(map.quantity, ("sans-serif", 15))
            .build_cartesian_2d(0.0..1.0, lo..hi)
            .map_err(&err)?;
        scale_chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(5)
            .y_label_formatter(&|v| tick_label(*v, false))
            .label_style(("sans-serif", HEAT_MAP_LABEL_PX - 2))
            .draw()
            .map_err(&err)?;
        let steps = 64;
        scale_chart
            .draw_series((0..steps).map(|s| {
                let a = lo + (hi - lo) * s as f64 / steps as f64;
                let b = lo + (hi - lo) * (s + 1) as f64 / steps as f64;
                Rectangle::new(
                    [(0.0, a), (1.0, b)],
                    colour(0.5 * (a + b), map.scale).filled(),
                )
            }))
            .map_err(&err)?;
        root.present().map_err(&err)?;
    }
    if let Some(image) = cells_image {
        // After the background: the first element the backend writes is its fill.
        let at = svg
            .find("<rect")
            .and_then(|r| svg[r..].find("/>").map(|e| r + e + 2))
            .unwrap_or(0);
        svg.insert_str(at, &image);
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::plot::plot_svg_has_tick;

    #[test]
    fn heat_maps_are_svg_with_radian_ticks_and_refuse_a_short_grid() {
        let values = [1.0, 2.0, f64::NAN, f64::INFINITY, -3.0, 0.5];
        let map = HeatMap {
            z_edges: &[],
            phi_edges: &[],
            title: "ggx α = 0.3",
            subtitle: "observed density",
            quantity: "density (sr⁻¹)",
            rows: 2,
            columns: 3,
            values: &values,
            scale: ColourScale::Diverging { limit: 4.0 },
        };
        let svg = heat_map_svg(&map).unwrap();
        assert!(svg.contains("θ (radians)") && svg.contains("φ (radians)"));
        for tick in ["π/8", "3π/8", "π/2", "3π/2", "2π"] {
            assert!(plot_svg_has_tick(&svg, tick), "{tick}: {svg}");
        }
        assert_eq!(pi_label(-std::f64::consts::PI), "−π");
        assert_eq!(pi_label(0.0), "0");
        let bad = HeatMap {
            z_edges: &[],
            phi_edges: &[],
            values: &values[..5],
            ..map
        };
        assert!(heat_map_svg(&bad).is_err());
    }
}
