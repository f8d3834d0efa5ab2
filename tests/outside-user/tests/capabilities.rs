//! The forgotten capability, as a renderer would forget it: a wrapper that implements `Smith`
//! and `NormalSampler` but leaves `as_smith` / `as_sampler` at their defaults. With
//! `mfh_harness::audit!` the compiler finds the implemented traits and wires them in, so a
//! planted Λ bug fails its smith check; with `Audit::of`, which sees D alone, the gate fails
//! `audit.capabilities` unless the caller states that D is all the model offers.

use mfh_harness::model::{Ndf, NormalSampler, Smith, Vec3};
use mfh_harness::{audit, Audit, Profile};
use mfh_outside_user::{Defect, Family, Microfacet};

/// Implements the traits, forgets to declare them.
struct Forgetful(Microfacet);

impl Ndf for Forgetful {
    fn d(&self, m: Vec3) -> f64 {
        self.0.d(m)
    }
}

impl Smith for Forgetful {
    fn lambda(&self, w: Vec3) -> f64 {
        self.0.lambda(w)
    }
}

impl NormalSampler for Forgetful {
    fn sample_wm(&self, u: [f64; 2]) -> Vec3 {
        self.0.sample_wm(u)
    }
}

fn ggx(defect: Defect) -> Microfacet {
    Microfacet::new(Family::Ggx, 0.3).with(defect)
}

#[test]
fn the_macro_finds_and_audits_a_forgotten_capability() {
    // A Λ bug the undeclared Smith capability would hide from `Audit::of`.
    let m = Forgetful(ggx(Defect::LambdaWrongAboveOnePointThree));
    let report = audit!(m).profile(Profile::Ci).run();
    let failed = report.failed_checks();
    assert!(
        failed.iter().any(|c| c.starts_with("smith.")),
        "the Λ bug must fail a smith check: {failed:?}"
    );
    assert!(!failed.contains(&"audit.capabilities"), "{failed:?}");
    let record = report.records_of("audit.capabilities").next().unwrap();
    assert_eq!(
        record.case["implemented"].to_string(),
        r#"["Smith","NormalSampler"]"#
    );
    assert_eq!(
        record.case["audited"].to_string(),
        r#"["Smith","NormalSampler"]"#
    );
    // The sampler was wired too: its checks ran.
    assert!(report.records_of("sampling.chi2").count() > 0);
    // The same type without the defect passes.
    let m = Forgetful(ggx(Defect::None));
    let report = audit!(m).profile(Profile::Ci).run();
    assert!(report.passed(), "{:?}", report.failed_checks());
}

#[test]
fn a_gate_without_the_macro_cannot_pass_on_d_alone() {
    // `Audit::of` sees only what the `as_*` methods declare: here D alone. Unless the caller
    // states that D is all the model has, the gate fails and says how to fix it.
    let m = Forgetful(ggx(Defect::LambdaWrongAboveOnePointThree));
    let report = Audit::of(&m).profile(Profile::Ci).run();
    assert_eq!(report.failed_checks(), ["audit.capabilities"]);
    let record = report.records_of("audit.capabilities").next().unwrap();
    let problems = record.case["problems"].to_string();
    assert!(
        problems.contains("D alone") && problems.contains("audit!") && problems.contains("d_only"),
        "{problems}"
    );
    assert_eq!(record.case["not_offered"][0].as_str(), Some("Smith"));
    // Stated: D is all it offers, and D is right.
    let report = Audit::of(&m).d_only().profile(Profile::Ci).run();
    assert!(report.passed(), "{:?}", report.failed_checks());
}

#[test]
fn d_only_stated_of_a_model_that_offers_more_fails() {
    struct WithSmith(Microfacet);
    impl Ndf for WithSmith {
        fn d(&self, m: Vec3) -> f64 {
            self.0.d(m)
        }
        fn as_smith(&self) -> Option<&dyn Smith> {
            Some(self)
        }
    }
    impl Smith for WithSmith {
        fn lambda(&self, w: Vec3) -> f64 {
            self.0.lambda(w)
        }
    }
    let m = WithSmith(ggx(Defect::None));
    let report = Audit::of(&m).d_only().profile(Profile::Ci).run();
    assert_eq!(report.failed_checks(), ["audit.capabilities"]);
    let record = report.records_of("audit.capabilities").next().unwrap();
    assert!(
        record.case["problems"].to_string().contains("d_only"),
        "{}",
        record.case
    );
}

#[test]
fn a_model_that_declares_what_it_implements_passes_the_capability_record() {
    struct Declared(Microfacet);
    impl Ndf for Declared {
        fn d(&self, m: Vec3) -> f64 {
            self.0.d(m)
        }
        fn as_smith(&self) -> Option<&dyn Smith> {
            Some(self)
        }
    }
    impl Smith for Declared {
        fn lambda(&self, w: Vec3) -> f64 {
            self.0.lambda(w)
        }
    }
    let m = Declared(ggx(Defect::None));
    let report = audit!(m).profile(Profile::Ci).run();
    let record = report.records_of("audit.capabilities").next().unwrap();
    assert!(!record.verdict.is_failure(), "{record:?}");
    assert_eq!(record.case["implemented"].to_string(), r#"["Smith"]"#);
    assert!(report.passed(), "{:?}", report.failed_checks());
}
