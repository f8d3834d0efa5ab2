//! The observed counts of the chi-square test: samples drawn from the counter-based streams,
//! chunk by chunk, and binned into the cells of a [`HemisphereGrid`] in parallel, with counts
//! independent of the thread count and of how the samples are batched.

use crate::oracle::hemisphere_grid::{CellFinder, DirectionError, HemisphereGrid};
use crate::random::stream;
use mfh_reference::geometry::Vec3;
use rayon::prelude::*;

/// Samples per random stream: the unit of work and of seeding.
pub const CHUNK: u64 = 1 << 16;
/// Samples drawn before they are binned, within a chunk (a throughput detail: the counts
/// do not depend on it).
const BATCH: usize = 256;

/// Observed counts per cell, with the samples that fell outside the upper hemisphere.
#[derive(Debug, Clone, PartialEq)]
pub struct Observed {
    /// Counts per cell (row-major, row 0 at the horizon).
    pub counts: Vec<u64>,
    /// Samples outside the upper hemisphere.
    pub outside: u64,
    /// The first sample outside the upper hemisphere (lowest index) and why.
    pub first_outside: Option<(u64, DirectionError)>,
}

impl Observed {
    fn zero(cells: usize) -> Self {
        Self {
            counts: vec![0; cells],
            outside: 0,
            first_outside: None,
        }
    }

    fn merge(mut self, other: Self) -> Self {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.outside += other.outside;
        self.first_outside = match (self.first_outside, other.first_outside) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
            (a, b) => a.or(b),
        };
        self
    }
}

/// Draws `samples` normals with `sample` and bins them into `grid`, in parallel, with a result
/// independent of the thread count (the scalar form of [`observe_batch`]: the same counts).
pub fn observe<S>(sample: &S, grid: HemisphereGrid, samples: u64, seed: u64) -> Observed
where
    S: Fn([f64; 2]) -> Vec3 + Sync + ?Sized,
{
    observe_batch(
        &|u: &[[f64; 2]], m: &mut [Vec3]| scalar_batch(sample, u, m),
        grid,
        samples,
        seed,
    )
}

/// `m[i] = sample(u[i])`: a scalar sampler as a batch sampler.
#[inline]
pub(super) fn scalar_batch<S>(sample: &S, u: &[[f64; 2]], m: &mut [Vec3])
where
    S: Fn([f64; 2]) -> Vec3 + ?Sized,
{
    for (m, &u) in m.iter_mut().zip(u) {
        *m = sample(u);
    }
}

/// Draws `samples` normals with the batch sampler `sample` (`sample(u, m)` sets `m[i]` to the
/// normal of `u[i]`, e.g. [`NormalSampler::sample_wm_batch`](mfh_reference::NormalSampler::sample_wm_batch)) and bins them into `grid`, in
/// parallel: per chunk of [`CHUNK`] samples, its stream's uniforms in blocks of [`BATCH`]
/// pairs ([`crate::random::Stream::fill_pairs`]) → the batch sampler → the block's cells
/// ([`CellFinder::cells_of`]) → the thread's histogram; the threads' histograms are summed
/// once at the end. Integer counts: the same whatever the thread count, and the same as
/// [`observe`] with the scalar form of the sampler.
pub fn observe_batch<S>(sample: &S, grid: HemisphereGrid, samples: u64, seed: u64) -> Observed
where
    S: Fn(&[[f64; 2]], &mut [Vec3]) + Sync + ?Sized,
{
    observe_blocks(sample, grid, samples, seed, BATCH)
}

/// [`observe_batch`] with blocks of `block` samples (at most [`CHUNK`]): the same counts for
/// any block size (the streams' pairs do not depend on how they are read); a whole chunk per
/// call suits an external model (one round trip per 65 536 samples).
pub fn observe_blocks<S>(
    sample: &S,
    grid: HemisphereGrid,
    samples: u64,
    seed: u64,
    block: usize,
) -> Observed
where
    S: Fn(&[[f64; 2]], &mut [Vec3]) + Sync + ?Sized,
{
    let chunks = samples.div_ceil(CHUNK);
    let finder = CellFinder::new(grid.clone());
    let block = block.clamp(1, CHUNK as usize);
    let deadline = crate::deadline::current();
    (0..chunks)
        .into_par_iter()
        .fold(
            || Observed::zero(grid.cells()),
            |mut acc, chunk| {
                crate::deadline::check(deadline);
                let mut rng = stream(seed, chunk);
                let start = chunk * CHUNK;
                let end = (start + CHUNK).min(samples);
                let mut u = vec![[0.0; 2]; block];
                let mut m = vec![[0.0; 3]; block];
                let mut cells = vec![0usize; block];
                let mut first = start;
                while first < end {
                    let n = (end - first).min(block as u64) as usize;
                    rng.fill_pairs(&mut u[..n]);
                    sample(&u[..n], &mut m[..n]);
                    if finder.cells_of(&m[..n], &mut cells[..n]) {
                        for &cell in &cells[..n] {
                            acc.counts[cell] += 1;
                        }
                    } else {
                        // A direction outside the upper hemisphere in this block (rare): one by one.
                        for (index, &m) in (first..).zip(&m[..n]) {
                            match finder.cell_of(m) {
                                Ok(cell) => acc.counts[cell] += 1,
                                Err(error) => {
                                    acc.outside += 1;
                                    if acc.first_outside.is_none_or(|(i, _)| index < i) {
                                        acc.first_outside = Some((index, error));
                                    }
                                }
                            }
                        }
                    }
                    first += n as u64;
                }
                acc
            },
        )
        .reduce(|| Observed::zero(grid.cells()), Observed::merge)
}
