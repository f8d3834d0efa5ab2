//! End to end: `mfh audit` and `mfh plan` (ARCHITECTURE.md "Checks and records", "Scenes"),
//! driven through `mfh_harness::cli::run` as the binary calls it, and the coverage registry:
//! every closed form of `reference/` is covered by a planned check of the default scene.

use mfh_harness::check::{Planned, Profile};
use mfh_harness::plan::plan;
use mfh_harness::record::{CheckRecord, Verdict, SCHEMA_VERSION};
use mfh_harness::run::{audit_scene, run_plan, AuditOptions};
use mfh_harness::scene::Scene;
use mfh_reference::Model;
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn mfh(args: &[&str]) -> (i32, String, String) {
    mfh_harness::cli::run_captured(args)
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mfh-audit-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A small scene: one GGX material that masks and samples, nothing else.
const GGX_SCENE: &str = r#"{
  "name": "ggx only",
  "materials": [
    {"name": "floor", "model": {"family": "ggx", "alpha": 0.3},
     "masking": "height_correlated", "sampling": "normals"}
  ],
  "incidence": {"theta_max": 1.4}
}"#;

#[test]
fn a_passing_audit_exits_0_and_writes_a_versioned_report_and_junit() {
    let dir = temp("pass");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, GGX_SCENE).unwrap();
    let out = dir.join("out");
    let (code, stdout, stderr) = mfh(&[
        "audit",
        "--scene",
        scene.to_str().unwrap(),
        "--seed",
        "11",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(stdout.contains("PASS"), "{stdout}");
    assert!(
        stdout.contains("--seed 11"),
        "the reproduce command: {stdout}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["schema_version"], SCHEMA_VERSION);
    assert_eq!(report["seed"], 11);
    let records = report["records"].as_array().unwrap();
    assert!(records.len() > 20, "{}", records.len());
    for r in records {
        for key in ["check", "model", "case", "verdict", "cost", "source"] {
            assert!(r.get(key).is_some(), "{key} missing in {r}");
        }
        assert!(!r["source"].as_str().unwrap().is_empty(), "{r}");
    }
    // Only what the scene uses: GGX (document 001) checks, no SG, D_s, GTR or piecewise checks.
    for r in records {
        let check = r["check"].as_str().unwrap();
        assert!(
            !check.starts_with("sg.") && !check.starts_with("ds."),
            "{check}"
        );
        if let Some(f) = r["model"].get("family").and_then(Value::as_str) {
            assert!(
                !matches!(f, "gtr" | "piecewise_linear" | "gaussian_slopes"),
                "{r}"
            );
        }
    }
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(junit.starts_with("<?xml"), "{junit}");
    assert!(junit.contains("<testsuite"), "{junit}");
    assert_eq!(junit.matches("<testcase").count(), records.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_exits_2_with_a_located_message() {
    let dir = temp("bad");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, GGX_SCENE.replace("\"masking\"", "\"maskin\"")).unwrap();
    let (code, _, stderr) = mfh(&["audit", "--scene", scene.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("maskin") && stderr.contains(":5:"),
        "{stderr}"
    );

    let (code, _, stderr) = mfh(&[
        "audit",
        "--scene",
        dir.join("missing.json").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cannot read"), "{stderr}");

    std::fs::write(&scene, GGX_SCENE.replace("\"alpha\": 0.3", "\"alpha\": -1")).unwrap();
    let (code, _, stderr) = mfh(&["audit", "--scene", scene.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("floor"), "names the material: {stderr}");

    let (code, _, stderr) = mfh(&["audit", "--profile", "fastest"]);
    assert_eq!(code, 2, "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A failing check fails the audit (the CLI maps `passed() == false` to exit status 1).
#[test]
fn a_failing_check_fails_the_audit() {
    let failing = Planned {
        check: "test.always_wrong".into(),
        model: json!({}),
        case: json!({}),
        why: "test".into(),
        covers: vec![],
        statistical: false,
        run: Box::new(|_| {
            let mut r = CheckRecord::new("test.always_wrong", json!({}), json!({}), "test");
            r.verdict = Verdict::Fail;
            r
        }),
    };
    let panicking = Planned {
        check: "test.panics".into(),
        model: json!({}),
        case: json!({}),
        why: "test".into(),
        covers: vec![],
        statistical: false,
        run: Box::new(|_| panic!("boom")),
    };
    let (records, _, _) = run_plan(&[failing, panicking], &AuditOptions::default());
    assert_eq!(records[0].verdict, Verdict::Fail);
    assert!(
        matches!(&records[1].verdict, Verdict::Error { message } if message.contains("boom")),
        "{:?}",
        records[1].verdict
    );
}

/// The same seed gives the same records whatever the number of threads.
#[test]
fn the_report_does_not_depend_on_the_thread_count() {
    let scene = Scene::parse(GGX_SCENE, "<test>").unwrap();
    let options = AuditOptions {
        profile: Profile::Quick,
        seed: 5,
        out: None,
        ..Default::default()
    };
    let strip = |records: Vec<CheckRecord>| -> Vec<Value> {
        records
            .into_iter()
            .map(|mut r| {
                r.cost = Default::default();
                serde_json::to_value(r).unwrap()
            })
            .collect()
    };
    let with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| strip(audit_scene(&scene, None, &options).records))
    };
    let (one, two) = (with(1), with(2));
    assert_eq!(one.len(), two.len());
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(a, b);
    }
}

/// The registry: every closed form the reference exposes for the default scene's models (D,
/// every Λ route, G1, both G2, P2/P22 and slope moments, sampling and its pdf, D_s moments by
/// every route) and every SG/ASG form is covered by a check the default plan runs.
#[test]
fn the_default_plan_covers_every_closed_form() {
    let scene = Scene::default_scene();
    let planned = plan(&scene, Profile::Quick);
    let covered: BTreeSet<&str> = planned
        .iter()
        .flat_map(|p| p.covers.iter().map(String::as_str))
        .collect();
    let mut required: BTreeSet<String> = BTreeSet::new();
    let mut families = BTreeSet::new();
    for material in &scene.materials {
        // The default scene's materials are NDF materials (no reference BSDF).
        let spec = material.model.as_ref().expect("an NDF material");
        let model: Box<dyn Model> = spec.build().unwrap();
        let f = model.family();
        families.insert(f);
        required.insert(format!("{f}/d/default"));
        if let Some(s) = model.as_smith() {
            for r in s.lambda_routes() {
                required.insert(format!("{f}/lambda/{r}"));
            }
            required.insert(format!("{f}/g1/default"));
            required.insert(format!("{f}/g2/uncorrelated"));
            required.insert(format!("{f}/g2/height_correlated"));
        }
        if model.as_slopes().is_some() {
            for q in ["p2", "p22", "slope_moment"] {
                required.insert(format!("{f}/{q}/default"));
            }
        }
        if model.as_sampler().is_some() && material.sampling.is_some() {
            required.insert(format!("{f}/sample_wm/default"));
            required.insert(format!("{f}/pdf_wm/default"));
        }
        if model.as_visible_sampler().is_some()
            && material.sampling == Some(mfh_harness::scene::Sampling::VisibleNormals)
        {
            required.insert(format!("{f}/sample_wm_visible/default"));
            required.insert(format!("{f}/pdf_wm_visible/default"));
        }
        if let Some(v) = model.as_visible_moments() {
            for r in v.visible_moments_routes() {
                required.insert(format!("{f}/visible_moments/{r}"));
            }
        }
    }
    for id in mfh_harness::check::sg::CLOSED_FORMS
        .iter()
        .chain(mfh_harness::check::sg::LIBRARY_FORMS)
    {
        required.insert(id.to_string());
    }
    let missing: Vec<&String> = required
        .iter()
        .filter(|id| !covered.contains(id.as_str()))
        .collect();
    assert!(missing.is_empty(), "not covered by any check: {missing:?}");
    // That the default scene holds every family is `scene::tests`'s check.
    assert!(families.len() >= 10, "{families:?}");
}

/// `mfh plan` prints one JSON line per check with the reason it is planned.
#[test]
fn plan_lists_each_check_with_its_reason() {
    let (code, stdout, stderr) = mfh(&["plan"]);
    assert_eq!(code, 0, "{stderr}");
    let lines: Vec<Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(lines.len() > 500, "{}", lines.len());
    for l in &lines {
        assert!(!l["why"].as_str().unwrap().is_empty(), "{l}");
    }
}
