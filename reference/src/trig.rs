//! Sine and cosine of an angle in radians, and the angle atan2(y, x) of a point, one at a time
//! ([`sin_cos`], [`atan2`]) or a block at a time ([`sin_cos_block`], [`atan2_block`],
//! vectorized: 4 lanes under AVX2, 8 under AVX-512), the two forms giving the same bits: for the
//! quadratures' directions (θ, φ) ↦ m, whose trigonometry was a quarter of an audit's time in
//! glibc's scalar `sincos`, and the KS test's marginal angles of millions of samples.
//!
//! **Method.** x = kπ/2 + y with k = round(2x/π) and y as an unevaluated sum y₀ + y₁ (|y₁| ≤
//! ½ ulp(y₀) + 2e-21·|k|, far below |y₀| even at the doubles nearest kπ/2): π/2 is split as
//! musl's `__rem_pio2` splits it, into P₁ + P₂ + P₃ + P₃ₜ with P₁, P₂, P₃ of 33 significant bits, so k·P₁, k·P₂ and k·P₃ are exact for |k| < 2²⁰; x − k·P₁ is
//! exact (Sterbenz), the subtraction of k·P₂ is made exact by a TwoSum, and the rest is added
//! to the low part: y is good to ~2⁻¹⁵⁰·|k| absolute, so even the doubles closest to a
//! multiple of π/2 keep their relative accuracy. Then musl's kernels `__sin(y₀, y₁, 1)` and
//! `__cos(y₀, y₁)` (k_sin.c, k_cos.c: minimax polynomials on [−π/4, π/4], < 1 ulp) and the
//! quadrant k mod 4. Every step is +, −, × on doubles with no branch, so a loop over it
//! vectorizes, and — Rust neither contracts a·b + c nor reassociates — the block path gives the
//! scalar path's bits on every instruction set (tests).
//!
//! **Accuracy**, tested: within 1 ulp of glibc's `sin`/`cos` (themselves < 1 ulp) at 10⁶
//! points of [−[`FAST_LIMIT`], [`FAST_LIMIT`]] and at the doubles nearest kπ/2, and exact at 0
//! (sin(±0) = ±0, cos 0 = 1). Outside |x| ≤ [`FAST_LIMIT`] (and for NaN, ±∞) both forms return
//! `libm::sincos(x)` (musl's general reduction).
//!
//! Hand-written because std has no vectorized sine, and the SIMD math crates either need
//! nightly Rust (`sleef`'s portable SIMD) or round differently from their own scalar forms
//! (`wide`), which would make a quadrature's value depend on how its nodes were batched.

/// musl `__sin` (k_sin.c) coefficients, bit patterns as in the `libm` crate's `k_sin.rs`.
pub(crate) const S1: f64 = f64::from_bits(0xbfc5_5555_5555_5549); // -1.66666666666666324348e-1
const S2: f64 = f64::from_bits(0x3f81_1111_1110_f8a6); // 8.33333333332248946124e-3
const S3: f64 = f64::from_bits(0xbf2a_01a0_19c1_61d5); // -1.98412698298579493134e-4
const S4: f64 = f64::from_bits(0x3ec7_1de3_57b1_fe7d); // 2.75573137070700676789e-6
const S5: f64 = f64::from_bits(0xbe5a_e5e6_8a2b_9ceb); // -2.50507602534068634195e-8
const S6: f64 = f64::from_bits(0x3de5_d93a_5acf_d57c); // 1.58969099521155010221e-10
/// musl `__cos` (k_cos.c) coefficients, bit patterns as in the `libm` crate's `k_cos.rs`.
const C1: f64 = f64::from_bits(0x3fa5_5555_5555_554c); // 4.16666666666666019037e-2
const C2: f64 = f64::from_bits(0xbf56_c16c_16c1_5177); // -1.38888888888741095749e-3
const C3: f64 = f64::from_bits(0x3efa_01a0_19cb_1590); // 2.48015872894767294178e-5
const C4: f64 = f64::from_bits(0xbe92_7e4f_809c_52ad); // -2.75573143513906633035e-7
const C5: f64 = f64::from_bits(0x3e21_ee9e_bdb4_b1c4); // 2.08757232129817482790e-9
const C6: f64 = f64::from_bits(0xbda8_fae9_be88_38d4); // -1.13596475577881948265e-11
/// `libm::sincos` returns (x, 1) below this |x| (high word 0x3e46a09e: 2⁻²⁷·√2).
pub(crate) const TINY: f64 = f64::from_bits(0x3e46_a09e_0000_0000);

/// 2/π (musl `invpio2`).
const INV_PIO2: f64 = f64::from_bits(0x3fe4_5f30_6dc9_c883);
/// π/2 in four parts (musl `pio2_1`, `pio2_2`, `pio2_3`, `pio2_3t`): the first three with 33
/// significant bits, so their products with an integer below 2²⁰ are exact.
const PIO2_1: f64 = f64::from_bits(0x3ff9_21fb_5440_0000);
const PIO2_2: f64 = f64::from_bits(0x3dd0_b461_1a60_0000);
const PIO2_3: f64 = f64::from_bits(0x3ba3_198a_2e00_0000);
const PIO2_3T: f64 = f64::from_bits(0x397b_839a_2520_49c1);
/// 1.5·2⁵²: (t + `TO_INT`) − `TO_INT` rounds |t| < 2⁵¹ to the nearest integer (ties to even),
/// and the low bits of t + `TO_INT` are that integer's (two's complement).
const TO_INT: f64 = 6_755_399_441_055_744.0;

/// musl `atan` (s_atan.c): atan(½) and atan(1) in two parts, and the polynomial's coefficients.
const ATAN_HI: [f64; 2] = [
    f64::from_bits(0x3fdd_ac67_0561_bb4f),
    f64::from_bits(0x3fe9_21fb_5444_2d18),
];
const ATAN_LO: [f64; 2] = [
    f64::from_bits(0x3c7a_2b7f_222f_65e2),
    f64::from_bits(0x3c81_a626_3314_5c07),
];
const AT: [f64; 11] = [
    f64::from_bits(0x3fd5_5555_5555_550d),
    f64::from_bits(0xbfc9_9999_9998_ebc4),
    f64::from_bits(0x3fc2_4924_9200_83ff),
    f64::from_bits(0xbfbc_71c6_fe23_1671),
    f64::from_bits(0x3fb7_45cd_c54c_206e),
    f64::from_bits(0xbfb3_b0f2_af74_9a6d),
    f64::from_bits(0x3fb1_0d66_a0d0_3d51),
    f64::from_bits(0xbfad_de2d_52de_fd9a),
    f64::from_bits(0x3fa9_7b4b_2476_0deb),
    f64::from_bits(0xbfa2_b444_2c6a_6c2f),
    f64::from_bits(0x3f90_ad3a_e322_da11),
];
/// π/2 and π in two parts (musl s_atan.c `atanhi[3]`, `atanlo[3]`; e_atan2.c `pi`, `pi_lo`).
const PIO2_HI: f64 = f64::from_bits(0x3ff9_21fb_5444_2d18);
const PIO2_LO: f64 = f64::from_bits(0x3c91_a626_3314_5c07);
const PI_HI: f64 = f64::from_bits(0x4009_21fb_5444_2d18);
const PI_LO: f64 = f64::from_bits(0x3ca1_a626_3314_5c07);

/// The largest |x| of the fast path (k ≤ 652 < 2²⁰); beyond it, `libm::sincos`.
pub const FAST_LIMIT: f64 = 1024.0;

/// (sin x, cos x), as [`sin_cos_block`] computes them (module doc).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= FAST_LIMIT {
        reduced(x)
    } else {
        libm::sincos(x)
    }
}

/// `s[i]`, `c[i]` = [`sin_cos`]`(x[i])`, vectorized (runtime dispatch through `pulp`: AVX-512 or
/// AVX2 + FMA where the CPU has them, else the baseline target's SSE2).
///
/// # Panics
/// If the three slices differ in length.
pub fn sin_cos_block(x: &[f64], s: &mut [f64], c: &mut [f64]) {
    sin_cos_block_on(pulp::Arch::new(), x, s, c);
}

/// [`sin_cos_block`] through the instruction set `arch` (`pulp::Arch::Scalar`: the baseline).
fn sin_cos_block_on(arch: pulp::Arch, x: &[f64], s: &mut [f64], c: &mut [f64]) {
    assert!(
        x.len() == s.len() && x.len() == c.len(),
        "sin_cos_block: slices of different lengths"
    );
    /// The loop as a `pulp::WithSimd` operation (instantiated per instruction set).
    struct Op<'a> {
        x: &'a [f64],
        s: &'a mut [f64],
        c: &'a mut [f64],
    }
    impl pulp::WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) {
            for ((&x, s), c) in self.x.iter().zip(self.s.iter_mut()).zip(self.c.iter_mut()) {
                (*s, *c) = reduced(x);
            }
        }
    }
    arch.dispatch(Op { x, s, c });
    // The rare arguments outside the fast path (or NaN): one predictable test per element.
    for ((&x, s), c) in x.iter().zip(s.iter_mut()).zip(c.iter_mut()) {
        if !(x.abs() <= FAST_LIMIT) {
            (*s, *c) = libm::sincos(x);
        }
    }
}

/// musl's k_sin and k_cos polynomials at z = x² (x ∈ [−π/4, π/4]): the r of `__sin`
/// (x + x³(S1 + z r)) and of `__cos` (1 − z/2 + z r), with their operations in their order.
#[inline(always)]
pub(crate) fn kernel_polynomials(z: f64) -> (f64, f64) {
    let w = z * z;
    let rs = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let rc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    (rs, rc)
}

/// The fast path of [`sin_cos`] (|x| ≤ [`FAST_LIMIT`]): straight-line, so it vectorizes.
#[inline(always)]
fn reduced(x: f64) -> (f64, f64) {
    // k = round(2x/π); its low two bits from the rounded sum's mantissa.
    let t = x * INV_PIO2 + TO_INT;
    let k = t - TO_INT;
    let quadrant = t.to_bits() & 3;
    // y = x − kπ/2 as hi + lo: x − k·P₁ exact, TwoSum for − k·P₂, the rest into lo.
    let r1 = x - k * PIO2_1;
    let p2 = -(k * PIO2_2);
    let hi = r1 + p2;
    let b = hi - r1;
    // The tail: |y1| ≤ ½ ulp(hi) + 2e-21·|k| ≪ |hi| even at the doubles nearest kπ/2 (the
    // test's worst cases, for every k of the fast path), so the kernels take it as it is,
    // without a renormalizing TwoSum on the critical path.
    let y0 = hi;
    let y1 = ((r1 - (hi - b)) + (p2 - b)) - k * PIO2_3 - k * PIO2_3T;
    // k_sin(y0, y1, 1) and k_cos(y0, y1)
    let z = y0 * y0;
    let (rs, rc) = kernel_polynomials(z);
    let v = z * y0;
    let sin = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * S1);
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let cos = w + (((1.0 - w) - hz) + (z * rc - y0 * y1));
    // Quadrant k mod 4: 0 (s, c), 1 (c, −s), 2 (−s, −c), 3 (−c, s). `==` on the bits and
    // `if` on booleans: selects, not branches.
    let odd = quadrant & 1 == 1;
    let high = quadrant & 2 == 2;
    let (a, b) = if odd { (cos, sin) } else { (sin, cos) };
    let sin = if high { -a } else { a };
    let cos = if odd ^ high { -b } else { b };
    // musl's sincos below 2⁻²⁷·√2: (x, 1), which keeps the sign of ±0.
    if x.abs() < TINY {
        (x, 1.0)
    } else {
        (sin, cos)
    }
}

/// atan2(y, x) ∈ [−π, π], as [`atan2_block`] computes it: within 2 ulps of glibc's (tested),
/// with its signs of zero and its ±π on the negative x axis.
///
/// **Method** (branch-free, so a loop over it vectorizes): with a = min(|x|, |y|) and
/// b = max(|x|, |y|), atan(a/b) ∈ [0, π/4] by musl's `atan` (s_atan.c, < 1 ulp) on its three
/// lowest intervals, the reduced argument formed in one division from a and b — a/b below
/// 7/16, (2a − b)/(2b + a) below 11/16 (2a − b exact by Sterbenz), (a − b)/(a + b) above
/// (a − b exact) — then π/2 − · where |y| > |x|, π − · where x < 0, − · where y has its sign
/// bit set, each with the low part of π/2 or π. Where x or y is not finite, or max(|x|, |y|)
/// is outside [2⁻¹⁰⁰⁰, 2¹⁰⁰⁰] (zeros, subnormals), both forms return `libm::atan2(y, x)`.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    if regular_atan2(y, x) {
        octant_atan2(y, x)
    } else {
        libm::atan2(y, x)
    }
}

/// `out[i]` = [`atan2`]`(y[i], x[i])`, vectorized (dispatch as [`sin_cos_block`]).
///
/// # Panics
/// If the three slices differ in length.
pub fn atan2_block(y: &[f64], x: &[f64], out: &mut [f64]) {
    atan2_block_on(pulp::Arch::new(), y, x, out);
}

/// [`atan2_block`] through the instruction set `arch`.
fn atan2_block_on(arch: pulp::Arch, y: &[f64], x: &[f64], out: &mut [f64]) {
    assert!(
        y.len() == x.len() && y.len() == out.len(),
        "atan2_block: slices of different lengths"
    );
    /// The loop as a `pulp::WithSimd` operation.
    struct Op<'a> {
        y: &'a [f64],
        x: &'a [f64],
        out: &'a mut [f64],
    }
    impl pulp::WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) {
            for ((&y, &x), out) in self.y.iter().zip(self.x).zip(self.out.iter_mut()) {
                *out = octant_atan2(y, x);
            }
        }
    }
    arch.dispatch(Op { y, x, out });
    for ((&y, &x), out) in y.iter().zip(x).zip(out.iter_mut()) {
        if !regular_atan2(y, x) {
            *out = libm::atan2(y, x);
        }
    }
}

/// Whether the fast path of [`atan2`] applies: x and y finite (not NaN) and b = max(|x|, |y|)
/// in [2⁻¹⁰⁰⁰, 2¹⁰⁰⁰], where 0.4375·b is a normal double and 2b + a cannot overflow.
#[inline(always)]
fn regular_atan2(y: f64, x: f64) -> bool {
    let b = x.abs().max(y.abs());
    x.is_finite() && y.is_finite() && (ATAN2_LOW..=ATAN2_HIGH).contains(&b)
}

/// The range of max(|x|, |y|) of [`atan2`]'s fast path: 2⁻¹⁰⁰⁰ and 2¹⁰⁰⁰.
const ATAN2_LOW: f64 = f64::from_bits(0x0170_0000_0000_0000);
const ATAN2_HIGH: f64 = f64::from_bits(0x7e70_0000_0000_0000);

/// The fast path of [`atan2`]: straight-line, so it vectorizes.
#[inline(always)]
fn octant_atan2(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (a, b) = (ax.min(ay), ax.max(ay));
    // The interval of t = a/b, decided without the division (7/16·b is exact).
    let middle = a >= 0.4375 * b;
    let upper = a >= 0.6875 * b;
    let num = if upper {
        a - b
    } else if middle {
        2.0 * a - b
    } else {
        a
    };
    let den = if upper {
        a + b
    } else if middle {
        2.0 * b + a
    } else {
        b
    };
    let t = num / den;
    let (hi, lo) = if upper {
        (ATAN_HI[1], ATAN_LO[1])
    } else if middle {
        (ATAN_HI[0], ATAN_LO[0])
    } else {
        (0.0, 0.0)
    };
    let z = t * t;
    let w = z * z;
    let s1 = z * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
    let s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
    // atan(a/b) = hi + atan(t) (with hi = lo = 0 on the lowest interval, where this is
    // musl's t − t(s1 + s2) bit for bit).
    let angle = hi - ((t * (s1 + s2) - lo) - t);
    let angle = if ay > ax {
        PIO2_HI - (angle - PIO2_LO)
    } else {
        angle
    };
    let angle = if x.is_sign_negative() {
        PI_HI - (angle - PI_LO)
    } else {
        angle
    };
    if y.is_sign_negative() {
        -angle
    } else {
        angle
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// Distance in ulps (of the larger magnitude's spacing) between two finite doubles.
    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        let scale = a.abs().max(b.abs());
        // ulp of a normal double; the smallest normal's for subnormals.
        let ulp = if scale < f64::MIN_POSITIVE {
            f64::from_bits(1)
        } else {
            f64::from_bits(scale.to_bits() & 0x7ff0_0000_0000_0000) * f64::EPSILON
        };
        (a - b).abs() / ulp
    }

    /// A stride over the fast range, small and tiny arguments, and the doubles nearest kπ/2
    /// with their neighbours (where the reduction cancels).
    fn arguments() -> Vec<f64> {
        let mut x: Vec<f64> = (0..1_000_003)
            .map(|i| -FAST_LIMIT + 2.0 * FAST_LIMIT * (i as f64 / 1_000_002.0))
            .collect();
        x.extend((0..100_000).map(|i| i as f64 * 1e-5));
        for k in -652..=652 {
            let m = k as f64 * FRAC_PI_2;
            let mut v = m;
            for _ in 0..4 {
                x.extend([v, -v]);
                v = v.next_up();
            }
            let mut v = m.next_down();
            for _ in 0..3 {
                x.extend([v, -v]);
                v = v.next_down();
            }
        }
        x.extend([
            0.0,
            -0.0,
            1e-300,
            -5e-324,
            1e-9,
            TINY,
            TINY.next_down(),
            1e-7,
        ]);
        x.extend([FAST_LIMIT, -FAST_LIMIT, FAST_LIMIT.next_up(), 1e6, -3e10]);
        x
    }

    #[test]
    fn within_an_ulp_of_glibc() {
        let mut worst = (0.0f64, 0.0);
        for x in arguments() {
            let (s, c) = sin_cos(x);
            let e = ulps(s, x.sin()).max(ulps(c, x.cos()));
            if e > worst.0 {
                worst = (e, x);
            }
        }
        assert!(worst.0 <= 1.0, "{} ulps at x = {:e}", worst.0, worst.1);
    }

    #[test]
    fn exact_where_it_must_be() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(-0.0);
        assert!(s == 0.0 && s.is_sign_negative() && c == 1.0);
        assert_eq!(sin_cos(1e-300), (1e-300, 1.0));
        // Beyond the fast path and for non-finite x: libm's.
        for x in [2e3, -1e9, 1e300, f64::INFINITY, f64::NAN] {
            let (s, c) = sin_cos(x);
            let (ws, wc) = libm::sincos(x);
            assert_eq!((s.to_bits(), c.to_bits()), (ws.to_bits(), wc.to_bits()));
        }
    }

    /// (y, x) pairs: every direction of a fine fan in all four quadrants at several radii, the
    /// interval edges of the reduction (t = 7/16, 11/16, 1), axes, signed zeros, tiny, huge
    /// and non-finite components.
    fn points() -> Vec<(f64, f64)> {
        let mut p = Vec::new();
        for i in 0..200_000 {
            let phi = -3.2 + 6.4 * (i as f64 / 199_999.0);
            let (s, c) = (phi.sin(), phi.cos());
            for r in [1.0, 3e-5, 7e4] {
                p.push((r * s, r * c));
            }
        }
        for t in [0.4375f64, 0.6875, 1.0] {
            for v in [t, t.next_up(), t.next_down()] {
                for (sy, sx) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
                    p.push((sy * v, sx * 1.0));
                    p.push((sx * 1.0, sy * v));
                }
            }
        }
        let specials = [0.0, -0.0, 1.0, -1.0, 1e-300, 5e-324, 1e300, f64::INFINITY];
        for &y in &specials {
            for &x in &specials {
                p.extend([(y, x), (-y, x), (y, -x), (-y, -x)]);
            }
        }
        p.extend([
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
            (2.0, 1e-320),
            (1e-320, 2.0),
        ]);
        p.extend([(1e300, 1e301), (9.3e-302, -1e-301), (1.7e308, -1.7e308)]);
        p
    }

    #[test]
    fn atan2_within_two_ulps_of_glibc() {
        let mut worst = (0.0f64, (0.0, 0.0));
        for (y, x) in points() {
            let (got, want) = (atan2(y, x), y.atan2(x));
            if want.is_nan() {
                assert!(got.is_nan(), "atan2({y:e}, {x:e}) = {got}");
                continue;
            }
            // Signs of zero and the ±π of the negative axis as glibc's.
            assert_eq!(
                got.is_sign_negative(),
                want.is_sign_negative(),
                "({y:e}, {x:e})"
            );
            let e = ulps(got, want);
            if e > worst.0 {
                worst = (e, (y, x));
            }
        }
        assert!(worst.0 <= 2.0, "{} ulps at {:?}", worst.0, worst.1);
    }

    #[test]
    fn atan2_block_paths_are_the_scalar_path_bit_for_bit() {
        let p = points();
        let (y, x): (Vec<f64>, Vec<f64>) = p.iter().copied().unzip();
        for arch in [pulp::Arch::new(), pulp::Arch::Scalar] {
            let mut out = vec![0.0; p.len()];
            atan2_block_on(arch, &y, &x, &mut out);
            for (i, &(y, x)) in p.iter().enumerate() {
                assert_eq!(out[i].to_bits(), atan2(y, x).to_bits(), "({y:e}, {x:e})");
            }
        }
    }

    /// The block path, dispatched (AVX-512 or AVX2 where the CPU has them) and baseline, gives
    /// the scalar path's bits, through odd lengths and non-finite arguments.
    #[test]
    fn block_paths_are_the_scalar_path_bit_for_bit() {
        let mut x = arguments();
        x.extend([f64::NAN, f64::INFINITY, -f64::INFINITY, 1e308]);
        for arch in [pulp::Arch::new(), pulp::Arch::Scalar] {
            for len in [x.len(), 37, 1] {
                let x = &x[x.len() - len..];
                let (mut s, mut c) = (vec![0.0; len], vec![0.0; len]);
                sin_cos_block_on(arch, x, &mut s, &mut c);
                for i in 0..len {
                    let (ws, wc) = sin_cos(x[i]);
                    assert_eq!(
                        (s[i].to_bits(), c[i].to_bits()),
                        (ws.to_bits(), wc.to_bits()),
                        "x = {:e}",
                        x[i]
                    );
                }
            }
        }
    }
}
