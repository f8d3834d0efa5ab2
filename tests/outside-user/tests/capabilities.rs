//! The forgotten capability, as a renderer would forget it: a wrapper that implements `Smith`
//! and `NormalSampler` but leaves `as_smith` / `as_sampler` at their defaults. Audited with
//! `Audit::of` it is audited on D alone, and a planted Λ bug and a planted sampler bug go
//! through; with `mfh_harness::audit!` the compiler finds the implemented traits and the gate
//! fails loudly on `audit.capabilities`, naming what was not declared.

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
fn a_forgotten_capability_fails_the_gate_with_the_macro() {
    // A Λ bug the undeclared Smith capability hides (and the sampler's is as hidden).
    let m = Forgetful(ggx(Defect::LambdaWrongAboveOnePointThree));
    let report = audit!(m).profile(Profile::Ci).run();
    assert_eq!(report.failed_checks(), ["audit.capabilities"]);
    let record = report.records_of("audit.capabilities").next().unwrap();
    let undeclared = record.case["undeclared"].to_string();
    assert!(
        undeclared.contains("as_smith") && undeclared.contains("as_sampler"),
        "{undeclared}"
    );
    // Without the macro the audit cannot know, and says so in the same record.
    let report = Audit::of(&m).profile(Profile::Ci).run();
    let record = report.records_of("audit.capabilities").next().unwrap();
    assert!(record.case["implemented"]
        .as_str()
        .is_some_and(|s| s.contains("audit!")));
    assert_eq!(record.case["not_offered"][0].as_str(), Some("Smith"));
    // And the hidden Λ bug passes the audit that cannot see it: why the macro exists.
    assert!(report.passed(), "{:?}", report.failed_checks());
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
