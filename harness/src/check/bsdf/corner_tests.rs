//! The reference BSDFs at the corners of their accepted domain pass their own ci audit, and a
//! sampler that loses 1 % of its samples fails it where the oracle's masses were wrong before.

use super::*;
use crate::check::RunContext;
use crate::record::{CheckRecord, Verdict};
use crate::{Audit, Profile};
use mfh_reference::bsdf::{BsdfSample, BsdfSpec, Directions, Transport};

fn build(text: &str) -> Arc<dyn Bsdf> {
    let spec: BsdfSpec = serde_json::from_str(text).unwrap();
    spec.build().unwrap()
}

/// Whether any record is not a pass, listed.
fn not_passed(records: &[CheckRecord]) -> Vec<String> {
    records
        .iter()
        .filter(|r| r.verdict != Verdict::Pass)
        .map(|r| format!("{} {} {:?} {:?}", r.check, r.case, r.verdict, r.measured))
        .collect()
}

/// The corners of the reference's accepted domain, one ci audit each: η at 0.1, 10 and within
/// the transmission-width limit of 1 (`TRANSMISSION_WIDTH_MIN`), α at 1e-7 and 1e4, the
/// anisotropy limit (100), both samplings, conductors and dielectrics; and the anisotropic GGX
/// (α 1e-6 × 1e-4) at η 1.0001, whose transmission lobe beyond the critical angle (cos θi
/// 0.0094 from inside: 1.3e-5 of the samples, about 1e-4 wide) the oracle missed before the
/// centres beyond the critical angle (`lobe_centres`: mass 1e-13, 17 samples in a cell
/// expecting 1e-7, smooth-component p 0).
const CORNERS: [&str; 9] = [
    r#"{"bsdf":"dielectric","eta":1.00005,"ndf":{"family":"ggx","alpha":0.3}}"#,
    r#"{"bsdf":"dielectric","eta":0.999,"ndf":{"family":"beckmann","alpha":1e-7},"sampling":"normals"}"#,
    r#"{"bsdf":"dielectric","eta":10,"ndf":{"family":"ggx","alpha":1e-7}}"#,
    r#"{"bsdf":"dielectric","eta":0.1,"ndf":{"family":"ggx","alpha":1e4}}"#,
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha_x":1e-6,"alpha_y":1e-4}}"#,
    r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"beckmann","alpha":1e-4}}"#,
    r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"ggx","alpha":1e-7}}"#,
    r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"beckmann","alpha_x":1e4,"alpha_y":100},"sampling":"normals"}"#,
    r#"{"bsdf":"dielectric","eta":1.0001,"ndf":{"family":"ggx","alpha_x":1e-6,"alpha_y":1e-4}}"#,
];

/// Beyond the domain: an anisotropy of 10¹¹, which the oracle could not certify, is refused
/// by the spec with an error that names the field and the limit.
#[test]
fn an_anisotropy_beyond_the_limit_is_refused_by_name() {
    let spec: BsdfSpec = serde_json::from_str(
        r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha_x":1e-7,"alpha_y":1e4}}"#,
    )
    .unwrap();
    let e = spec.build().err().expect("refused");
    assert_eq!(e.field(), "ndf.alpha_x");
    assert!(e.to_string().contains("factor of 100"), "{e}");
    // A transmission lobe narrower than 1e-10 rad: α 1e-7 at η 0.99994.
    let spec: BsdfSpec = serde_json::from_str(
        r#"{"bsdf":"dielectric","eta":0.99994,"ndf":{"family":"beckmann","alpha":1e-7}}"#,
    )
    .unwrap();
    let e = spec.build().err().expect("refused");
    assert_eq!(e.field(), "eta");
    assert!(e.to_string().contains("1e-10/alpha"), "{e}");
}

/// One test a corner, so that nextest spreads them over the cores. Every record passes,
/// `bsdf.jacobian` included: until its step ladder (`check/step_ladder.rs`) and the rounding
/// bound that counts the columns' conditioning, three corners failed it by 2.3e-6 to 9.4e-5
/// (η 0.1 α 1e4 from outside; the anisotropic 1e-6 × 1e-4 at η 1.5 and 1.0001), the check's
/// own error: the reference's pdf agrees with an mpmath evaluation of Walter's (eq 17) to 2e-11
/// at the points that failed, where the densities at step 1.25e-5 were off by 2e-6 to 7e-6.
/// [`a_pdf_one_part_in_1e5_too_large_fails_the_jacobian_at_every_corner`] shows that they pass
/// with bounds tight enough to fail a pdf off by 1e-5.
fn corner_passes(i: usize) {
    let b = build(CORNERS[i]);
    let report = Audit::of_bsdf(&b).profile(Profile::Ci).run();
    assert_eq!(
        not_passed(&report.records),
        Vec::<String>::new(),
        "{}",
        CORNERS[i]
    );
}

macro_rules! corners {
    ($($name:ident: $i:expr,)*) => {
        $(
            #[test]
            fn $name() {
                corner_passes($i);
            }
        )*
    };
}

corners! {
    corner_eta_1_00005_ggx_0_3: 0,
    corner_eta_0_999_beckmann_1e_7_normals: 1,
    corner_eta_10_ggx_1e_7: 2,
    corner_eta_0_1_ggx_1e4: 3,
    corner_eta_1_5_anisotropic_1e_6_1e_4: 4,
    corner_conductor_beckmann_1e_4: 5,
    corner_conductor_ggx_1e_7: 6,
    corner_conductor_beckmann_1e4_100_normals: 7,
    corner_eta_1_0001_anisotropic_1e_6_1e_4: 8,
}

/// The reference that silently fails `loss` of its samples (those whose u₀ has its 7th–16th
/// binary digits below loss·2¹⁰: independent of the direction drawn, so the chi-square,
/// conditional on success, cannot see it; only the failure rate against 1 − ∫ pdf can).
struct Lossy {
    base: Arc<dyn Bsdf>,
    loss: f64,
}

impl Lossy {
    fn lost(&self, u: [f64; 3]) -> bool {
        ((u[0] * 64.0).fract()) < self.loss
    }
}

impl Bsdf for Lossy {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.base.eval(wi, wo)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.base.pdf(wi, wo)
    }
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        if self.lost(u) {
            None
        } else {
            self.base.sample(wi, u)
        }
    }
    fn eta(&self) -> Option<f64> {
        self.base.eta()
    }
    fn transport(&self) -> Transport {
        self.base.transport()
    }
    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.base.pdf_batch(wi, wo, out)
    }
    fn eval_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.base.eval_batch(wi, wo, out)
    }
    fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
        self.base.sample_wo_batch(wi, u, out);
        for (k, &u) in u.iter().enumerate() {
            if self.lost(u) {
                out.set(k, None);
            }
        }
    }
}

/// The GGX α 0.3 dielectric of η 1.0001 (a stress value the docs use) losing 1 % of its
/// samples fails `bsdf.failure_rate` at every incidence of the audit; before the lobe centres,
/// its transmission lobe's mass was 0.9444 for ≥ 0.9987 and a loss of 5.5 % passed at the
/// oblique incidence.
#[test]
fn a_one_percent_sample_loss_fails_at_every_incidence() {
    let b = Lossy {
        base: build(r#"{"bsdf":"dielectric","eta":1.0001,"ndf":{"family":"ggx","alpha":0.3}}"#),
        loss: 0.01,
    };
    let audit = Audit::of_bsdf(&b).profile(Profile::Ci).seed(7);
    let (plan, _) = audit.plan();
    let records: Vec<CheckRecord> = plan
        .iter()
        .filter(|p| p.check == "bsdf.failure_rate")
        .map(|p| (p.run)(&RunContext { seed: 7 }))
        .collect();
    assert_eq!(records.len(), incidences(&b).len());
    for r in &records {
        eprintln!("{} {:?} {:?}", r.case["incidence"], r.verdict, r.measured);
        assert_eq!(r.verdict, Verdict::Fail, "{} {:?}", r.case, r.measured);
    }
}

/// A BSDF whose pdf is `factor` × its base's: what `bsdf.jacobian` must fail.
struct Scaled {
    base: Arc<dyn Bsdf>,
    factor: f64,
}

impl Bsdf for Scaled {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.base.eval(wi, wo)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.factor * self.base.pdf(wi, wo)
    }
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        self.base.sample(wi, u).map(|mut s| {
            s.pdf *= self.factor;
            s
        })
    }
    fn eta(&self) -> Option<f64> {
        self.base.eta()
    }
    fn transport(&self) -> Transport {
        self.base.transport()
    }
    fn pdf_batch(&self, wi: &[Vec3], wo: &[Vec3], out: &mut [f64]) {
        self.base.pdf_batch(wi, wo, out);
        out.iter_mut().for_each(|p| *p *= self.factor);
    }
    fn sample_wo_batch(&self, wi: Vec3, u: &[[f64; 3]], out: &mut Directions) {
        self.base.sample_wo_batch(wi, u, out)
    }
}

/// At every corner, `bsdf.jacobian` fails a pdf 1e-5 too large on each side (ten times its
/// tolerance, 1e-6): its step ladder judges the points at steps where its bounds are tight,
/// so the corners pass for the right reason, not because their bounds grew. The excess over
/// the allowance is printed.
#[test]
fn a_pdf_one_part_in_1e5_too_large_fails_the_jacobian_at_every_corner() {
    use rayon::prelude::*;
    let missed: Vec<String> = (0..CORNERS.len())
        .into_par_iter()
        .flat_map(|i| {
            let b = Scaled {
                base: build(CORNERS[i]),
                factor: 1.0 + 1e-5,
            };
            let audit = Audit::of_bsdf(&b).profile(Profile::Ci).seed(7);
            let (plan, _) = audit.plan();
            plan.iter()
                .filter(|p| p.check == "bsdf.jacobian")
                .map(|p| (p.run)(&RunContext { seed: 7 }))
                .filter_map(|r| {
                    eprintln!(
                        "{} {}: {:?} {:?}",
                        CORNERS[i], r.case["side"], r.verdict, r.measured
                    );
                    (r.verdict != Verdict::Fail)
                        .then(|| format!("{} {}", CORNERS[i], r.case["side"]))
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(missed, Vec::<String>::new());
}
