//! `bsdf.energy` in the importance transport: a radiance BSDF that gains energy fails from
//! either side, the reference passes.

use crate::check::RunContext;
use crate::record::Verdict;
use crate::{Audit, Profile};
use mfh_reference::bsdf::{Bsdf, BsdfSample, BsdfSpec, Transport};
use mfh_reference::geometry::Vec3;
use std::sync::Arc;

/// A BSDF whose eval and sampling weight are `gain` × its base's (the pdf and the sampled
/// directions unchanged): an energy gain that only the albedo's level shows.
struct Gain {
    base: Arc<dyn Bsdf>,
    gain: f64,
}

impl Bsdf for Gain {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.gain * self.base.eval(wi, wo)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.base.pdf(wi, wo)
    }
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        self.base.sample(wi, u).map(|s| BsdfSample {
            weight: self.gain * s.weight,
            ..s
        })
    }
    fn eta(&self) -> Option<f64> {
        self.base.eta()
    }
    fn transport(&self) -> Transport {
        self.base.transport()
    }
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.base.eval_batch(wi, wo, out);
        out.iter_mut().for_each(|v| *v *= self.gain);
    }
    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.base.pdf_batch(wi, wo, out)
    }
}

/// The `bsdf.energy` records of `spec`'s BSDF times `gain`, at the ci profile: (incidence,
/// importance albedo, failed).
fn energy(spec: &str, gain: f64) -> Vec<(String, f64, bool)> {
    let spec: BsdfSpec = serde_json::from_str(spec).unwrap();
    let b = Gain {
        base: spec.build().unwrap(),
        gain,
    };
    let audit = Audit::of_bsdf(&b).profile(Profile::Ci).seed(7);
    let (plan, _) = audit.plan();
    plan.iter()
        .filter(|p| p.check == "bsdf.energy")
        .map(|p| {
            let r = (p.run)(&RunContext { seed: 7 });
            let albedo = r.value.unwrap_or(f64::NAN);
            eprintln!(
                "gain {gain}: {} {albedo:.6} {:?}",
                r.case["incidence"], r.verdict
            );
            (
                r.case["incidence"].as_str().unwrap_or("").to_string(),
                albedo,
                r.verdict != Verdict::Pass,
            )
        })
        .collect()
}

/// The radiance GGX dielectric (η 1.5, α 0.05): its importance albedo is within a few percent
/// of 1 at normal incidence from outside and from inside, so a 5 % gain exceeds 1 there; the
/// raw radiance albedo from outside, (η_i/η_o)² = 0.44 on the transmitted part, stayed below 1
/// up to a gain of ~1.97.
#[test]
fn an_energy_gain_fails_in_the_importance_transport_from_both_sides() {
    let text = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.05}}"#;
    let correct = energy(text, 1.0);
    assert_eq!(correct.len(), 5, "every incidence: {correct:?}");
    assert!(correct.iter().all(|c| !c.2), "{correct:?}");
    let gained = energy(text, 1.05);
    let failed: Vec<&str> = gained
        .iter()
        .filter(|g| g.2)
        .map(|g| g.0.as_str())
        .collect();
    assert!(failed.contains(&"normal"), "{gained:?}");
    assert!(failed.contains(&"inside"), "{gained:?}");
}

/// The same from the importance side: a BSDF declared `importance` is judged as it is.
#[test]
fn an_importance_bsdf_is_judged_without_conversion() {
    let text = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.05},"transport":"importance"}"#;
    assert!(energy(text, 1.0).iter().all(|c| !c.2));
    assert!(energy(text, 1.05).iter().any(|c| c.2 && c.0 == "normal"));
}
