//! GGX's batch visible-normal sampler: `Ggx::sample_wm_visible` (Heitz 2018, see
//! `ndf::ggx_visible`) over a block at one incidence, normalized by one reciprocal instead of
//! three divisions, within [`MAX_ULPS`] of the scalar sampler and the same bits on every
//! dispatch path.
//!
//! Per sample the scalar sampler computes r = √u₀ and (sin, cos) 2πu₁, the stretched normal
//! v = (αx N_h,x, αy N_h,y, max(0, N_h,z)) from them and the frame (three square roots: r,
//! √(1 − t₁²) and the lift), and m = v/ℓ with ℓ = √(v·v): four square roots and three
//! divisions. The batch computes (sin, cos) 2πu₁ a block at a time
//! (`batch::sin_cos_turns_block`, the scalar bits), v by the scalar's own code
//! ([`VisibleFrame::unnormalized`], so v is the scalar's v bit for bit), and then
//!
//! ```text
//! k = 1/ℓ = 1/√(v·v),   m = (v_x·k, v_y·k, v_z·k)
//! ```
//!
//! one division and three products where the scalar has three divisions. **Error bound.** ℓ is
//! the scalar's ℓ; k = (1/ℓ)(1 + δ) with |δ| ≤ 2⁻⁵³, so the exact v_i·k differs from the exact
//! v_i/ℓ by less than |v_i/ℓ|·2⁻⁵³ < 1 ulp, and the two correctly rounded results are at most
//! 1 ulp apart (2 where v_i·k rounds across a power of two): [`MAX_ULPS`] = 2, measured 1 (the
//! test `within_max_ulps_of_the_scalar_sampler`, over α from 1e-4 to 3 and (0.02, 0.8), normal
//! to grazing incidence (wi_z = 1e-300), u at 0, 2⁻³², 1 − 2⁻³² and 1 − 2⁻⁵³, where the lift
//! vanishes; also 1 over 2²⁰ random u at five incidences and α up to (1e-7, 1e4)). Only +, −,
//! ×, ÷ and √, each correctly rounded and never contracted into an FMA, so every dispatch path
//! (AVX-512, AVX2 + FMA, baseline) gives the same bits (the test
//! `every_path_gives_the_same_bits`). Elements with u₁ ∉ [0, 1) (the scalar sin/cos's general
//! reduction) are the scalar sampler's; v·v = 0 (a normal on the horizon at α → 0) is NaN on
//! both paths (0/0 and 0·∞), so no range guard is needed.
//!
//! **Cost.** On a 2-core machine (AMD EPYC Zen 4, 2 cores, shared; one block of 256 at
//! GGX α = 0.3, θi = 1 rad: the bench `chi2_stages/ggx_visible_sampler`, `--quick`) this form
//! takes 1.23–1.30 µs a block on the AVX-512 path against the three divisions' 1.39–1.58 µs.
//! The AVX2 and baseline paths are a little slower there (1.84 against 1.77 µs and 4.16
//! against 4.08 µs, best of 30 in a timing loop): a Zen 4 divides four lanes cheaply.
//!
//! **Why not reciprocal square roots by Newton steps** (f32's 1/√a, then two in f64; tried for
//! GGX's normal batch and removed, `Ggx::sample_wm_batch`).
//! In that timing loop on the AVX-512 path, normalizing by it took 1.40 µs a block against the
//! exact form's 1.37 (this form: 1.23): the f32 start (conversions, `vsqrtps`, `vdivps`) and
//! the Newton products cost more than an f64 √ and ÷ on that divider. And the other three
//! square roots must stay exact: they feed cancellations (1 − t₁² − t₂², and N_h = t₁T₁ +
//! t₂T₂ + lift·V_h, whose components vanish along curves of u), so an ulp there becomes up to
//! 10⁷ ulps of a small component (measured with all four roots by Newton steps, which also
//! took 2.38 µs): no per-component bound would hold. Only the normalization comes after every
//! cancellation.

use super::batch::{dispatch_blocks, sin_cos_turns_block, BlockKernel};
use super::ggx_visible::VisibleFrame;
use crate::geometry::Vec3;

/// The most ulps a component of `Ggx::sample_wm_visible_batch` differs from
/// `Ggx::sample_wm_visible`'s.
pub const MAX_ULPS: f64 = 2.0;

/// `out[i]` = GGX's visible normal of `u[i]` in the incidence `frame`, within [`MAX_ULPS`] of
/// `scalar(u[i])`, the model's `sample_wm_visible` at the same incidence, which also gives the
/// elements outside the fast path (u₁ ∉ [0, 1)).
///
/// # Panics
/// If `u` and `out` differ in length.
pub(crate) fn sample_visible_batch(
    frame: &VisibleFrame,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    scalar: impl Fn([f64; 2]) -> Vec3,
) {
    sample_visible_batch_on(pulp::Arch::new(), frame, u, out, scalar)
}

/// [`sample_visible_batch`] through the instruction set `arch`.
#[inline(always)]
fn sample_visible_batch_on<S: Fn([f64; 2]) -> Vec3>(
    arch: pulp::Arch,
    frame: &VisibleFrame,
    u: &[[f64; 2]],
    out: &mut [Vec3],
    scalar: S,
) {
    dispatch_blocks(
        arch,
        "sample_wm_visible_batch",
        u,
        out,
        &Visible(frame),
        scalar,
    )
}

/// The block: (sin, cos) 2πu₁, then per element the stretched normal at √u₀ and its
/// normalization by one reciprocal.
struct Visible<'a>(&'a VisibleFrame);

impl BlockKernel for Visible<'_> {
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
        // (sin, cos) 2πu₁ into (y, z), then the normal over them.
        sin_cos_turns_block(u1, y, z);
        for ((((x, s), c), fast), (&u0, &u1)) in x
            .iter_mut()
            .zip(y.iter_mut())
            .zip(z.iter_mut())
            .zip(fast.iter_mut())
            .zip(u0.iter().zip(u1))
        {
            let v = self.0.unnormalized(u0.sqrt(), *s, *c);
            // ℓ² as the scalar `normalize` sums it.
            let k = 1.0 / (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            (*x, *s, *c) = (v[0] * k, v[1] * k, v[2] * k);
            *fast = (0.0..1.0).contains(&u1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::from_spherical;
    use crate::model::VisibleNormalSampler;
    use crate::ndf::batch::{dispatch_paths, ulps_apart};
    use crate::ndf::Ggx;

    /// u₀ and u₁ on a stride through [0, 1), on the 32-bit grid's ends (u₀ → 1: the lift
    /// vanishes), the quadrant points and the doubles next to them, and outside the fast path.
    fn arguments() -> Vec<[f64; 2]> {
        let mut v: Vec<f64> = (0..4001).map(|i| i as f64 / 4001.0).collect();
        let tiny = 2f64.powi(-32);
        v.extend([0.0, tiny, 2.0 * tiny, 1.0 - tiny, 1.0 - 2.0 * tiny]);
        for k in 0..4 {
            let q = k as f64 / 4.0 + 0.125;
            for w in [k as f64 / 4.0, q] {
                v.extend([w, w.next_up(), w.next_down().max(0.0)]);
            }
        }
        v.extend([1e-300, 1.0 - f64::EPSILON / 2.0]);
        let mut u = Vec::new();
        for (i, &a) in v.iter().enumerate() {
            for j in [0, 1, 7, 1999] {
                u.push([a, v[(i * 7919 + j) % v.len()]]);
            }
        }
        u.extend([
            [0.3, 1.0],
            [0.3, 1.5],
            [0.3, -0.25],
            [f64::NAN, 0.5],
            [0.5, f64::NAN],
        ]);
        u
    }

    /// Normal, oblique and grazing incidences, the last with wi_z = 1e-300.
    fn incidences() -> [Vec3; 6] {
        [
            [0.0, 0.0, 1.0],
            from_spherical(0.7, 0.4),
            from_spherical(1.0, 0.0),
            from_spherical(1.5, 2.9),
            from_spherical(std::f64::consts::FRAC_PI_2 - 1e-6, -1.2),
            [1.0, 0.0, 1e-300],
        ]
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
            (1.7, 0.5),
        ] {
            let ggx = Ggx::new(ax, ay).unwrap();
            for wi in incidences() {
                let mut out = vec![[0.0; 3]; u.len()];
                ggx.sample_wm_visible_batch(wi, &u, &mut out);
                for (&u, m) in u.iter().zip(&out) {
                    let want = ggx.sample_wm_visible(wi, u);
                    for k in 0..3 {
                        let d = ulps_apart(m[k], want[k]);
                        worst = worst.max(d);
                        assert!(
                            d <= MAX_ULPS,
                            "α ({ax}, {ay}), wi {wi:?}, u {u:?}: {m:?} vs {want:?}"
                        );
                    }
                }
            }
            // Below the horizon: NaN, as the scalar sampler.
            let mut out = vec![[0.0; 3]; 3];
            ggx.sample_wm_visible_batch([0.0, 0.6, -0.8], &u[..3], &mut out);
            assert!(out.iter().flatten().all(|v| v.is_nan()), "{out:?}");
        }
        assert!(worst > 0.0, "the batch is no longer the reciprocal form");
    }

    /// The dispatched paths (AVX-512, AVX2 + FMA where the CPU has them) and the baseline give
    /// the same bits, whole and in odd-sized slices (partial blocks), and the trait method is
    /// the dispatched path.
    #[test]
    fn every_path_gives_the_same_bits() {
        let u = arguments();
        let paths = dispatch_paths();
        let same = |p: &Vec3, q: &Vec3| p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits());
        for (ax, ay) in [(0.3, 0.3), (0.02, 0.8), (1.7, 0.5)] {
            let ggx = Ggx::new(ax, ay).unwrap();
            for wi in incidences() {
                let frame = VisibleFrame::new(ax, ay, wi).expect("visible incidence");
                let run = |arch: pulp::Arch, u: &[[f64; 2]]| {
                    let mut out = vec![[0.0; 3]; u.len()];
                    sample_visible_batch_on(arch, &frame, u, &mut out, |u| {
                        ggx.sample_wm_visible(wi, u)
                    });
                    out
                };
                let base = run(pulp::Arch::Scalar, &u);
                let mut via_trait = vec![[0.0; 3]; u.len()];
                ggx.sample_wm_visible_batch(wi, &u, &mut via_trait);
                for (i, (a, b)) in via_trait.iter().zip(&base).enumerate() {
                    assert!(same(a, b), "trait, wi {wi:?}, u {:?}: {a:?} vs {b:?}", u[i]);
                }
                for &arch in &paths {
                    let got = run(arch, &u);
                    let tail = run(arch, &u[1000..1037]);
                    for (i, (a, b)) in got.iter().zip(&base).enumerate() {
                        assert!(
                            same(a, b),
                            "{arch:?}, wi {wi:?}, u {:?}: {a:?} vs {b:?}",
                            u[i]
                        );
                        if (1000..1037).contains(&i) {
                            assert!(same(&tail[i - 1000], b), "{arch:?}, u {:?}", u[i]);
                        }
                    }
                }
            }
        }
    }
}
