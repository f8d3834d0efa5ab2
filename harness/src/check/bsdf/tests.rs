use super::*;
use crate::check::RunContext;
use crate::record::{CheckRecord, Verdict};
use mfh_reference::bsdf::BsdfSpec;

fn spec(text: &str) -> BsdfSpec {
    serde_json::from_str(text).unwrap()
}

fn run(plan: &[PlannedCheck<'_>]) -> Vec<CheckRecord> {
    plan.iter()
        .enumerate()
        .map(|(i, p)| {
            (p.run)(&RunContext {
                seed: 11 + i as u64,
            })
        })
        .collect()
}

fn failures(records: &[CheckRecord]) -> Vec<String> {
    records
        .iter()
        .filter(|r| r.verdict.is_failure())
        .map(|r| format!("{} {} {:?} {:?}", r.check, r.case, r.verdict, r.measured))
        .collect()
}

/// A BSDF mutant is killed by a check its entry names, planned by the public gate at the ci
/// profile: at seed 7, and at two more seeds in the extensive tier (`MFH_EXTENSIVE=1`). Only
/// the named checks run, as a shard of the gate's plan would run them (`shard.rs`): each
/// with the seed the whole audit gives it (`check_seed`), its statistical verdicts at the
/// Šidák level of the whole plan's statistical checks; so each record is the one
/// `Audit::of_bsdf(&m).run()` writes (the test below compares them for one mutant), and the
/// others' cost (the albedo's cubature, the consistency
/// pairs: about half of a ci audit) is not paid thirteen times in CI. `mfh selftest --only
/// bsdf` runs the whole audits. One test a mutant (below), so that nextest spreads them over
/// the cores.
fn is_killed_by_its_named_check(defect: crate::selftest::bsdf_mutant::BsdfDefect) {
    use crate::run::{check_seed, judge_at, sidak_alpha};
    use crate::selftest::bsdf_mutant::MutatedBsdf;
    use crate::tolerance::STATISTICAL_ALPHA;
    use crate::{Audit, Profile};
    use rayon::prelude::*;
    let seeds: &[u64] = if cfg!(mfh_extensive) {
        &[7, 8, 9]
    } else {
        &[7]
    };
    let mut missed = Vec::new();
    for &seed in seeds {
        let m = MutatedBsdf::new(defect);
        let audit = Audit::of_bsdf(&m).profile(Profile::Ci).seed(seed);
        let (plan, errors) = audit.plan();
        assert_eq!(failures(&errors), Vec::<String>::new(), "{}", defect.id());
        let k = plan.iter().filter(|p| p.statistical).count();
        let named: Vec<_> = plan
            .iter()
            .filter(|p| defect.killers().contains(&p.check.as_str()))
            .collect();
        assert!(!named.is_empty(), "{}: no named check planned", defect.id());
        let mut records: Vec<CheckRecord> = named
            .par_iter()
            .map(|p| {
                (p.run)(&RunContext {
                    seed: check_seed(seed, p),
                })
            })
            .collect();
        judge_at(&mut records, sidak_alpha(STATISTICAL_ALPHA.value, k));
        let mut killers: Vec<&str> = records
            .iter()
            .filter(|r| r.verdict.is_failure())
            .map(|r| r.check.as_str())
            .collect();
        killers.sort_unstable();
        killers.dedup();
        println!(
            "{:40} seed {seed}: {} of {} planned checks named, killed by {killers:?}",
            defect.id(),
            named.len(),
            plan.len()
        );
        if killers.is_empty() {
            missed.push(format!(
                "{} seed {seed}: none of {:?} fails",
                defect.id(),
                defect.killers()
            ));
        }
    }
    assert!(missed.is_empty(), "{missed:#?}");
}

macro_rules! mutant_tests {
    ($($name:ident: $defect:ident,)*) => {
        /// The tests below cover every mutant of the catalog, once each.
        #[test]
        fn every_bsdf_mutant_has_its_kill_test() {
            use crate::selftest::bsdf_mutant::BsdfDefect;
            let tested = [$(BsdfDefect::$defect),*];
            assert_eq!(tested.len(), BsdfDefect::ALL.len());
            for d in BsdfDefect::ALL {
                assert!(tested.contains(&d), "{} has no kill test", d.id());
            }
        }
        mod mutant_is_killed {
            $(
                #[test]
                fn $name() {
                    super::is_killed_by_its_named_check(
                        crate::selftest::bsdf_mutant::BsdfDefect::$defect,
                    );
                }
            )*
        }
    };
}

/// The named checks run alone give the records the whole audit gives them (same seeds, same
/// level), so the kill tests above judge what the gate judges.
#[test]
fn named_checks_run_alone_give_the_whole_audits_records() {
    use crate::run::{check_seed, judge_at, sidak_alpha};
    use crate::selftest::bsdf_mutant::{BsdfDefect, MutatedBsdf};
    use crate::tolerance::STATISTICAL_ALPHA;
    let m = MutatedBsdf::new(BsdfDefect::EtaSquaredMissing);
    let whole = crate::Audit::of_bsdf(&m).profile(Profile::Ci).seed(7).run();
    let audit = crate::Audit::of_bsdf(&m).profile(Profile::Ci).seed(7);
    let (plan, _) = audit.plan();
    let k = plan.iter().filter(|p| p.statistical).count();
    let mut alone: Vec<CheckRecord> = plan
        .iter()
        .filter(|p| p.check == "bsdf.reciprocity" || p.check == "bsdf.stability")
        .map(|p| {
            (p.run)(&RunContext {
                seed: check_seed(7, p),
            })
        })
        .collect();
    judge_at(&mut alone, sidak_alpha(STATISTICAL_ALPHA.value, k));
    assert!(alone.len() >= 2);
    for r in &alone {
        let w = whole
            .records
            .iter()
            .find(|w| w.check == r.check && w.case == r.case)
            .unwrap_or_else(|| panic!("{} {} not in the whole audit", r.check, r.case));
        assert_eq!(
            (&w.verdict, &w.measured, w.value),
            (&r.verdict, &r.measured, r.value),
            "{} {}",
            r.check,
            r.case
        );
    }
}

mutant_tests! {
    weight_off: WeightOff,
    reflection_jacobian_missing: ReflectionJacobianMissing,
    refraction_jacobian_missing: RefractionJacobianMissing,
    eta_squared_inverted: EtaSquaredInverted,
    eta_squared_missing: EtaSquaredMissing,
    fresnel_wrong_cosine_in_pdf: FresnelWrongCosineInPdf,
    total_internal_reflection_lost: TotalInternalReflectionLost,
    side_condition_lost_in_eval: SideConditionLostInEval,
    samples_lost: SamplesLost,
    g1_missing_in_visible_pdf: G1MissingInVisiblePdf,
    arguments_swapped: ArgumentsSwapped,
    nan_at_degenerate_half_vector: NanAtDegenerateHalfVector,
    reflection_value_off: ReflectionValueOff,
    total_internal_reflection_early: TotalInternalReflectionEarly,
}

#[test]
fn the_reference_bsdfs_pass_every_check() {
    for text in [
        r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#,
        r#"{"bsdf":"dielectric","eta":0.6,"ndf":{"family":"beckmann","alpha_x":0.2,"alpha_y":0.5},"masking":"uncorrelated","sampling":"normals","transport":"importance"}"#,
        r#"{"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"ggx","alpha":0.5},"fresnel":"schlick"}"#,
    ] {
        // Through the gate: the statistical checks at the audit's Šidák level.
        let b = spec(text).build().unwrap();
        let report = crate::Audit::of_bsdf(&b).profile(Profile::Ci).run();
        let records = report.records;
        assert!(records.len() > 10, "{text}: {}", records.len());
        assert_eq!(failures(&records), Vec::<String>::new(), "{text}");
        let checks: std::collections::BTreeSet<_> =
            records.iter().map(|r| r.check.as_str()).collect();
        for c in [
            "bsdf.chi2",
            "bsdf.sample_consistency",
            "bsdf.failure_rate",
            "bsdf.albedo",
            "bsdf.energy",
            "bsdf.reciprocity",
            "bsdf.stability",
        ] {
            assert!(checks.contains(c), "{text}: {c} not planned");
        }
    }
}

#[test]
fn a_transmitting_bsdf_is_checked_from_inside_and_beyond_the_critical_angle() {
    let b = spec(r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#)
        .build()
        .unwrap();
    let names: Vec<_> = incidences(b.as_ref()).iter().map(|i| i.name).collect();
    assert_eq!(
        names,
        [
            "normal",
            "oblique",
            "grazing",
            "inside",
            "total_internal_reflection"
        ]
    );
    let tir = incidences(b.as_ref())[4].wi;
    // Inside (z < 0), beyond the critical angle asin(1/1.5).
    assert!(tir[2] < 0.0 && (-tir[2]).acos() > (1.0f64 / 1.5).asin());
}

#[test]
fn the_reference_against_itself_agrees_and_a_different_eta_does_not() {
    let text = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#;
    let subject = BsdfSubject::reference(&spec(text)).unwrap();
    let records = run(&plan_against(&subject, &spec(text), "test"));
    assert_eq!(records.len(), 3);
    assert_eq!(failures(&records), Vec::<String>::new());
    let other = spec(r#"{"bsdf":"dielectric","eta":1.33,"ndf":{"family":"ggx","alpha":0.3}}"#);
    let records = run(&plan_against(&subject, &other, "test"));
    assert!(records.iter().all(|r| r.verdict == Verdict::Fail));
}
