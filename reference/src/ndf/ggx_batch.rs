//! GGX's batch normal sampler (issue 26): the slope-space inversion of `Ggx::sample_wm`
//! rewritten without its two divisions and two square roots in f64 — the chi-square's hot loop
//! spent half its sampler time waiting on the divider — and within [`MAX_ULPS`] of it.
//!
//! The scalar sampler computes r = √(u₁/(1 − u₁)), (p, q) = r·(αx cos 2πu₀, αy sin 2πu₀) and
//! m = (p, q, 1)/√(1 + p² + q²). With (dx, dy) = (αx cos, αy sin), g = dx² + dy², v = 1 − u₁
//! and d = v + g·u₁ = v(1 + r²g), the same normal is
//!
//! ```text
//! m = (dx·k, dy·k, m_z),   k = √(u₁/d) = u₁/√(u₁·d),   m_z = √(v/d) = v/√(v·d),
//! ```
//!
//! two reciprocal square roots and products. Each reciprocal square root starts from f32 (a
//! conversion, a square root and a division, correctly rounded: 8 or 16 lanes wide where f64
//! has 4 or 8, and far shorter) and takes two Newton steps y ← y(3/2 − ½·a·y²) in f64:
//! relative error 1e-7 → 1e-14 → rounding. Only +, −, ×, ÷, √ and conversions, each
//! correctly rounded and never contracted into an FMA, so every dispatch path (AVX-512,
//! AVX2 + FMA, baseline) gives the same bits (the test `every_path_gives_the_same_bits`); the
//! scalar sampler differs by at most [`MAX_ULPS`] per component (the test
//! `within_max_ulps_of_the_scalar_sampler`). Elements outside the fast path (u₀ ∉ [0, 1),
//! u₁·d or v·d outside f32's comfortable range [1e-30, 1e30], e.g. u₁ = 0 or 1, NaN) are
//! the scalar sampler's.

use super::batch::{dispatch_blocks, sin_cos_turns_block, BlockKernel};
use crate::geometry::Vec3;

/// The most ulps a component of `sample_ggx_batch` differs from `Ggx::sample_wm`'s.
pub const MAX_ULPS: f64 = 8.0;

/// `out[i]` = GGX's normal of `u[i]` (roughness αx = `sx`, αy = `sy`), within [`MAX_ULPS`] of
/// `scalar(u[i])`, the model's `sample_wm`, which also gives the elements outside the fast path.
///
/// # Panics
/// If `u` and `out` differ in length.
pub(crate) fn sample_ggx_batch(
    sx: f64,
    sy: f64,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    scalar: impl Fn([f64; 2]) -> Vec3,
) {
    sample_ggx_batch_on(pulp::Arch::new(), sx, sy, u, out, scalar)
}

/// [`sample_ggx_batch`] through the instruction set `arch`.
#[inline(always)]
fn sample_ggx_batch_on<S: Fn([f64; 2]) -> Vec3>(
    arch: pulp::Arch,
    sx: f64,
    sy: f64,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    scalar: S,
) {
    dispatch_blocks(arch, "sample_wm_batch", u, out, &Kernel { sx, sy }, scalar)
}

/// The block: (sin, cos) 2πu₀, then the normal by the reciprocal square roots.
struct Kernel {
    sx: f64,
    sy: f64,
}

/// The range of u₁·d and v·d where the f32 start is a normal number with room to spare.
const RANGE: [f64; 2] = [1e-30, 1e30];

impl BlockKernel for Kernel {
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
        // (sin, cos) 2πu₀ into (y, x).
        sin_cos_turns_block(u0, y, x);
        for (((((c, s), mz), fast), &u0), &u1) in x
            .iter_mut()
            .zip(y.iter_mut())
            .zip(z.iter_mut())
            .zip(fast.iter_mut())
            .zip(u0)
            .zip(u1)
        {
            let (dx, dy) = (sx * *c, sy * *s);
            let g = dx * dx + dy * dy;
            let v = 1.0 - u1;
            let d = v + g * u1;
            let (a, b) = (u1 * d, v * d);
            let k = u1 * rsqrt(a);
            (*c, *s, *mz) = (dx * k, dy * k, v * rsqrt(b));
            let in_range = |t: f64| (RANGE[0]..=RANGE[1]).contains(&t);
            // `&`, not `&&`: no branch.
            *fast = (0.0..1.0).contains(&u0) & in_range(a) & in_range(b);
        }
    }
}

/// 1/√a for a in [`RANGE`]: f32's correctly rounded 1/√a, then two Newton steps in f64.
#[inline(always)]
fn rsqrt(a: f64) -> f64 {
    let y = f64::from(1.0f32 / (a as f32).sqrt());
    let newton = |y: f64| y * (1.5 - 0.5 * (a * y * y));
    newton(newton(y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::NormalSampler;
    use crate::ndf::batch::{dispatch_paths, ulps_apart};
    use crate::ndf::Ggx;

    /// u₀ and u₁ on a stride through [0, 1), on the 32-bit grid's ends, the quadrant points,
    /// and outside the fast path.
    fn arguments() -> Vec<[f64; 2]> {
        let mut v: Vec<f64> = (0..4001).map(|i| i as f64 / 4001.0).collect();
        let tiny = 2f64.powi(-32);
        v.extend([
            0.0,
            tiny,
            2.0 * tiny,
            1.0 - tiny,
            1.0 - 2.0 * tiny,
            0.25,
            0.5,
            0.75,
        ]);
        v.extend([1e-300, 1.0 - f64::EPSILON / 2.0, 1.0, f64::NAN]);
        let mut u = Vec::new();
        for (i, &a) in v.iter().enumerate() {
            for j in [0, 1, 7, 1999] {
                u.push([a, v[(i * 7919 + j) % v.len()]]);
            }
        }
        u.extend([[1.5, 0.3], [-0.25, 0.3]]);
        u
    }

    #[test]
    fn within_max_ulps_of_the_scalar_sampler() {
        let u = arguments();
        let mut worst = 0.0f64;
        for (ax, ay) in [
            (0.3, 0.3),
            (0.02, 0.8),
            (1.0, 1.0),
            (1e-4, 1e-4),
            (3.0, 0.5),
        ] {
            let ggx = Ggx::new(ax, ay).unwrap();
            let mut out = vec![[0.0; 3]; u.len()];
            ggx.sample_wm_batch(&u, &mut out);
            for (&u, m) in u.iter().zip(&out) {
                let want = ggx.sample_wm(u);
                for k in 0..3 {
                    let d = ulps_apart(m[k], want[k]);
                    worst = worst.max(d);
                    assert!(d <= MAX_ULPS, "α ({ax}, {ay}), u {u:?}: {m:?} vs {want:?}");
                }
            }
        }
        assert!(worst > 0.0, "the batch is no longer the rsqrt form");
    }

    #[test]
    fn every_path_gives_the_same_bits() {
        let u = arguments();
        let paths = dispatch_paths();
        for (ax, ay) in [(0.3, 0.3), (0.02, 0.8)] {
            let ggx = Ggx::new(ax, ay).unwrap();
            let run = |arch: pulp::Arch, u: &[[f64; 2]]| {
                let mut out = vec![[0.0; 3]; u.len()];
                sample_ggx_batch_on(arch, ax, ay, u, &mut out, |u| ggx.sample_wm(u));
                out
            };
            let base = run(pulp::Arch::Scalar, &u);
            for &arch in &paths {
                let got = run(arch, &u);
                // Odd-sized slices (partial blocks) too.
                let tail = run(arch, &u[1000..1037]);
                for (i, (a, b)) in got.iter().zip(&base).enumerate() {
                    let same = |p: &Vec3, q: &Vec3| {
                        p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits())
                    };
                    assert!(same(a, b), "{arch:?}, u {:?}: {a:?} vs {b:?}", u[i]);
                    if (1000..1037).contains(&i) {
                        assert!(same(&tail[i - 1000], b), "{arch:?}, u {:?}", u[i]);
                    }
                }
            }
        }
    }
}
