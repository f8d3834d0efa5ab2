//! The reference BSDFs' sampled directions over a block of sampled microfacet normals
//! (`sample_wo_batch`, the BSDF chi-square's hot loop). For the rough dielectric, per element the Fresnel
//! reflectance at wi·m, the lobe choice by u₀, the reflected or refracted direction and its
//! side test — [`scatter_lane`], which the scalar `Dielectric::scattered` calls too, so the two
//! are one computation — as straight-line loops over the block's components, written in
//! place into the output's x, y and z arrays ([`DirectionsMut`]), both
//! directions computed and one selected; for the conductor, the reflection and its side test
//! ([`reflect_lane`], the scalar's too). The loops vectorize (8 or 4 lanes under AVX-512 or
//! AVX2 through `pulp`'s safe runtime dispatch, 2 under baseline SSE2). The same bits on every
//! path and as the scalar: Rust never contracts into FMA, and packed +, −, ×, ÷, √, min and
//! compares round as scalar ones (the test `the_block_is_the_scalar_on_every_path`).

use super::directions::DirectionsMut;
use super::fresnel_block::lane as fresnel_lane;
use super::microfacet::{normal_ok, reflect, refract};
use crate::geometry::{dot, Vec3};

/// Elements per pass of the scatter (its lobe choices live on the stack).
const PASS: usize = 64;

/// The direction `Dielectric::scattered` makes of wi through the normal m with the lobe
/// choice `u0`, given the Fresnel reflectance and refracted cosine at wi·m and `eta`, the far
/// side's index over wi's: reflected (Walter eq 39) if u₀ < F, else refracted (eq 40); and
/// whether it is a sample — finite, off the surface, on the chosen lobe's side. Both
/// directions are computed and one selected (no branch).
#[inline(always)]
pub(super) fn scatter_lane(
    wi: Vec3,
    m: Vec3,
    u0: f64,
    eta: f64,
    (reflectance, cos_t): (f64, f64),
) -> (Vec3, bool) {
    let reflected = u0 < reflectance;
    let (r, t) = (reflect(wi, m), refract(wi, m, eta, cos_t));
    let wo = [0, 1, 2].map(|k| if reflected { r[k] } else { t[k] });
    let finite = wo[0].is_finite() & wo[1].is_finite() & wo[2].is_finite();
    // `&`, not `&&`: no branch.
    let ok = finite & ((wo[2] * wi[2] > 0.0) == reflected) & (wo[2] != 0.0);
    (wo, ok)
}

/// `out[k]` = the dielectric's sampled direction of the normal `m[k]` sampled at `v` = wi⁺
/// (a failed sample where [`normal_ok`] fails: a failed normal) with the lobe choice
/// `u[k][0]`, from `wi` into a far side of index `eta` over wi's: `Dielectric::scattered` bit
/// for bit.
///
/// # Panics
/// If `u`, `m` and `out` differ in length.
pub(super) fn scatter_block(
    (wi, v): (Vec3, Vec3),
    eta: f64,
    u: &[[f64; 3]],
    m: &[Vec3],
    out: DirectionsMut<'_>,
) {
    scatter_block_on(pulp::Arch::new(), (wi, v), eta, u, m, out)
}

/// [`scatter_block`] through the instruction set `arch` (`pulp::Arch::Scalar`: baseline).
fn scatter_block_on(
    arch: pulp::Arch,
    (wi, v): (Vec3, Vec3),
    eta: f64,
    u: &[[f64; 3]],
    m: &[Vec3],
    out: DirectionsMut<'_>,
) {
    let n = u.len();
    assert!(
        m.len() == n && out.len() == n,
        "scatter_block: u, m and out differ in length"
    );
    /// The loop as a `pulp::WithSimd` operation (instantiated per instruction set).
    struct Op<'a> {
        wi: Vec3,
        v: Vec3,
        eta: f64,
        u: &'a [[f64; 3]],
        m: &'a [Vec3],
        out: DirectionsMut<'a>,
    }
    impl pulp::WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) {
            let (wi, v, eta) = (self.wi, self.v, self.eta);
            // fresnel::dielectric's constants of η, as the block form takes them.
            let (e2, em1) = (eta * eta, (eta - 1.0) * (eta + 1.0));
            let [x, y, z] = self.out.xyz;
            split(self.m, [&mut *x, &mut *y, &mut *z]);
            // The lobe choices apart, a pass at a time: read from the u triples in the loop,
            // they kept it from vectorizing.
            let mut u0 = [0.0; PASS];
            let passes = (x.chunks_mut(PASS).zip(y.chunks_mut(PASS)))
                .zip(z.chunks_mut(PASS).zip(self.out.sampled.chunks_mut(PASS)));
            for (((x, y), (z, sampled)), u) in passes.zip(self.u.chunks(PASS)) {
                for (u0, u) in u0.iter_mut().zip(u) {
                    *u0 = u[0];
                }
                // Zipped slices of one length: no bounds checks, so the loop vectorizes.
                let lanes = x.iter_mut().zip(y.iter_mut()).zip(z.iter_mut());
                for ((((x, y), z), sampled), &u0) in lanes.zip(sampled).zip(&u0[..u.len()]) {
                    let m = [*x, *y, *z];
                    let fresnel = fresnel_lane(dot(wi, m), eta, e2, em1);
                    let (wo, ok) = scatter_lane(wi, m, u0, eta, fresnel);
                    (*x, *y, *z) = (wo[0], wo[1], wo[2]);
                    *sampled = normal_ok(v, m) & ok;
                }
            }
        }
    }
    arch.dispatch(Op {
        wi,
        v,
        eta,
        u,
        m,
        out,
    })
}

/// The components of `m` into `xyz` (as long), for the passes that load whole vectors.
#[inline(always)]
fn split(m: &[Vec3], [x, y, z]: [&mut [f64]; 3]) {
    for (((m, x), y), z) in m.iter().zip(x).zip(y).zip(z) {
        (*x, *y, *z) = (m[0], m[1], m[2]);
    }
}

/// The direction the conductor's `sample` reflects wi into about the normal m (Walter eq 39),
/// and whether it is a sample: finite and above the surface. No branch.
#[inline(always)]
pub(super) fn reflect_lane(wi: Vec3, m: Vec3) -> (Vec3, bool) {
    let wo = reflect(wi, m);
    let finite = wo[0].is_finite() & wo[1].is_finite() & wo[2].is_finite();
    (wo, finite & (wo[2] > 0.0))
}

/// `out[k]` = the conductor's sampled direction of the normal `m[k]` sampled at `v` = wi⁺
/// (a failed sample where [`normal_ok`] or [`reflect_lane`] fails), as its scalar `sample`
/// makes it, bit for bit, in one vectorized pass.
///
/// # Panics
/// If `m` and `out` differ in length.
pub(super) fn reflect_block((wi, v): (Vec3, Vec3), m: &[Vec3], out: DirectionsMut<'_>) {
    reflect_block_on(pulp::Arch::new(), (wi, v), m, out)
}

/// [`reflect_block`] through the instruction set `arch`.
fn reflect_block_on(arch: pulp::Arch, (wi, v): (Vec3, Vec3), m: &[Vec3], out: DirectionsMut<'_>) {
    assert_eq!(
        m.len(),
        out.len(),
        "reflect_block: m and out differ in length"
    );
    /// The loop as a `pulp::WithSimd` operation (instantiated per instruction set).
    struct Op<'a> {
        wi: Vec3,
        v: Vec3,
        m: &'a [Vec3],
        out: DirectionsMut<'a>,
    }
    impl pulp::WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) {
            let (wi, v) = (self.wi, self.v);
            let [x, y, z] = self.out.xyz;
            split(self.m, [&mut *x, &mut *y, &mut *z]);
            let lanes = x.iter_mut().zip(y.iter_mut()).zip(z.iter_mut());
            for (((x, y), z), sampled) in lanes.zip(self.out.sampled) {
                let m = [*x, *y, *z];
                let (wo, ok) = reflect_lane(wi, m);
                (*x, *y, *z) = (wo[0], wo[1], wo[2]);
                *sampled = normal_ok(v, m) & ok;
            }
        }
    }
    arch.dispatch(Op { wi, v, m, out })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::directions::Directions;
    use crate::bsdf::fresnel::dielectric;
    use crate::bsdf::microfacet::upper;
    use crate::geometry::from_spherical;

    /// The scalar: `Dielectric::scattered`'s computation.
    fn scalar(wi: Vec3, m: Vec3, u0: f64, eta: f64) -> Option<Vec3> {
        let f = dielectric(dot(wi, m), eta);
        let (wo, ok) = scatter_lane(wi, m, u0, eta, (f.reflectance, f.cos_t));
        ok.then_some(wo)
    }

    #[test]
    fn the_block_is_the_scalar_on_every_path() {
        // Weyl sequences: k·a mod 1 for irrational a, evenly spread and reproducible.
        let weyl = |k: usize, a: f64| (k as f64 * a).fract();
        for eta in [1.5, 1.0 / 1.5, 1.0001, 1.0 / 1.0001, 4.0, 0.25] {
            for theta in [0.0, 0.3, 1.0, 1.5, 1.57, 3.0, 2.2] {
                let wi = from_spherical(theta, 0.7);
                let v = upper(wi);
                // Normals over the whole sphere (wi·m of either sign, grazing, total internal
                // reflection), exact ones, failed samples and non-finite ones; u₀ at the ends.
                let mut m: Vec<Option<Vec3>> = (0..2000)
                    .map(|k| {
                        let (a, b) = (weyl(k, 0.618_033_988_7), weyl(k, 0.414_213_562_4));
                        Some(from_spherical(a * 3.2, b * 6.3))
                    })
                    .collect();
                m.extend([None, Some([0.0, 0.0, 1.0]), Some([f64::NAN, 0.0, 1.0])]);
                m.extend([
                    Some(wi),
                    Some([-wi[0], -wi[1], -wi[2]]),
                    Some([1.0, 0.0, 0.0]),
                ]);
                let u: Vec<[f64; 3]> = (0..m.len())
                    .map(|k| match k % 7 {
                        0 => [0.0, 0.5, 0.5],
                        1 => [1.0f64.next_down(), 0.5, 0.5],
                        _ => [weyl(k, 0.732_050_807_6), 0.5, 0.5],
                    })
                    .collect();
                for arch in [pulp::Arch::new(), pulp::Arch::Scalar] {
                    for range in [0..m.len(), 5..72] {
                        // A failed normal as the sampler may leave it: anything (zero here).
                        let normals: Vec<Vec3> = m[range.clone()]
                            .iter()
                            .map(|m| m.unwrap_or([0.0; 3]))
                            .collect();
                        let mut out = Directions::from_options(&vec![Some([9.0; 3]); range.len()]);
                        let u = &u[range.clone()];
                        scatter_block_on(arch, (wi, v), eta, u, &normals, out.as_mut());
                        for (k, got) in range.clone().zip(out.iter()) {
                            let want = m[k]
                                .filter(|&m| normal_ok(v, m))
                                .and_then(|m| scalar(wi, m, u[k - range.start][0], eta));
                            let bits = |w: &Option<Vec3>| w.map(|w| w.map(f64::to_bits));
                            assert_eq!(bits(&got), bits(&want), "η {eta}, θ {theta}, m {:?}", m[k]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_reflection_block_is_the_scalar_on_every_path() {
        let weyl = |k: usize, a: f64| (k as f64 * a).fract();
        for theta in [0.0, 0.3, 1.0, 1.5, 1.57] {
            let wi = from_spherical(theta, 0.7);
            let v = upper(wi);
            let mut m: Vec<Vec3> = (0..2000)
                .map(|k| {
                    let (a, b) = (weyl(k, 0.618_033_988_7), weyl(k, 0.414_213_562_4));
                    from_spherical(a * 3.2, b * 6.3)
                })
                .collect();
            m.extend([[0.0, 0.0, 1.0], [f64::NAN, 0.0, 1.0], wi, [1.0, 0.0, 0.0]]);
            for arch in [pulp::Arch::new(), pulp::Arch::Scalar] {
                for range in [0..m.len(), 5..72] {
                    let mut out = Directions::from_options(&vec![Some([9.0; 3]); range.len()]);
                    reflect_block_on(arch, (wi, v), &m[range.clone()], out.as_mut());
                    for (k, got) in range.clone().zip(out.iter()) {
                        let want = Some(m[k]).filter(|&m| normal_ok(v, m)).and_then(|m| {
                            let (wo, ok) = reflect_lane(wi, m);
                            ok.then_some(wo)
                        });
                        let bits = |w: &Option<Vec3>| w.map(|w| w.map(f64::to_bits));
                        assert_eq!(bits(&got), bits(&want), "θ {theta}, m {:?}", m[k]);
                    }
                }
            }
        }
    }
}
