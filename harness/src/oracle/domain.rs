//! The (φ, cos θ) grid over the upper hemisphere: cells ↔ directions, for binning samples and
//! integrating densities cell by cell.
//!
//! The map (φ, z = cos θ) ↦ (√(1 − z²) cos φ, √(1 − z²) sin φ, z) is equal-area: dω = dφ dz, so
//! a density with respect to solid angle is also the density in (φ, z) and every cell of the
//! grid has the same solid angle 2π / (2R · R). The map is regular at the pole (the pole is
//! the edge z = 1 of the rectangle, and D(m)(m·n) is a smooth function of z and φ there), so
//! no pole margin is needed: the top row is binned and integrated like every other row. The
//! horizon z = 0 belongs to the bottom row.

use mfh_reference::geometry::Vec3;
use std::f64::consts::TAU;

/// How far from unit length a sample may be before it is outside the domain.
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// A grid of `2R` φ-columns over [0, 2π) by `R` z-rows over [0, 1] (z = cos θ).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HemisphereGrid {
    resolution: usize,
}

/// Why a direction lies outside the upper hemisphere.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum DomainError {
    /// A component is NaN or infinite.
    #[error("non-finite direction {0:?}")]
    NotFinite(Vec3),
    /// The length differs from 1 by more than [`UNIT_TOLERANCE`].
    #[error("non-unit direction {0:?} (length {1})")]
    NotUnit(Vec3, f64),
    /// m_z < 0.
    #[error("direction below the horizon {0:?}")]
    BelowHorizon(Vec3),
}

/// A cell as a rectangle in (φ, z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// φ range (radians).
    pub phi: [f64; 2],
    /// z = cos θ range.
    pub z: [f64; 2],
}

impl HemisphereGrid {
    /// A grid with `resolution` z-rows and `2 * resolution` φ-columns; `None` if `resolution`
    /// is 0.
    pub fn new(resolution: usize) -> Option<Self> {
        (resolution > 0).then_some(Self { resolution })
    }

    /// The number of z-rows R.
    pub fn rows(&self) -> usize {
        self.resolution
    }

    /// The number of φ-columns 2R.
    pub fn columns(&self) -> usize {
        2 * self.resolution
    }

    /// The number of cells 2R².
    pub fn cells(&self) -> usize {
        self.rows() * self.columns()
    }

    /// The cell index (row-major: `row * columns + column`, row 0 at the horizon) of a unit
    /// direction in the upper hemisphere, or why it is not in the domain.
    #[inline]
    pub fn cell_of(&self, m: Vec3) -> Result<usize, DomainError> {
        if !(m[0].is_finite() && m[1].is_finite() && m[2].is_finite()) {
            return Err(DomainError::NotFinite(m));
        }
        let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        if !((len - 1.0).abs() <= UNIT_TOLERANCE) {
            return Err(DomainError::NotUnit(m, len));
        }
        if m[2] < 0.0 {
            return Err(DomainError::BelowHorizon(m));
        }
        let z = m[2] / len;
        let rows = self.rows();
        let row = ((z * rows as f64) as usize).min(rows - 1);
        let mut phi = m[1].atan2(m[0]);
        if phi < 0.0 {
            phi += TAU;
        }
        let columns = self.columns();
        let column = ((phi / TAU * columns as f64) as usize).min(columns - 1);
        Ok(row * columns + column)
    }

    /// The (φ, z) rectangle of cell `index` (row-major, as [`HemisphereGrid::cell_of`]).
    pub fn cell(&self, index: usize) -> Cell {
        let (row, column) = (index / self.columns(), index % self.columns());
        let dz = 1.0 / self.rows() as f64;
        let dphi = TAU / self.columns() as f64;
        Cell {
            phi: [column as f64 * dphi, (column + 1) as f64 * dphi],
            z: [row as f64 * dz, ((row + 1) as f64 * dz).min(1.0)],
        }
    }

    /// The unit direction at (φ, z = cos θ).
    #[inline]
    pub fn direction(phi: f64, z: f64) -> Vec3 {
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = phi.sin_cos();
        [r * c, r * s, z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_centres_map_back_to_their_cells() {
        let grid = HemisphereGrid::new(7).unwrap();
        assert_eq!(grid.cells(), 98);
        for i in 0..grid.cells() {
            let c = grid.cell(i);
            let m = HemisphereGrid::direction(0.5 * (c.phi[0] + c.phi[1]), 0.5 * (c.z[0] + c.z[1]));
            assert_eq!(grid.cell_of(m), Ok(i));
        }
    }

    #[test]
    fn edges_and_invalid_directions() {
        let grid = HemisphereGrid::new(4).unwrap();
        assert_eq!(grid.cell_of([0.0, 0.0, 1.0]), Ok(3 * 8));
        assert_eq!(grid.cell_of([1.0, 0.0, 0.0]), Ok(0));
        assert_eq!(grid.cell_of([1.0, -1e-300, 0.0]), Ok(7));
        assert!(matches!(
            grid.cell_of([0.0, 0.6, -0.8]),
            Err(DomainError::BelowHorizon(_))
        ));
        assert!(matches!(
            grid.cell_of([f64::NAN, 0.0, 1.0]),
            Err(DomainError::NotFinite(_))
        ));
        assert!(matches!(
            grid.cell_of([0.0, 0.0, 1.1]),
            Err(DomainError::NotUnit(..))
        ));
        assert!(HemisphereGrid::new(0).is_none());
    }
}
