//! `bsdf.ndf_consistency`: the reference BSDFs pass against their own NDFs (declared or
//! fitted G2), and a BSDF whose D, Λ, G2 form, refraction η² or pdf is not what its NDF and
//! Walter's formulas say fails, for the right relation.

use super::*;
use crate::check::RunContext;
use crate::precision::Precision;
use crate::record::CheckRecord;
use crate::selftest::bsdf_mutant::{BsdfDefect, MutatedBsdf};
use mfh_reference::bsdf::{BsdfSample, BsdfSpec, Dielectric, Microfacet, Sampling, Transport};
use mfh_reference::model::{NormalSampler, Smith};
use mfh_reference::ndf::{Beckmann, Ggx};
use mfh_reference::Ndf;

fn spec(text: &str) -> BsdfSpec {
    serde_json::from_str(text).unwrap()
}

fn run(subject: &Arc<BsdfSubject<'_>>) -> Vec<CheckRecord> {
    plan(subject, "test")
        .iter()
        .map(|p| (p.run)(&RunContext { seed: 1 }))
        .collect()
}

/// (relation, verdict is pass, worst error, G2 form judged under).
fn summary(records: &[CheckRecord]) -> Vec<(String, bool, f64, String)> {
    records
        .iter()
        .map(|r| {
            (
                r.case["relation"].as_str().unwrap().to_string(),
                r.verdict == Verdict::Pass,
                r.value.unwrap_or(f64::NAN),
                r.case["g2"]["masking"].as_str().unwrap_or("").to_string(),
            )
        })
        .collect()
}

fn user<'a>(
    bsdf: Arc<dyn Bsdf + 'a>,
    ndf: Arc<dyn Ndf + 'a>,
    masking: Option<Masking>,
    visible_normals: bool,
) -> Arc<BsdfSubject<'a>> {
    BsdfSubject::user(
        bsdf,
        "test",
        Some(OwnNdf {
            ndf,
            masking,
            visible_normals,
        }),
        Precision::F64,
    )
}

const REFERENCES: [&str; 5] = [
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#,
    r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"masking":"uncorrelated","transport":"importance"}"#,
    r#"{"bsdf":"dielectric","eta":0.6,"ndf":{"family":"beckmann","alpha_x":0.2,"alpha_y":0.5},"masking":"uncorrelated","sampling":"normals","transport":"importance"}"#,
    r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"ggx","alpha":0.5},"fresnel":"schlick"}"#,
    r#"{"bsdf":"conductor","n":1.1,"k":2.4,"ndf":{"family":"beckmann","alpha":0.3},"masking":"uncorrelated"}"#,
];

/// The reference BSDFs pass every relation against their own NDFs, under their declared G2
/// and with the G2 undeclared (the fitted form is theirs); the conductor with Schlick's
/// Fresnel passes too (F is still a function of |wi·h| alone).
#[test]
fn the_reference_bsdfs_agree_with_their_own_ndfs() {
    for text in REFERENCES {
        let s = spec(text);
        let subject = BsdfSubject::reference(&s).unwrap();
        let records = run(&subject);
        let visible = !text.contains(r#""sampling":"normals""#);
        let want = 1 + usize::from(s.eta().is_some()) + usize::from(visible);
        assert_eq!(records.len(), want, "{text}");
        for (relation, pass, error, _) in summary(&records) {
            println!("{text}\n  {relation}: {error:.3e}");
            assert!(pass && error < 1e-12, "{text} {relation}: {error}");
        }
        // Undeclared: the form that fits is the BSDF's.
        let own = subject.own_ndf.clone().unwrap();
        let fitted = user(subject.bsdf.clone(), own.ndf, None, own.visible_normals);
        let masking = if text.contains("uncorrelated") {
            "uncorrelated"
        } else {
            "height_correlated"
        };
        for (relation, pass, error, form) in summary(&run(&fitted)) {
            assert!(pass, "{text} {relation} fitted: {error}");
            assert_eq!(form, masking, "{text} {relation}");
        }
    }
}

/// The records say where the worst error was, how many pairs were compared, and the form.
#[test]
fn a_record_carries_its_worst_pair_and_form() {
    let subject = BsdfSubject::reference(&spec(REFERENCES[0])).unwrap();
    let records = run(&subject);
    let relations: Vec<_> = records.iter().map(|r| r.case["relation"].clone()).collect();
    assert_eq!(
        relations,
        ["reflection", "transmission", "visible_normal_pdf"]
    );
    for r in &records {
        assert!(r.case["pairs"].as_u64().unwrap() > 100, "{}", r.case);
        assert!(r.case["worst"]["wi"].is_array(), "{}", r.case);
        assert_eq!(r.case["g2"]["declared"], true);
        assert_eq!(r.tolerance.as_ref().unwrap().name, "bsdf_ndf_consistency");
    }
    assert!(records[0].cost.evaluations > 0);
}

/// Not planned without an NDF, nor with an NDF that has no Smith Λ; transmission only where
/// the BSDF declares η, the pdf only where it declares visible normals.
#[test]
fn planned_from_the_capabilities() {
    let b = spec(REFERENCES[0]).build().unwrap();
    assert!(plan(
        &BsdfSubject::user(b.clone(), "b", None, Precision::F64),
        "t"
    )
    .is_empty());
    struct DOnly;
    impl Ndf for DOnly {
        fn d(&self, _: Vec3) -> f64 {
            1.0
        }
    }
    assert!(plan(&user(b.clone(), Arc::new(DOnly), None, true), "t").is_empty());
    let ggx: Arc<dyn Ndf> = Arc::new(Ggx::new(0.3, 0.3).unwrap());
    assert_eq!(plan(&user(b, ggx.clone(), None, false), "t").len(), 2);
    let c = spec(REFERENCES[3]).build().unwrap();
    assert_eq!(
        plan(&user(c.clone(), ggx.clone(), None, false), "t").len(),
        1
    );
    assert_eq!(plan(&user(c, ggx, None, true), "t").len(), 2);
}

/// An NDF whose D is one GGX and whose Λ is another model's: a BSDF built on it has a D or a
/// masking that its (correct) NDF does not.
struct Hybrid {
    d: Ggx,
    lambda: Box<dyn Smith>,
}

impl Ndf for Hybrid {
    fn d(&self, m: Vec3) -> f64 {
        self.d.d(m)
    }
    fn as_smith(&self) -> Option<&dyn Smith> {
        Some(self)
    }
    fn as_sampler(&self) -> Option<&dyn NormalSampler> {
        Some(self)
    }
}

impl Smith for Hybrid {
    fn lambda(&self, w: Vec3) -> f64 {
        self.lambda.lambda(w)
    }
}

impl NormalSampler for Hybrid {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        self.d.sample_wm(u)
    }
}

fn dielectric_on(ndf: Hybrid, masking: Masking) -> Arc<dyn Bsdf> {
    let mf = Microfacet::new(Arc::new(ndf), "hybrid", masking, Sampling::Normals).unwrap();
    Arc::new(Dielectric::new(1.5, mf, Transport::Radiance).unwrap())
}

fn ggx(alpha: f64) -> Ggx {
    Ggx::new(alpha, alpha).unwrap()
}

/// Fails every Fresnel relation, declared or fitted, and says so.
fn fails_both_relations(bsdf: Arc<dyn Bsdf>, what: &str) {
    for masking in [None, Some(Masking::HeightCorrelated)] {
        let subject = user(bsdf.clone(), Arc::new(ggx(0.3)), masking, false);
        for (relation, pass, error, form) in summary(&run(&subject)) {
            println!("{what} {masking:?} {relation}: {error:.3e} ({form})");
            assert!(
                !pass && error > 1e-3,
                "{what} {masking:?} {relation}: {error}"
            );
        }
    }
}

/// A BSDF whose D uses α × 1.01 against its NDF's α fails, declared or fitted.
#[test]
fn a_bsdf_whose_d_is_not_its_ndfs_fails() {
    let ndf = Hybrid {
        d: ggx(0.303),
        lambda: Box::new(ggx(0.3)),
    };
    fails_both_relations(dielectric_on(ndf, Masking::HeightCorrelated), "D α×1.01");
}

/// A BSDF whose masking is not its NDF's Λ (Beckmann's Λ, or GGX's of α × 1.1, on GGX's D)
/// fails, declared or fitted.
#[test]
fn a_bsdf_whose_masking_is_not_its_ndfs_lambda_fails() {
    for (what, lambda) in [
        (
            "Beckmann Λ",
            Box::new(Beckmann::new(0.3, 0.3).unwrap()) as Box<dyn Smith>,
        ),
        ("Λ α×1.1", Box::new(ggx(0.33))),
    ] {
        let ndf = Hybrid {
            d: ggx(0.3),
            lambda,
        };
        fails_both_relations(dielectric_on(ndf, Masking::HeightCorrelated), what);
    }
}

/// A BSDF declared height-correlated that evaluates the uncorrelated G2 fails; undeclared, the
/// check finds the uncorrelated form and passes.
#[test]
fn a_declared_g2_form_is_held_to() {
    let b = spec(REFERENCES[1]).build().unwrap();
    let ndf: Arc<dyn Ndf> = Arc::new(ggx(0.3));
    let declared = user(
        b.clone(),
        ndf.clone(),
        Some(Masking::HeightCorrelated),
        false,
    );
    for (relation, pass, error, _) in summary(&run(&declared)) {
        assert!(!pass && error > 1e-3, "{relation}: {error}");
    }
    let fitted = user(b, ndf, None, false);
    assert!(summary(&run(&fitted)).iter().all(|s| s.1));
}

/// The refraction defects: eval without η_o² (the Jacobian's), and the η² of the other
/// transport convention.
#[derive(Clone, Copy, Debug)]
enum EtaDefect {
    NoEtaOSquared,
    OtherTransport,
}

struct EtaMutant {
    inner: Arc<dyn Bsdf>,
    defect: EtaDefect,
}

impl Bsdf for EtaMutant {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        let v = self.inner.eval(wi, wo);
        match self.defect {
            EtaDefect::NoEtaOSquared if wi[2] * wo[2] < 0.0 && wo[2] < 0.0 => v / (1.5 * 1.5),
            _ => v,
        }
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.inner.pdf(wi, wo)
    }
    fn sample(&self, wi: Vec3, u: [f64; 3]) -> Option<BsdfSample> {
        self.inner.sample(wi, u)
    }
    fn eta(&self) -> Option<f64> {
        self.inner.eta()
    }
    fn transport(&self) -> Transport {
        match self.defect {
            // Evaluates importance, states radiance.
            EtaDefect::OtherTransport => Transport::Radiance,
            EtaDefect::NoEtaOSquared => self.inner.transport(),
        }
    }
}

/// A refraction without η_o² (from outside, where η_o = 1.5) or with the other convention's η²
/// fails the transmission relation (and only it: reflection is untouched).
#[test]
fn a_misplaced_eta_squared_fails_the_transmission_relation() {
    for (defect, text) in [
        (EtaDefect::NoEtaOSquared, REFERENCES[0]),
        (
            EtaDefect::OtherTransport,
            r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3},"transport":"importance"}"#,
        ),
    ] {
        let inner = spec(text).build().unwrap();
        let m: Arc<dyn Bsdf> = Arc::new(EtaMutant { inner, defect });
        for masking in [None, Some(Masking::HeightCorrelated)] {
            let subject = user(m.clone(), Arc::new(ggx(0.3)), masking, false);
            let s = summary(&run(&subject));
            println!("{defect:?} {masking:?}: {s:?}");
            assert!(s[0].1, "{defect:?}: reflection {s:?}");
            assert!(!s[1].1 && s[1].2 > 0.1, "{defect:?}: transmission {s:?}");
        }
    }
}

/// The selftest's BSDF mutants with their base's GGX as their own NDF (declared G2 and
/// visible normals, as the base is): every defect of eval or pdf is seen, by the relation it
/// breaks; those of `sample` alone, the conductor below its horizon, a NaN at wo = −wi and a
/// uniform Fresnel scale (still a factor of |wi·h| alone, in [0, 1]) are outside its view.
#[test]
fn the_selftest_mutants_of_eval_and_pdf_fail_it() {
    use BsdfDefect as D;
    let seen = [
        (D::ReflectionJacobianMissing, "visible_normal_pdf"),
        (D::RefractionJacobianMissing, "visible_normal_pdf"),
        (D::EtaSquaredInverted, "transmission"),
        (D::EtaSquaredMissing, "transmission"),
        (D::FresnelWrongCosineInPdf, "visible_normal_pdf"),
        (D::G1MissingInVisiblePdf, "visible_normal_pdf"),
        (D::ArgumentsSwapped, "transmission"),
    ];
    for defect in BsdfDefect::ALL {
        let m = MutatedBsdf::new(defect);
        let ndf: Arc<dyn Ndf> = Arc::new(defect.base().ndf().build().unwrap());
        let subject = user(Arc::new(m), ndf, Some(Masking::HeightCorrelated), true);
        let s = summary(&run(&subject));
        let failed: Vec<&str> = s.iter().filter(|x| !x.1).map(|x| x.0.as_str()).collect();
        println!("{:40} fails {failed:?}", defect.id());
        match seen.iter().find(|x| x.0 == defect) {
            Some((_, relation)) => assert!(failed.contains(relation), "{}", defect.id()),
            None => assert!(failed.is_empty(), "{}: {s:?}", defect.id()),
        }
    }
}

/// No false alarm across the registry: every family's examples that have a Smith Λ, as a
/// dielectric (η = 1.5 and its inverse) and as a conductor, and GGX and Beckmann from
/// α = 0.01 to 1, pass against their own NDFs.
#[test]
fn every_family_with_a_smith_lambda_passes() {
    let mut ndfs: Vec<String> = mfh_reference::registry::FAMILIES
        .iter()
        .flat_map(|f| f.examples.iter().map(|e| e.to_string()))
        .collect();
    for a in [0.01, 0.05, 1.0] {
        ndfs.push(format!(r#"{{"family":"ggx","alpha":{a}}}"#));
        ndfs.push(format!(r#"{{"family":"beckmann","alpha":{a}}}"#));
    }
    let (mut worst, mut audited) = (0.0f64, 0);
    for ndf in &ndfs {
        for bsdf in [
            format!(r#"{{"bsdf":"dielectric","eta":1.5,"ndf":{ndf},"sampling":"normals"}}"#),
            format!(r#"{{"bsdf":"dielectric","eta":0.66,"ndf":{ndf},"sampling":"normals"}}"#),
            format!(r#"{{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{ndf},"sampling":"normals"}}"#),
        ] {
            let Ok(s) = serde_json::from_str::<BsdfSpec>(&bsdf) else {
                continue;
            };
            let Ok(subject) = BsdfSubject::reference(&s) else {
                continue; // no Smith Λ, or not as a BSDF
            };
            for (relation, pass, error, _) in summary(&run(&subject)) {
                assert!(pass, "{bsdf} {relation}: {error}");
                worst = worst.max(error);
            }
            audited += 1;
        }
    }
    println!("worst over {audited} BSDFs of the registry: {worst:.3e}");
    assert!(audited >= 3 * 12, "{audited}");
}

/// A user's Rust BSDF with its NDF through the public gate: `Audit::of_bsdf(…).ndf(…)` plans
/// the relations (the pdf one with visible normals declared) and passes; without `.ndf`
/// nothing is planned.
#[test]
fn audit_of_bsdf_with_ndf_plans_and_passes() {
    let b = spec(REFERENCES[0]).build().unwrap();
    let g = ggx(0.3);
    let ids = |audit: crate::Audit<'_>| -> usize {
        let (plan, records) = audit.plan();
        // Only the passing `audit.precision` record of the probe.
        assert!(
            records.iter().all(|r| r.verdict == Verdict::Pass),
            "{records:?}"
        );
        plan.iter()
            .filter(|p| p.check == "bsdf.ndf_consistency")
            .count()
    };
    assert_eq!(ids(crate::Audit::of_bsdf(&b)), 0);
    assert_eq!(ids(crate::Audit::of_bsdf(&b).ndf(&g)), 2);
    let audit = || {
        crate::Audit::of_bsdf(&b)
            .ndf(&g)
            .masking(Some(Masking::HeightCorrelated))
            .sampling(Some(crate::Sampling::VisibleNormals))
    };
    assert_eq!(ids(audit()), 3);
    let (plan, _) = audit().plan();
    for p in plan.iter().filter(|p| p.check == "bsdf.ndf_consistency") {
        let r = (p.run)(&RunContext { seed: 1 });
        assert_eq!(r.verdict, Verdict::Pass, "{}", r.case);
        assert_eq!(r.case["g2"]["declared"], true);
    }
}
