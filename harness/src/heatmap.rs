//! Heat maps of a grid of values as PNG images: each cell a square block of pixels, written with
//! the `png` crate (pure Rust: no fonts, no system libraries). The colour scale is not drawn;
//! it is stated in the image's `Description` text chunk (iTXt, UTF-8), and the numbers are in
//! the tables written beside the maps.

use std::io::BufWriter;
use std::path::Path;

/// How values map to colours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scale {
    /// Linear from 0 (dark violet) to `max` (yellow), viridis-like; values ≤ 0 are darkest.
    Sequential {
        /// The value drawn in the brightest colour.
        max: f64,
    },
    /// Linear from −`limit` (blue) through 0 (white) to +`limit` (red), clipped beyond.
    Diverging {
        /// The magnitude drawn in the fullest colour.
        limit: f64,
    },
}

/// A grid of values to draw: `rows` × `columns`, row-major, row 0 drawn at the bottom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatMap<'a> {
    /// Rows of the grid.
    pub rows: usize,
    /// Columns of the grid.
    pub columns: usize,
    /// The values (row-major; NaN drawn grey, ±∞ magenta).
    pub values: &'a [f64],
    /// The colour scale.
    pub scale: Scale,
}

/// Why a heat map could not be written.
#[derive(Debug, thiserror::Error)]
pub enum HeatMapError {
    /// The values do not fill the grid, or the grid is empty.
    #[error("{values} values for a {rows} × {columns} grid")]
    Shape {
        /// Rows.
        rows: usize,
        /// Columns.
        columns: usize,
        /// Values given.
        values: usize,
    },
    /// The file could not be written.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The encoder failed.
    #[error(transparent)]
    Encoding(#[from] png::EncodingError),
}

/// The widest image drawn with ≥ 4 pixels per cell; past it cells get fewer pixels (≥ 1).
pub const MAX_WIDTH: usize = 4096;

/// Pixels per cell side for a grid of `columns` columns: enough for an image ~256 px wide,
/// at least 4 (cells stay visible), fewer only where the image would pass [`MAX_WIDTH`].
pub fn cell_pixels(columns: usize) -> usize {
    let columns = columns.max(1);
    let p = (256 / columns).max(4);
    if columns * p > MAX_WIDTH {
        (MAX_WIDTH / columns).max(1)
    } else {
        p
    }
}

const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];
const BLUE: [f64; 3] = [33.0, 102.0, 172.0];
const WHITE: [f64; 3] = [247.0, 247.0, 247.0];
const RED: [f64; 3] = [178.0, 24.0, 43.0];
const GREY: [u8; 3] = [128, 128, 128];
const MAGENTA: [u8; 3] = [255, 0, 255];

fn mix(a: [f64; 3], b: [f64; 3], t: f64) -> [u8; 3] {
    let c = |i: usize| (a[i] + (b[i] - a[i]) * t).round().clamp(0.0, 255.0) as u8;
    [c(0), c(1), c(2)]
}

/// The colour of one value under a scale.
pub fn colour(value: f64, scale: Scale) -> [u8; 3] {
    if value.is_nan() {
        return GREY;
    }
    if value.is_infinite() {
        return MAGENTA;
    }
    match scale {
        Scale::Sequential { max } => {
            let t = if max > 0.0 {
                (value / max).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let x = t * (VIRIDIS.len() - 1) as f64;
            let i = (x as usize).min(VIRIDIS.len() - 2);
            mix(VIRIDIS[i], VIRIDIS[i + 1], x - i as f64)
        }
        Scale::Diverging { limit } => {
            let t = if limit > 0.0 {
                (value / limit).clamp(-1.0, 1.0)
            } else {
                0.0
            };
            if t < 0.0 {
                mix(WHITE, BLUE, -t)
            } else {
                mix(WHITE, RED, t)
            }
        }
    }
}

/// The image of a heat map: (width, height, RGB bytes, row-major from the top).
pub fn render(map: &HeatMap<'_>) -> Result<(usize, usize, Vec<u8>), HeatMapError> {
    if map.rows == 0 || map.columns == 0 || map.values.len() != map.rows * map.columns {
        return Err(HeatMapError::Shape {
            rows: map.rows,
            columns: map.columns,
            values: map.values.len(),
        });
    }
    let p = cell_pixels(map.columns);
    let (width, height) = (map.columns * p, map.rows * p);
    let mut pixels = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        let row = map.rows - 1 - y / p;
        for x in 0..width {
            let v = map.values[row * map.columns + x / p];
            pixels.extend_from_slice(&colour(v, map.scale));
        }
    }
    Ok((width, height, pixels))
}

/// Writes a heat map as an 8-bit RGB PNG with `description` as its `Description` text chunk.
pub fn write_png(path: &Path, map: &HeatMap<'_>, description: &str) -> Result<(), HeatMapError> {
    let (width, height, pixels) = render(map)?;
    let too_big = || HeatMapError::Shape {
        rows: map.rows,
        columns: map.columns,
        values: map.values.len(),
    };
    let w = u32::try_from(width).map_err(|_| too_big())?;
    let h = u32::try_from(height).map_err(|_| too_big())?;
    let file = std::fs::File::create(path)?;
    let mut encoder = png::Encoder::new(BufWriter::new(file), w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.add_text_chunk("Software".to_string(), "mfh".to_string())?;
    encoder.add_itxt_chunk("Description".to_string(), description.to_string())?;
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&pixels)?;
    writer.finish()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_maps_render_cells_as_blocks_and_write_valid_pngs() {
        let values = [0.0, 1.0, 2.0, f64::NAN, f64::INFINITY, -1.0];
        let map = HeatMap {
            rows: 2,
            columns: 3,
            values: &values,
            scale: Scale::Sequential { max: 2.0 },
        };
        let (w, h, px) = render(&map).unwrap();
        let p = cell_pixels(3);
        assert_eq!((w, h, px.len()), (3 * p, 2 * p, 3 * p * 2 * p * 3));
        // Row 0 is drawn at the bottom: the top-left pixel is value 3 (NaN, grey).
        assert_eq!(&px[0..3], &GREY);
        assert_eq!(
            &px[(w * (h - 1)) * 3..(w * (h - 1)) * 3 + 3],
            &colour(0.0, map.scale)
        );
        assert_eq!(colour(2.0, map.scale), [253, 231, 37]);
        let d = Scale::Diverging { limit: 4.0 };
        assert_eq!(colour(0.0, d), [247, 247, 247]);
        assert_eq!(colour(9.0, d), [178, 24, 43]);
        assert_eq!(colour(-4.0, d), [33, 102, 172]);
        let dir = std::env::temp_dir().join(format!("mfh-heatmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("map.png");
        write_png(&path, &map, "test").unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let reader = decoder.read_info().unwrap();
        assert_eq!(
            (reader.info().width as usize, reader.info().height as usize),
            (w, h)
        );
        let _ = std::fs::remove_dir_all(&dir);
        assert!(matches!(
            render(&HeatMap {
                rows: 2,
                columns: 2,
                values: &values,
                scale: map.scale
            }),
            Err(HeatMapError::Shape { .. })
        ));
        assert_eq!(cell_pixels(64), 4);
        assert_eq!(cell_pixels(32), 8);
        assert_eq!(cell_pixels(2000), 2);
    }
}
