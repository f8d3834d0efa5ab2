//! `sample_wo_batch` of the reference BSDFs (the directions without the eval and pdf) returns
//! the directions of `sample` (to the ulps of the batch normal samplers), on every configuration and incidence of the consistency tests
//! and at the hard cases (tiny and anisotropic roughness, grazing and near-critical
//! incidence, u at the ends of [0, 1)).

use super::tests::{build, incidences, r3, CONFIGS};
use super::Bsdf;
use crate::geometry::Vec3;

/// Configurations at the hard cases, beside the consistency tests' ones.
const HARD: &[&str] = &[
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":1e-4},"sampling":"visible_normals"}"#,
    r#"{"bsdf":"dielectric","eta":1.0001,"ndf":{"family":"ggx","alpha_x":1e-3,"alpha_y":0.1},"sampling":"visible_normals"}"#,
    r#"{"bsdf":"dielectric","eta":4.0,"ndf":{"family":"beckmann","alpha":1.0},"sampling":"normals"}"#,
    r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"ggx","alpha":1e-4},"sampling":"visible_normals"}"#,
];

/// The same directions, to the ulps a batch normal sampler may differ from its scalar form by
/// (GGX's visible normals: 2 ulps a component, `ndf/ggx_visible_batch.rs`; the others bit for
/// bit), carried through a reflection or refraction: 1e-12 a component.
fn close(a: &Option<Vec3>, b: &Option<Vec3>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => a.iter().zip(b).all(|(a, b)| (a - b).abs() <= 1e-12),
        (None, None) => true,
        _ => false,
    }
}

/// The direction of `sample` (None where it fails or answers pdf 0).
fn scalar(b: &dyn Bsdf, wi: Vec3, u: [f64; 3]) -> Option<Vec3> {
    b.sample(wi, u).filter(|s| s.pdf > 0.0).map(|s| s.wo)
}

/// `sample_wo_batch` into directions that hold something else before (so every element must
/// be written).
fn wo_batch(b: &dyn Bsdf, wi: Vec3, u: &[[f64; 3]]) -> Vec<Option<Vec3>> {
    let mut out = super::Directions::from_options(&vec![Some([9.0; 3]); u.len()]);
    b.sample_wo_batch(wi, u, &mut out);
    out.iter().collect()
}

#[test]
fn sampled_directions_are_those_of_sample() {
    let ends = [0.0, 0.5, 1.0 - f64::EPSILON / 2.0];
    let mut compared = 0usize;
    for text in CONFIGS.iter().chain(HARD) {
        let b = build(text);
        for wi in incidences(b.eta()) {
            let mut u: Vec<[f64; 3]> = (0..4000).map(r3).collect();
            for a in ends {
                for c in ends {
                    u.extend(ends.map(|e| [a, c, e]));
                }
            }
            let fast = wo_batch(b.as_ref(), wi, &u);
            for (k, (&u, fast)) in u.iter().zip(&fast).enumerate() {
                let slow = scalar(b.as_ref(), wi, u);
                assert!(
                    close(fast, &slow),
                    "{text} wi {wi:?} sample {k} u {u:?}: {fast:?} vs {slow:?}"
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 100_000, "{compared} samples compared");
}

/// The trait's default (through `sample_batch`, the scalar `sample`) gives the same directions
/// as the override (through the batch normal samplers), to [`close`]'s 1e-12 a component.
#[test]
fn the_default_keeps_the_directions_of_sample_batch() {
    struct Plain(std::sync::Arc<dyn Bsdf>);
    impl Bsdf for Plain {
        fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.0.eval(wi, wo)
        }
        fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.0.pdf(wi, wo)
        }
        fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<super::BsdfSample> {
            self.0.sample(wi, u)
        }
        fn eta(&self) -> Option<f64> {
            self.0.eta()
        }
    }
    let b = build(CONFIGS[0]);
    let plain = Plain(b.clone());
    let u: Vec<[f64; 3]> = (0..2000).map(r3).collect();
    for wi in incidences(b.eta()) {
        let (a, c) = (wo_batch(b.as_ref(), wi, &u), wo_batch(&plain, wi, &u));
        for (k, (a, c)) in a.iter().zip(&c).enumerate() {
            assert!(close(a, c), "wi {wi:?} sample {k}: {a:?} vs {c:?}");
        }
        assert!(a.iter().filter(|w| w.is_some()).count() > 1000);
    }
}
