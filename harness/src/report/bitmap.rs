//! A heat map's cells as a bitmap image for its SVG (`heat_map::heat_map_svg` embeds it):
//! one pixel per cell where the cells are even, finer pixels where the grid's edges are uneven
//! (the chi-square's rows at the lobe's quantiles).

/// The grid a bitmap draws.
pub struct Cells<'a> {
    /// cos θ-rows.
    pub rows: usize,
    /// φ-columns.
    pub columns: usize,
    /// The row edges z₀ = 0 < … < z_R = 1 (empty: i/R).
    pub z_edges: &'a [f64],
    /// The column edges φ₀ = 0 < … < φ_C = 2π (empty: equal columns).
    pub phi_edges: &'a [f64],
    /// The RGB colour of a cell (row-major, row 0 at the horizon).
    pub colour: &'a dyn Fn(usize) -> [u8; 3],
}

/// Pixel rows of a heat map's bitmap: one per degree of θ (the cos θ-rows are uneven in θ).
const BITMAP_ROWS: usize = 90;

/// The heat map's cells as an uncompressed 24-bit BMP, one column per φ-column and one row per
/// degree of θ (each pixel the colour of the cos θ-row its θ falls in). Hand-written because
/// BMP needs only a 54-byte header and browsers display it: the dependency tree has no PNG
/// encoder, and at 64 × 90 pixels (17 kB) the image is an eighth of the per-cell SVG.
pub fn cells_bitmap(map: &Cells<'_>) -> Vec<u8> {
    // Given edges: finer pixels (0.5° in θ, 2° in φ), each the cell its centre falls in
    // (uneven columns only: equal φ-columns keep one pixel a column). At most 180 × 180 × 3 B
    // = 97 kB, 173 kB once base64 in the SVG and again in report.html (whose images stay
    // under 200 kB: tests/tests/html_report.rs).
    let given_rows = map.z_edges.len() == map.rows + 1;
    let given_columns = map.phi_edges.len() == map.columns + 1 && !equal_columns(map);
    let w = if given_columns { 180 } else { map.columns };
    let h = if given_rows {
        2 * BITMAP_ROWS
    } else {
        BITMAP_ROWS
    };
    let stride = (3 * w).div_ceil(4) * 4;
    let size = 54 + stride * h;
    let mut b = Vec::with_capacity(size);
    b.extend_from_slice(b"BM");
    b.extend_from_slice(&(size as u32).to_le_bytes());
    b.extend_from_slice(&[0; 4]);
    b.extend_from_slice(&54u32.to_le_bytes());
    b.extend_from_slice(&40u32.to_le_bytes());
    b.extend_from_slice(&(w as i32).to_le_bytes());
    b.extend_from_slice(&(h as i32).to_le_bytes()); // positive: rows stored bottom-up
    b.extend_from_slice(&1u16.to_le_bytes());
    b.extend_from_slice(&24u16.to_le_bytes());
    b.extend_from_slice(&[0; 24]); // BI_RGB, no sizes, no palette
    for k in (0..h).rev() {
        let theta = ((k as f64 + 0.5) * 90.0 / h as f64).to_radians();
        let row = if given_rows {
            let z = theta.cos();
            map.z_edges[1..map.rows].partition_point(|&e| e <= z)
        } else {
            ((theta.cos() * map.rows as f64) as usize).min(map.rows - 1)
        };
        let start = b.len();
        for j in 0..w {
            let column = if given_columns {
                let phi = ((j as f64 + 0.5) * 360.0 / w as f64).to_radians();
                map.phi_edges[1..map.columns].partition_point(|&e| e <= phi)
            } else {
                j
            };
            let [r, g, bl] = (map.colour)(row * map.columns + column);
            b.extend_from_slice(&[bl, g, r]);
        }
        b.resize(start + stride, 0);
    }
    b
}

/// Whether the map's φ edges are the equal columns j·2π/columns (to 1e-12 rad).
fn equal_columns(map: &Cells<'_>) -> bool {
    let step = std::f64::consts::TAU / map.columns as f64;
    map.phi_edges
        .iter()
        .enumerate()
        .all(|(j, &e)| (e - j as f64 * step).abs() <= 1e-12)
}
