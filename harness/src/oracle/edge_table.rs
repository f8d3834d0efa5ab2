//! How many of a rising list of edges lie at or below a value, in O(1) and without a branch:
//! the row (cos θ) and column (φ) search of the chi-square's cell finder on a grid whose cells
//! follow the lobe (`oracle::chi2::cells`), where the edges are uneven and counting them one by
//! one (64 rows, 128 columns) cost more than the sampler.
//!
//! The value's range is cut into K buckets of equal width (K a power of two, chosen from the
//! edges' spacing). A bucket stores the edge `split` that lies within the margin m of it (at
//! most one, or none: +∞) and the number of edges `below` that edge (or below the whole
//! bucket). For a value v in the bucket the count is `below + [v ≥ split]`, and it is *clear* —
//! the count of any v' with |v' − v| ≤ m — when |v − split| > m: every other edge is farther
//! than m from the bucket, so v and v' compare alike with it. A bucket within the margin of two
//! or more edges stores NaN and is never clear. Callers decide the unclear values exactly (the
//! finder's `cell_of`); they are the values within m of an edge, and those in a bucket crowded
//! by edges closer than its width (a lobe so narrow that its quantile rows crowd within ~1e-5
//! of the pole), so counts never depend on the table, only the speed does.
//!
//! [`EdgeTable::count`] is two table reads and a few selects, written so the finder's loop
//! vectorizes (gathers under AVX2 and AVX-512); every IEEE operation in it is exact or
//! correctly rounded, so the same bits on every dispatch path.

/// The most buckets a table gets (2¹⁶: 1 MiB of tables; narrower spacing leaves crowded
/// buckets to the exact path).
const MAX_BUCKETS: usize = 1 << 16;
/// The fewest buckets per edge (so that a bucket seldom holds an edge at all).
const BUCKETS_PER_EDGE: usize = 8;

/// A table for counting `edges` ≤ v over [lo, hi] (see the module documentation).
#[derive(Debug, Clone)]
pub(crate) struct EdgeTable {
    /// The value range's start.
    lo: f64,
    /// Buckets per unit of value: K / (hi − lo).
    scale: f64,
    /// K − 1 as f64 (the last bucket).
    last: f64,
    /// Per bucket, packed into one word so that a lookup is one load (one gather in the
    /// finder's vector loop): the high 32 bits the split edge rounded to f32 (+∞ without an
    /// edge, NaN within the margin of two), the low 32 bits the edges below it (or below the
    /// bucket). Always [`MAX_BUCKETS`] long, the first K used: a lookup's index masked to
    /// the array's length is then provably in bounds, so the finder's loop gathers without a
    /// bounds test per lane (which `get` made a select it did not vectorize: 1.7 ns a lookup).
    /// The unused tail is never written, so its pages are never touched.
    buckets: Box<[u64; MAX_BUCKETS]>,
    /// The margin widened by the f32 rounding of the split: a value farther than this from
    /// the rounded split is farther than the margin from the edge, on the same side.
    margin: f64,
}

/// An [`EdgeTable`] borrowed for a loop: plain values and a slice, so that the compiler keeps
/// them in registers (through the `Option` of the table it reloaded the buckets' address in
/// every lane).
#[derive(Debug, Clone, Copy)]
pub(crate) struct EdgeLookup<'a> {
    lo: f64,
    scale: f64,
    last: f64,
    buckets: &'a [u64; MAX_BUCKETS],
    margin: f64,
}

impl EdgeTable {
    /// The table of the rising `edges` for values in [lo, hi] within `margin` of the value
    /// whose count is wanted.
    pub(crate) fn new(edges: &[f64], lo: f64, hi: f64, margin: f64) -> Self {
        let width = hi - lo;
        // The narrowest gap between edges, less both margins: buckets narrower than it hold
        // the margins of at most one edge.
        let gap = edges
            .windows(2)
            .map(|w| w[1] - w[0] - 2.0 * margin)
            .fold(f64::INFINITY, f64::min);
        let wanted = if gap > 0.0 {
            (2.0 * width / gap).ceil().min(MAX_BUCKETS as f64) as usize
        } else {
            MAX_BUCKETS
        };
        let k = wanted
            .max(BUCKETS_PER_EDGE * edges.len())
            .clamp(1, MAX_BUCKETS)
            .next_power_of_two();
        let scale = k as f64 / width;
        // A bucket's extent in value, widened by the margin and a rounding slack (the bucket
        // of v is ⌊(v − lo)·scale⌋, computed with roundings).
        let slack = margin + 4.0 * f64::EPSILON * (lo.abs() + hi.abs());
        let pack = |below: usize, split: f32| (u64::from(split.to_bits()) << 32) | below as u64;
        let mut buckets: Box<[u64; MAX_BUCKETS]> = vec![0; MAX_BUCKETS]
            .into_boxed_slice()
            .try_into()
            .expect("a slice of MAX_BUCKETS");
        let packed = (0..k).map(|b| {
            let start = lo + b as f64 / scale;
            let end = lo + (b + 1) as f64 / scale;
            let first = edges.partition_point(|&e| e < start - slack);
            let past = edges.partition_point(|&e| e < end + slack);
            match past - first {
                0 => pack(first, f32::INFINITY),
                1 => pack(first, edges[first] as f32),
                _ => pack(0, f32::NAN),
            }
        });
        for (bucket, word) in buckets.iter_mut().zip(packed) {
            *bucket = word;
        }
        // |split − split as f32| ≤ 2⁻²⁴·|split| ≤ 2⁻²⁴·max(|lo|, |hi|) (edges lie in [lo, hi]).
        let rounding = lo.abs().max(hi.abs()) * f64::from(f32::EPSILON);
        Self {
            lo,
            scale,
            last: (k - 1) as f64,
            buckets,
            margin: margin + rounding,
        }
    }

    /// The table as plain values for a loop.
    pub(crate) fn lookup(&self) -> EdgeLookup<'_> {
        EdgeLookup {
            lo: self.lo,
            scale: self.scale,
            last: self.last,
            buckets: &self.buckets,
            margin: self.margin,
        }
    }

    /// The number of buckets K (for the tests).
    #[cfg(test)]
    pub(crate) fn buckets(&self) -> usize {
        (self.last + 1.0) as usize
    }
}

impl EdgeLookup<'_> {
    /// The number of edges ≤ v, and whether it is the number of edges ≤ v' for every v' within
    /// the margin of v (false for NaN). Branch-free, to vectorize inside the caller's loop.
    #[inline(always)]
    pub(crate) fn count(&self, v: f64) -> (f64, bool) {
        // The bucket, clamped into the table (a NaN v gives bucket 0 and, below, not clear).
        let b = ((v - self.lo) * self.scale).floor().max(0.0).min(self.last);
        // b is an integer in [0, 2¹⁶): adding 2⁵² + 2⁵¹ puts it in the low mantissa bits
        // (a packed operation where the saturating `as` conversion goes lane by lane).
        const MAGIC: f64 = 6_755_399_441_055_744.0;
        let index = ((b + MAGIC).to_bits() & 0xffff_ffff) as usize;
        // index ≤ K − 1 < MAX_BUCKETS already; the mask only shows it to the compiler.
        let word = self.buckets[index & (MAX_BUCKETS - 1)];
        // The low half exactly as a double (2⁵² + below, less 2⁵²); the high half's f32.
        const TWO_52: u64 = 0x4330_0000_0000_0000;
        let below = f64::from_bits(TWO_52 | (word & 0xffff_ffff)) - f64::from_bits(TWO_52);
        let split = f64::from(f32::from_bits((word >> 32) as u32));
        let count = below + if v >= split { 1.0 } else { 0.0 };
        let clear = (v - split).abs() > self.margin;
        (count, clear)
    }
}

#[cfg(test)]
mod tests {
    use super::EdgeTable;

    /// On random values, on and beside every edge, at the range's ends and beyond, and with
    /// edges crowded closer than the margin: a clear count is the count of every value within
    /// the margin, and most values away from edges are clear.
    #[test]
    fn clear_counts_are_exact_within_the_margin() {
        let crowded: Vec<f64> = (1..40)
            .map(|k| 1.0 - 1e-7 * (40 - k) as f64)
            .chain([0.25, 0.5])
            .collect();
        let mut crowded_sorted = crowded.clone();
        crowded_sorted.sort_by(f64::total_cmp);
        let cases: Vec<(Vec<f64>, f64, f64, f64)> = vec![
            (
                (1..64)
                    .map(|k| 1.0 - (1.0 - k as f64 / 64.0).powi(6))
                    .collect(),
                0.0,
                1.0,
                2e-6,
            ),
            (crowded_sorted, 0.0, 1.0, 2e-6),
            (
                (0..=128)
                    .map(|j| std::f64::consts::TAU * j as f64 / 128.0)
                    .collect(),
                0.0,
                std::f64::consts::TAU,
                1e-4,
            ),
            (vec![], 0.0, 1.0, 2e-6),
        ];
        for (edges, lo, hi, margin) in cases {
            let owned = EdgeTable::new(&edges, lo, hi, margin);
            let table = owned.lookup();
            assert!(owned.buckets().is_power_of_two());
            let exact = |v: f64| edges.partition_point(|&e| e <= v) as f64;
            let mut values: Vec<f64> = (0..=100_000)
                .map(|i| lo + (hi - lo) * i as f64 / 100_000.0)
                .collect();
            for &e in &edges {
                for d in [0.0, 1e-16, 1e-12, 0.5 * margin, margin, 1.01 * margin, 1e-3] {
                    values.extend([e + d, e - d, e.next_up(), e.next_down()]);
                }
            }
            values.extend([lo - 1.0, hi + 1e-6, hi, hi.next_up(), f64::NAN]);
            let mut clear_away = (0, 0);
            for v in values {
                let (count, clear) = table.count(v);
                if v.is_nan() {
                    assert!(!clear);
                    continue;
                }
                let away = edges.iter().all(|&e| (e - v).abs() > 1.5 * margin);
                if away {
                    clear_away.1 += 1;
                    clear_away.0 += usize::from(clear);
                }
                if clear {
                    for w in [v, v + margin, v - margin, v + 0.999 * margin] {
                        assert_eq!(count, exact(w), "v = {v:e}, w = {w:e}, {edges:?}");
                    }
                }
            }
            assert!(
                clear_away.0 as f64 >= 0.99 * clear_away.1 as f64,
                "{clear_away:?}"
            );
        }
    }
}
