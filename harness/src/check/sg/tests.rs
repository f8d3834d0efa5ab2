use super::isotropic::SRC_INTEGRAL;
use super::*;
use crate::check::RunContext;
use crate::tolerance::CLOSED_FORM;
use mfh_reference::sg::Sg;
use serde_json::json;

#[test]
fn quick_plan_passes_or_fails_as_expected() {
    let plan = plan(Profile::Quick, true, true, "test");
    let ctx = RunContext { seed: 1 };
    use rayon::prelude::*;
    let records: Vec<CheckRecord> = plan.par_iter().map(|p| (p.run)(&ctx)).collect();
    let mut expected = 0;
    let mut errors = Vec::new();
    for r in records {
        match &r.verdict {
            Verdict::Pass => {}
            Verdict::ExpectedFailure { .. } => expected += 1,
            v => errors.push(format!(
                "{} {} {:?} {:?} {:?}: {v:?}",
                r.check, r.case, r.value, r.oracle, r.measured
            )),
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    assert!(expected > 0);
}

#[test]
fn standard_plan_covers_every_closed_form_of_eval() {
    let plan = plan(Profile::Standard, true, true, "");
    let covered: std::collections::BTreeSet<&str> = plan
        .iter()
        .flat_map(|p| p.covers.iter().map(String::as_str))
        .collect();
    for id in CLOSED_FORMS.iter().chain(LIBRARY_FORMS) {
        assert!(covered.contains(id), "{id} is not covered");
    }
    for id in &covered {
        assert!(
            CLOSED_FORMS.contains(id) || LIBRARY_FORMS.contains(id),
            "{id} is not listed"
        );
    }
    // The ids are the quantities `mfh eval` answers.
    for id in CLOSED_FORMS {
        let quantity = id.split('/').nth(1).unwrap();
        assert!(crate::eval::sg::QUANTITIES.contains(&quantity), "{id}");
    }
}

#[test]
fn checks_can_fail() {
    // A wrong value is caught by the comparison the checks use.
    let a = Sg::new(axis(), 10.0, 1.0).unwrap();
    let o = sphere(&|v| a.eval(v), axis(), PI, width(10.0), None);
    let mut r = CheckRecord::new("sg.integral_route", Value::Null, json!({}), SRC_INTEGRAL);
    compare(&mut r, a.integral(), o, &CLOSED_FORM);
    assert_eq!(r.verdict, Verdict::Pass);
    compare(&mut r, a.integral() * (1.0 + 1e-8), o, &CLOSED_FORM);
    assert_eq!(r.verdict, Verdict::Fail);
}

#[test]
fn great_circle_cut_lies_on_the_circle() {
    let p = axis();
    let n = around(p, 1.0, 0.4);
    let (theta, _) = great_circle(p, n);
    for phi in [0.0, 1.0, 2.5, 4.0, 6.0] {
        let v = around(p, theta(phi)[0], phi);
        assert!(dot(v, n).abs() < 1e-12, "{phi}");
    }
}

/// Runs and prints every record of the standard plan and asserts that none fails (extensive
/// tier: `cargo test -p mfh-harness --lib check::sg::tests::dump -- --nocapture` with
/// `MFH_EXTENSIVE=1`).
#[cfg(test)]
mod dump {
    use super::*;

    #[test]
    #[cfg_attr(not(mfh_extensive), ignore = "extensive tier: set MFH_EXTENSIVE=1")]
    fn standard() {
        let ctx = crate::check::RunContext { seed: 1 };
        for p in plan(Profile::Standard, true, true, "") {
            let r = (p.run)(&ctx);
            println!(
                "{:28} {:9} {:.2e} {:.3}s {}",
                r.check,
                r.verdict.name(),
                r.measured.and_then(|m| m.error()).unwrap_or(f64::NAN),
                r.cost.wall_seconds,
                r.case
            );
            // The standard plan holds: every record passes, fails as expected or is skipped
            // with its reason (what the printed table shows).
            assert!(
                !r.verdict.is_failure(),
                "{} {}: {:?}",
                r.check,
                r.case,
                r.verdict
            );
        }
    }
}
