//! `mfh selftest`: the CI subset of the mutant catalog is killed at every seed, each mutant by
//! one of the checks expected to see its defect, and every unmutated control passes (through
//! the command line, in-process, reading its report.json back); bad input is exit 2. With
//! `MFH_EXTENSIVE=1`, the false-alarm calibration: 1000 seeded chi-square and KS runs of the
//! correct GGX and Beckmann samplers lie in their 99 % binomial intervals with uniform
//! p-values.

use mfh_harness::selftest::{calibrate, catalog::CATALOG};
use serde_json::Value;
use std::path::PathBuf;

fn mfh(args: &[&str]) -> (i32, String, String) {
    mfh_harness::cli::run_captured(args)
}

fn out_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn the_ci_subset_is_killed_at_every_seed_by_an_expected_check() {
    let dir = out_dir("mfh-selftest-ci");
    let (code, out, err) = mfh(&[
        "selftest",
        "--subset",
        "ci",
        "--profile",
        "quick",
        "--seeds",
        "3",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    println!("{out}");
    assert_eq!(code, 0, "{out}\n{err}");
    let text = std::fs::read_to_string(dir.join("report.json")).expect("report.json");
    let doc: Value = serde_json::from_str(&text).expect("json");
    assert_eq!(doc["schema_version"], 1);
    let st = &doc["selftest"];
    let mutants = st["mutants"].as_array().expect("mutants");
    let ci: Vec<_> = CATALOG.iter().filter(|e| e.ci).collect();
    assert_eq!(mutants.len(), ci.len());
    for (m, e) in mutants.iter().zip(&ci) {
        assert_eq!(m["id"], e.id);
        let runs = m["runs"].as_array().expect("runs");
        assert_eq!(runs.len(), 3, "{}", e.id);
        for r in runs {
            assert_eq!(r["killed"], true, "{} survived: {r}", e.id);
            let killers: Vec<&str> = r["killers"]
                .as_array()
                .unwrap()
                .iter()
                .filter_map(Value::as_str)
                .collect();
            assert!(
                e.expected.iter().any(|x| killers.contains(x)),
                "{}: killers {killers:?}, expected one of {:?}",
                e.id,
                e.expected
            );
        }
    }
    let controls = st["controls"].as_array().expect("controls");
    assert!(!controls.is_empty());
    for c in controls {
        assert_eq!(c["passed"], true, "control failed: {c}");
    }
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    assert!(html.contains("Kill matrix") && html.contains(ci[0].id));
}

#[test]
fn bad_selftest_input_is_exit_2_naming_the_option() {
    let dir = out_dir("mfh-selftest-bad");
    let d = dir.to_str().unwrap();
    for (args, needle) in [
        (vec!["selftest", "--seeds", "0", "--out", d], "--seeds 0"),
        (
            vec!["selftest", "--seeds", "101", "--out", d],
            "--seeds 101",
        ),
        (
            vec!["selftest", "--calibrate", "0", "--out", d],
            "--calibrate 0",
        ),
        (
            vec!["selftest", "--only", "no such mutant", "--out", d],
            "--only",
        ),
        (vec!["selftest", "--subset", "some", "--out", d], "--subset"),
    ] {
        let (code, out, err) = mfh(&args);
        assert_eq!(code, 2, "{args:?}: {out} {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn a_survivor_or_a_miss_fails_the_selftest() {
    use mfh_harness::selftest::{
        catalog::Route, mutant::Defect, KillRun, MutantResult, SelftestOptions, SelftestReport,
        Subset,
    };
    let options = SelftestOptions {
        profile: mfh_harness::Profile::Quick,
        seeds: SelftestOptions::seeds(1),
        subset: Subset::Ci,
        filter: None,
        on_check: None,
    };
    let run = |killed: bool, hit: bool| KillRun {
        seed: options.seeds[0],
        killed,
        killers: if killed {
            vec!["smith.g1_g2".into()]
        } else {
            vec![]
        },
        expected_hit: hit,
        unexpected_passes: vec![],
        records: 10,
        seconds: 0.0,
    };
    let mutant = |runs: Vec<KillRun>| MutantResult {
        id: "m".into(),
        description: String::new(),
        base: Value::Null,
        defect: Defect::G2Uncorrelated,
        expected: vec!["smith.g1_g2".into()],
        route: Route::Gate {
            slope_moments: false,
        },
        runs,
    };
    let mut report = SelftestReport::empty(&options);
    report.mutants.push(mutant(vec![run(true, true)]));
    assert!(report.passed());
    for (runs, why) in [
        (vec![run(false, false)], "survived"),
        (vec![run(true, false)], "none of the expected"),
        (vec![], ""),
    ] {
        let mut r = report.clone();
        r.mutants.push(mutant(runs));
        assert!(!r.passed());
        assert!(
            r.survivors().iter().all(|s| s.contains(why)),
            "{:?}",
            r.survivors()
        );
    }
}

#[test]
#[cfg_attr(
    not(mfh_extensive),
    ignore = "extensive tier: set MFH_EXTENSIVE=1 (1000 calibration runs per test)"
)]
fn false_alarm_calibration_extensive() {
    let c = calibrate::calibrate(
        &calibrate::DEFAULT_MODELS,
        1000,
        mfh_harness::Profile::Quick,
        None,
    )
    .expect("calibration");
    for t in &c.tests {
        println!(
            "{} {}: {:?}, uniformity D = {}, p = {}",
            t.model, t.test, t.levels, t.uniformity_statistic, t.uniformity_p_value
        );
        assert_eq!(t.runs, 1000);
        assert!(t.passed(), "{} {} miscalibrated: {t:?}", t.model, t.test);
    }
    assert_eq!(c.tests.len(), 6);
    let b = calibrate::calibrate_bsdf(1000, mfh_harness::Profile::Quick, None).expect("BSDF");
    for t in &b {
        println!(
            "{} {}: {:?}, uniformity p = {}",
            t.model, t.test, t.levels, t.uniformity_p_value
        );
        assert!(t.passed(), "{} {} miscalibrated: {t:?}", t.model, t.test);
    }
    assert_eq!(b.len(), 2);
}
