//! The (φ, cos θ) grid over the upper hemisphere: cells ↔ directions, for binning samples and
//! integrating densities cell by cell.
//!
//! The map (φ, z = cos θ) ↦ (√(1 − z²) cos φ, √(1 − z²) sin φ, z) is equal-area: dω = dφ dz, so
//! a density with respect to solid angle is also the density in (φ, z) and every cell of the
//! grid has the same solid angle 2π / (2R · R). The map is regular at the pole (the pole is
//! the edge z = 1 of the rectangle, and D(m)(m·n) is a smooth function of z and φ there), so
//! no pole margin is needed: the top row is binned and integrated like every other row. The
//! horizon z = 0 belongs to the bottom row.
//!
//! A grid may also have arbitrary row edges 0 = z₀ < z₁ < … < z_R = 1 and column edges 0 = φ₀ <
//! … < φ_2R = 2π ([`HemisphereGrid::with_edges`]: the chi-square's cells at the quantiles of a
//! lobe's marginals, `oracle::chi2::cells`); its cells then differ in solid angle. A direction's
//! row is the number of interior edges z_k ≤ z / |m| (z / |m| as [`validate`] computes it), its
//! column the number of interior edges φ_j ≤ atan2(y, x).

use crate::oracle::edge_table::{EdgeLookup, EdgeTable};
use mfh_reference::geometry::{sin_cos_turns, Vec3};
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

/// How far from unit length a sample may be before it is outside the upper hemisphere.
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// A grid of `2R` φ-columns over [0, 2π) by `R` z-rows over [0, 1] (z = cos θ): equal-area
/// ([`HemisphereGrid::new`]) or with given edges ([`HemisphereGrid::with_edges`]).
#[derive(Debug, Clone, PartialEq)]
pub struct HemisphereGrid {
    resolution: usize,
    /// The row edges z₀ = 0 < … < z_R = 1 (`None`: k/R).
    z_edges: Option<Arc<[f64]>>,
    /// The column edges φ₀ = 0 < … < φ_2R = 2π (`None`: 2πj/2R).
    phi_edges: Option<Arc<[f64]>>,
}

/// Why edges do not make a grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    /// No rows.
    #[error("a grid needs at least one row")]
    NoRows,
    /// The column edges are not 2R + 1 for R + 1 row edges.
    #[error("{columns} column edges for {rows} row edges (2R + 1 for R + 1 are needed)")]
    ColumnCount {
        /// Row edges given.
        rows: usize,
        /// Column edges given.
        columns: usize,
    },
    /// The row edges do not rise strictly from 0 to 1.
    #[error("row edges must rise strictly from 0 to 1: {0:?}")]
    Rows(Vec<f64>),
    /// The column edges do not rise strictly from 0 to 2π by steps below π.
    #[error("column edges must rise strictly from 0 to 2π by steps below π: {0:?}")]
    Columns(Vec<f64>),
}

/// Why a direction lies outside the upper hemisphere.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum DirectionError {
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
        (resolution > 0).then_some(Self {
            resolution,
            z_edges: None,
            phi_edges: None,
        })
    }

    /// A grid with the row edges `z` (0 = z₀ < … < z_R = 1) and the column edges `phi` (0 =
    /// φ₀ < … < φ_2R = 2π, each step below π so that a column's side tests stay exact; `None`:
    /// equal columns), or why they do not make one.
    pub fn with_edges(z: Vec<f64>, phi: Option<Vec<f64>>) -> Result<Self, GridError> {
        let rows = z
            .len()
            .checked_sub(1)
            .filter(|&r| r > 0)
            .ok_or(GridError::NoRows)?;
        let rising =
            |e: &[f64]| e.windows(2).all(|w| w[0] < w[1]) && e.iter().all(|v| v.is_finite());
        if z[0] != 0.0 || z[rows] != 1.0 || !rising(&z) {
            return Err(GridError::Rows(z));
        }
        if let Some(phi) = &phi {
            if phi.len() != 2 * rows + 1 {
                return Err(GridError::ColumnCount {
                    rows: z.len(),
                    columns: phi.len(),
                });
            }
            if phi[0] != 0.0
                || phi[2 * rows] != TAU
                || !rising(phi)
                || phi.windows(2).any(|w| w[1] - w[0] >= PI)
            {
                return Err(GridError::Columns(phi.clone()));
            }
        }
        Ok(Self {
            resolution: rows,
            z_edges: Some(z.into()),
            phi_edges: phi.map(Into::into),
        })
    }

    /// Whether the grid is the equal-area one of [`HemisphereGrid::new`].
    pub fn is_equal_area(&self) -> bool {
        self.z_edges.is_none() && self.phi_edges.is_none()
    }

    /// The row edges z₀ = 0, …, z_R = 1.
    pub fn z_edges(&self) -> Vec<f64> {
        match &self.z_edges {
            Some(z) => z.to_vec(),
            None => (0..=self.rows()).map(|k| self.z_edge(k)).collect(),
        }
    }

    /// The column edges φ₀ = 0, …, φ_2R = 2π.
    pub fn phi_edges(&self) -> Vec<f64> {
        match &self.phi_edges {
            Some(phi) => phi.to_vec(),
            None => (0..=self.columns()).map(|j| self.phi_edge(j)).collect(),
        }
    }

    /// Row edge k (0 ≤ k ≤ R).
    fn z_edge(&self, k: usize) -> f64 {
        match &self.z_edges {
            Some(z) => z[k],
            None => (k as f64 * (1.0 / self.rows() as f64)).min(1.0),
        }
    }

    /// Column edge j (0 ≤ j ≤ 2R).
    fn phi_edge(&self, j: usize) -> f64 {
        match &self.phi_edges {
            Some(phi) => phi[j],
            None => j as f64 * (TAU / self.columns() as f64),
        }
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
    /// direction in the upper hemisphere, or why it is not in the upper hemisphere.
    #[inline]
    pub fn cell_of(&self, m: Vec3) -> Result<usize, DirectionError> {
        let row = self.row_of(m)?;
        let mut phi = m[1].atan2(m[0]);
        if phi < 0.0 {
            phi += TAU;
        }
        let columns = self.columns();
        let column = match &self.phi_edges {
            Some(edges) => edges[1..columns].partition_point(|&e| e <= phi),
            None => ((phi / TAU * columns as f64) as usize).min(columns - 1),
        };
        Ok(row * columns + column)
    }

    /// The z-row of a unit direction in the upper hemisphere, or why it is not in the upper hemisphere.
    #[inline]
    fn row_of(&self, m: Vec3) -> Result<usize, DirectionError> {
        let len = validate(m)?;
        let z = m[2] / len;
        let rows = self.rows();
        if let Some(edges) = &self.z_edges {
            return Ok(edges[1..rows].partition_point(|&e| e <= z));
        }
        // Through i64: the saturating f64 → usize cast costs ~20 instructions, → i64 ~5.
        Ok(((z * rows as f64) as i64 as usize).min(rows - 1))
    }

    /// The (φ, z) rectangle of cell `index` (row-major, as [`HemisphereGrid::cell_of`]).
    pub fn cell(&self, index: usize) -> Cell {
        let (row, column) = (index / self.columns(), index % self.columns());
        Cell {
            phi: [self.phi_edge(column), self.phi_edge(column + 1)],
            z: [self.z_edge(row), self.z_edge(row + 1)],
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

/// The length of `m` if it is a unit direction (within [`UNIT_TOLERANCE`]) in the closed upper
/// hemisphere, else why it is not.
#[inline]
pub fn validate(m: Vec3) -> Result<f64, DirectionError> {
    if !(m[0].is_finite() && m[1].is_finite() && m[2].is_finite()) {
        return Err(DirectionError::NotFinite(m));
    }
    let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    if !((len - 1.0).abs() <= UNIT_TOLERANCE) {
        return Err(DirectionError::NotUnit(m, len));
    }
    if m[2] < 0.0 {
        return Err(DirectionError::BelowHorizon(m));
    }
    Ok(len)
}

/// Bins directions into the cells of a [`HemisphereGrid`] like [`HemisphereGrid::cell_of`],
/// without an `atan2` per direction (the chi-square oracle's hot loop).
///
/// The column comes from an estimate of φ good to 2.5e-7 rad ([`approximate_azimuth`]: a
/// polynomial approximation of atan on [0, 1], folded by octant), corrected by
/// [`CellFinder::cell_of`] with side tests against the column boundaries (which
/// [`CellFinder::cells_of`] skips where the estimate is clear of every edge by 2.5e-6 rad),
/// unit vectors b_j = (cos φ_j, sin φ_j), φ_j = 2πj / 2R, tabulated once (by
/// `sin_cos_turns`, exact at multiples of π/2): the direction is at or past boundary j iff
/// b_j × (m_x, m_y) > 0, or = 0 with b_j · (m_x, m_y) > 0. Each test is exact up to the
/// rounding of b_j (≤ 1 ulp), as `atan2` is up to its own; a direction within ~1e-16 rad of a
/// boundary may fall on either side, in both. The pole (m_x = m_y = 0) is column 0, as with
/// `atan2`.
#[derive(Debug, Clone)]
pub struct CellFinder {
    grid: HemisphereGrid,
    /// b_j for j = 0 … 2R (the last is b_0 again).
    boundaries: Vec<[f64; 2]>,
    /// 2R / 2π.
    columns_per_radian: f64,
    /// The squared lengths |m|² (summed as in [`validate`]) that [`validate`] accepts: the
    /// closed interval `[squared_length[0], squared_length[1]]` (√ is monotone), so the
    /// unit-length check needs no square root.
    squared_length: [f64; 2],
    /// R as f64.
    rows: f64,
    /// How far z·R may be from an integer for ⌊z·R⌋ to be the row of `validate`'s z / |m|
    /// (|z / |m| − z| ≤ 1.000004e-6 within the unit tolerance, times R, plus rounding).
    row_margin: f64,
    /// A grid with given edges: its interior row edges, counted from z within [`ROW_MARGIN`].
    row_table: Option<EdgeTable>,
    /// A grid with given column edges: all of them (0 and 2π included), counted from the
    /// azimuth estimate within [`COLUMN_MARGIN`].
    column_table: Option<EdgeTable>,
}

impl CellFinder {
    /// The finder of `grid`'s cells.
    pub fn new(grid: HemisphereGrid) -> Self {
        let columns = grid.columns();
        let boundaries = (0..=columns)
            .map(|j| {
                let (s, c) = match &grid.phi_edges {
                    // Given edges: their sines and cosines (exact at 0 and 2π by the turns).
                    Some(phi) if j > 0 && j < columns => phi[j].sin_cos(),
                    _ => sin_cos_turns(j as f64 / columns as f64),
                };
                [c, s]
            })
            .collect();
        let rows = grid.rows() as f64;
        let row_table = grid
            .z_edges
            .as_ref()
            .map(|z| EdgeTable::new(&z[1..grid.rows()], 0.0, 1.0, ROW_MARGIN));
        let column_table = grid
            .phi_edges
            .as_ref()
            .map(|phi| EdgeTable::new(phi, 0.0, TAU, COLUMN_MARGIN));
        Self {
            row_table,
            column_table,
            grid,
            boundaries,
            columns_per_radian: columns as f64 / TAU,
            squared_length: accepted_squared_lengths(),
            rows,
            row_margin: rows * 2e-6 + 1e-9,
        }
    }

    /// The grid binned into.
    pub fn grid(&self) -> &HemisphereGrid {
        &self.grid
    }

    /// The cell index of a direction, or why it is not in the upper hemisphere: the same answer as
    /// [`HemisphereGrid::cell_of`] (up to directions within ~1e-16 rad of a column boundary).
    #[inline(always)]
    pub fn cell_of(&self, m: Vec3) -> Result<usize, DirectionError> {
        // The same decisions as `validate` (`squared_length` is its accepted interval of |m|²;
        // a non-finite component makes |m|² NaN or ∞, outside it), without its square root;
        // a rejected direction goes through `validate` for the same error.
        let squared = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
        let [low, high] = self.squared_length;
        if !(squared >= low && squared <= high && m[2] >= 0.0) {
            return Err(self.rejection(m));
        }
        // ⌊z·R⌋ is ⌊(z / |m|)·R⌋ unless z·R is within `row_margin` of an integer: only then is
        // the row taken, as by `HemisphereGrid::row_of`, from z / |m|.
        let t = m[2] * self.rows;
        let floor = t as i64;
        let fraction = t - floor as f64;
        let row = if self.grid.z_edges.is_some() {
            self.grid.row_of(m)?
        } else if fraction > self.row_margin && fraction < 1.0 - self.row_margin {
            (floor as usize).min(self.grid.rows() - 1)
        } else {
            self.grid.row_of(m)?
        };
        Ok(row * self.grid.columns() + self.column(m[0], m[1]))
    }

    /// The cells of a block of directions: `cells[i]` is the cell of `m[i]` as
    /// [`CellFinder::cell_of`] finds it; returns whether every direction was in the upper hemisphere
    /// (if not, the cells of those outside are unspecified: callers redo the block one by
    /// one for the errors).
    ///
    /// One straight-line pass per sub-block of [`FIND_BLOCK`] directions, no branch and no
    /// table, so it vectorizes (8 lanes under AVX-512, 4 under AVX2: it runs through `pulp`'s
    /// safe runtime dispatch, compiled for x86-64-v4 or v3 where the CPU has it): the hemisphere test on |m|², the
    /// row ⌊z·R⌋ and the column ⌊φ̃·2R/2π⌋ of the azimuth estimate φ̃ of
    /// [`approximate_azimuth`], and whether each is *clear*: z·R farther than `row_margin`
    /// from an integer, φ̃·2R/2π farther than [`COLUMN_MARGIN`]·2R/2π (a margin of 2.5e-6 rad,
    /// 10× the estimate's error bound of 2.5e-7 rad, tested) and x² + y² above
    /// [`POLE_CLEARANCE`] (so that the side tests of `cell_of` neither underflow nor tie).
    /// Where both are clear, the exact side tests of [`CellFinder::cell_of`] against the
    /// boundaries b_j, b_{j+1} are decided before they are made — the direction is at least
    /// 2.5e-6 − 2.5e-7 rad inside the column, where |b × (x, y)| ≥ |(x, y)| sin(2.2e-6) dwarfs
    /// the rounding of b_j (≤ 1 ulp, 1.1e-16) — so the answer is `cell_of`'s without making them. The
    /// rest (outside the upper hemisphere, near a row or column edge or the pole: at R = 64 a fraction
    /// ≈ 2·2.5e-6·128/2π ≈ 1e-4 of directions for the columns) goes through
    /// [`CellFinder::cell_of`]. Either way the cell is a function of the direction alone,
    /// whatever the block, the thread or the dispatch path (the test
    /// `cells_of_is_the_same_on_the_dispatched_and_baseline_paths`).
    ///
    /// # Panics
    /// If `m` and `cells` differ in length.
    pub fn cells_of(&self, m: &[Vec3], cells: &mut [usize]) -> bool {
        self.cells_of_on(pulp::Arch::new(), m, cells)
    }

    /// [`CellFinder::cells_of`] through the instruction set `arch` (`pulp::Arch::Scalar`: the
    /// baseline path).
    fn cells_of_on(&self, arch: pulp::Arch, m: &[Vec3], cells: &mut [usize]) -> bool {
        assert_eq!(
            m.len(),
            cells.len(),
            "cells_of: m and cells differ in length"
        );
        // The fast pass computes cell indices in i32: grids of more than 2³¹ − 1 cells (R >
        // 32 767; every caller allocates 2R² counts, so none in practice) take the scalar path.
        if self.grid.cells() > i32::MAX as usize {
            return self.cells_of_one_by_one(m, cells);
        }
        /// The pass as a `pulp::WithSimd` operation (instantiated per instruction set).
        struct Op<'a> {
            finder: &'a CellFinder,
            m: &'a [Vec3],
            cells: &'a mut [usize],
        }
        impl pulp::WithSimd for Op<'_> {
            type Output = bool;
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _simd: S) -> bool {
                if self.finder.grid.is_equal_area() {
                    self.finder.cells_of_block(self.m, self.cells)
                } else {
                    self.finder.cells_of_block_edges(self.m, self.cells)
                }
            }
        }
        arch.dispatch(Op {
            finder: self,
            m,
            cells,
        })
    }

    /// The body of [`CellFinder::cells_of`], inlined into each dispatch target.
    #[inline(always)]
    fn cells_of_block(&self, m: &[Vec3], cells: &mut [usize]) -> bool {
        let [low, high] = self.squared_length;
        let (rows, margin) = (self.rows, self.row_margin);
        let columns = self.grid.columns() as i32;
        let (last_row, last_column) = (self.grid.rows() as i32 - 1, columns - 1);
        let per_radian = self.columns_per_radian;
        let column_margin = COLUMN_MARGIN * per_radian;
        let (mut x, mut y, mut z) = ([0.0; FIND_BLOCK], [0.0; FIND_BLOCK], [0.0; FIND_BLOCK]);
        let mut found = [0.0f64; FIND_BLOCK];
        let mut inside = true;
        let (columns_f, last_row_f, last_column_f) = (
            f64::from(columns),
            f64::from(last_row),
            f64::from(last_column),
        );
        for (m, cells) in m.chunks(FIND_BLOCK).zip(cells.chunks_mut(FIND_BLOCK)) {
            let n = m.len();
            // Components apart (three arrays), so the pass loads whole vectors.
            for (((m, x), y), z) in m.iter().zip(&mut x).zip(&mut y).zip(&mut z) {
                (*x, *y, *z) = (m[0], m[1], m[2]);
            }
            // Zipped slices of one length: no bounds checks, so the loop vectorizes. All in
            // f64 lanes (floor, not a conversion, until the cell): `found` is the cell, an
            // integer below 2³¹ held exactly, or −1 where the direction is not clear.
            for (((&x, &y), &z), found) in
                x[..n].iter().zip(&y[..n]).zip(&z[..n]).zip(&mut found[..n])
            {
                // x² + y² + z² summed as in `validate`.
                let planar = x * x + y * y;
                let squared = planar + z * z;
                let valid = (squared >= low) & (squared <= high) & (z >= 0.0);
                // For a valid direction (0 ≤ t ≤ R(1 + 1e-6)), ⌊t⌋ is `cell_of`'s ⌊t⌋ (through
                // i64); NaN compares false below.
                let t = z * rows;
                let row = t.floor();
                let fraction = t - row;
                let row_clear =
                    (fraction > margin) & (fraction < 1.0 - margin) & (row <= last_row_f);
                let u = approximate_azimuth(x, y) * per_radian;
                let column = u.floor();
                let fraction = u - column;
                let column_clear = (fraction > column_margin)
                    & (fraction < 1.0 - column_margin)
                    & (column >= 0.0)
                    & (column <= last_column_f)
                    & (planar > POLE_CLEARANCE);
                let clear = valid & row_clear & column_clear;
                *found = if clear {
                    row * columns_f + column
                } else {
                    -1.0
                };
            }
            inside &= self.finish_block(m, &found[..n], cells);
        }
        inside
    }

    /// The body of [`CellFinder::cells_of`] for a grid with given edges, inlined into each
    /// dispatch target: the pass of [`CellFinder::cells_of_block`] with the row and column
    /// counted in O(1) by [`EdgeTable`]s (the row from z itself, clear when z is farther than
    /// [`ROW_MARGIN`] from every row edge, so that z / |m| — what [`validate`] and
    /// [`HemisphereGrid::cell_of`] compare — counts the same edges; the column from the azimuth
    /// estimate φ̃, clear when φ̃ is farther than [`COLUMN_MARGIN`] from every column edge, 0
    /// and 2π included, as for the equal-area grid; equal columns are found as there). The
    /// rest goes through [`CellFinder::cell_of`].
    #[inline(always)]
    fn cells_of_block_edges(&self, m: &[Vec3], cells: &mut [usize]) -> bool {
        let Some(rows) = &self.row_table else {
            return self.cells_of_one_by_one(m, cells);
        };
        match &self.column_table {
            Some(columns) => self.cells_of_block_with(m, cells, rows.lookup(), columns.lookup()),
            None => {
                let per_radian = self.columns_per_radian;
                let columns = EqualColumns {
                    per_radian,
                    margin: COLUMN_MARGIN * per_radian,
                    last: self.grid.columns() as f64 - 1.0,
                };
                self.cells_of_block_with(m, cells, rows.lookup(), columns)
            }
        }
    }

    /// [`CellFinder::cells_of_block_edges`] with its column finder.
    #[inline(always)]
    fn cells_of_block_with(
        &self,
        m: &[Vec3],
        cells: &mut [usize],
        rows: EdgeLookup<'_>,
        columns: impl ColumnFinder,
    ) -> bool {
        let [low, high] = self.squared_length;
        let columns_f = self.grid.columns() as f64;
        let (mut x, mut y, mut z) = ([0.0; FIND_BLOCK], [0.0; FIND_BLOCK], [0.0; FIND_BLOCK]);
        let mut found = [0.0f64; FIND_BLOCK];
        let mut inside = true;
        for (m, cells) in m.chunks(FIND_BLOCK).zip(cells.chunks_mut(FIND_BLOCK)) {
            let n = m.len();
            for (((m, x), y), z) in m.iter().zip(&mut x).zip(&mut y).zip(&mut z) {
                (*x, *y, *z) = (m[0], m[1], m[2]);
            }
            for (((&x, &y), &z), found) in
                x[..n].iter().zip(&y[..n]).zip(&z[..n]).zip(&mut found[..n])
            {
                let planar = x * x + y * y;
                let squared = planar + z * z;
                let valid = (squared >= low) & (squared <= high) & (z >= 0.0);
                let (row, row_clear) = rows.count(z);
                let (column, column_clear) = columns.column(approximate_azimuth(x, y));
                let clear = valid & row_clear & column_clear & (planar > POLE_CLEARANCE);
                *found = if clear {
                    row * columns_f + column
                } else {
                    -1.0
                };
            }
            inside &= self.finish_block(m, &found[..n], cells);
        }
        inside
    }

    /// The cells of a block from the fast pass's `found` (see [`finish_cells`]), the unclear
    /// ones found by [`CellFinder::cell_of`].
    #[inline(always)]
    fn finish_block(&self, m: &[Vec3], found: &[f64], cells: &mut [usize]) -> bool {
        finish_cells(found, cells, |k| self.cell_of(m[k]).ok())
    }

    /// [`CellFinder::cells_of`] by [`CellFinder::cell_of`] alone.
    #[cold]
    fn cells_of_one_by_one(&self, m: &[Vec3], cells: &mut [usize]) -> bool {
        let mut inside = true;
        for (cell, &m) in cells.iter_mut().zip(m) {
            *cell = self.cell_of(m).unwrap_or_else(|_| {
                inside = false;
                0
            });
        }
        inside
    }

    /// Whether (x, y) is at or past column boundary j (0 ≤ j ≤ 2R): φ − φ_j ∈ [0, π), on the
    /// boundary counting as past (b_j × (x, y) > 0, or = 0 with b_j · (x, y) > 0).
    #[inline(always)]
    fn past(&self, j: usize, x: f64, y: f64) -> bool {
        let [c, s] = self.boundaries[j];
        let cross = c * y - s * x;
        (cross > 0.0) | ((cross == 0.0) & (c * x + s * y > 0.0))
    }

    /// Why `m`, rejected by the squared-length test, is outside the upper hemisphere.
    #[cold]
    #[inline(never)]
    fn rejection(&self, m: Vec3) -> DirectionError {
        match validate(m) {
            Err(error) => error,
            Ok(len) => unreachable!(
                "{m:?} (length {len}) passes validate but not |m|² ∈ {:?}",
                self.squared_length
            ),
        }
    }

    /// The column of azimuth atan2(y, x) ∈ [0, 2π).
    #[inline(always)]
    fn column(&self, x: f64, y: f64) -> usize {
        if x == 0.0 && y == 0.0 {
            return 0;
        }
        let columns = self.grid.columns();
        let estimate = approximate_azimuth(x, y);
        let mut j = match &self.grid.phi_edges {
            Some(edges) => edges[1..columns].partition_point(|&e| e <= estimate),
            None => ((estimate * self.columns_per_radian) as i64 as usize).min(columns - 1),
        };
        // Whether the direction is at or past boundary j: φ − φ_j ∈ [0, π) (on the boundary
        // counts as past; the antipode of b_j, reachable only when 2R ≤ 2, does not).
        let past = |j: usize| self.past(j, x, y);
        // The first step of the two searches below, without a branch (the estimate is off by
        // a column in a few % of directions, an unpredictable branch): one step down if not
        // past j, else one step up if past j + 1 (`boundaries` has 2R + 1 entries). The
        // searches then go on from there, evaluating the same tests in the same order.
        let down = j > 0 && !past(j);
        let up = !down && j + 1 < columns && past(j + 1);
        j = j - usize::from(down) + usize::from(up);
        while j > 0 && !past(j) {
            j -= 1;
        }
        while j + 1 < columns && past(j + 1) {
            j += 1;
        }
        j
    }
}

/// The cells of a block from a finder's fast pass: `found[k]` is the cell as an exact f64 (an
/// integer in [0, 2³¹)), or −1 where the direction was not clear and `exact(k)` decides it
/// (`None`: outside the upper hemisphere). Returns whether every direction was in the upper hemisphere (if not,
/// the cells of those outside are unspecified).
#[inline(always)]
pub(crate) fn finish_cells(
    found: &[f64],
    cells: &mut [usize],
    mut exact: impl FnMut(usize) -> Option<usize>,
) -> bool {
    // −1 or an integer in [0, 2³¹), converted exactly by adding 1.5·2⁵² (the sum's low
    // mantissa bits are then the integer, two's complement for −1): integer lanes, where
    // Rust's saturating `as` conversion (NaN → 0) is done lane by lane, which made this loop
    // a quarter of the pass under AVX-512. −1 becomes usize::MAX.
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    for (cell, &found) in cells.iter_mut().zip(found) {
        *cell = ((found + MAGIC).to_bits() as i64 - MAGIC.to_bits() as i64) as usize;
    }
    if found.iter().fold(true, |all, &f| all & (f >= 0.0)) {
        return true;
    }
    let mut inside = true;
    for (k, (cell, &found)) in cells.iter_mut().zip(found).enumerate() {
        if found < 0.0 {
            *cell = exact(k).unwrap_or_else(|| {
                inside = false;
                0
            });
        }
    }
    inside
}

/// The column of an azimuth estimate φ̃ and whether it is clear (see
/// [`CellFinder::cells_of_block_edges`]), a trait so that each finder's loop is compiled apart.
trait ColumnFinder: Copy {
    /// (column as f64, clear).
    fn column(&self, u: f64) -> (f64, bool);
}

/// Equal columns: ⌊φ̃·2R/2π⌋, clear farther than the margin (in columns) from both sides.
#[derive(Clone, Copy)]
struct EqualColumns {
    per_radian: f64,
    margin: f64,
    last: f64,
}

impl ColumnFinder for EqualColumns {
    #[inline(always)]
    fn column(&self, u: f64) -> (f64, bool) {
        let t = u * self.per_radian;
        let c = t.floor();
        let fraction = t - c;
        let clear = (fraction > self.margin)
            & (fraction < 1.0 - self.margin)
            & (c >= 0.0)
            & (c <= self.last);
        (c, clear)
    }
}

/// Given column edges, 0 and 2π among them: one less than the edges ≤ φ̃.
impl ColumnFinder for EdgeLookup<'_> {
    #[inline(always)]
    fn column(&self, u: f64) -> (f64, bool) {
        let (count, clear) = self.count(u);
        (count - 1.0, clear)
    }
}

/// The interval `[low, high]` of squared lengths x² + y² + z² whose square root `validate`
/// accepts (|√· − 1| ≤ [`UNIT_TOLERANCE`]), found by bisection over the bit patterns of positive
/// doubles (ordered like their values).
pub(crate) fn accepted_squared_lengths() -> [f64; 2] {
    let accepted = |bits: u64| (f64::from_bits(bits).sqrt() - 1.0).abs() <= UNIT_TOLERANCE;
    // The last accepted pattern in (accepted `a`, rejected `r`) and the first, searching
    // between a rejected `r` below and an accepted `a` above.
    let (mut a, mut r) = (1.0f64.to_bits(), 2.0f64.to_bits());
    while r - a > 1 {
        let mid = a + (r - a) / 2;
        if accepted(mid) {
            a = mid;
        } else {
            r = mid;
        }
    }
    let high = f64::from_bits(a);
    let (mut r, mut a) = (0.5f64.to_bits(), 1.0f64.to_bits());
    while a - r > 1 {
        let mid = r + (a - r) / 2;
        if accepted(mid) {
            a = mid;
        } else {
            r = mid;
        }
    }
    [f64::from_bits(a), high]
}

/// Directions per pass of [`CellFinder::cells_of`] (its temporaries live on the stack).
pub(crate) const FIND_BLOCK: usize = 64;

/// How far (radians) the azimuth estimate of [`CellFinder::cells_of`] must be from a column
/// edge for the column to be taken from it: 10× the estimate's error bound (2.5e-7 rad,
/// `azimuth_estimate_is_within_its_stated_error`), so that the exact side tests of
/// [`CellFinder::cell_of`] would find the same column.
pub(crate) const COLUMN_MARGIN: f64 = 2.5e-6;

/// How far z may be from every row edge of a grid with given edges for the row of z to be the
/// row of z / |m| (|z / |m| − z| ≤ z·1e-6 / (1 − 1e-6) + 3 ulps within the unit tolerance).
pub(crate) const ROW_MARGIN: f64 = 2e-6;

/// The least x² + y² for which [`CellFinder::cells_of`] takes the column from the estimate:
/// nearer the pole (|(x, y)| < 1e-100), the side tests' products c·y − s·x may lose every
/// digit to underflow, and `cell_of` decides.
pub(crate) const POLE_CLEARANCE: f64 = 1e-200;

/// atan2(y, x) in [0, 2π) to within 2.5e-7 rad, (x, y) ≠ (0, 0) (NaN at (0, 0)): atan q on q =
/// min/max ∈ [0, 1] by an odd polynomial of degree 13, q·P(q²) with the seven coefficients of
/// a near-minimax fit to atan on [0, 1] (iteratively reweighted least squares over 40 001
/// points, numpy; |error| ≤ 2.48e-7 measured over 3·10⁶ points, f64 Horner as here), unfolded
/// by octant with selects (no branch, so the loop of [`CellFinder::cells_of`] vectorizes).
/// Only the speed depends on this accuracy (the columns are decided by exact side tests): a
/// direction within [`COLUMN_MARGIN`] of a column edge takes the exact path. Abramowitz &
/// Stegun 4.4.47's five coefficients (1.2e-5 rad) sent 1.9 % of a rough dielectric's
/// transmitted directions there, whose lobe-following columns are a few mrad wide; ten
/// coefficients (9e-10 rad) cost the NDF finder 13 % more time and gained nothing measurable.
#[inline(always)]
pub(crate) fn approximate_azimuth(x: f64, y: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    const A: [f64; 7] = [
        0.999_996_111_470_625_5,
        -0.333_173_677_907_245_17,
        0.198_078_131_040_128_25,
        -0.132_333_324_453_990_32,
        0.079_623_491_071_556_27,
        -0.033_604_058_988_425_396,
        0.006_811_738_437_856_684,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    // min / max, not a select between two quotients (which the compiler turns into a branch
    // to spare a division).
    let q = ax.min(ay) / ax.max(ay);
    let q2 = q * q;
    let mut a = q * A.iter().rev().fold(0.0, |p, &c| c + q2 * p);
    a = if steep { FRAC_PI_2 - a } else { a };
    a = if x < 0.0 { PI - a } else { a };
    if y < 0.0 {
        TAU - a
    } else {
        a
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
    fn cell_finder_agrees_with_atan2_binning() {
        let mut rng = crate::random::Stream::new(7, 0);
        let mut uniform = || rng.uniform();
        for resolution in [1, 2, 3, 7, 64, 1000] {
            let grid = HemisphereGrid::new(resolution).unwrap();
            let finder = CellFinder::new(grid.clone());
            for _ in 0..20_000 {
                let m = HemisphereGrid::direction(uniform() * TAU, uniform());
                assert_eq!(
                    finder.cell_of(m),
                    grid.cell_of(m),
                    "R = {resolution}, {m:?}"
                );
            }
            // Cell centres, the axes, the pole and points just either side of φ = 0.
            for i in 0..grid.cells() {
                let c = grid.cell(i);
                let m =
                    HemisphereGrid::direction(0.5 * (c.phi[0] + c.phi[1]), 0.5 * (c.z[0] + c.z[1]));
                assert_eq!(finder.cell_of(m), Ok(i));
            }
            for m in [
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [-1.0, 0.0, 0.0],
                [-1.0, -0.0, 0.0],
                [0.0, -1.0, 0.0],
                [1.0, -1e-300, 0.0],
                [1.0, 1e-300, 0.0],
                [0.6, -0.8, 0.0],
            ] {
                assert_eq!(
                    finder.cell_of(m),
                    grid.cell_of(m),
                    "R = {resolution}, {m:?}"
                );
            }
            assert!(matches!(
                finder.cell_of([0.0, 0.6, -0.8]),
                Err(DirectionError::BelowHorizon(_))
            ));
        }
    }

    /// The cell of `m` as `CellFinder::cell_of` found it before the square-root-free
    /// validation, the row from z·R and the branch-free first step (validate, row from
    /// z / |m|, then the two searches from the estimate).
    fn previous_cell_of(finder: &CellFinder, m: Vec3) -> Result<usize, DirectionError> {
        let row = finder.grid.row_of(m)?;
        let (x, y) = (m[0], m[1]);
        let columns = finder.grid.columns();
        if x == 0.0 && y == 0.0 {
            return Ok(row * columns);
        }
        let mut j =
            ((previous_azimuth(x, y) * finder.columns_per_radian) as i64 as usize).min(columns - 1);
        let past = |j: usize| {
            let [c, s] = finder.boundaries[j];
            let cross = c * y - s * x;
            cross > 0.0 || (cross == 0.0 && c * x + s * y > 0.0)
        };
        while j > 0 && !past(j) {
            j -= 1;
        }
        while j + 1 < columns && past(j + 1) {
            j += 1;
        }
        Ok(row * columns + j)
    }

    /// The previous column estimate: atan2(y, x) in [0, 2π) to within 0.0015 rad, atan q ≈
    /// πq/4 − q(q − 1)(0.2447 + 0.0663 q) on q = min/max ∈ [0, 1], unfolded by octant.
    fn previous_azimuth(x: f64, y: f64) -> f64 {
        use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        let (ax, ay) = (x.abs(), y.abs());
        let q = ax.min(ay) / ax.max(ay);
        let mut a = FRAC_PI_4 * q - q * (q - 1.0) * (0.2447 + 0.0663 * q);
        if ay > ax {
            a = FRAC_PI_2 - a;
        }
        if x < 0.0 {
            a = PI - a;
        }
        if y < 0.0 {
            a = TAU - a;
        }
        a
    }

    /// The double `steps` doubles above (below, if negative) the finite `v`.
    fn nudge(mut v: f64, steps: i64) -> f64 {
        for _ in 0..steps.unsigned_abs() {
            v = if steps > 0 {
                v.next_up()
            } else {
                v.next_down()
            };
        }
        v
    }

    #[test]
    fn cell_finder_matches_previous_finder_and_atan2_on_adversarial_directions() {
        let mut rng = crate::random::Stream::new(11, 0);
        let mut uniform = || rng.uniform();
        // Debug text: errors carrying NaN compare unequal with ==.
        let same = |a: &Result<usize, DirectionError>, b: &Result<usize, DirectionError>| {
            format!("{a:?}") == format!("{b:?}")
        };
        let mut rejected = 0usize;
        for resolution in [1, 2, 3, 4, 7, 64, 1000, 300_000] {
            let grid = HemisphereGrid::new(resolution).unwrap();
            let finder = CellFinder::new(grid.clone());
            let mut directions: Vec<Vec3> = Vec::new();
            for _ in 0..20_000 {
                directions.push(HemisphereGrid::direction(uniform() * TAU, uniform()));
            }
            // Column boundaries (the tabulated b_j and the atan2 image of j·2π/2R), and the
            // doubles next to them, at several heights.
            let columns = grid.columns();
            for j in 0..=columns.min(4096) {
                let [c, s] = finder.boundaries[j];
                let phi = j as f64 * TAU / columns as f64;
                for z in [0.0f64, 0.3, 1.0 / 3.0, 0.999_999_9] {
                    let r = (1.0 - z * z).sqrt();
                    for (x, y) in [(r * c, r * s), (r * phi.cos(), r * phi.sin())] {
                        for (dx, dy) in [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1), (2, -2)] {
                            directions.push([nudge(x, dx), nudge(y, dy), z]);
                        }
                    }
                }
            }
            // φ near 0 and 2π, the axes, the pole and its neighbourhood, the horizon.
            for tiny in [1e-300, 1e-200, 1e-17, 1e-16, 1e-12, 5e-324] {
                for (x, y) in [(1.0, tiny), (1.0, -tiny), (-1.0, tiny), (-1.0, -tiny)] {
                    directions.push([x, y, 0.0]);
                    directions.push([y, x, 0.0]);
                }
                for (x, y) in [(tiny, 0.0), (0.0, tiny), (-tiny, tiny), (-tiny, -tiny)] {
                    directions.push([x, y, 1.0]);
                }
            }
            for m in [
                [0.0, 0.0, 1.0],
                [-0.0, -0.0, 1.0],
                [1.0, 0.0, -0.0],
                [0.0, -1.0, 0.0],
                [-1.0, -0.0, 0.0],
                [0.6, -0.8, 0.0],
                [0.6, 0.8, -1e-300],
            ] {
                directions.push(m);
            }
            // Row boundaries z = k/R and the doubles next to them.
            for k in 0..=resolution.min(4096) {
                let z0 = k as f64 / resolution as f64;
                for dz in [0, 1, -1, 3, -3] {
                    let z = if z0 == 0.0 {
                        nudge(z0, dz.max(0))
                    } else {
                        nudge(z0, dz)
                    };
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let phi = uniform() * TAU;
                    directions.push([r * phi.cos(), r * phi.sin(), z]);
                }
            }
            // Lengths around the unit tolerance: scaled directions, the scale next to the
            // accepted limits of |m|².
            let [low, high] = finder.squared_length;
            for _ in 0..2000 {
                let m = HemisphereGrid::direction(uniform() * TAU, uniform());
                let limit = if uniform() < 0.5 { low } else { high };
                for scale in [
                    limit.sqrt(),
                    1.0 + (uniform() - 0.5) * 4e-6,
                    1.0 + 1e-6,
                    1.0 - 1e-6,
                ] {
                    for ds in -3..=3 {
                        let s = nudge(scale, ds);
                        directions.push([m[0] * s, m[1] * s, m[2] * s]);
                    }
                }
            }
            for ds in -3..=3 {
                for limit in [low, high] {
                    let z = nudge(limit.sqrt(), ds);
                    directions.push([0.0, 0.0, z]);
                    directions.push([z, 0.0, 0.0]);
                }
            }
            // Outside the upper hemisphere.
            for m in [
                [f64::NAN, 0.0, 1.0],
                [0.0, f64::INFINITY, 0.0],
                [0.0, 0.0, f64::NEG_INFINITY],
                [1e200, 1e200, 1e200],
                [0.0, 0.6, -0.8],
                [0.0, 0.0, 1.1],
                [0.0, 0.0, -1.0 - 1e-7],
                [0.0, 0.0, 0.0],
            ] {
                directions.push(m);
            }
            // The block finder agrees with the one-by-one finder on every direction inside
            // the upper hemisphere, and reports the block as not inside when one is outside.
            let mut cells = vec![usize::MAX; directions.len()];
            let all_inside = finder.cells_of(&directions, &mut cells);
            let mut any_outside = false;
            for (&m, &cell) in directions.iter().zip(&cells) {
                match finder.cell_of(m) {
                    Ok(c) => assert_eq!(cell, c, "R = {resolution}, {m:?}"),
                    Err(_) => any_outside = true,
                }
            }
            assert_eq!(all_inside, !any_outside, "R = {resolution}");
            for m in directions {
                let new = finder.cell_of(m);
                assert!(
                    same(&new, &previous_cell_of(&finder, m)),
                    "R = {resolution}, {m:?}"
                );
                let atan2 = grid.cell_of(m);
                match (new, atan2) {
                    (Ok(a), Ok(b)) => {
                        // Same row; the column within one of atan2's (on a boundary, to
                        // ~1e-16 rad, either side), and equal off the boundaries.
                        assert_eq!(a / columns, b / columns, "R = {resolution}, {m:?}");
                        let (ca, cb) = (a % columns, b % columns);
                        // (At the pole with a signed zero, atan2(−0, −0) = −π: column R, not 0;
                        // within ~1e-300 of the pole, the side tests b_j × (x, y) underflow to
                        // 0 and the finder's column is not atan2's, as before.)
                        let pole = m[0].hypot(m[1]) < 1e-290;
                        assert!(
                            pole || ca == cb
                                || (ca + 1) % columns == cb
                                || (cb + 1) % columns == ca,
                            "R = {resolution}, {m:?}: {ca} vs {cb}"
                        );
                    }
                    (a, b) => {
                        rejected += 1;
                        assert!(same(&a, &b), "R = {resolution}, {m:?}");
                    }
                }
            }
        }
        assert!(rejected > 1000, "{rejected}");
    }

    /// The block finder on the dispatched path (AVX-512 or AVX2 + FMA where the CPU has it) and
    /// on the baseline path (`pulp::Arch::Scalar`, what a CPU without AVX2 runs) finds the cell of
    /// `cell_of` for every direction: random ones, and ones at angular distances around the
    /// column margin (1e-4 rad) and the estimate's error (1.2e-5 rad) from every column edge.
    /// A grid with given edges (rows crowded at the pole as a narrow lobe's quantiles are,
    /// uneven columns): the block finder, its baseline path, the scalar finder and atan2
    /// binning agree on random directions, on and beside every row and column edge (z exactly
    /// on an edge, nudged by ulps, non-unit by the unit tolerance), at the pole, at φ = 0 and
    /// 2π and below the horizon.
    ///
    /// Also with rows crowded closer than the row table's margin (a lobe so narrow that its
    /// quantile rows lie within 1e-6 of the pole and of each other) and with equal columns,
    /// and directions at the table's margins either side of every edge.
    #[test]
    fn a_grid_with_edges_bins_like_atan2_on_every_path() {
        let rows = 16;
        let mut z: Vec<f64> = (0..=rows)
            .map(|k| 1.0 - (1.0 - k as f64 / rows as f64).powi(6))
            .collect();
        z[rows] = 1.0;
        let phi: Vec<f64> = (0..=2 * rows)
            .map(|j| {
                let t = j as f64 / (2 * rows) as f64;
                (TAU * (t + 0.05 * (TAU * t).sin())).clamp(0.0, TAU)
            })
            .collect();
        let mut crowded: Vec<f64> = (0..=rows)
            .map(|k| 1.0 - 4e-7 * ((rows - k) * (rows - k)) as f64)
            .collect();
        crowded[0] = 0.0;
        let equal: Vec<f64> = (0..=2 * rows)
            .map(|j| TAU * j as f64 / (2 * rows) as f64)
            .collect();
        bins_like_atan2_on_every_path(&z, &phi);
        bins_like_atan2_on_every_path(&crowded, &phi);
        bins_like_atan2_on_every_path(&z, &equal);
        bins_like_atan2_on_every_path(&crowded, &equal);
    }

    /// The body of [`a_grid_with_edges_bins_like_atan2_on_every_path`] for one grid.
    fn bins_like_atan2_on_every_path(z: &[f64], phi: &[f64]) {
        let rows = z.len() - 1;
        let grid = HemisphereGrid::with_edges(z.to_vec(), Some(phi.to_vec())).unwrap();
        let finder = CellFinder::new(grid.clone());
        let mut rng = crate::random::Stream::new(17, 0);
        let mut uniform = || rng.uniform();
        let mut directions: Vec<Vec3> = (0..20_000)
            .map(|_| HemisphereGrid::direction(uniform() * TAU, 1.0 - uniform().powi(8)))
            .collect();
        for &ze in z {
            let beside = [1e-7, 1.9e-6, ROW_MARGIN, 2.1e-6, 1e-5, 1e-4];
            let zs = [-2, -1, 0, 1, 2]
                .map(|steps| nudge(ze, steps))
                .into_iter()
                .chain(beside.iter().flat_map(|d| [ze + d, ze - d]));
            for zz in zs.map(|zz| zz.clamp(0.0, 1.0)) {
                for p in [0.3, 2.0, 5.0] {
                    let m = HemisphereGrid::direction(p, zz);
                    directions.push(m);
                    for s in [1.0 + 0.9e-6, 1.0 - 0.9e-6] {
                        directions.push([m[0] * s, m[1] * s, m[2] * s]);
                    }
                }
            }
        }
        for &pe in phi {
            for d in [0.0, 1e-12, 1e-5, 9.9e-5, 1e-4, 1.01e-4] {
                for p in [pe + d, pe - d] {
                    directions.push(HemisphereGrid::direction(p, uniform()));
                }
            }
        }
        directions.extend([
            [0.0, 0.0, 1.0],
            [1e-120, 1e-120, 1.0],
            [1.0, 0.0, 0.0],
            [1.0, -1e-17, 0.0],
            [0.6, 0.0, -0.8],
            [f64::NAN, 0.0, 1.0],
        ]);
        // Near the pole, where crowded rows lie.
        directions.extend(
            (0..5000).map(|_| HemisphereGrid::direction(uniform() * TAU, 1.0 - 1e-4 * uniform())),
        );
        let mut detected = vec![usize::MAX; directions.len()];
        assert!(!finder.cells_of(&directions, &mut detected));
        // Every dispatch path this CPU has (AVX-512, AVX2 + FMA, baseline) finds the same cells.
        for arch in crate::random::every_arch() {
            let mut path = vec![usize::MAX; directions.len()];
            assert!(!finder.cells_of_on(arch, &directions, &mut path));
            for ((&m, &a), &b) in directions.iter().zip(&detected).zip(&path) {
                if finder.cell_of(m).is_ok() {
                    assert_eq!(a, b, "{arch:?}, {m:?}");
                }
            }
        }
        let mut inside = 0;
        for (&m, &a) in directions.iter().zip(&detected) {
            match (finder.cell_of(m), grid.cell_of(m)) {
                (Ok(c), Ok(g)) => {
                    assert_eq!(a, c, "{m:?}");
                    // At the exact pole the finder takes column 0 where atan2(±0, −0) = π, and
                    // within ~1e-16 rad of a column edge either side is right (side tests
                    // against the rounded b_j, atan2 against φ_j): rows always agree.
                    let azimuth = m[1].atan2(m[0]).rem_euclid(TAU);
                    let near_edge = phi.iter().any(|&e| (azimuth - e).abs() < 1e-12);
                    if (m[0] != 0.0 || m[1] != 0.0) && !near_edge {
                        assert_eq!(c, g, "{m:?}");
                    } else {
                        assert_eq!(c / (2 * rows), g / (2 * rows), "{m:?}");
                    }
                    inside += 1;
                }
                (Err(e), Err(f)) => assert_eq!(format!("{e}"), format!("{f}")),
                other => panic!("{m:?}: {other:?}"),
            }
        }
        assert!(inside > 20_000);
        // The cells are where the edges put them.
        let c = grid.cell(3 * 32 + 5);
        assert_eq!((c.z, c.phi), ([z[3], z[4]], [phi[5], phi[6]]));
    }

    #[test]
    fn edges_that_do_not_make_a_grid_are_refused() {
        let phi = |n: usize| {
            (0..=n)
                .map(|j| TAU * j as f64 / n as f64)
                .collect::<Vec<_>>()
        };
        assert_eq!(
            HemisphereGrid::with_edges(vec![0.0], None),
            Err(GridError::NoRows)
        );
        assert!(matches!(
            HemisphereGrid::with_edges(vec![0.0, 0.5, 0.5, 1.0], None),
            Err(GridError::Rows(_))
        ));
        assert!(matches!(
            HemisphereGrid::with_edges(vec![0.0, 0.5, 0.9], None),
            Err(GridError::Rows(_))
        ));
        assert!(matches!(
            HemisphereGrid::with_edges(vec![0.0, 0.5, 1.0], Some(phi(3))),
            Err(GridError::ColumnCount { .. })
        ));
        // Four columns, one of them π wide: its side tests would not be exact.
        assert!(matches!(
            HemisphereGrid::with_edges(
                vec![0.0, 0.5, 1.0],
                Some(vec![0.0, 0.1, 0.2, 0.2 + PI, TAU])
            ),
            Err(GridError::Columns(_))
        ));
        let ok = HemisphereGrid::with_edges(vec![0.0, 0.5, 1.0], Some(phi(4))).unwrap();
        assert!(!ok.is_equal_area() && ok.cells() == 8);
    }

    #[test]
    fn cells_of_is_the_same_on_the_dispatched_and_baseline_paths() {
        let mut rng = crate::random::Stream::new(13, 0);
        let mut uniform = || rng.uniform();
        for resolution in [1, 2, 5, 64, 512] {
            let grid = HemisphereGrid::new(resolution).unwrap();
            let finder = CellFinder::new(grid.clone());
            let mut directions: Vec<Vec3> = (0..50_000)
                .map(|_| HemisphereGrid::direction(uniform() * TAU, uniform()))
                .collect();
            let columns = grid.columns();
            for j in 0..columns {
                let edge = j as f64 * TAU / columns as f64;
                for d in [
                    0.0, 1e-12, 1e-5, 1.2e-5, 2e-5, 8e-5, 9.9e-5, 1e-4, 1.01e-4, 2e-4,
                ] {
                    for phi in [edge + d, edge - d] {
                        directions.push(HemisphereGrid::direction(phi, uniform()));
                    }
                }
            }
            directions.extend([[0.0, 0.0, 1.0], [1e-120, 1e-120, 1.0], [f64::NAN, 0.0, 1.0]]);
            // Every path this CPU has: baseline, AVX2 + FMA, AVX-512.
            for arch in crate::random::every_arch() {
                let mut path = vec![usize::MAX; directions.len()];
                let inside = finder.cells_of_on(arch, &directions, &mut path);
                assert!(!inside, "R = {resolution}");
                for (&m, &a) in directions.iter().zip(&path) {
                    if let Ok(c) = finder.cell_of(m) {
                        assert_eq!(a, c, "R = {resolution}, {arch:?}, {m:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn azimuth_estimate_is_within_its_stated_error() {
        let mut rng = crate::random::Stream::new(5, 0);
        let mut uniform = || rng.uniform();
        let mut worst = 0.0f64;
        let mut directions: Vec<(f64, f64)> = (0..200_000)
            .map(|_| {
                let phi = uniform() * TAU;
                (phi.cos(), phi.sin())
            })
            .collect();
        directions.extend([(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, 1.0)]);
        directions.extend([(-1.0, -1.0), (1.0, -1e-300), (-1.0, 1e-300), (1e-300, 1.0)]);
        for (x, y) in directions {
            let mut exact = y.atan2(x);
            if exact < 0.0 {
                exact += TAU;
            }
            let estimate = approximate_azimuth(x, y);
            // Across φ = 0 the two may sit at opposite ends of [0, 2π).
            let error = (estimate - exact).abs();
            worst = worst.max(error.min(TAU - error));
        }
        assert!(worst <= 2.5e-7, "{worst:e}");
        assert!(approximate_azimuth(0.0, 0.0).is_nan());
    }

    #[test]
    fn edges_and_invalid_directions() {
        let grid = HemisphereGrid::new(4).unwrap();
        assert_eq!(grid.cell_of([0.0, 0.0, 1.0]), Ok(3 * 8));
        assert_eq!(grid.cell_of([1.0, 0.0, 0.0]), Ok(0));
        assert_eq!(grid.cell_of([1.0, -1e-300, 0.0]), Ok(7));
        assert!(matches!(
            grid.cell_of([0.0, 0.6, -0.8]),
            Err(DirectionError::BelowHorizon(_))
        ));
        assert!(matches!(
            grid.cell_of([f64::NAN, 0.0, 1.0]),
            Err(DirectionError::NotFinite(_))
        ));
        assert!(matches!(
            grid.cell_of([0.0, 0.0, 1.1]),
            Err(DirectionError::NotUnit(..))
        ));
        assert!(HemisphereGrid::new(0).is_none());
    }
}
