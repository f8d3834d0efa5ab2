//! ChaCha8 keystream blocks computed 16 at once under AVX-512: the bulk path of
//! [`super::Stream::fill_pairs`].
//!
//! **Why by hand.** `rand_chacha` (ppv-lite86) computes 4 blocks per refill with at most AVX2
//! and was 41 % of `mfh chi2`'s time (GGX, 1 thread, perf); RustCrypto's `chacha20` has an
//! AVX-512 backend only for its cipher, behind a `--cfg` flag, and not for its RNG. Here the
//! same function — the ChaCha block function of Bernstein (2008) with 8 rounds, in
//! `rand_chacha`'s layout: constants, the 8 key words, a 64-bit block counter in words 12–13,
//! the 64-bit stream id in words 14–15 — is computed for 16 consecutive blocks at once, one
//! block per 32-bit lane of the AVX-512 registers: the rounds as straight-line loops over
//! `[u32; 16]` that the compiler vectorizes (`vprold` for the rotations), then the 16 × 16
//! transposition of words into blocks by AVX-512 shuffles through `pulp`'s safe wrappers of
//! the intrinsics (no `unsafe`). 1.2 ns a pair of uniforms against `rand_chacha`'s 4.7 on an
//! AMD EPYC (Zen 5). The words are those of `rand_chacha` bit for bit (the test
//! `blocks_are_rand_chacha_s`), so every seeded number of mfh is unchanged.
//!
//! Only AVX-512 is worth it: the same rounds for 8 blocks under AVX2 with the element-wise
//! transposition (which compiles to gathers) took 4.4 ns a pair and 10.5 on the SSE2
//! baseline, so without AVX-512 [`Fast::detect`] says no and `rand_chacha` does the work.

/// Words per block.
pub(super) const WORDS: usize = 16;

/// The AVX-512 keystream, on a CPU that has AVX-512 (x86-64-v4): `pulp`'s proof of it.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy)]
pub(super) struct Fast(pulp::x86::V4);

/// The AVX-512 keystream: none off x86-64.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Debug, Clone, Copy)]
pub(super) enum Fast {}

impl Fast {
    /// The fast keystream if this CPU has AVX-512 (detected once per process: `fill_pairs`
    /// asks per block of uniforms).
    pub(super) fn detect() -> Option<Fast> {
        #[cfg(target_arch = "x86_64")]
        {
            static DETECTED: std::sync::OnceLock<Option<Fast>> = std::sync::OnceLock::new();
            *DETECTED.get_or_init(|| pulp::x86::V4::try_new().map(Fast))
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
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
            avx512::blocks(self.0, &key, stream, counter, out);
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (key, stream, counter, out);
            match self {}
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::WORDS;
    use core::arch::x86_64::__m512i;
    use pulp::x86::V4;

    /// "expand 32-byte k".
    const CONSTANTS: [u32; 4] = [0x6170_7865, 0x3320_646e, 0x7962_2d32, 0x6b20_6574];
    /// ChaCha8: 4 double rounds.
    const DOUBLE_ROUNDS: usize = 4;
    /// Blocks per group: one per 32-bit lane of a 512-bit register.
    const LANES: usize = 16;

    /// [`super::Fast::blocks`] (`simd` is the proof of AVX-512).
    pub(super) fn blocks(
        simd: V4,
        key: &[u32; 8],
        stream: u64,
        counter: u64,
        out: &mut [[u32; WORDS]],
    ) {
        /// The loop as a `pulp::WithSimd` operation: compiled for AVX-512 with `group`
        /// inlined into it.
        struct Op<'a> {
            simd: V4,
            key: &'a [u32; 8],
            stream: u64,
            counter: u64,
            out: &'a mut [[u32; WORDS]],
        }
        impl pulp::WithSimd for Op<'_> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _: S) {
                let mut chunks = self.out.chunks_exact_mut(LANES);
                let mut next = self.counter;
                for chunk in &mut chunks {
                    group(self.simd, self.key, self.stream, next, chunk);
                    next = next.wrapping_add(LANES as u64);
                }
                let rest = chunks.into_remainder();
                if !rest.is_empty() {
                    let mut buffer = [[0u32; WORDS]; LANES];
                    group(self.simd, self.key, self.stream, next, &mut buffer);
                    let n = rest.len();
                    rest.copy_from_slice(&buffer[..n]);
                }
            }
        }
        pulp::Simd::vectorize(
            simd,
            Op {
                simd,
                key,
                stream,
                counter,
                out,
            },
        );
    }

    /// Blocks `counter` … `counter + 15` into `out[..16]`.
    #[inline(always)]
    fn group(simd: V4, key: &[u32; 8], stream: u64, counter: u64, out: &mut [[u32; WORDS]]) {
        let f = simd.avx512f;
        let input = initial(key, stream, counter);
        let mut x = input;
        rounds(&mut x);
        let (x, input): ([__m512i; WORDS], [__m512i; WORDS]) =
            (bytemuck::cast(x), bytemuck::cast(input));
        // Plain loops over registers, not `array::from_fn` or element-wise forms: a closure
        // does not inherit the target features (its intrinsics would be calls), and the
        // element-wise add and transposition compiled to gathers and scatters. x86-64 is
        // little-endian, so the words are as stored.
        let mut r = x;
        for (r, input) in r.iter_mut().zip(&input) {
            *r = f._mm512_add_epi32(*r, *input);
        }
        // Word w of block j is lane j of r[w]. 32-bit interleave of rows 2k and 2k + 1 within
        // each 128-bit lane ℓ: t[2k] = (r2k[4ℓ], r2k+1[4ℓ], r2k[4ℓ+1], r2k+1[4ℓ+1]), t[2k+1]
        // the same at 4ℓ + 2, 4ℓ + 3.
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
        // Block 4ℓ + m is lane ℓ of u[m], u[4 + m], u[8 + m], u[12 + m]: a 4 × 4 transposition
        // of 128-bit lanes. Masks select lanes (two bits each): 0x44 = (0, 1 | 0, 1),
        // 0xEE = (2, 3 | 2, 3), 0x88 = (0, 2 | 0, 2), 0xDD = (1, 3 | 1, 3).
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

    /// The input words of blocks `counter` … `counter + 15`, block j in lane j.
    #[inline(always)]
    fn initial(key: &[u32; 8], stream: u64, counter: u64) -> [[u32; LANES]; WORDS] {
        let mut x = [[0u32; LANES]; WORDS];
        for (w, c) in CONSTANTS.iter().enumerate() {
            x[w] = [*c; LANES];
        }
        for (w, k) in key.iter().enumerate() {
            x[4 + w] = [*k; LANES];
        }
        let block = |j: usize| counter.wrapping_add(j as u64);
        x[12] = std::array::from_fn(|j| block(j) as u32);
        x[13] = std::array::from_fn(|j| (block(j) >> 32) as u32);
        x[14] = [stream as u32; LANES];
        x[15] = [(stream >> 32) as u32; LANES];
        x
    }

    /// ChaCha8's 4 double rounds on every lane.
    #[inline(always)]
    fn rounds(x: &mut [[u32; LANES]; WORDS]) {
        for _ in 0..DOUBLE_ROUNDS {
            // Columns, then diagonals.
            quarter_round(x, 0, 4, 8, 12);
            quarter_round(x, 1, 5, 9, 13);
            quarter_round(x, 2, 6, 10, 14);
            quarter_round(x, 3, 7, 11, 15);
            quarter_round(x, 0, 5, 10, 15);
            quarter_round(x, 1, 6, 11, 12);
            quarter_round(x, 2, 7, 8, 13);
            quarter_round(x, 3, 4, 9, 14);
        }
    }

    /// The ChaCha quarter round on words a, b, c, d of every lane.
    #[inline(always)]
    fn quarter_round(x: &mut [[u32; LANES]; WORDS], a: usize, b: usize, c: usize, d: usize) {
        let (mut xa, mut xb, mut xc, mut xd) = (x[a], x[b], x[c], x[d]);
        for j in 0..LANES {
            xa[j] = xa[j].wrapping_add(xb[j]);
            xd[j] = (xd[j] ^ xa[j]).rotate_left(16);
            xc[j] = xc[j].wrapping_add(xd[j]);
            xb[j] = (xb[j] ^ xc[j]).rotate_left(12);
            xa[j] = xa[j].wrapping_add(xb[j]);
            xd[j] = (xd[j] ^ xa[j]).rotate_left(8);
            xc[j] = xc[j].wrapping_add(xd[j]);
            xb[j] = (xb[j] ^ xc[j]).rotate_left(7);
        }
        (x[a], x[b], x[c], x[d]) = (xa, xb, xc, xd);
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
        let Some(fast) = Fast::detect() else {
            eprintln!("skipped: this CPU has no AVX-512, where the fast keystream is never used");
            return;
        };
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
            let mut got = vec![[0u32; WORDS]; n];
            fast.blocks(&seed, stream, counter, &mut got);
            assert_eq!(got, want, "stream {stream}, counter {counter}");
        }
    }
}
