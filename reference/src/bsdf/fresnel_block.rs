//! The dielectric Fresnel term over a block of cosines, for the reference dielectric's batch
//! of sampled directions (`Dielectric::sample_wo_batch`): the reflectance and refracted
//! cosine of [`super::fresnel::dielectric`], bit for bit, as one straight-line loop with the
//! total-internal-reflection and NaN cases selected rather than branched to, so that it
//! vectorizes (8 or 4 lanes under AVX-512 or AVX2 through `pulp`'s safe runtime dispatch, 2
//! under baseline SSE2; the same bits on every path: Rust never contracts into FMA, and packed
//! +, −, ×, ÷, √, min and compares round as scalar ones — the tests).

/// `reflectance[k]`, `cos_t[k]` = the `reflectance` and `cos_t` of
/// [`super::fresnel::dielectric`]`(cos_i[k], eta)`.
///
/// # Panics
/// If the slices differ in length.
pub fn dielectric_block(cos_i: &[f64], eta: f64, reflectance: &mut [f64], cos_t: &mut [f64]) {
    dielectric_block_on(pulp::Arch::new(), cos_i, eta, reflectance, cos_t);
}

/// [`dielectric_block`] through the instruction set `arch` (`pulp::Arch::Scalar`: baseline).
fn dielectric_block_on(
    arch: pulp::Arch,
    cos_i: &[f64],
    eta: f64,
    reflectance: &mut [f64],
    cos_t: &mut [f64],
) {
    assert!(
        cos_i.len() == reflectance.len() && cos_i.len() == cos_t.len(),
        "dielectric_block: cos_i, reflectance and cos_t differ in length"
    );
    /// The loop as a `pulp::WithSimd` operation (instantiated per instruction set).
    struct Op<'a> {
        cos_i: &'a [f64],
        eta: f64,
        reflectance: &'a mut [f64],
        cos_t: &'a mut [f64],
    }
    impl pulp::WithSimd for Op<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) {
            let eta = self.eta;
            let e2 = eta * eta;
            let em1 = (eta - 1.0) * (eta + 1.0);
            for ((&cos_i, r), t) in self
                .cos_i
                .iter()
                .zip(self.reflectance.iter_mut())
                .zip(self.cos_t.iter_mut())
            {
                (*r, *t) = lane(cos_i, eta, e2, em1);
            }
        }
    }
    arch.dispatch(Op {
        cos_i,
        eta,
        reflectance,
        cos_t,
    })
}

/// One element: `fresnel::dielectric`'s arithmetic in the same order, its branches as selects.
#[inline(always)]
pub(super) fn lane(cos_i: f64, eta: f64, e2: f64, em1: f64) -> (f64, f64) {
    let c = if cos_i.abs() > 1.0 { 1.0 } else { cos_i.abs() };
    let g2 = em1 + c * c;
    // Under total internal reflection (g² ≤ 0) the values below are selected away.
    let g = g2.max(0.0).sqrt();
    let s = c + g;
    let p = e2 * c + g;
    let rs = -em1 / (s * s);
    let rp = em1 * ((e2 + 1.0) * c * c - 1.0) / (p * p);
    let reflectance = (0.5 * (rs * rs + rp * rp)).min(1.0);
    let cos_t = (g / eta).min(1.0);
    if g2 > 0.0 {
        (reflectance, cos_t)
    } else if g2.is_nan() {
        (f64::NAN, f64::NAN)
    } else {
        (1.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::fresnel::dielectric;

    /// Cosines at the hard places: 0, ±1, beyond ±1, around the critical cosine of each η,
    /// tiny, NaN, and a sweep.
    fn cosines(eta: f64) -> Vec<f64> {
        let mut c = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            1.5,
            -2.0,
            1e-300,
            f64::NAN,
            f64::INFINITY,
        ];
        if eta < 1.0 {
            let critical = (1.0 - eta * eta).sqrt();
            for k in -20..=20 {
                c.push(critical + k as f64 * f64::EPSILON);
                c.push(critical * (1.0 + k as f64 * 1e-6));
            }
        }
        c.extend((0..4000).map(|k| (k as f64 / 3999.0) * 2.0 - 1.0));
        c
    }

    #[test]
    fn the_block_is_the_scalar_fresnel_bit_for_bit_on_every_path() {
        for eta in [1.5, 1.0 / 1.5, 1.0001, 1.0 / 1.0001, 4.0, 0.25, 1.33] {
            let c = cosines(eta);
            for arch in [pulp::Arch::new(), pulp::Arch::Scalar] {
                let (mut r, mut t) = (vec![0.0; c.len()], vec![0.0; c.len()]);
                dielectric_block_on(arch, &c, eta, &mut r, &mut t);
                for (k, &ci) in c.iter().enumerate() {
                    let want = dielectric(ci, eta);
                    assert_eq!(
                        (r[k].to_bits(), t[k].to_bits()),
                        (want.reflectance.to_bits(), want.cos_t.to_bits()),
                        "η {eta}, cos {ci}: block ({}, {}) vs scalar {want:?}",
                        r[k],
                        t[k]
                    );
                }
            }
        }
    }
}
