//! A two-sided reflector: a reflection-only BSDF seen from below as from above (Mitsuba's
//! `twosided` wrapper; a renderer's conductor that mirrors wi below the surface). For wi_z < 0
//! every query is answered by the front side at the directions with z negated,
//!
//! ```text
//! eval(wi, wo) = eval_front(wi', wo'),  pdf likewise,  sample(wi, u) = (sample_front(wi', u))'
//! w' = (w_x, w_y, −w_z)
//! ```
//!
//! so it reflects into wi's hemisphere from either side and is 0 across the surface; for
//! wi_z > 0 it is the front BSDF itself. (Mitsuba 3's `twosided` flips the frame's z with the
//! same sign rule, `TwoSidedBSDF::eval`; with the mirror in z an anisotropic lobe keeps its
//! axes.)

use super::{Bsdf, BsdfSample, Directions, Sampling, Transport};
use crate::geometry::Vec3;

/// `inner` from both sides (see the module documentation). `inner` should be reflection-only:
/// a transmitting BSDF has two sides already, and wrapping it would map its inside onto its
/// outside.
#[derive(Debug, Clone)]
pub struct TwoSided<B>(pub B);

/// The mirror image in the surface plane.
#[inline]
fn flip(w: Vec3) -> Vec3 {
    [w[0], w[1], -w[2]]
}

/// The pair as the front side sees it.
#[inline]
fn front(wi: Vec3, wo: Vec3) -> (Vec3, Vec3) {
    if wi[2] < 0.0 {
        (flip(wi), flip(wo))
    } else {
        (wi, wo)
    }
}

impl<B: Bsdf> TwoSided<B> {
    /// The pairs of a batch as the front side sees them.
    fn fronts(wi: &[Vec3], wo: &[Vec3]) -> (Vec<Vec3>, Vec<Vec3>) {
        wi.iter().zip(wo).map(|(&a, &b)| front(a, b)).unzip()
    }
}

impl<B: Bsdf> Bsdf for TwoSided<B> {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        let (wi, wo) = front(wi, wo);
        self.0.eval(wi, wo)
    }

    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        let (wi, wo) = front(wi, wo);
        self.0.pdf(wi, wo)
    }

    fn eval_pdf(&self, wi: Vec3, wo: Vec3) -> (f64, f64) {
        let (wi, wo) = front(wi, wo);
        self.0.eval_pdf(wi, wo)
    }

    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        if wi[2] < 0.0 {
            self.0.sample(flip(wi), u).map(|s| BsdfSample {
                wo: flip(s.wo),
                ..s
            })
        } else {
            self.0.sample(wi, u)
        }
    }

    fn eta(&self) -> Option<f64> {
        self.0.eta()
    }

    fn transport(&self) -> Transport {
        self.0.transport()
    }

    fn two_sided(&self) -> bool {
        true
    }

    fn reference_map(&self) -> Option<Sampling> {
        self.0.reference_map()
    }

    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        let (wi, wo) = Self::fronts(wi, wo);
        self.0.eval_batch(&wi, &wo, out)
    }

    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        let (wi, wo) = Self::fronts(wi, wo);
        self.0.pdf_batch(&wi, &wo, out)
    }

    fn sample_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut [Option<BsdfSample>]) {
        if wi[2] < 0.0 {
            self.0.sample_batch(flip(wi), u, out);
            for s in out.iter_mut().flatten() {
                s.wo = flip(s.wo);
            }
        } else {
            self.0.sample_batch(wi, u, out)
        }
    }

    fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
        if wi[2] < 0.0 {
            self.0.sample_wo_batch(flip(wi), u, out);
            for z in out.as_mut().xyz[2].iter_mut() {
                *z = -*z;
            }
        } else {
            self.0.sample_wo_batch(wi, u, out)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::BsdfSpec;

    /// From below, the two-sided conductor is the conductor mirrored: eval, pdf, samples and
    /// sampled directions of the batch path; the one-sided one is black there.
    #[test]
    fn a_two_sided_conductor_is_its_front_mirrored() {
        let spec: BsdfSpec = serde_json::from_str(
            r#"{"bsdf":"conductor","n":0.2,"k":3.4,"two_sided":true,
                "ndf":{"family":"ggx","alpha_x":0.2,"alpha_y":0.5}}"#,
        )
        .unwrap();
        let two = spec.build().unwrap();
        let one = match &spec {
            BsdfSpec::Conductor(c) => BsdfSpec::Conductor(crate::bsdf::ConductorSpec {
                two_sided: false,
                ..c.clone()
            }),
            _ => unreachable!(),
        }
        .build()
        .unwrap();
        assert!(two.two_sided() && !one.two_sided());
        let wi = [0.3, -0.4, 0.866_025_403_784_438_6];
        let below = flip(wi);
        let u = [0.2, 0.7, 0.4];
        let s = one.sample(wi, u).unwrap();
        let t = two.sample(below, u).unwrap();
        assert_eq!(t.wo, flip(s.wo));
        assert_eq!((t.pdf, t.weight), (s.pdf, s.weight));
        assert!(s.pdf > 0.0 && s.weight > 0.0);
        assert_eq!(two.eval(below, t.wo), one.eval(wi, s.wo));
        assert_eq!(two.pdf(below, t.wo), one.pdf(wi, s.wo));
        assert_eq!(one.eval(below, t.wo), 0.0);
        assert!(one.sample(below, u).is_none());
        // Across the surface it is 0 from both sides.
        assert_eq!(two.eval(below, s.wo), 0.0);
        assert_eq!(two.eval(wi, t.wo), 0.0);
        let us = [u, [0.9, 0.1, 0.5], [0.5, 0.5, 0.99]];
        let mut d = Directions::new(3);
        two.sample_wo_batch(below, &us, &mut d);
        for (k, &u) in us.iter().enumerate() {
            let w = d.get(k).unwrap();
            let x = two.sample(below, u).unwrap().wo;
            assert!((0..3).all(|c| (w[c] - x[c]).abs() <= 1e-12), "{w:?} {x:?}");
        }
        let mut batch = [0.0; 2];
        two.eval_batch(&[below, wi], &[t.wo, s.wo], &mut batch);
        assert_eq!(batch, [two.eval(below, t.wo), two.eval(wi, s.wo)]);
    }

    #[test]
    fn only_a_conductor_can_be_two_sided_and_the_default_is_not_written() {
        let e = serde_json::from_str::<BsdfSpec>(
            r#"{"bsdf":"dielectric","eta":1.5,"two_sided":true,"ndf":{"family":"ggx","alpha":0.3}}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("two_sided"), "{e}");
        let spec: BsdfSpec = serde_json::from_str(
            r#"{"bsdf":"conductor","n":0.2,"k":3.4,"ndf":{"family":"ggx","alpha":0.3}}"#,
        )
        .unwrap();
        assert!(!serde_json::to_string(&spec).unwrap().contains("two_sided"));
    }
}
