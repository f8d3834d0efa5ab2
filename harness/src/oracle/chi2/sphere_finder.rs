//! The cells of sampled directions over the whole sphere, for the BSDF chi-square
//! (`oracle::chi2::sphere`): the upper hemisphere's grid for z ≥ 0, the lower hemisphere's,
//! mirrored through the surface, for z < 0, numbered as one list — the upper grid's cells,
//! then the lower grid's, then one cell for the failed samples (`None`).
//!
//! [`SphereFinder::cells_of`] bins a block in one vectorized pass, with no split into
//! hemispheres first (a BSDF's reflection or refraction is a coin toss: a branch per sample
//! that no predictor learns, or a compaction that cost a quarter of the chi-square's time).
//! Both hemispheres' edges are put on one line, so that one table lookup counts them for
//! either:
//!
//! - rows: z ∈ [−1, 1] against the lower grid's interior row edges mirrored (−z_k), the
//!   horizon 0, and the upper grid's interior row edges. A clear count c (z farther than the
//!   margin from every edge) is R_lower − 1 − row for z < 0 (the mirrored z' = −z has row
//!   edges ≥ z' exactly where −z_k ≤ z) and R_lower + row for z ≥ 0;
//! - columns: φ̃ − 2π for z < 0 and φ̃ for z ≥ 0 (φ̃ the azimuth estimate, in [0, 2π]) against
//!   the lower grid's column edges less 2π (the last, 0, dropped) and the upper grid's: a
//!   clear count is 1 + column for z < 0 and 1 + 2R_lower + column for z ≥ 0. The line is
//!   [−2π, 2π], not [0, 4π]: the tables store edges as f32, whose rounding widens the margin
//!   by max |value| · 2⁻²³ (7.5e-7 rad here, as for one hemisphere's table).
//!
//! Counted by [`EdgeTable`]s with the margins of [`CellFinder::cells_of`] ([`ROW_MARGIN`],
//! [`COLUMN_MARGIN`]), a clear count is the count of every value within the margin — of z / |m|,
//! which the grids compare, and of the true azimuth, within the estimate's error bound — so it
//! is the cell [`CellFinder::cell_of`] finds; the rest (not a unit direction, near an edge or the
//! pole) go through it. A grid without given edges (equal-area) counts its edges k/R and
//! 2πj/2R the same way. Either way the cell is a function of the direction alone, whatever the
//! block, the thread or the dispatch path (tested).

use crate::oracle::edge_table::EdgeTable;
use crate::oracle::hemisphere_grid::{
    accepted_squared_lengths, approximate_azimuth, finish_cells, CellFinder, DirectionError,
    HemisphereGrid, COLUMN_MARGIN, FIND_BLOCK, POLE_CLEARANCE, ROW_MARGIN,
};
use mfh_reference::bsdf::Directions;
use mfh_reference::geometry::Vec3;
use std::f64::consts::{PI, TAU};

/// The cell finder of a whole-sphere chi-square (see the module documentation).
#[derive(Debug, Clone)]
pub struct SphereFinder {
    upper: CellFinder,
    lower: CellFinder,
    /// Both hemispheres' row edges on z ∈ [−1, 1].
    rows: EdgeTable,
    /// Both hemispheres' column edges on [−2π, 2π].
    columns: EdgeTable,
    /// The squared lengths the domain accepts (see `CellFinder`).
    squared_length: [f64; 2],
}

impl SphereFinder {
    /// The finder of `upper`'s cells for z ≥ 0 and `lower`'s (mirrored) for z < 0.
    pub fn new(upper: HemisphereGrid, lower: HemisphereGrid) -> Self {
        let (upper_z, lower_z) = (upper.z_edges(), lower.z_edges());
        // Interior edges only (z_0 = 0 and z_R = 1 bound every row alike).
        let row_edges: Vec<f64> = lower_z[1..lower.rows()]
            .iter()
            .rev()
            .map(|&z| -z)
            .chain([0.0])
            .chain(upper_z[1..upper.rows()].iter().copied())
            .collect();
        let (upper_phi, lower_phi) = (upper.phi_edges(), lower.phi_edges());
        let column_edges: Vec<f64> = lower_phi[..lower.columns()]
            .iter()
            .map(|&phi| phi - TAU)
            .chain(upper_phi.iter().copied())
            .collect();
        Self {
            rows: EdgeTable::new(&row_edges, -1.0, 1.0, ROW_MARGIN),
            columns: EdgeTable::new(&column_edges, -TAU, TAU, COLUMN_MARGIN),
            upper: CellFinder::new(upper),
            lower: CellFinder::new(lower),
            squared_length: accepted_squared_lengths(),
        }
    }

    /// The upper hemisphere's finder.
    pub fn upper(&self) -> &CellFinder {
        &self.upper
    }

    /// The lower hemisphere's finder (of mirrored directions).
    pub fn lower(&self) -> &CellFinder {
        &self.lower
    }

    /// The cells of both grids: the upper grid's are 0 … U − 1, the lower's U … U + L − 1.
    pub fn cells(&self) -> usize {
        self.upper.grid().cells() + self.lower.grid().cells()
    }

    /// The cell of the failed samples: U + L.
    pub fn failed_cell(&self) -> usize {
        self.cells()
    }

    /// The cell of a direction: the upper grid's for z ≥ 0, the lower grid's (of (x, y, −z),
    /// after the upper's) for z < 0 or NaN, as [`CellFinder::cell_of`] finds them; or why it
    /// is not a unit direction.
    pub fn cell_of(&self, w: Vec3) -> Result<usize, DirectionError> {
        if w[2] >= 0.0 {
            self.upper.cell_of(w)
        } else {
            let mirrored = [w[0], w[1], -w[2]];
            Ok(self.upper.grid().cells() + self.lower.cell_of(mirrored)?)
        }
    }

    /// The cells of a block of sampled directions: `cells[k]` is [`SphereFinder::cell_of`]
    /// of `w[k]`, or [`SphereFinder::failed_cell`] where it is `None`; returns whether every
    /// direction was a unit direction (if not, the cells of those outside are unspecified:
    /// callers redo the block one by one for the errors). One vectorized pass (see the module
    /// documentation) through `pulp`'s safe runtime dispatch.
    ///
    /// # Panics
    /// If `w` and `cells` differ in length.
    pub fn cells_of(&self, w: &Directions, cells: &mut [usize]) -> bool {
        self.cells_of_on(pulp::Arch::new(), w, cells)
    }

    /// [`SphereFinder::cells_of`] through the instruction set `arch`.
    fn cells_of_on(&self, arch: pulp::Arch, w: &Directions, cells: &mut [usize]) -> bool {
        assert_eq!(
            w.len(),
            cells.len(),
            "cells_of: w and cells differ in length"
        );
        // The pass computes cells in f64 lanes converted through i32-range integers.
        if self.failed_cell() > i32::MAX as usize {
            return self.cells_of_one_by_one(w, cells);
        }
        /// The pass as a `pulp::WithSimd` operation (instantiated per instruction set).
        struct Op<'a> {
            finder: &'a SphereFinder,
            w: &'a Directions,
            cells: &'a mut [usize],
        }
        impl pulp::WithSimd for Op<'_> {
            type Output = bool;
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _simd: S) -> bool {
                self.finder.cells_of_block(self.w, self.cells)
            }
        }
        arch.dispatch(Op {
            finder: self,
            w,
            cells,
        })
    }

    /// The body of [`SphereFinder::cells_of`], inlined into each dispatch target.
    #[inline(always)]
    fn cells_of_block(&self, w: &Directions, cells: &mut [usize]) -> bool {
        let [low, high] = self.squared_length;
        let (rows, columns) = (self.rows.lookup(), self.columns.lookup());
        let (upper, lower) = (self.upper.grid(), self.lower.grid());
        // Cell = base + row · columns + column, per hemisphere, from the counts on the line.
        let (upper_columns, lower_columns) = (upper.columns() as f64, lower.columns() as f64);
        let (lower_rows, lower_base) = (lower.rows() as f64, upper.cells() as f64);
        let failed = self.failed_cell() as f64;
        let mut found = [0.0f64; FIND_BLOCK];
        let mut inside = true;
        let ([x, y, z], sampled) = w.components();
        let blocks = (x.chunks(FIND_BLOCK).zip(y.chunks(FIND_BLOCK)))
            .zip(z.chunks(FIND_BLOCK).zip(sampled.chunks(FIND_BLOCK)));
        for (block, (((x, y), (z, sampled)), cells)) in
            blocks.zip(cells.chunks_mut(FIND_BLOCK)).enumerate()
        {
            let n = x.len();
            let lanes = x.iter().zip(y).zip(z).zip(sampled);
            for ((((&x, &y), &z), &sampled), found) in lanes.zip(&mut found[..n]) {
                // x² + y² + z² summed as in `validate`.
                let planar = x * x + y * y;
                let squared = planar + z * z;
                let valid = (squared >= low) & (squared <= high) & (planar > POLE_CLEARANCE);
                let below = z < 0.0;
                let (row, row_clear) = rows.count(z);
                // φ̃ − 2π below the surface, by the sign bit: exactly 0 or −2π added (a select
                // here was speculated into both tables' lookups: two gathers more a lane).
                // z = −0 is shifted but not `below`: within the margin of the row edge 0, it
                // is never clear.
                let azimuth = approximate_azimuth(x, y) + (PI.copysign(z) - PI);
                let (column, column_clear) = columns.count(azimuth);
                let cell = if below {
                    lower_base + (lower_rows - 1.0 - row) * lower_columns + (column - 1.0)
                } else {
                    (row - lower_rows) * upper_columns + (column - 1.0 - lower_columns)
                };
                let clear = valid & row_clear & column_clear;
                *found = match (sampled, clear) {
                    (false, _) => failed,
                    (true, true) => cell,
                    (true, false) => -1.0,
                };
            }
            let first = block * FIND_BLOCK;
            inside &= finish_cells(&found[..n], cells, |k| {
                w.get(first + k).and_then(|v| self.cell_of(v).ok())
            });
        }
        inside
    }

    /// [`SphereFinder::cells_of`] by [`SphereFinder::cell_of`] alone.
    #[cold]
    fn cells_of_one_by_one(&self, w: &Directions, cells: &mut [usize]) -> bool {
        let mut inside = true;
        for (cell, w) in cells.iter_mut().zip(w.iter()) {
            *cell = match w {
                None => self.failed_cell(),
                Some(v) => self.cell_of(v).unwrap_or_else(|_| {
                    inside = false;
                    0
                }),
            };
        }
        inside
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{every_arch, Stream};

    /// The one-pass finder finds, on every dispatch path, the cell each hemisphere's own
    /// `CellFinder::cell_of` finds, for grids that differ (uneven rows and columns above, with
    /// edges crowded near the pole; equal-area below) and directions at every hard place: the
    /// row edges of both grids and the horizon from both sides (±0 included), the column edges
    /// of both (φ = 0 among them), the poles, failed, non-finite and non-unit directions.
    #[test]
    fn one_pass_finds_what_each_hemisphere_finds_on_every_path() {
        let upper = HemisphereGrid::with_edges(
            vec![0.0, 0.02, 0.3, 0.5, 0.9, 0.999_99, 0.999_995, 1.0],
            Some(
                [
                    0.0, 0.1, 0.11, 1.0, 2.5, 3.0, 3.001, 4.0, 5.5, 6.0, 6.1, 6.2, 6.25, 6.27,
                ]
                .into_iter()
                .chain([TAU])
                .collect(),
            ),
        )
        .unwrap();
        let lower = HemisphereGrid::new(5).unwrap();
        let finder = SphereFinder::new(upper.clone(), lower.clone());
        let (upper_finder, lower_finder) = (CellFinder::new(upper.clone()), CellFinder::new(lower));
        let mut rng = Stream::new(21, 0);
        let mut uniform = || rng.uniform();
        let at = |phi: f64, z: f64| {
            let s = (1.0 - z * z).max(0.0).sqrt();
            [s * phi.cos(), s * phi.sin(), z]
        };
        let mut w: Vec<Option<Vec3>> = (0..20_000)
            .map(|_| Some(at(uniform() * TAU, 2.0 * uniform() - 1.0)))
            .collect();
        let (z_edges, phi_edges) = (
            [upper.z_edges(), finder.lower().grid().z_edges()].concat(),
            [upper.phi_edges(), finder.lower().grid().phi_edges()].concat(),
        );
        for d in [0.0, 1e-15, 1e-9, 1e-6, 2e-6, 2.5e-6, 4e-6, 1e-5] {
            for &z in &z_edges {
                for z in [z + d, z - d, -(z + d), -(z - d)] {
                    w.push(Some(at(uniform() * TAU, z.clamp(-1.0, 1.0))));
                }
            }
            for &phi in &phi_edges {
                for phi in [phi + d, phi - d] {
                    let z = 2.0 * uniform() - 1.0;
                    w.push(Some(at(phi, z)));
                }
            }
        }
        w.extend([None, Some([0.0, 0.0, 1.0]), Some([0.0, 0.0, -1.0])]);
        w.extend([
            Some([1.0, 0.0, 0.0]),
            Some([1.0, 0.0, -0.0]),
            Some([0.6, 0.8, 0.0]),
        ]);
        w.extend([Some([1e-120, 1e-120, -1.0]), Some([f64::NAN, 0.0, 1.0])]);
        w.extend([Some([0.0, 0.0, f64::NAN]), Some([0.7, 0.7, -0.7]), None]);
        let want: Vec<Option<usize>> = w
            .iter()
            .map(|w| match *w {
                None => Some(finder.failed_cell()),
                Some(v) if v[2] >= 0.0 => upper_finder.cell_of(v).ok(),
                Some(v) => lower_finder
                    .cell_of([v[0], v[1], -v[2]])
                    .ok()
                    .map(|c| upper.cells() + c),
            })
            .collect();
        let directions = Directions::from_options(&w);
        for arch in every_arch() {
            let mut cells = vec![usize::MAX; w.len()];
            let inside = finder.cells_of_on(arch, &directions, &mut cells);
            assert!(
                !inside,
                "{arch:?}: the NaN and non-unit directions are outside"
            );
            for (k, (&got, want)) in cells.iter().zip(&want).enumerate() {
                if let Some(want) = *want {
                    assert_eq!(got, want, "{arch:?}: {:?}", w[k]);
                }
            }
            // Without the directions outside, the pass says all were inside.
            let kept: Vec<Option<Vec3>> = w
                .iter()
                .zip(&want)
                .filter(|(_, c)| c.is_some())
                .map(|(w, _)| *w)
                .collect();
            let mut cells = vec![0; kept.len()];
            assert!(finder.cells_of_on(arch, &Directions::from_options(&kept), &mut cells));
        }
        assert_eq!(want.iter().filter(|c| c.is_none()).count(), 3);
        // And the pass decides almost all random directions itself (the exact path is the
        // exception): both counts clear for all but a few of the 20 000.
        let (rows, columns) = (finder.rows.lookup(), finder.columns.lookup());
        let unclear = w[..20_000]
            .iter()
            .flatten()
            .filter(|v| {
                let azimuth = approximate_azimuth(v[0], v[1]) + (PI.copysign(v[2]) - PI);
                !(rows.count(v[2]).1 && columns.count(azimuth).1)
            })
            .count();
        assert!(unclear < 20, "{unclear} of 20 000 not clear");
        // The one-by-one path agrees too.
        let mut cells = vec![0; w.len()];
        assert!(!finder.cells_of_one_by_one(&directions, &mut cells));
        for (&got, want) in cells.iter().zip(&want) {
            if let Some(want) = *want {
                assert_eq!(got, want);
            }
        }
    }
}
