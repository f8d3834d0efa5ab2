//! Sharded-then-merged equals unsharded ("Beyond one machine"): the audit of a small
//! scene run whole, and run as n = 1, 3, 7 shards by `examples/ci/shard.sh` and merged by
//! `examples/ci/merge.sh` — the scripts the GitHub Actions and Slurm examples call — gives the
//! same report.json, timings and artefact folders aside. Also: merge refuses a missing shard,
//! shards of another seed and another schema version; `--baseline` finds a grown error.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mfh-shard-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `bash script args…` from the repository root with `MFH` set to the built binary.
fn script(name: &str, args: &[&str]) -> (i32, String) {
    let out = Command::new("bash")
        .arg(root().join("examples/ci").join(name))
        .args(args)
        .current_dir(root())
        .env("MFH", env!("CARGO_BIN_EXE_mfh"))
        .output()
        .expect("bash runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code().unwrap_or(-1), text)
}

fn mfh(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("mfh runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code().unwrap_or(-1), text)
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The report without what may differ between runs: wall times, and the output folder in
/// artefact paths.
fn normalized(mut v: Value) -> Value {
    v["summary"]["wall_seconds"] = Value::Null;
    if let Some(by) = v["summary"]["by_check"].as_object_mut() {
        for c in by.values_mut() {
            c["seconds"] = Value::Null;
        }
    }
    for r in v["records"].as_array_mut().unwrap() {
        r["cost"]["wall_seconds"] = Value::Null;
        if let Some(a) = r["artefacts"].as_array_mut() {
            for p in a.iter_mut() {
                let s = p.as_str().unwrap_or("");
                let at = ["chi2/", "ks/", "curves/"].iter().find_map(|k| s.find(k));
                *p = Value::from(at.map_or(s, |i| &s[i..]));
            }
        }
    }
    v
}

const SCENE: &str = "examples/scenes/conductor.xml";

#[test]
fn sharded_then_merged_equals_unsharded_for_1_3_7_shards() {
    let dir = temp("equal");
    let whole = dir.join("whole");
    let (code, text) = mfh(&[
        "audit",
        "--scene",
        SCENE,
        "--seed",
        "5",
        "--out",
        whole.to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 1, "{text}");
    let expected = read(&whole.join("report.json"));
    let statistical = expected["summary"]["statistical"][0].as_u64().unwrap();
    assert!(statistical > 0, "the scene has statistical checks");
    for n in [1usize, 3, 7] {
        let out = dir.join(format!("n{n}"));
        let out_s = out.to_str().unwrap();
        let mut records = 0;
        for i in 1..=n {
            let (c, text) = script(
                "shard.sh",
                &[
                    &i.to_string(),
                    &n.to_string(),
                    out_s,
                    "--scene",
                    SCENE,
                    "--seed",
                    "5",
                ],
            );
            assert!(c == 0 || c == 1, "shard {i}/{n}: {text}");
            let shard = read(&out.join(format!("shard-{i}/report.json")));
            records += shard["records"].as_array().unwrap().len();
            assert!(
                shard["command"]
                    .as_str()
                    .unwrap()
                    .ends_with(&format!("--shard {i}/{n}")),
                "{shard}"
            );
        }
        assert_eq!(
            records,
            expected["records"].as_array().unwrap().len(),
            "n = {n}"
        );
        let (c, text) = script("merge.sh", &[&n.to_string(), out_s]);
        assert_eq!(c, code, "n = {n}: {text}");
        let merged = read(&out.join("merged/report.json"));
        assert_eq!(
            merged["summary"]["statistical"], expected["summary"]["statistical"],
            "n = {n}: Šidák level over the whole family"
        );
        let (m, e) = (normalized(merged), normalized(expected.clone()));
        if m != e {
            for (a, b) in m["records"]
                .as_array()
                .unwrap()
                .iter()
                .zip(e["records"].as_array().unwrap())
            {
                assert_eq!(a, b, "n = {n}: first differing record");
            }
            panic!("n = {n}: merged ≠ unsharded:\n{m}\n{e}");
        }
        assert!(out.join("merged/junit.xml").exists());
    }

    // A missing shard, a shard of another seed: exit 2 naming the problem.
    let n3 = dir.join("n3");
    let (c, text) = mfh(&[
        "merge",
        n3.join("shard-1").to_str().unwrap(),
        n3.join("shard-3").to_str().unwrap(),
        "--out",
        dir.join("bad").to_str().unwrap(),
    ]);
    assert_eq!(c, 2);
    assert!(text.contains("missing shard(s) 2/3"), "{text}");
    let other = dir.join("other");
    let (c, _) = script(
        "shard.sh",
        &[
            "2",
            "3",
            other.to_str().unwrap(),
            "--scene",
            SCENE,
            "--seed",
            "6",
        ],
    );
    assert!(c == 0 || c == 1);
    let (c, text) = mfh(&[
        "merge",
        n3.join("shard-1").to_str().unwrap(),
        other.join("shard-2").to_str().unwrap(),
        n3.join("shard-3").to_str().unwrap(),
        "--out",
        dir.join("bad").to_str().unwrap(),
    ]);
    assert_eq!(c, 2);
    assert!(
        text.contains("not shards of one audit: seed 5 ≠ 6"),
        "{text}"
    );
    // Another schema version is refused by name.
    let old = dir.join("old");
    std::fs::create_dir_all(&old).unwrap();
    let mut v = read(&n3.join("shard-2/report.json"));
    v["schema_version"] = Value::from(99);
    std::fs::write(old.join("report.json"), v.to_string()).unwrap();
    std::fs::copy(n3.join("shard-2/shard.json"), old.join("shard.json")).unwrap();
    let (c, text) = mfh(&[
        "merge",
        n3.join("shard-1").to_str().unwrap(),
        old.to_str().unwrap(),
        n3.join("shard-3").to_str().unwrap(),
    ]);
    assert_eq!(c, 2);
    assert!(text.contains("schema_version 99"), "{text}");

    // --baseline: a baseline whose first error-measuring record had a tenth of today's error
    // (and slow checks everywhere, so cost cannot regress) makes that record regress.
    let mut base = expected.clone();
    let records = base["records"].as_array_mut().unwrap();
    let mut target = None;
    for r in records.iter_mut() {
        r["cost"]["wall_seconds"] = Value::from(1e9);
        r["cost"]["samples"] = Value::from(u64::MAX / 4);
        r["cost"]["evaluations"] = Value::from(u64::MAX / 4);
        let e = r["measured"]["error"].as_f64().unwrap_or(0.0);
        if target.is_none() && e > 1e-12 && e.is_finite() {
            r["measured"]["error"] = Value::from(e / 10.0);
            target = Some(r["check"].as_str().unwrap().to_string());
        }
    }
    let target = target.expect("a record with an error above 1e-12");
    let base_path = dir.join("baseline.json");
    std::fs::write(&base_path, base.to_string()).unwrap();
    let merged = n3.join("merged");
    let baseline_args = [
        "merge",
        n3.join("shard-1").to_str().unwrap(),
        n3.join("shard-2").to_str().unwrap(),
        n3.join("shard-3").to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
        "--baseline",
        base_path.to_str().unwrap(),
    ]
    .map(String::from);
    let args: Vec<&str> = baseline_args.iter().map(String::as_str).collect();
    let (c, text) = mfh(&args);
    assert_eq!(c, code, "{text}");
    assert!(
        text.contains("1 regression(s)") && text.contains(&target),
        "{text}"
    );
    let mut strict = args.clone();
    strict.push("--fail-on-regression");
    let (c, text) = mfh(&strict);
    assert_eq!(c, 1, "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Merge re-judges every stored verdict from the record's numbers. A shard whose
/// passing record was edited to a measured error of 1.0 against a tolerance of 1e-10 (a failure
/// with its verdict left at pass) merges as a fail, exit 1, and merge says how many verdicts it
/// corrected; the unedited shard merges with no correction.
#[test]
fn merge_rejudges_a_verdict_its_numbers_contradict() {
    let dir = temp("rejudge");
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"name": "tiny", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3}}]}"#,
    )
    .unwrap();
    let shard = dir.join("shard");
    let (code, text) = mfh(&[
        "audit",
        "--scene",
        scene.to_str().unwrap(),
        "--profile",
        "ci",
        "--seed",
        "5",
        "--shard",
        "1/1",
        "--quiet",
        "--out",
        shard.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{text}");
    let merged = dir.join("merged");
    let (code, text) = mfh(&[
        "merge",
        shard.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{text}");
    assert!(!text.contains("corrected"), "{text}");

    let path = shard.join("report.json");
    let mut v = read(&path);
    let records = v["records"].as_array_mut().unwrap();
    let (index, r) = records
        .iter_mut()
        .enumerate()
        .find(|(_, r)| r["verdict"] == "pass" && r["measured"]["error"].is_number())
        .expect("a passing record with a measured error");
    r["measured"]["error"] = Value::from(1.0);
    r["tolerance"]["value"] = Value::from(1e-10);
    let check = r["check"].as_str().unwrap().to_string();
    std::fs::write(&path, v.to_string()).unwrap();
    let (code, text) = mfh(&[
        "merge",
        shard.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("corrected 1 stored verdict(s)"), "{text}");
    assert!(
        text.contains(&format!(
            "plan index {index} ({check}): stored verdict pass"
        )),
        "{text}"
    );
    let report = read(&merged.join("report.json"));
    assert_eq!(report["records"][index]["verdict"], "fail");
    assert_eq!(
        report["summary"]["counts"]["fail"], 1,
        "{}",
        report["summary"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An edit of shard folders read back: (report.json, shard.json) of each shard.
type Edit<'a> = dyn Fn(&mut [(Value, Value)]) + 'a;

/// Shard folders can be edited: merge takes a record only at the plan index of the check that
/// made it (its check, model and case are the planned check's, and the planned checks make up
/// the plan's fingerprint), and a failure with no numbers to re-judge cannot become a pass or
/// a skip. Each tampering starts from the same two shards of a tiny audit.
#[test]
fn merge_refuses_or_rejudges_every_tampered_shard() {
    let dir = temp("tamper");
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"name": "tiny", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3}, "sampling": "normals"}]}"#,
    )
    .unwrap();
    for i in 1..=2 {
        let out = dir.join(format!("shard-{i}"));
        let shard = format!("{i}/2");
        let (code, text) = mfh(&[
            "audit",
            "--scene",
            scene.to_str().unwrap(),
            "--profile",
            "ci",
            "--seed",
            "5",
            "--shard",
            &shard,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{text}");
    }
    let original: Vec<(Value, Value)> = (1..=2)
        .map(|i| {
            let d = dir.join(format!("shard-{i}"));
            (read(&d.join("report.json")), read(&d.join("shard.json")))
        })
        .collect();
    // Merges the shards as `edit` leaves them: (exit code, output, merged report.json).
    let merge = |name: &str, edit: &Edit<'_>| {
        let mut shards = original.clone();
        edit(&mut shards);
        let mut dirs = Vec::new();
        for (i, (report, info)) in shards.iter().enumerate() {
            let d = dir.join(name).join(format!("shard-{}", i + 1));
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(d.join("report.json"), report.to_string()).unwrap();
            std::fs::write(d.join("shard.json"), info.to_string()).unwrap();
            dirs.push(d.display().to_string());
        }
        let out = dir.join(name).join("merged");
        let mut args = vec!["merge", "--out", out.to_str().unwrap()];
        args.extend(dirs.iter().map(String::as_str));
        let (code, text) = mfh(&args);
        let merged = std::fs::read_to_string(out.join("report.json"))
            .ok()
            .map(|t| serde_json::from_str::<Value>(&t).unwrap());
        (code, text, merged)
    };
    let (code, text, _) = merge("untouched", &|_| {});
    assert_eq!(code, 0, "{text}");

    // A chi-square that failed its sanity checks, as the check writes it (its tolerance, no
    // p-value, the reason in its case), edited to pass or to skipped: re-judged as a fail.
    for verdict in ["pass", "skipped"] {
        let (code, text, merged) = merge(verdict, &|s| {
            let records = s[0].0["records"].as_array_mut().unwrap();
            let r = records
                .iter_mut()
                .find(|r| r["measured"]["kind"] == "p_value")
                .expect("a chi-square record");
            r["measured"] = Value::Null;
            r["case"]["sanity_failure"] = Value::from("pdf mass 0.9 ≠ 1");
            r["verdict"] = Value::from(verdict);
            r["reason"] = Value::from("edited");
        });
        assert_eq!(code, 1, "{verdict}: {text}");
        assert!(
            text.contains(&format!("stored verdict {verdict}"))
                && text.contains("re-judged as fail"),
            "{verdict}: {text}"
        );
        assert_eq!(merged.unwrap()["summary"]["counts"]["fail"], 1, "{verdict}");
    }

    // Refused, exit 2, with the shard and what is wrong: indices swapped in a shard.json (with
    // and without their planned checks), a renamed check, an edited case.
    let cases: [(&str, &Edit<'_>, &str); 4] = [
        (
            "indices",
            &|s| {
                let idx = s[0].1["indices"].as_array_mut().unwrap();
                idx.swap(0, 1);
            },
            "a shard.json was edited",
        ),
        (
            "indices-and-planned",
            &|s| {
                s[0].1["indices"].as_array_mut().unwrap().swap(0, 1);
                s[0].1["planned"].as_array_mut().unwrap().swap(0, 1);
                s[0].0["records"].as_array_mut().unwrap().swap(0, 1);
                // Moved together, they merge as before; a planned check edited with its
                // record is not the plan's.
                s[0].1["planned"][0]["case"]["edited"] = Value::from(true);
                s[0].0["records"][0]["case"]["edited"] = Value::from(true);
            },
            "a shard.json was edited",
        ),
        (
            "renamed",
            &|s| s[1].0["records"][0]["check"] = Value::from("smith.no_such_check"),
            "its check is `smith.no_such_check`",
        ),
        (
            "case",
            &|s| {
                let records = s[1].0["records"].as_array_mut().unwrap();
                let r = records
                    .iter_mut()
                    .find(|r| r["case"].as_object().is_some_and(|c| !c.is_empty()))
                    .expect("a record with a case");
                let key = r["case"]
                    .as_object()
                    .unwrap()
                    .keys()
                    .next()
                    .unwrap()
                    .clone();
                r["case"][&key] = Value::from("edited");
            },
            "does not hold the planned case",
        ),
    ];
    for (name, edit, says) in cases {
        let (code, text, _) = merge(name, edit);
        assert_eq!(code, 2, "{name}: {text}");
        assert!(text.contains(says), "{name}: {text}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
