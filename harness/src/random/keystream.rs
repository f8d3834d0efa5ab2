//! ChaCha8 keystream blocks computed many at once: the bulk path of [`super::Stream::fill_pairs`].
//!
//! **Why by hand.** `rand_chacha` (ppv-lite86) computes 4 blocks per refill with at most AVX2
//! and was 41 % of `mfh chi2`'s time (GGX, 1 thread, perf); RustCrypto's `chacha20` has an
//! AVX-512 backend only for its cipher, behind a `--cfg` flag, and not for its RNG. Here the
//! same function — the ChaCha block function of Bernstein (2008) with 8 rounds, in
//! `rand_chacha`'s layout: constants, the 8 key words, a 64-bit block counter in words 12–13,
//! the 64-bit stream id in words 14–15 — is computed for L consecutive blocks at once, one
//! block per SIMD lane (L = 16 under AVX-512, 8 under AVX2, 4 on the baseline), as straight-line
//! loops over `[u32; L]` that the compiler vectorizes under `pulp`'s runtime dispatch. The
//! words are those of `rand_chacha` bit for bit (the test `blocks_are_rand_chacha_s`, on every
//! path), so every seeded number of mfh is unchanged. Only the AVX-512 path beats
//! `rand_chacha` ([`pays`]): the transposition of the lanes into blocks compiles to gathers
//! (an explicit butterfly of two-source shuffles compiled worse still), which is what a
//! hand-written intrinsic transpose would remove.

/// "expand 32-byte k".
const CONSTANTS: [u32; 4] = [0x6170_7865, 0x3320_646e, 0x7962_2d32, 0x6b20_6574];
/// ChaCha8: 4 double rounds.
const DOUBLE_ROUNDS: usize = 4;
/// Words per block.
pub(super) const WORDS: usize = 16;

/// Whether [`blocks`] is faster than `rand_chacha` on this CPU: under AVX-512 only (16 blocks
/// at once: 3.0 ns a pair of uniforms against `rand_chacha`'s 4.6 on an AMD EPYC; under AVX2
/// 4.4 against 4.6 and on the SSE2 baseline 10.5, so there `rand_chacha` keeps the work).
pub(super) fn pays() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        matches!(pulp::Arch::new(), pulp::Arch::V4(_))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Writes blocks `counter`, `counter + 1`, … of the keystream of (`key`, `stream`) into `out`,
/// one block of 16 words (as stored little-endian bytes, i.e. `u32::to_le`) per element.
pub(super) fn blocks(key: &[u32; 8], stream: u64, counter: u64, out: &mut [[u32; WORDS]]) {
    blocks_on(pulp::Arch::new(), key, stream, counter, out);
}

/// [`blocks`] through the instruction set `arch` (`pulp::Arch::Scalar` for the tests).
fn blocks_on(
    arch: pulp::Arch,
    key: &[u32; 8],
    stream: u64,
    counter: u64,
    out: &mut [[u32; WORDS]],
) {
    /// The loop as a `pulp::WithSimd` operation, instantiated once per instruction set.
    struct Op<'a> {
        key: &'a [u32; 8],
        stream: u64,
        counter: u64,
        out: &'a mut [[u32; WORDS]],
    }
    impl pulp::WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) {
            // One block per u32 lane of the instruction set's register.
            match core::mem::size_of::<S::u32s>() / 4 {
                16.. => all_groups::<16>(self.key, self.stream, self.counter, self.out),
                8..=15 => all_groups::<8>(self.key, self.stream, self.counter, self.out),
                _ => all_groups::<4>(self.key, self.stream, self.counter, self.out),
            }
        }
    }
    arch.dispatch(Op {
        key,
        stream,
        counter,
        out,
    });
}

/// Every block of `out`, L at a time (the last group through a buffer).
#[inline(always)]
fn all_groups<const L: usize>(key: &[u32; 8], stream: u64, counter: u64, out: &mut [[u32; WORDS]]) {
    let mut chunks = out.chunks_exact_mut(L);
    let mut next = counter;
    for chunk in &mut chunks {
        group::<L>(key, stream, next, chunk);
        next = next.wrapping_add(L as u64);
    }
    let rest = chunks.into_remainder();
    if !rest.is_empty() {
        let mut buffer = [[0u32; WORDS]; L];
        group::<L>(key, stream, next, &mut buffer);
        let n = rest.len();
        rest.copy_from_slice(&buffer[..n]);
    }
}

/// Blocks `counter` … `counter + L − 1` into `out[..L]`, block j in lane j.
#[inline(always)]
fn group<const L: usize>(key: &[u32; 8], stream: u64, counter: u64, out: &mut [[u32; WORDS]]) {
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
    let input = x;
    for _ in 0..DOUBLE_ROUNDS {
        // Columns, then diagonals.
        quarter_round(&mut x, 0, 4, 8, 12);
        quarter_round(&mut x, 1, 5, 9, 13);
        quarter_round(&mut x, 2, 6, 10, 14);
        quarter_round(&mut x, 3, 7, 11, 15);
        quarter_round(&mut x, 0, 5, 10, 15);
        quarter_round(&mut x, 1, 6, 11, 12);
        quarter_round(&mut x, 2, 7, 8, 13);
        quarter_round(&mut x, 3, 4, 9, 14);
    }
    for (w, (x, input)) in x.iter().zip(&input).enumerate() {
        for (j, block) in out[..L].iter_mut().enumerate() {
            block[w] = x[j].wrapping_add(input[j]).to_le();
        }
    }
}

/// The ChaCha quarter round on words a, b, c, d of every lane.
#[inline(always)]
fn quarter_round<const L: usize>(
    x: &mut [[u32; L]; WORDS],
    a: usize,
    b: usize,
    c: usize,
    d: usize,
) {
    let (mut xa, mut xb, mut xc, mut xd) = (x[a], x[b], x[c], x[d]);
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
    (x[a], x[b], x[c], x[d]) = (xa, xb, xc, xd);
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
        let seed = super::super::key_of(0x5eed);
        let key: [u32; 8] =
            std::array::from_fn(|i| u32::from_le_bytes(seed[4 * i..4 * i + 4].try_into().unwrap()));
        // Group sizes that leave remainders for every lane count; a counter that carries
        // from word 12 into word 13 inside a group; a stream id using both of its words.
        for (stream, counter, n) in [
            (0u64, 0u64, 1usize),
            (3, 5, 37),
            (u64::MAX - 1, (1 << 32) - 7, 40),
            (1 << 40, 123_456_789, 16),
        ] {
            let want = reference(seed, stream, counter, n);
            // The detected path (AVX-512 here), AVX2 where the CPU has it, and the baseline.
            #[cfg(target_arch = "x86_64")]
            let avx2 = pulp::x86::V3::try_new().map(pulp::Arch::V3);
            #[cfg(not(target_arch = "x86_64"))]
            let avx2 = None;
            for arch in [pulp::Arch::new(), pulp::Arch::Scalar]
                .into_iter()
                .chain(avx2)
            {
                let mut got = vec![[0u32; WORDS]; n];
                blocks_on(arch, &key, stream, counter, &mut got);
                assert_eq!(got, want, "stream {stream}, counter {counter}, {arch:?}");
            }
        }
    }
}
