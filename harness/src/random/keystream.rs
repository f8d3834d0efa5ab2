//! ChaCha8 keystream blocks computed 16 at once under AVX-512 and 8 at once under AVX2: the
//! bulk path of [`super::Stream::fill_pairs`].
//!
//! **Why by hand.** `rand_chacha` (ppv-lite86) computes 4 blocks per refill with at most AVX2
//! and was 41 % of `mfh chi2`'s time (GGX, 1 thread, perf, AVX-512 machine); RustCrypto's
//! `chacha20` has an AVX-512 backend only for its cipher, behind a `--cfg` flag, and not for
//! its RNG. Here the same function — the ChaCha block function of Bernstein (2008) with 8
//! rounds, in `rand_chacha`'s layout: constants, the 8 key words, a 64-bit block counter in
//! words 12–13, the 64-bit stream id in words 14–15 — is computed for consecutive blocks at
//! once, one block per 32-bit lane of the vector registers (16 lanes under AVX-512, 8 under
//! AVX2): the rounds — under AVX-512 straight-line loops over `[u32; 16]` that the compiler
//! vectorizes (`vprold`), under AVX2 intrinsics (`vpshufb` for the rotations by 16 and 8, a
//! shift pair for 12 and 7) — then the transposition of words into blocks by shuffles, all
//! through `pulp`'s safe wrappers of the intrinsics (no `unsafe`).
//!
//! A pair of uniforms now takes 8 bytes (two 32-bit words): 1.2 ns a pair with the
//! conversion to doubles on an AMD EPYC Zen 4 (AVX-512, `chi2_stages/uniforms`, load ~4).
//! Before, per pair of 53-bit uniforms (16 bytes), against `rand_chacha`: 1.2 ns against 4.7 on an AMD EPYC
//! Zen 5 (AVX-512, keystream alone); 4.1 ns against 5.8 on an AMD EPYC Zen 3 (AVX2, with the
//! conversion to doubles: the `chi2_stages/uniforms` benchmark). The words are those of
//! `rand_chacha` bit for bit (the test `blocks_are_rand_chacha_s`, on every path the CPU has),
//! so every seeded number of mfh is unchanged. The transpositions are intrinsics, not element-wise loops: those compiled to
//! gathers and scatters (4.4 ns a pair under AVX2 on Zen 5, no faster than `rand_chacha`).
//! Without AVX2 [`Fast::detect`] says no and `rand_chacha` does the work.

/// Words per block.
pub(super) const WORDS: usize = 16;

/// The vectorized keystream, on a CPU that has AVX-512 (x86-64-v4) or AVX2 (x86-64-v3):
/// `pulp`'s proof of it.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy)]
pub(super) enum Fast {
    /// 16 blocks at once.
    Avx512(pulp::x86::V4),
    /// 8 blocks at once.
    Avx2(pulp::x86::V3),
}

/// The vectorized keystream: none off x86-64.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Debug, Clone, Copy)]
pub(super) enum Fast {}

impl Fast {
    /// The fast keystream if this CPU has AVX-512 or AVX2 (detected once per process:
    /// `fill_pairs` asks per block of uniforms).
    pub(super) fn detect() -> Option<Fast> {
        #[cfg(target_arch = "x86_64")]
        {
            static DETECTED: std::sync::OnceLock<Option<Fast>> = std::sync::OnceLock::new();
            *DETECTED.get_or_init(|| {
                pulp::x86::V4::try_new()
                    .map(Fast::Avx512)
                    .or_else(|| pulp::x86::V3::try_new().map(Fast::Avx2))
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
        }
    }

    /// Every path this CPU can run (the tests compare each with `rand_chacha`).
    #[cfg(test)]
    fn available() -> Vec<Fast> {
        #[cfg(target_arch = "x86_64")]
        {
            let mut paths: Vec<Fast> = pulp::x86::V4::try_new()
                .map(Fast::Avx512)
                .into_iter()
                .collect();
            paths.extend(pulp::x86::V3::try_new().map(Fast::Avx2));
            paths
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Vec::new()
        }
    }

    /// Writes blocks `counter`, `counter + 1`, … of the keystream of (`key`, `stream`) into
    /// `out`, one block of 16 words (as stored little-endian bytes) per element; `key` is the
    /// 32-byte ChaCha key as `rand_chacha` takes it (words little-endian).
    pub(super) fn blocks(
        self,
        key: &[u8; 32],
        stream: u64,
        counter: u64,
        out: &mut [[u32; WORDS]],
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            let key = std::array::from_fn(|i| {
                u32::from_le_bytes([key[4 * i], key[4 * i + 1], key[4 * i + 2], key[4 * i + 3]])
            });
            let key = &key;
            match self {
                Fast::Avx512(simd) => dispatch(simd, Keyed { simd, key, stream }, counter, out),
                Fast::Avx2(simd) => dispatch(simd, Keyed { simd, key, stream }, counter, out),
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (key, stream, counter, out);
            match self {}
        }
    }
}

/// "expand 32-byte k".
const CONSTANTS: [u32; 4] = [0x6170_7865, 0x3320_646e, 0x7962_2d32, 0x6b20_6574];
/// ChaCha8: 4 double rounds.
const DOUBLE_ROUNDS: usize = 4;

/// The input words of blocks `counter` … `counter + L − 1`, block j in lane j.
#[inline(always)]
fn initial<const L: usize>(key: &[u32; 8], stream: u64, counter: u64) -> [[u32; L]; WORDS] {
    let mut x = [[0u32; L]; WORDS];
    for (w, c) in CONSTANTS.iter().enumerate() {
        x[w] = [*c; L];
    }
    for (w, k) in key.iter().enumerate() {
        x[4 + w] = [*k; L];
    }
    let block = |j: usize| counter.wrapping_add(j as u64);
    x[12] = std::array::from_fn(|j| block(j) as u32);
    x[13] = std::array::from_fn(|j| (block(j) >> 32) as u32);
    x[14] = [stream as u32; L];
    x[15] = [(stream >> 32) as u32; L];
    x
}

/// A state the ChaCha quarter round applies to (the words of every lane): a trait, so that the
/// double round's schedule below is written once for every instruction set.
trait QuarterRound {
    /// The quarter round on words a, b, c, d.
    fn quarter_round(&mut self, words: [usize; 4]);
}

/// ChaCha8's 4 double rounds: columns, then diagonals (straight-line calls with constant
/// words: a loop over a table of words kept the AVX2 state in memory, 9.1 against 4.1 ns a
/// pair).
#[inline(always)]
fn rounds(x: &mut impl QuarterRound) {
    for _ in 0..DOUBLE_ROUNDS {
        x.quarter_round([0, 4, 8, 12]);
        x.quarter_round([1, 5, 9, 13]);
        x.quarter_round([2, 6, 10, 14]);
        x.quarter_round([3, 7, 11, 15]);
        x.quarter_round([0, 5, 10, 15]);
        x.quarter_round([1, 6, 11, 12]);
        x.quarter_round([2, 7, 8, 13]);
        x.quarter_round([3, 4, 9, 14]);
    }
}

/// Words as lanes of plain arrays, a loop the compiler vectorizes (`vprold` under AVX-512;
/// under AVX2 it kept the 8-lane form scalar, hence `avx2`'s intrinsics).
impl<const L: usize> QuarterRound for [[u32; L]; WORDS] {
    #[inline(always)]
    fn quarter_round(&mut self, [a, b, c, d]: [usize; 4]) {
        let (mut xa, mut xb, mut xc, mut xd) = (self[a], self[b], self[c], self[d]);
        for j in 0..L {
            xa[j] = xa[j].wrapping_add(xb[j]);
            xd[j] = (xd[j] ^ xa[j]).rotate_left(16);
            xc[j] = xc[j].wrapping_add(xd[j]);
            xb[j] = (xb[j] ^ xc[j]).rotate_left(12);
            xa[j] = xa[j].wrapping_add(xb[j]);
            xd[j] = (xd[j] ^ xa[j]).rotate_left(8);
            xc[j] = xc[j].wrapping_add(xd[j]);
            xb[j] = (xb[j] ^ xc[j]).rotate_left(7);
        }
        (self[a], self[b], self[c], self[d]) = (xa, xb, xc, xd);
    }
}

/// A group of consecutive blocks computed at once (a trait, not a closure: a closure does not
/// inherit the target features of the function it is written in, so its intrinsics would be
/// calls).
trait Group {
    /// Blocks per group.
    const LANES: usize;
    /// Blocks `counter` … `counter + LANES − 1` into `out[..LANES]`.
    fn group(&self, counter: u64, out: &mut [[u32; WORDS]]);
}

/// Blocks `counter`, `counter + 1`, … into `out` in groups of `G::LANES` ≤ 16 (whole groups
/// in place, the remainder through a buffer).
#[inline(always)]
fn in_groups<G: Group>(g: &G, counter: u64, out: &mut [[u32; WORDS]]) {
    let mut chunks = out.chunks_exact_mut(G::LANES);
    let mut next = counter;
    for chunk in &mut chunks {
        g.group(next, chunk);
        next = next.wrapping_add(G::LANES as u64);
    }
    let rest = chunks.into_remainder();
    if !rest.is_empty() {
        let mut buffer = [[0u32; WORDS]; 16];
        g.group(next, &mut buffer[..G::LANES]);
        let n = rest.len();
        rest.copy_from_slice(&buffer[..n]);
    }
}

/// The keystream of (`key`, `stream`) computed with the instruction set `simd` proves (its
/// [`Group`] is in the module of that instruction set).
#[cfg(target_arch = "x86_64")]
struct Keyed<'a, S> {
    simd: S,
    key: &'a [u32; 8],
    stream: u64,
}

/// Runs `in_groups` of `G` compiled for the instruction set `simd` proves (`G::group`
/// inlined into it).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn dispatch<S: pulp::Simd, G: Group>(simd: S, g: G, counter: u64, out: &mut [[u32; WORDS]]) {
    /// The loop as a `pulp::WithSimd` operation.
    struct Op<'a, G> {
        g: G,
        counter: u64,
        out: &'a mut [[u32; WORDS]],
    }
    impl<G: Group> pulp::WithSimd for Op<'_, G> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _: S) {
            in_groups(&self.g, self.counter, self.out);
        }
    }
    simd.vectorize(Op { g, counter, out });
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::{initial, rounds, Group, Keyed, WORDS};
    use core::arch::x86_64::__m512i;
    use pulp::x86::V4;

    /// Blocks per group: one per 32-bit lane of a 512-bit register.
    const LANES: usize = 16;

    /// 16 blocks at once.
    impl Group for Keyed<'_, V4> {
        const LANES: usize = LANES;

        #[inline(always)]
        fn group(&self, counter: u64, out: &mut [[u32; WORDS]]) {
            let f = self.simd.avx512f;
            let input = initial::<LANES>(self.key, self.stream, counter);
            let mut x = input;
            rounds(&mut x);
            let (x, input): ([__m512i; WORDS], [__m512i; WORDS]) =
                (bytemuck::cast(x), bytemuck::cast(input));
            // Plain loops over registers, not `array::from_fn` or element-wise forms: a
            // closure does not inherit the target features (its intrinsics would be calls),
            // and the element-wise add and transposition compiled to gathers and scatters.
            // x86-64 is little-endian, so the words are as stored.
            let mut r = x;
            for (r, input) in r.iter_mut().zip(&input) {
                *r = f._mm512_add_epi32(*r, *input);
            }
            // Word w of block j is lane j of r[w]. 32-bit interleave of rows 2k and 2k + 1
            // within each 128-bit lane ℓ: t[2k] = (r2k[4ℓ], r2k+1[4ℓ], r2k[4ℓ+1],
            // r2k+1[4ℓ+1]), t[2k+1] the same at 4ℓ + 2, 4ℓ + 3.
            let mut t = r;
            for (t, r) in t.chunks_exact_mut(2).zip(r.chunks_exact(2)) {
                t[0] = f._mm512_unpacklo_epi32(r[0], r[1]);
                t[1] = f._mm512_unpackhi_epi32(r[0], r[1]);
            }
            // 64-bit interleave: lane ℓ of u[4k + m] holds words 4k … 4k + 3 of block 4ℓ + m.
            let mut u = t;
            for (u, t) in u.chunks_exact_mut(4).zip(t.chunks_exact(4)) {
                u[0] = f._mm512_unpacklo_epi64(t[0], t[2]);
                u[1] = f._mm512_unpackhi_epi64(t[0], t[2]);
                u[2] = f._mm512_unpacklo_epi64(t[1], t[3]);
                u[3] = f._mm512_unpackhi_epi64(t[1], t[3]);
            }
            // Block 4ℓ + m is lane ℓ of u[m], u[4 + m], u[8 + m], u[12 + m]: a 4 × 4
            // transposition of 128-bit lanes. Masks select lanes (two bits each): 0x44 =
            // (0, 1 | 0, 1), 0xEE = (2, 3 | 2, 3), 0x88 = (0, 2 | 0, 2), 0xDD = (1, 3 | 1, 3).
            for m in 0..4 {
                let (a, b, c, d) = (u[m], u[4 + m], u[8 + m], u[12 + m]);
                let p0 = f._mm512_shuffle_i32x4::<0x44>(a, b);
                let p1 = f._mm512_shuffle_i32x4::<0xEE>(a, b);
                let q0 = f._mm512_shuffle_i32x4::<0x44>(c, d);
                let q1 = f._mm512_shuffle_i32x4::<0xEE>(c, d);
                out[m] = bytemuck::cast(f._mm512_shuffle_i32x4::<0x88>(p0, q0));
                out[4 + m] = bytemuck::cast(f._mm512_shuffle_i32x4::<0xDD>(p0, q0));
                out[8 + m] = bytemuck::cast(f._mm512_shuffle_i32x4::<0x88>(p1, q1));
                out[12 + m] = bytemuck::cast(f._mm512_shuffle_i32x4::<0xDD>(p1, q1));
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{initial, rounds, Group, Keyed, QuarterRound, WORDS};
    use core::arch::x86_64::__m256i;
    use pulp::x86::V3;

    /// Blocks per group: one per 32-bit lane of a 256-bit register.
    const LANES: usize = 8;

    /// The `vpshufb` control that rotates every 32-bit word left by `k` bytes: byte i of a
    /// rotated word is byte (i − k) mod 4 of the word (the control indexes bytes within each
    /// 128-bit lane).
    #[inline(always)]
    fn bytes_rotated(k: usize) -> __m256i {
        let control: [u8; 32] =
            std::array::from_fn(|i| ((i % 16) / 4 * 4 + (i % 4 + 4 - k) % 4) as u8);
        bytemuck::cast(control)
    }

    /// The state of 8 blocks in AVX2 registers, with the byte shuffles that rotate by 16
    /// and 8 bits.
    struct State {
        simd: V3,
        x: [__m256i; WORDS],
        rotate_16: __m256i,
        rotate_8: __m256i,
    }

    impl State {
        /// Every 32-bit word rotated left by `L` bits (`R` = 32 − `L`).
        #[inline(always)]
        fn rotate<const L: i32, const R: i32>(&self, x: __m256i) -> __m256i {
            let f = self.simd.avx2;
            f._mm256_or_si256(f._mm256_slli_epi32::<L>(x), f._mm256_srli_epi32::<R>(x))
        }
    }

    impl QuarterRound for State {
        #[inline(always)]
        fn quarter_round(&mut self, [a, b, c, d]: [usize; 4]) {
            let f = self.simd.avx2;
            let x = &self.x;
            let (mut xa, mut xb, mut xc, mut xd) = (x[a], x[b], x[c], x[d]);
            xa = f._mm256_add_epi32(xa, xb);
            xd = f._mm256_shuffle_epi8(f._mm256_xor_si256(xd, xa), self.rotate_16);
            xc = f._mm256_add_epi32(xc, xd);
            xb = self.rotate::<12, 20>(f._mm256_xor_si256(xb, xc));
            xa = f._mm256_add_epi32(xa, xb);
            xd = f._mm256_shuffle_epi8(f._mm256_xor_si256(xd, xa), self.rotate_8);
            xc = f._mm256_add_epi32(xc, xd);
            xb = self.rotate::<7, 25>(f._mm256_xor_si256(xb, xc));
            (self.x[a], self.x[b], self.x[c], self.x[d]) = (xa, xb, xc, xd);
        }
    }

    /// 8 blocks at once.
    impl Group for Keyed<'_, V3> {
        const LANES: usize = LANES;

        #[inline(always)]
        fn group(&self, counter: u64, out: &mut [[u32; WORDS]]) {
            let f = self.simd.avx2;
            let input: [__m256i; WORDS] =
                bytemuck::cast(initial::<LANES>(self.key, self.stream, counter));
            let mut state = State {
                simd: self.simd,
                x: input,
                rotate_16: bytes_rotated(2),
                rotate_8: bytes_rotated(1),
            };
            // The rounds in intrinsics: written over `[u32; 8]` as for AVX-512, the compiler
            // kept them scalar (`rorx`), at 21 ns a pair.
            rounds(&mut state);
            // As in the AVX-512 group: plain loops over registers (see there why).
            let mut r = state.x;
            for (r, input) in r.iter_mut().zip(&input) {
                *r = f._mm256_add_epi32(*r, *input);
            }
            // Word w of block j is lane j of r[w]; each half of a block (words 8h … 8h + 7)
            // is an 8 × 8 transposition of r[8h …]. 32-bit interleave of rows 2k, 2k + 1
            // within each 128-bit lane ℓ: t[2k] = (r2k[4ℓ], r2k+1[4ℓ], r2k[4ℓ+1], r2k+1[4ℓ+1]),
            // t[2k+1] the same at 4ℓ + 2, 4ℓ + 3.
            let mut t = r;
            for (t, r) in t.chunks_exact_mut(2).zip(r.chunks_exact(2)) {
                t[0] = f._mm256_unpacklo_epi32(r[0], r[1]);
                t[1] = f._mm256_unpackhi_epi32(r[0], r[1]);
            }
            // 64-bit interleave: lane ℓ of u[4k + m] holds words 4k … 4k + 3 of block 4ℓ + m.
            let mut u = t;
            for (u, t) in u.chunks_exact_mut(4).zip(t.chunks_exact(4)) {
                u[0] = f._mm256_unpacklo_epi64(t[0], t[2]);
                u[1] = f._mm256_unpackhi_epi64(t[0], t[2]);
                u[2] = f._mm256_unpacklo_epi64(t[1], t[3]);
                u[3] = f._mm256_unpackhi_epi64(t[1], t[3]);
            }
            // Words 8h … 8h + 7 of block 4ℓ + m are lane ℓ of u[8h + m] then of u[8h + 4 + m]:
            // 0x20 joins the low lanes, 0x31 the high ones.
            for h in 0..2 {
                for m in 0..4 {
                    let (a, b) = (u[8 * h + m], u[8 * h + 4 + m]);
                    let low: [u32; 8] = bytemuck::cast(f._mm256_permute2x128_si256::<0x20>(a, b));
                    let high: [u32; 8] = bytemuck::cast(f._mm256_permute2x128_si256::<0x31>(a, b));
                    out[m][8 * h..8 * h + 8].copy_from_slice(&low);
                    out[4 + m][8 * h..8 * h + 8].copy_from_slice(&high);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::ChaCha8Rng;
    use rand_core::{RngCore, SeedableRng};

    /// `rand_chacha`'s words of blocks `counter ..` of (key, stream).
    fn reference(seed: [u8; 32], stream: u64, counter: u64, n: usize) -> Vec<[u32; WORDS]> {
        let mut rng = ChaCha8Rng::from_seed(seed);
        rng.set_stream(stream);
        rng.set_word_pos(u128::from(counter) * WORDS as u128);
        (0..n)
            .map(|_| std::array::from_fn(|_| rng.next_u32().to_le()))
            .collect()
    }

    #[test]
    fn blocks_are_rand_chacha_s() {
        let paths = Fast::available();
        if paths.is_empty() {
            eprintln!(
                "skipped: this CPU has neither AVX-512 nor AVX2: the keystream is never used"
            );
        }
        let seed = super::super::key_of(0x5eed);
        // Whole groups of 16 and remainders; a counter that carries from word 12 into word 13
        // inside a group; a stream id using both of its words.
        for (stream, counter, n) in [
            (0u64, 0u64, 1usize),
            (3, 5, 37),
            (u64::MAX - 1, (1 << 32) - 7, 40),
            (1 << 40, 123_456_789, 16),
        ] {
            let want = reference(seed, stream, counter, n);
            for fast in &paths {
                let mut got = vec![[0u32; WORDS]; n];
                fast.blocks(&seed, stream, counter, &mut got);
                assert_eq!(got, want, "{fast:?}: stream {stream}, counter {counter}");
            }
        }
    }
}
