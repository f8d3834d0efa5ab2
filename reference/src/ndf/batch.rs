//! Batch forms of the reference normal samplers: the elliptic normal samplers (GGX, Beckmann,
//! Student), for which this module writes the steps every one of them shares — (cos 2πu₀,
//! sin 2πu₀) scaled by the axis scales, times the slope radius, and the normal of the slope —
//! and the block loop, its dispatch and the block sin/cos that GGX's visible-normal batch
//! (`ndf/ggx_visible_batch.rs`, within ulps of its scalar sampler) shares with them: straight-line loops over fixed
//! blocks that the compiler vectorizes (no branch, no call per element; SSE2 two-lane f64 on
//! the baseline x86-64 target, 4 or 8 lanes where the CPU has AVX2 or AVX-512, through
//! `pulp`'s dispatch below).
//!
//! **Bit for bit.** Every step performs the same IEEE operations in the same order as the
//! scalar path (`geometry::sin_cos_turns` with musl's `__sin`/`__cos` kernels as ported by the
//! `libm` crate, `model::elliptic_direction`, `geometry::normal_from_slopes`); +, −, ×, ÷ and √
//! are correctly rounded in vector registers as in scalar ones and Rust does not contract or
//! reassociate floating-point arithmetic, so the batch result is the scalar result exactly
//! (0 ulps: the test `batch_samplers_agree_with_scalar_bit_for_bit`). Elements outside the
//! fast path's domain (u₀ ∉ [0, 1), non-finite slopes: the scalar path's other branches) are
//! recomputed by the scalar method. Hand-written because std has no vectorized sin/cos, and a
//! SIMD math crate would not round as the scalar `libm` kernels do.

use crate::geometry::Vec3;

/// Elements per block: the temporaries live on the stack (5 × 64 doubles).
const BLOCK: usize = 64;

use crate::trig::{kernel_polynomials, S1, TINY};

/// (sin 2πu, cos 2πu) of every u in [0, 1), as `geometry::sin_cos_turns` computes them: k =
/// round(4u), r = u − k/4, x = 2πr ∈ [−π/4, π/4], musl's kernels at (x, 0), quadrant k.
/// Elements with u outside [0, 1) give unspecified values (the callers recompute them).
#[inline(always)]
pub(super) fn sin_cos_turns_block(u: &[f64], s: &mut [f64], c: &mut [f64]) {
    for ((&u, s), c) in u.iter().zip(s.iter_mut()).zip(c.iter_mut()) {
        // 4u + 0.5 ∈ [0.5, 4.5): its floor is the scalar path's truncation through i64 (a
        // packed round, where a saturating conversion to i32 goes lane by lane).
        let k = (4.0 * u + 0.5).floor();
        let r = u - 0.25 * k;
        let x = std::f64::consts::TAU * r;
        // k_sin(x, 0, 0) and k_cos(x, 0)
        let z = x * x;
        let (rs, rc) = kernel_polynomials(z);
        let v = z * x;
        let sin = x + v * (S1 + z * rs);
        let hz = 0.5 * z;
        let w1 = 1.0 - hz;
        let cos = w1 + (((1.0 - w1) - hz) + (z * rc - x * 0.0));
        let tiny = x.abs() < TINY;
        let (sin, cos) = if tiny { (x, 1.0) } else { (sin, cos) };
        // Quadrant k mod 4 (k ∈ {0, …, 4}): 0 (s, c), 1 (c, −s), 2 (−s, −c), 3 (−c, s).
        // `|` and `^`, not `||` and `!=`: no short-circuit branch, so the loop vectorizes
        // (checked in the asm: packed mulpd/addpd on the baseline x86-64 target).
        let odd = (k == 1.0) | (k == 3.0);
        let high = (k == 2.0) | (k == 3.0);
        let (a, b) = if odd { (cos, sin) } else { (sin, cos) };
        *s = if high { -a } else { a };
        *c = if odd ^ high { -b } else { b };
    }
}

/// `out[i]` = the normal of slope radius(u[i][1]) · (sx cos 2πu[i][0], sy sin 2πu[i][0]), as the
/// scalar `sample_wm` of an elliptic model computes it: `radius2_block` fills the squared slope
/// radius of each u₁ (written as a loop the compiler may vectorize, or calling a scalar
/// function per element), and `scalar` is the model's `sample_wm` for the elements outside the
/// fast path.
///
/// **Dispatch.** The loop runs through `pulp::Arch::dispatch` (safe runtime dispatch; pulp is
/// the SIMD layer of faer): on a CPU with AVX-512 (x86-64-v4) or AVX2 + FMA (x86-64-v3) it is
/// compiled for it, so the straight-line loops vectorize 8 or 4 f64 lanes wide instead of
/// baseline SSE2's 2; elsewhere
/// (or on other architectures) the same source compiled for the baseline. Both give the same
/// bits: Rust never contracts a·b + c into an FMA, and packed +, −, ×, ÷, √ and conversions
/// round as scalar ones (the test `dispatched_and_baseline_paths_agree_bit_for_bit`).
///
/// # Panics
/// If `u` and `out` differ in length.
pub(crate) fn sample_elliptic_batch(
    sx: f64,
    sy: f64,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    radius2_block: impl Fn(&[f64], &mut [f64]),
    scalar: impl Fn([f64; 2]) -> Vec3,
) {
    sample_elliptic_batch_on(pulp::Arch::new(), sx, sy, u, out, radius2_block, scalar)
}

/// [`sample_elliptic_batch`] through the instruction set `arch` (`pulp::Arch::Scalar`: the
/// baseline path, for the tests that compare the two).
#[inline(always)]
fn sample_elliptic_batch_on<R, S>(
    arch: pulp::Arch,
    sx: f64,
    sy: f64,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    radius2_block: R,
    scalar: S,
) where
    R: Fn(&[f64], &mut [f64]),
    S: Fn([f64; 2]) -> Vec3,
{
    let kernel = Elliptic {
        sx,
        sy,
        radius2_block: &radius2_block,
    };
    dispatch_blocks(arch, "sample_wm_batch", u, out, &kernel, scalar)
}

/// [`for_each_block`] with `kernel` through `pulp::Arch::dispatch`: `with_simd` is
/// instantiated once per instruction set, with the block loop and the kernel inlined into it.
///
/// # Panics
/// If `u` and `out` differ in length (the message names `method`).
#[inline(always)]
pub(super) fn dispatch_blocks<K: BlockKernel, S: Fn([f64; 2]) -> Vec3>(
    arch: pulp::Arch,
    method: &str,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    kernel: &K,
    scalar: S,
) {
    assert_eq!(u.len(), out.len(), "{method}: u and out differ in length");
    /// The loop as a `pulp::WithSimd` operation.
    struct Op<'a, K, S> {
        u: &'a [[f64; 2]],
        out: &'a mut [Vec3],
        kernel: &'a K,
        scalar: S,
    }
    impl<K: BlockKernel, S: Fn([f64; 2]) -> Vec3> pulp::WithSimd for Op<'_, K, S> {
        type Output = ();
        #[inline(always)]
        fn with_simd<Simd: pulp::Simd>(self, _simd: Simd) {
            for_each_block(self.u, self.out, &self.scalar, self.kernel)
        }
    }
    arch.dispatch(Op {
        u,
        out,
        kernel,
        scalar,
    })
}

/// One block's computation for [`for_each_block`]: the normals' components of the pairs
/// (u₀[i], u₁[i]) into (x, y, z), and whether each element is on the fast path. A trait with an
/// `#[inline(always)]` method rather than a closure, which would be compiled for the baseline
/// (without the dispatch target's features) unless the inliner chose to inline it: the
/// closure form ran at half the speed under AVX-512.
pub(super) trait BlockKernel {
    /// The computation; every slice has the block's length.
    fn run(
        &self,
        u0: &[f64],
        u1: &[f64],
        x: &mut [f64],
        y: &mut [f64],
        z: &mut [f64],
        fast: &mut [bool],
    );
}

/// The elliptic samplers' block: squared slope radius, (cos, sin) 2πu₀ scaled by the axis
/// scales, the normal of the slope.
struct Elliptic<'a, R> {
    sx: f64,
    sy: f64,
    radius2_block: &'a R,
}

impl<R: Fn(&[f64], &mut [f64])> BlockKernel for Elliptic<'_, R> {
    #[inline(always)]
    fn run(
        &self,
        u0: &[f64],
        u1: &[f64],
        x: &mut [f64],
        y: &mut [f64],
        z: &mut [f64],
        fast: &mut [bool],
    ) {
        let (sx, sy) = (self.sx, self.sy);
        // The squared slope radius into z, (sin, cos) 2πu₀ into (y, x).
        (self.radius2_block)(u1, z);
        sin_cos_turns_block(u0, y, x);
        // Zipped slices of one length (no bounds checks, so the loop vectorizes).
        for ((((c, s), r), fast), &u0) in x
            .iter_mut()
            .zip(y.iter_mut())
            .zip(z.iter_mut())
            .zip(fast.iter_mut())
            .zip(u0)
        {
            let radius = r.sqrt();
            // elliptic_direction, then normal_from_slopes' finite branch.
            let (p, q) = (radius * (sx * *c), radius * (sy * *s));
            let inv = 1.0 / (1.0 + p * p + q * q).sqrt();
            let (mx, my) = (p * inv, q * inv);
            (*c, *s, *r) = (mx, my, inv);
            // The scalar path's other branches: u₀ outside [0, 1) (a general argument
            // reduction), an infinite or NaN slope (the horizon branch); either leaves m_x or
            // m_y non-finite here or is flagged by u₀. (`&`, not `&&`: no branch.)
            *fast = (0.0..1.0).contains(&u0) & mx.is_finite() & my.is_finite();
        }
    }
}

/// The block structure every batch sampler shares: per block of [`BLOCK`] pairs, u split into
/// its components, the [`BlockKernel`] (straight-line loops writing the normals' components
/// and whether each element is on the fast path), the components interleaved into `out`, and the elements off the fast path recomputed by `scalar` (rare:
/// one predictable test per block, then the flagged elements).
#[inline(always)]
fn for_each_block(
    u: &[[f64; 2]],
    out: &mut [Vec3],
    scalar: &impl Fn([f64; 2]) -> Vec3,
    kernel: &impl BlockKernel,
) {
    let (mut u0, mut u1) = ([0.0; BLOCK], [0.0; BLOCK]);
    let (mut x, mut y, mut z) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
    let mut fast = [false; BLOCK];
    for (u, out) in u.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
        let n = u.len();
        for ((a, b), u) in u0.iter_mut().zip(u1.iter_mut()).zip(u) {
            (*a, *b) = (u[0], u[1]);
        }
        kernel.run(
            &u0[..n],
            &u1[..n],
            &mut x[..n],
            &mut y[..n],
            &mut z[..n],
            &mut fast[..n],
        );
        for (((m, &mx), &my), &mz) in out.iter_mut().zip(&x[..n]).zip(&y[..n]).zip(&z[..n]) {
            *m = [mx, my, mz];
        }
        if fast[..n].iter().fold(true, |all, &f| all & f) {
            continue;
        }
        for ((m, &fast), &u) in out.iter_mut().zip(&fast[..n]).zip(u) {
            if !fast {
                *m = scalar(u);
            }
        }
    }
}

/// For the batch samplers' tests: the distance of two doubles in units in the last place (the
/// count of doubles between them; 0 for two NaNs).
#[cfg(test)]
pub(super) fn ulps_apart(a: f64, b: f64) -> f64 {
    if a.is_nan() && b.is_nan() {
        return 0.0;
    }
    let key = |x: f64| {
        let bits = x.to_bits() as i64;
        if bits < 0 {
            i64::MIN - bits
        } else {
            bits
        }
    };
    (key(a) as i128 - key(b) as i128).unsigned_abs() as f64
}

/// For the batch samplers' tests: every dispatch path this CPU can run (the baseline, and
/// x86-64-v3 and -v4 where it has them).
#[cfg(test)]
pub(super) fn dispatch_paths() -> Vec<pulp::Arch> {
    let mut paths = vec![pulp::Arch::Scalar];
    #[cfg(target_arch = "x86_64")]
    {
        paths.extend(pulp::x86::V3::try_new().map(pulp::Arch::V3));
        paths.extend(pulp::x86::V4::try_new().map(pulp::Arch::V4));
    }
    paths
}

#[cfg(test)]
mod tests {
    use crate::geometry::sin_cos_turns;
    use crate::model::NormalSampler;
    use crate::ndf::student::Member;
    use crate::ndf::{Beckmann, Ggx, Student};

    /// u on [0, 1): a stride through it, the quadrant points and the doubles next to them,
    /// the tiny-angle branch, and arguments outside the fast path.
    fn arguments() -> Vec<[f64; 2]> {
        let mut u: Vec<f64> = (0..20_011).map(|i| i as f64 / 20_011.0).collect();
        for k in 0..=4 {
            let q = k as f64 / 8.0;
            for v in [q, q.next_up(), q.next_down(), k as f64 / 4.0] {
                u.extend([v, v.next_up(), v.next_down(), v + 1e-9, v - 1e-9]);
            }
        }
        u.extend([
            0.0,
            1e-300,
            5e-324,
            1e-10,
            2e-9,
            1.0f64.next_down(),
            0.25 + 1e-12,
        ]);
        let mut pairs: Vec<[f64; 2]> = Vec::new();
        for (i, &a) in u.iter().enumerate() {
            let b = u[(i * 7919) % u.len()];
            pairs.push([a, b]);
        }
        // Outside the fast path: u₀ ∉ [0, 1), u₁ = 1 (an infinite slope radius), NaN.
        for w in [
            [1.0, 0.3],
            [1.5, 0.3],
            [-0.25, 0.3],
            [0.3, 1.0],
            [f64::NAN, 0.5],
            [0.5, f64::NAN],
        ] {
            pairs.push(w);
        }
        pairs.retain(|p| p[1] <= 1.0 && !(p[1] < 0.0));
        pairs
    }

    fn same(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn sin_cos_block_is_the_scalar_sin_cos_turns() {
        let u: Vec<f64> = arguments()
            .iter()
            .map(|p| p[0])
            .filter(|u| (0.0..1.0).contains(u))
            .collect();
        let (mut s, mut c) = (vec![0.0; u.len()], vec![0.0; u.len()]);
        super::sin_cos_turns_block(&u, &mut s, &mut c);
        for i in 0..u.len() {
            let (ws, wc) = sin_cos_turns(u[i]);
            assert_eq!(
                (s[i].to_bits(), c[i].to_bits()),
                (ws.to_bits(), wc.to_bits()),
                "u = {:e}",
                u[i]
            );
        }
    }

    /// The dispatched loop (AVX-512 or AVX2 + FMA on a CPU that has it) and the baseline loop
    /// (`pulp::Arch::Scalar`, what a CPU without AVX2 runs) give the same bits, and both the
    /// scalar sampler's.
    #[test]
    fn dispatched_and_baseline_paths_agree_bit_for_bit() {
        let u = arguments();
        for (ax, ay) in [(0.3, 0.3), (0.02, 0.8)] {
            let ggx = Ggx::new(ax, ay).unwrap();
            let run = |arch: pulp::Arch| {
                let mut out = vec![[0.0; 3]; u.len()];
                super::sample_elliptic_batch_on(
                    arch,
                    ax,
                    ay,
                    &u,
                    &mut out,
                    |u1, r2| {
                        for (r2, &u1) in r2.iter_mut().zip(u1) {
                            *r2 = u1 / (1.0 - u1);
                        }
                    },
                    |u| ggx.sample_wm(u),
                );
                out
            };
            let (detected, baseline) = (run(pulp::Arch::new()), run(pulp::Arch::Scalar));
            for ((&u, a), b) in u.iter().zip(&detected).zip(&baseline) {
                let want = ggx.sample_wm(u);
                assert!(
                    same(*a, want) && same(*b, want),
                    "u = {u:?}: {a:?} {b:?} {want:?}"
                );
            }
        }
    }

    #[test]
    fn batch_samplers_agree_with_scalar_bit_for_bit() {
        let u = arguments();
        let samplers: Vec<(&str, Box<dyn NormalSampler>)> = vec![
            ("ggx 0.3", Box::new(Ggx::new(0.3, 0.3).unwrap())),
            ("ggx 0.02 0.8", Box::new(Ggx::new(0.02, 0.8).unwrap())),
            ("beckmann 0.3", Box::new(Beckmann::new(0.3, 0.3).unwrap())),
            (
                "beckmann 0.1 0.5",
                Box::new(Beckmann::new(0.1, 0.5).unwrap()),
            ),
            (
                "std 2.5",
                Box::new(Student::new(Member::Std, 2.5, 0.1, 0.4).unwrap()),
            ),
            (
                "std 40",
                Box::new(Student::new(Member::Std, 40.0, 0.3, 0.3).unwrap()),
            ),
        ];
        for (name, sampler) in &samplers {
            let mut out = vec![[0.0; 3]; u.len()];
            sampler.sample_wm_batch(&u, &mut out);
            // Also through an odd-sized slice (a partial block).
            let mut tail = vec![[0.0; 3]; 37];
            sampler.sample_wm_batch(&u[1000..1037], &mut tail);
            for (i, (&u, &m)) in u.iter().zip(&out).enumerate() {
                let want = sampler.sample_wm(u);
                assert!(same(m, want), "{name}, u = {u:?}: {m:?} vs {want:?}");
                if (1000..1037).contains(&i) {
                    assert!(same(tail[i - 1000], want), "{name}, u = {u:?}");
                }
            }
        }
    }
}
