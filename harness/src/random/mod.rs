//! Randomness for every statistical oracle (chi-square, Kolmogorov–Smirnov, Monte Carlo) and
//! for the audit's per-check seeds: one leaf module, built on `rand_chacha` (ARCHITECTURE.md's choice
//! of the `rand` family).
//!
//! **Generator.** ChaCha with 8 rounds ([`rand_chacha::ChaCha8Rng`]): a counter-based generator,
//! i.e. a keyed bijection of (key, stream, block counter). The key is expanded from the seed by
//! SplitMix64 ([`key_of`]); the 64-bit stream id is the chunk index. So the stream of chunk
//! `c` under seed `s` is the keystream of (key(s), c): streams of distinct chunks, or of
//! distinct seeds, are distinct keystreams of a cipher — independent by construction, not by
//! hoping that two seeded states do not overlap — and any position of a stream can be reached
//! without drawing what precedes it ([`Stream::seek_pair`]).
//!
//! **Uniforms.** The i-th 32-bit word of a stream (ChaCha's words in order, as
//! `rand_chacha`'s `next_u32` gives them) gives the i-th uniform ([`to_unit32`]: the word times
//! 2⁻³², in [0, 1) on the grid k·2⁻³²); the i-th pair `u = [u₀, u₁]` is uniforms 2i and 2i + 1.
//! 32 bits, not 53: the samplers' u needs no finer grid (the smallest u > 0 is
//! 2.3e-10, far below any chi-square cell or KS step at 10⁹ samples), and a sample then costs
//! 8 keystream bytes instead of 16. Generating in blocks ([`Stream::fill_pairs`]) and one at a
//! time ([`Stream::uniform`], [`uniform`]) give the same numbers (a test), so scalar and batch
//! callers see the same samples.
//!
//! **Chunking.** Callers split their samples into fixed chunks (e.g. 2¹⁶ for the chi-square
//! test), one stream per chunk, and reduce per-chunk results in chunk order or by integer
//! sums: results are the same whatever the thread count.
//!
//! **Per-check seeds.** [`derive_seed`] mixes a seed with a label (e.g. a hash of a check's
//! name) through SplitMix64's finalizer, a bijection of 64 bits.

mod keystream;

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

/// One random stream: a ChaCha8 keystream keyed by a seed and numbered by a stream id.
#[derive(Debug, Clone)]
pub struct Stream {
    /// `rand_chacha`'s generator: the scalar draws, the key and stream id of the bulk path of
    /// [`Stream::fill_pairs`], and the position in the stream.
    rng: ChaCha8Rng,
    /// Where the stream is (in ChaCha words) after a bulk fill, until the next draw moves
    /// `rng` there: consecutive bulk fills then never make `rand_chacha` refill its buffer.
    parked: Option<u128>,
    /// The keystream words of the last bulk fill (kept to spare an allocation per fill).
    words: Vec<u32>,
}

/// Whole blocks below which [`Stream::fill_pairs`] leaves the work to `rand_chacha` (moving
/// it back to the stream's position after a bulk fill costs one 4-block refill).
const MIN_BULK_BLOCKS: usize = 16;

impl Stream {
    /// Stream `id` under `seed`, at its start.
    pub fn new(seed: u64, id: u64) -> Self {
        let mut rng = ChaCha8Rng::from_seed(key_of(seed));
        rng.set_stream(id);
        Self {
            rng,
            parked: None,
            words: Vec::new(),
        }
    }

    /// The next uniform in [0, 1) (32 random bits).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        to_unit32(self.generator().next_u32())
    }

    /// The next pair of uniforms.
    #[inline]
    pub fn pair(&mut self) -> [f64; 2] {
        let u0 = self.uniform();
        [u0, self.uniform()]
    }

    /// Fills `out` with the next `out.len()` pairs of uniforms: the same numbers as that many
    /// calls of [`Stream::pair`]. The keystream words go into the stream's own buffer (8
    /// bytes a pair), then each word is converted ([`to_unit32`], written to vectorize) into
    /// `out`. The whole blocks of a large request are computed 16 at once under AVX-512 or 8
    /// at once under AVX2 ([`keystream`]: the same words as `rand_chacha`'s), the words before
    /// the first and after the last block boundary, and everything on a CPU without AVX2, by
    /// `rand_chacha`.
    pub fn fill_pairs(&mut self, out: &mut [[f64; 2]]) {
        let mut words = std::mem::take(&mut self.words);
        words.resize(2 * out.len(), 0);
        self.fill_words(&mut words);
        /// The conversion as a `pulp::WithSimd` operation: under AVX2 or AVX-512 it goes 4 or
        /// 8 lanes wide.
        struct Convert<'a>(&'a [u32], &'a mut [[f64; 2]]);
        impl pulp::WithSimd for Convert<'_> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _simd: S) {
                for (u, w) in self.1.iter_mut().zip(self.0.chunks_exact(2)) {
                    *u = [to_unit32(w[0]), to_unit32(w[1])];
                }
            }
        }
        pulp::Arch::new().dispatch(Convert(&words, out));
        self.words = words;
    }

    /// Moves to pair `index` of the stream (pair i is uniforms 2i and 2i + 1): the next pair
    /// drawn is the one the stream would give after `index` pairs from its start.
    pub fn seek_pair(&mut self, index: u64) {
        // 2 ChaCha words (u32) per pair.
        self.parked = None;
        self.rng.set_word_pos(u128::from(index) * 2);
    }

    /// The next `out.len()` words of the keystream.
    fn fill_words(&mut self, out: &mut [u32]) {
        let position = match self.parked {
            Some(words) => words,
            None => self.rng.get_word_pos(),
        };
        let block_words = keystream::WORDS as u128;
        let head = ((block_words - position % block_words) % block_words) as usize;
        let bulk = out.len().saturating_sub(head) / keystream::WORDS;
        let fast = match keystream::Fast::detect() {
            Some(fast) if bulk >= MIN_BULK_BLOCKS => fast,
            _ => {
                self.fill_words_plain(out);
                return;
            }
        };
        let (first, rest) = out.split_at_mut(head);
        let (middle, last) = rest.split_at_mut(bulk * keystream::WORDS);
        self.fill_words_plain(first);
        let block = ((position + head as u128) / block_words) as u64;
        let (key, id) = (self.rng.get_seed(), self.rng.get_stream());
        // The words as values (x86-64 only, where the fast path exists).
        fast.blocks(&key, id, block, bytemuck::cast_slice_mut(middle));
        self.parked = Some(position + head as u128 + (bulk * keystream::WORDS) as u128);
        self.fill_words_plain(last);
    }

    /// The next `out.len()` words by `rand_chacha` (its bytes, read little-endian as
    /// `next_u32` reads them).
    fn fill_words_plain(&mut self, out: &mut [u32]) {
        if out.is_empty() {
            return;
        }
        self.generator().fill_bytes(bytemuck::cast_slice_mut(out));
        for w in out.iter_mut() {
            *w = u32::from_le(*w);
        }
    }

    /// `rand_chacha`'s generator, first moved to where a bulk fill left the stream.
    fn generator(&mut self) -> &mut ChaCha8Rng {
        if let Some(words) = self.parked.take() {
            self.rng.set_word_pos(words);
        }
        &mut self.rng
    }
}

impl RngCore for Stream {
    fn next_u32(&mut self) -> u32 {
        self.generator().next_u32()
    }

    fn next_u64(&mut self) -> u64 {
        self.generator().next_u64()
    }

    fn fill_bytes(&mut self, dest: &mut [u8]) {
        self.generator().fill_bytes(dest)
    }

    fn try_fill_bytes(&mut self, dest: &mut [u8]) -> Result<(), rand_core::Error> {
        self.generator().try_fill_bytes(dest)
    }
}

/// The random stream of chunk `chunk` under `seed` (see the module documentation).
pub fn stream(seed: u64, chunk: u64) -> Stream {
    Stream::new(seed, chunk)
}

/// A uniform number in [0, 1) with 32 random bits, from the next u32 of `rng` (the stream's
/// [`Stream::uniform`]).
#[inline]
pub fn uniform(rng: &mut impl RngCore) -> f64 {
    to_unit32(rng.next_u32())
}

/// `x` times 2⁻³²: a uniform double in [0, 1) on the grid k·2⁻³² when `x` is uniform. Exact,
/// and written without a u32 → f64 conversion (x86 has no packed unsigned one below AVX-512)
/// so that the loop of [`Stream::fill_pairs`] vectorizes: x in the low mantissa bits of 2⁵²
/// (2⁵² + x exactly), less 2⁵², times 2⁻³² (a power of 2).
#[inline(always)]
pub fn to_unit32(x: u32) -> f64 {
    const TWO_52: u64 = 0x4330_0000_0000_0000;
    (f64::from_bits(TWO_52 | u64::from(x)) - f64::from_bits(TWO_52)) * (1.0 / (1u64 << 32) as f64)
}

/// Every dispatch path of `pulp` this CPU can run — the baseline, and AVX2 + FMA (x86-64-v3)
/// and AVX-512 (x86-64-v4) where it has them — for the tests that ask each path for the same
/// bits.
#[cfg(test)]
pub(crate) fn every_arch() -> Vec<pulp::Arch> {
    let mut paths = vec![pulp::Arch::Scalar];
    #[cfg(target_arch = "x86_64")]
    {
        paths.extend(pulp::x86::V3::try_new().map(pulp::Arch::V3));
        paths.extend(pulp::x86::V4::try_new().map(pulp::Arch::V4));
    }
    paths
}

/// SplitMix64's finalizer (Steele, Lea & Flood 2014): a bijective mix of 64 bits.
#[inline]
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A seed derived from `seed` and a `label` (e.g. a hash of a check's identity): distinct
/// labels give unrelated seeds.
pub fn derive_seed(seed: u64, label: u64) -> u64 {
    splitmix64(seed ^ label)
}

/// The 256-bit ChaCha key of a seed: four successive SplitMix64 outputs from it
/// (the generator's own seeding, state += golden gamma, then the finalizer).
pub fn key_of(seed: u64) -> [u8; 32] {
    let mut key = [0u8; 32];
    let mut state = seed;
    for word in key.chunks_exact_mut(8) {
        word.copy_from_slice(&splitmix64(state).to_le_bytes());
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    }
    key
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_and_scalar_draws_agree_and_seek_reaches_any_pair() {
        let mut scalar = stream(42, 3);
        let expected: Vec<[f64; 2]> = (0..1000).map(|_| scalar.pair()).collect();
        // Blocks of awkward sizes, across ChaCha8's 4-block (256-byte) refills.
        let mut block = stream(42, 3);
        let mut got = vec![[0.0; 2]; 1000];
        let (a, rest) = got.split_at_mut(7);
        block.fill_pairs(a);
        let (b, c) = rest.split_at_mut(300);
        block.fill_pairs(b);
        block.fill_pairs(c);
        assert_eq!(got, expected);
        // Scalar draws continue where the blocks stopped.
        assert_eq!(block.pair(), scalar.pair());
        let mut seek = stream(42, 3);
        seek.seek_pair(123);
        assert_eq!(seek.pair(), expected[123]);
        // `uniform` on the RngCore is the same sequence.
        let mut generic = stream(42, 3);
        assert_eq!(uniform(&mut generic), expected[0][0]);
        assert_eq!(uniform(&mut generic), expected[0][1]);
    }

    #[test]
    fn bulk_fills_continue_any_position_of_the_stream() {
        // Pair-aligned, word-misaligned (one `next_u32` before) and seeked starts, each
        // followed by bulk fills of many blocks and by scalar draws.
        for start in 0..3 {
            let mut scalar = stream(7, 11);
            let mut bulk = stream(7, 11);
            match start {
                1 => {
                    assert_eq!(scalar.next_u32(), bulk.next_u32());
                }
                2 => {
                    scalar.seek_pair(1_000_003);
                    bulk.seek_pair(1_000_003);
                }
                _ => {}
            }
            let want: Vec<[f64; 2]> = (0..5000)
                .map(|_| {
                    let a = scalar.next_u32();
                    [to_unit32(a), to_unit32(scalar.next_u32())]
                })
                .collect();
            let mut got = vec![[0.0; 2]; 5000];
            let (a, b) = got.split_at_mut(1999);
            bulk.fill_pairs(a);
            bulk.fill_pairs(b);
            assert_eq!(got, want, "start {start}");
            assert_eq!(bulk.next_u64(), scalar.next_u64());
            // A seek right after a bulk fill (the stream parked where the fill ended).
            bulk.fill_pairs(&mut got[..256]);
            bulk.seek_pair(17);
            let mut fresh = stream(7, 11);
            fresh.seek_pair(17);
            assert_eq!(bulk.pair(), fresh.pair());
        }
    }

    #[test]
    fn streams_differ_by_seed_and_id_and_are_uniform() {
        let first = |seed, id| stream(seed, id).pair();
        assert_ne!(first(1, 0), first(1, 1));
        assert_ne!(first(1, 0), first(2, 0));
        assert_eq!(first(1, 0), first(1, 0));
        // Mean and variance of 10⁶ uniforms: 1/2 ± 5σ (σ = √(1/12/n)) and 1/12 ± 5σ
        // (σ = √(1/180/n)); the extreme values lie in [0, 1).
        let n = 1_000_000usize;
        let mut pairs = vec![[0.0; 2]; n / 2];
        stream(9, 0).fill_pairs(&mut pairs);
        let values: Vec<f64> = pairs.iter().flatten().copied().collect();
        let mean = values.iter().sum::<f64>() / n as f64;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(
            (mean - 0.5).abs() < 5.0 * (1.0 / 12.0 / n as f64).sqrt(),
            "{mean}"
        );
        assert!(
            (var - 1.0 / 12.0).abs() < 5.0 * (1.0 / 180.0 / n as f64).sqrt(),
            "{var}"
        );
        assert!(values.iter().all(|&v| (0.0..1.0).contains(&v)));
        assert_eq!(to_unit32(u32::MAX), 1.0 - 2f64.powi(-32));
        assert_eq!(to_unit32(0), 0.0);
    }

    #[test]
    fn to_unit32_is_the_word_times_2_to_the_minus_32() {
        let direct = |v: u32| f64::from(v) / 4_294_967_296.0;
        let mut x = 0x0123_4567_89ab_cdefu64;
        let random = (0..1_000_000u64).map(|i| {
            x = splitmix64(x ^ i);
            x as u32
        });
        for v in [0, 1, 2, u32::MAX - 1, u32::MAX, 1 << 31]
            .into_iter()
            .chain(random)
        {
            assert_eq!(to_unit32(v).to_bits(), direct(v).to_bits(), "x = {v:#x}");
        }
    }

    /// The first words of the stream of (seed 0, chunk 0) as uniforms: the record of what
    /// every seeded number of mfh is drawn from (ChaCha8 of the key `key_of(0)`, stream 0,
    /// `rand_chacha`'s words), so that a change of generator or of the conversion fails here
    /// first.
    #[test]
    fn the_first_uniforms_of_a_stream_are_its_first_words_over_2_to_the_32() {
        let mut words = ChaCha8Rng::from_seed(key_of(0));
        words.set_stream(0);
        let mut s = stream(0, 0);
        for _ in 0..8 {
            assert_eq!(s.uniform(), f64::from(words.next_u32()) / 4_294_967_296.0);
        }
    }

    #[test]
    fn derived_seeds_and_keys() {
        assert_ne!(derive_seed(1, 2), derive_seed(1, 3));
        assert_ne!(key_of(1), key_of(2));
        // SplitMix64's published first output from state 0 (after the gamma increment).
        assert_eq!(splitmix64(0), 0xe220_a839_7b1d_cdaf);
    }
}
