//! The colour scales of the heat maps: viridis for values, a blue–pale–red diverging scale for
//! signed residuals, and the colours of NaN and infinite values.

use plotters::style::RGBColor;

/// How heat-map values map to colours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ColourScale {
    /// Linear from `min` (dark violet) to `max` (yellow), viridis-like.
    Sequential {
        /// The value drawn darkest.
        min: f64,
        /// The value drawn brightest.
        max: f64,
    },
    /// Linear from −`limit` (blue) through 0 (white) to +`limit` (red), clipped beyond.
    Diverging {
        /// The magnitude drawn in the fullest colour.
        limit: f64,
    },
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
const PALE: [f64; 3] = [247.0, 247.0, 247.0];
const RED: [f64; 3] = [178.0, 24.0, 43.0];
/// Cells with no samples and none expected (NaN).
pub const NAN_COLOUR: RGBColor = RGBColor(150, 150, 150);
/// Cells with samples where none are expected (±∞).
pub const INFINITE_COLOUR: RGBColor = RGBColor(255, 0, 255);

fn mix(a: [f64; 3], b: [f64; 3], t: f64) -> RGBColor {
    let c = |i: usize| (a[i] + (b[i] - a[i]) * t).round().clamp(0.0, 255.0) as u8;
    RGBColor(c(0), c(1), c(2))
}

/// The colour of a value under a scale (NaN grey, ±∞ magenta).
pub fn colour(value: f64, scale: ColourScale) -> RGBColor {
    if value.is_nan() {
        return NAN_COLOUR;
    }
    if value.is_infinite() {
        return INFINITE_COLOUR;
    }
    match scale {
        ColourScale::Sequential { min, max } => {
            let t = if max > min {
                ((value - min) / (max - min)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let x = t * (VIRIDIS.len() - 1) as f64;
            let i = (x as usize).min(VIRIDIS.len() - 2);
            mix(VIRIDIS[i], VIRIDIS[i + 1], x - i as f64)
        }
        ColourScale::Diverging { limit } => {
            let t = if limit > 0.0 {
                (value / limit).clamp(-1.0, 1.0)
            } else {
                0.0
            };
            if t < 0.0 {
                mix(PALE, BLUE, -t)
            } else {
                mix(PALE, RED, t)
            }
        }
    }
}
