//! Audits that never go silent and never lose work: every finished record is in
//! `report.jsonl` when an audit is killed, `--resume` finishes it with the records of an
//! uninterrupted run, `--max-time` ends it with a failing report naming what did not run, and a
//! non-terminal standard error gets progress lines.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mfh-resume-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A scene of one GGX material, masking and sampled: its `ci` plan has a few dozen checks of a
/// few seconds in all (chi-square and KS among them: records with data).
fn tiny_scene(dir: &Path) -> String {
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"name": "tiny", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3},
            "masking": "height_correlated", "sampling": "normals"}]}"#,
    )
    .unwrap();
    scene.display().to_string()
}

/// Runs mfh with `args` and the environment `env`: (exit code, stdout, stderr).
fn mfh_env(args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_mfh"));
    c.args(args).current_dir(root()).stdin(Stdio::null());
    for (k, v) in env {
        c.env(k, v);
    }
    let out = c.output().expect("mfh runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn mfh(args: &[&str]) -> (i32, String, String) {
    mfh_env(args, &[])
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The lines of a report.jsonl: (header, record lines).
fn jsonl(path: &Path) -> (Value, Vec<Value>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap());
    let header = lines.next().expect("a header line");
    (header, lines.collect())
}

/// A report's records without what timing or the output folder changes: wall times, and the
/// folder in artefact paths.
fn normalized_records(report: &Value, dir: &Path) -> Vec<Value> {
    let prefix = dir.display().to_string();
    let mut records = report["records"].as_array().unwrap().clone();
    for r in &mut records {
        r["cost"]["wall_seconds"] = Value::Null;
        if let Some(a) = r["artefacts"].as_array_mut() {
            for p in a {
                *p = Value::String(p.as_str().unwrap().replace(&prefix, "OUT"));
            }
        }
    }
    records
}

/// Common arguments of the tiny audit.
fn tiny_args<'a>(scene: &'a str, out: &'a str) -> Vec<&'a str> {
    vec![
        "audit",
        "--scene",
        scene,
        "--profile",
        "ci",
        "--seed",
        "5",
        "--quiet",
        "--out",
        out,
    ]
}

#[test]
fn a_killed_audit_keeps_its_records_and_resume_gives_the_uninterrupted_records() {
    let dir = temp("kill");
    let scene = tiny_scene(&dir);
    let (whole, part) = (dir.join("whole"), dir.join("part"));
    let (code, _, err) = mfh(&tiny_args(&scene, whole.to_str().unwrap()));
    assert_eq!(code, 0, "{err}");
    let expected = read(&whole.join("report.json"));
    let planned = expected["records"].as_array().unwrap().len();
    let (_, streamed) = jsonl(&whole.join("report.jsonl"));
    assert_eq!(streamed.len(), planned, "one line per finished check");
    assert!(streamed
        .iter()
        .all(|r| r["planned"].as_str().unwrap().len() == 16));

    // The interrupted run: one thread (the order of checks differs from the run above; records
    // must not depend on it), killed (SIGKILL) as soon as a record is on disk.
    let mut child = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(tiny_args(&scene, part.to_str().unwrap()))
        .env("RAYON_NUM_THREADS", "1")
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stream = part.join("report.jsonl");
    let t = Instant::now();
    let mut exited = false;
    loop {
        let lines = std::fs::read_to_string(&stream)
            .map(|s| s.matches('\n').count())
            .unwrap_or(0);
        if lines >= 2 {
            break;
        }
        if child.try_wait().unwrap().is_some() {
            exited = true;
            break;
        }
        assert!(t.elapsed() < Duration::from_secs(120), "no record in 120 s");
        std::thread::sleep(Duration::from_millis(5));
    }
    let _ = child.kill();
    let _ = child.wait();
    assert!(!exited, "the audit ended before it could be killed");
    assert!(
        !part.join("report.json").exists(),
        "killed before the end: no report.json"
    );
    let (header, kept) = jsonl(&stream);
    assert_eq!(header["header"]["seed"], 5, "{header}");
    assert_eq!(header["header"]["profile"], "ci", "{header}");
    assert!(
        !kept.is_empty() && kept.len() < planned,
        "{} records",
        kept.len()
    );
    for r in &kept {
        assert!(r["check"].is_string() && r["verdict"].is_string(), "{r}");
    }
    // A kill in the middle of a write leaves a line without its newline: dropped on resume.
    let mut text = std::fs::read_to_string(&stream).unwrap();
    text.push_str(r#"{"check":"smith.g1","model":{"fam"#);
    std::fs::write(&stream, text).unwrap();

    let (code, _, err) = mfh(&[
        "audit",
        "--scene",
        &scene,
        "--profile",
        "ci",
        "--seed",
        "5",
        "--quiet",
        "--resume",
        part.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("dropped the last line"), "{err}");
    let resumed = read(&part.join("report.json"));
    assert_eq!(
        normalized_records(&resumed, &part),
        normalized_records(&expected, &whole),
        "a resumed audit has the records of an uninterrupted one"
    );
    assert_eq!(resumed["summary"]["counts"], expected["summary"]["counts"]);
    let (_, all) = jsonl(&stream);
    assert_eq!(
        all.len(),
        planned,
        "the kept records and the new ones, once each"
    );
    // The records kept from the killed run are the first lines, unchanged.
    assert_eq!(&all[..kept.len()], &kept[..]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn max_time_ends_the_audit_with_a_failing_report_and_resume_finishes_it() {
    let dir = temp("maxtime");
    let scene = tiny_scene(&dir);
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let mut args = tiny_args(&scene, out_s);
    args.extend(["--max-time", "0.000001"]);
    let (code, _, err) = mfh_env(&args, &[("RAYON_NUM_THREADS", "1")]);
    assert_eq!(code, 1, "a time limit that ran out fails the audit: {err}");
    assert!(err.contains("--max-time 0.000001 s ran out"), "{err}");
    let report = read(&out.join("report.json"));
    let records = report["records"].as_array().unwrap();
    let not_run: Vec<&Value> = records
        .iter()
        .filter(|r| {
            r["verdict"] == "error"
                && r["message"]
                    .as_str()
                    .unwrap_or("")
                    .contains("time limit of 0.000001 s")
        })
        .collect();
    assert!(!not_run.is_empty(), "{report}");
    // Every record is either run (and streamed) or an error record naming the limit.
    let (_, streamed) = jsonl(&out.join("report.jsonl"));
    assert_eq!(streamed.len() + not_run.len(), records.len());
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(junit.contains("time limit"), "junit names the limit");

    // --resume without the limit runs the rest.
    let (code, _, err) = mfh(&[
        "audit",
        "--scene",
        &scene,
        "--profile",
        "ci",
        "--seed",
        "5",
        "--quiet",
        "--resume",
        out_s,
    ]);
    assert_eq!(code, 0, "{err}");
    let report = read(&out.join("report.json"));
    assert_eq!(report["records"].as_array().unwrap().len(), records.len());
    assert_eq!(report["summary"]["counts"]["error"], 0, "{report}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_max_time_and_a_foreign_or_broken_resume_are_exit_2() {
    let dir = temp("bad");
    let scene = tiny_scene(&dir);
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    for bad in ["0", "-1", "nan", "inf", "1e300"] {
        let flag = format!("--max-time={bad}");
        let mut args = tiny_args(&scene, out_s);
        args.push(&flag);
        let (code, _, err) = mfh(&args);
        assert_eq!(code, 2, "--max-time {bad}: {err}");
        assert!(err.contains("--max-time"), "{err}");
    }
    // No report.jsonl to resume.
    let mut args = tiny_args(&scene, out_s);
    args.extend(["--resume", out_s]);
    let (code, _, err) = mfh(&args);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--resume") && err.contains("report.jsonl"),
        "{err}"
    );

    // A stopped run (nothing run) of seed 5 at ci, then resumes of other audits.
    let mut args = tiny_args(&scene, out_s);
    args.extend(["--max-time", "0.000001"]);
    let (code, _, err) = mfh_env(&args, &[("RAYON_NUM_THREADS", "1")]);
    assert_eq!(code, 1, "{err}");
    let stream = out.join("report.jsonl");
    let original = std::fs::read_to_string(&stream).unwrap();
    let other = dir.join("other");
    let other_s = other.to_str().unwrap();
    for (changed, field) in [
        (["--seed", "6"], "seed"),
        (["--profile", "quick"], "profile"),
    ] {
        let mut args = tiny_args(&scene, other_s);
        let at = args.iter().position(|a| *a == changed[0]).unwrap();
        args[at + 1] = changed[1];
        args.extend(["--resume", out_s]);
        let (code, _, err) = mfh(&args);
        assert_eq!(code, 2, "{changed:?}: {err}");
        assert!(
            err.contains("belongs to another audit") && err.contains(&format!("{field}:")),
            "{err}"
        );
    }
    // A scene with another plan (a second material).
    let scene2 = dir.join("scene2.json");
    std::fs::write(
        &scene2,
        r#"{"name": "tiny", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3}}, {"name": "b", "model": {"family": "beckmann", "alpha": 0.5}}]}"#,
    )
    .unwrap();
    let mut args = tiny_args(scene2.to_str().unwrap(), other_s);
    args.extend(["--resume", out_s]);
    let (code, _, err) = mfh(&args);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("plan:") && err.contains("subject:"), "{err}");
    // A complete line that is not a record names its line.
    std::fs::write(&stream, format!("{original}not a record\n")).unwrap();
    let mut args = tiny_args(&scene, out_s);
    args.extend(["--resume", out_s]);
    let (code, _, err) = mfh(&args);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("line 2 is not a record"), "{err}");
    // A refused resume leaves the file as it was.
    assert_eq!(
        std::fs::read_to_string(&stream).unwrap(),
        format!("{original}not a record\n")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_non_terminal_stderr_gets_progress_lines_unless_quiet() {
    let dir = temp("progress");
    let scene = tiny_scene(&dir);
    let out = dir.join("out");
    let args = [
        "audit",
        "--scene",
        &scene,
        "--profile",
        "ci",
        "--out",
        out.to_str().unwrap(),
    ];
    let env = [("MFH_PROGRESS_INTERVAL_MS", "20")];
    let (code, _, err) = mfh_env(&args, &env);
    assert_eq!(code, 0, "{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("mfh audit: ") && l.contains("checks done"))
        .unwrap_or_else(|| panic!("no progress line: {err}"));
    assert!(
        line.contains(" failed") && line.contains("elapsed"),
        "{line}"
    );
    let mut quiet = args.to_vec();
    quiet.push("--quiet");
    let (code, _, err) = mfh_env(&quiet, &env);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("checks done"), "--quiet: {err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `MFH_TRACE` makes the CLI print one `start` line as each check starts and one `done` line,
/// with its time and verdict, as it ends (from the library's check events: the library itself
/// prints nothing); without it, neither.
#[test]
fn mfh_trace_prints_each_check_start_and_end() {
    let dir = temp("trace");
    let scene = tiny_scene(&dir);
    let out = dir.join("out");
    let args = tiny_args(&scene, out.to_str().unwrap());
    let (code, _, err) = mfh_env(&args, &[("MFH_TRACE", "1")]);
    assert_eq!(code, 0, "{err}");
    let records = read(&out.join("report.json"))["records"]
        .as_array()
        .expect("records")
        .len();
    let starts: Vec<&str> = err.lines().filter(|l| l.starts_with("start ")).collect();
    let dones: Vec<&str> = err.lines().filter(|l| l.starts_with("done ")).collect();
    assert!(records > 0);
    assert_eq!((starts.len(), dones.len()), (records, records), "{err}");
    for line in &dones {
        // done 0.123s pass sampling.chi2 {model} {case}
        let words: Vec<&str> = line.split_whitespace().collect();
        let seconds = words[1].strip_suffix('s').expect("seconds");
        assert!(seconds.parse::<f64>().is_ok_and(|t| t >= 0.0), "{line}");
        assert!(words[3].contains('.'), "a check id: {line}");
        assert!(
            starts
                .iter()
                .any(|s| s.starts_with(&format!("start {} ", words[3]))),
            "{line}"
        );
    }
    // Without it (when the test itself runs without it), no trace line.
    if std::env::var_os("MFH_TRACE").is_none() {
        let (code, _, err) = mfh(&args);
        assert_eq!(code, 0, "{err}");
        let traced = |l: &str| l.starts_with("start ") || l.starts_with("done ");
        assert!(!err.lines().any(traced), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The library's hook: `on_check` sees every check start and finish with its record, and those
/// records given back as `resume` run nothing and give the same report.
#[test]
fn the_api_streams_records_and_resumes_from_them() {
    use mfh_harness::run::{plan_key, CheckEvent, CheckEventFn, RunControl};
    use mfh_harness::{Audit, Profile};
    use mfh_reference::ndf::Ggx;
    use std::sync::{Arc, Mutex};
    let ggx = Ggx::new(0.3, 0.3).unwrap();
    type Seen = (usize, Vec<(String, mfh_harness::record::CheckRecord)>);
    let seen = Arc::new(Mutex::new((0usize, Vec::new())));
    let hook = |seen: Arc<Mutex<Seen>>| {
        CheckEventFn(Arc::new(move |e: CheckEvent<'_>| {
            let mut s = seen.lock().unwrap();
            match e {
                CheckEvent::Started { .. } => s.0 += 1,
                CheckEvent::Finished {
                    planned, record, ..
                } => s.1.push((plan_key(planned), record.clone())),
                CheckEvent::Plan { .. } => {}
            }
        }))
    };
    let first = Audit::of(&ggx)
        .profile(Profile::Ci)
        .seed(9)
        .control(RunControl {
            on_check: Some(hook(seen.clone())),
            ..RunControl::default()
        })
        .run();
    let (started, streamed) = std::mem::take(&mut *seen.lock().unwrap());
    assert!(first.passed());
    // Every planned check was started and streamed (the report adds records that are not
    // checks run, e.g. the capabilities audited).
    assert_eq!(started, streamed.len());
    assert!(!streamed.is_empty() && streamed.len() <= first.records.len());
    for (_, r) in &streamed {
        assert!(
            first
                .records
                .iter()
                .any(|f| (&f.check, &f.model, &f.case) == (&r.check, &r.model, &r.case)),
            "{} is in the report",
            r.check
        );
    }
    let again = Audit::of(&ggx)
        .profile(Profile::Ci)
        .seed(9)
        .control(RunControl {
            on_check: Some(hook(seen.clone())),
            resume: Some(Arc::new(streamed.into_iter().collect())),
            ..RunControl::default()
        })
        .run();
    assert_eq!(
        seen.lock().unwrap().0,
        0,
        "every record was resumed: nothing ran"
    );
    assert_eq!(again.records, first.records);
}

/// A report.jsonl can be edited: `--resume` re-judges every stored verdict from the record's
/// numbers (as `mfh merge` does) and takes a record only under the plan key of the check that
/// made it. Each tampering below starts from the complete report.jsonl of the tiny audit.
#[test]
fn resume_rejudges_or_refuses_every_tampered_record() {
    let dir = temp("tamper");
    let scene = tiny_scene(&dir);
    let whole = dir.join("whole");
    let (code, _, err) = mfh(&tiny_args(&scene, whole.to_str().unwrap()));
    assert_eq!(code, 0, "{err}");
    let expected = read(&whole.join("report.json"));
    let (header, lines) = jsonl(&whole.join("report.jsonl"));
    let passing = lines
        .iter()
        .position(|r| r["verdict"] == "pass" && r["measured"]["error"].is_number())
        .expect("a passing record with a measured error");
    let other = lines
        .iter()
        .position(|r| r["check"] != lines[passing]["check"])
        .expect("a record of another check");
    // Resumes `edited` (the record lines) in a fresh folder: (exit code, stderr, report).
    let resume = |name: &str, edited: &[Value]| {
        let out = dir.join(name);
        std::fs::create_dir_all(&out).unwrap();
        let mut text = format!("{header}\n");
        for l in edited {
            text.push_str(&format!("{l}\n"));
        }
        std::fs::write(out.join("report.jsonl"), text).unwrap();
        let mut args = tiny_args(&scene, out.to_str().unwrap());
        args.extend(["--resume", out.to_str().unwrap()]);
        let (code, _, err) = mfh(&args);
        (code, err, read(&out.join("report.json")), out)
    };

    // An expected failure (error 1.0) edited to pass, and a pass edited to an error of 0.5
    // against a tolerance of 1e-9: re-judged as the failures their numbers say, exit 1.
    for (name, error, verdict) in [("xfail", 1.0, "expected_failure"), ("error", 0.5, "pass")] {
        let mut edited = lines.clone();
        let r = &mut edited[passing];
        r["measured"]["error"] = Value::from(error);
        r["tolerance"]["value"] = Value::from(1e-9);
        if verdict == "expected_failure" {
            // The stored record of an expected failure, then its verdict edited to pass.
            r["reason"] = Value::from("erratum");
        }
        r["verdict"] = Value::from("pass");
        let (code, err, report, _) = resume(name, &edited);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(
            err.contains("were not taken as written")
                && err.contains("stored verdict pass contradicts measured error"),
            "{name}: {err}"
        );
        assert_eq!(report["summary"]["counts"]["fail"], 1, "{name}");
    }

    // A record of a nonexistent check under a real plan key, and two records' keys swapped:
    // not taken, their checks run again, and the report is the uninterrupted one.
    let mut renamed = lines.clone();
    renamed[passing]["check"] = Value::from("smith.no_such_check");
    let mut swapped = lines.clone();
    let key = swapped[passing]["planned"].clone();
    swapped[passing]["planned"] = swapped[other]["planned"].clone();
    swapped[other]["planned"] = key;
    for (name, edited, refused) in [("renamed", renamed, 1), ("swapped", swapped, 2)] {
        let (code, err, report, out) = resume(name, &edited);
        assert_eq!(code, 0, "{name}: {err}");
        assert_eq!(
            err.matches("is not that planned check's").count(),
            refused,
            "{name}: {err}"
        );
        assert!(err.contains("the check runs again"), "{name}: {err}");
        assert_eq!(
            normalized_records(&report, &out),
            normalized_records(&expected, &whole),
            "{name}: the report of the uninterrupted audit"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
