//! An output that does not arrive is not a success: `mfh plan` and `mfh audit
//! --json` with standard output on /dev/full (every write fails with ENOSPC) or on a pipe whose
//! reader has gone exit 2 with "cannot write standard output" on standard error, as `mfh eval`
//! and `mfh chi2` do.

use std::fs::File;
use std::process::{Command, Stdio};

/// A scene of one GGX material: its ci audit plans 10 checks and takes ~0.3 s in a debug build.
fn tiny_scene() -> std::path::PathBuf {
    let path = std::env::temp_dir().join(format!("mfh-stdout-scene-{}.json", std::process::id()));
    std::fs::write(
        &path,
        r#"{"name": "tiny", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3}}]}"#,
    )
    .unwrap();
    path
}

fn out_dir(name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("mfh-stdout-{name}-{}", std::process::id()));
    dir.to_str().unwrap().to_string()
}

/// Runs `mfh args…` with standard output on /dev/full: (exit status, standard error).
fn to_dev_full(args: &[&str]) -> (Option<i32>, String) {
    let full = File::create("/dev/full").expect("/dev/full opens for writing");
    let out = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::from(full))
        .stderr(Stdio::piped())
        .output()
        .expect("mfh runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `mfh args…` with standard output on a pipe whose reader is gone before mfh writes (as
/// `| head -c100` after its 100 bytes, deterministically: a report that fits in the pipe's
/// buffer before the reader leaves is delivered, and rightly a pass): (exit status, standard
/// error).
fn to_closed_pipe(args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mfh runs");
    // Dropping the only read end: every write of mfh's fails with EPIPE (Rust ignores SIGPIPE).
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("mfh ends");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_write_error(command: &str, (code, stderr): (Option<i32>, String)) {
    assert_eq!(code, Some(2), "{command}: {stderr}");
    assert!(
        stderr.contains(&format!("mfh {command}: cannot write standard output")),
        "{command}: {stderr:?}"
    );
}

#[test]
fn plan_to_a_full_disk_exits_two() {
    assert_write_error("plan", to_dev_full(&["plan"]));
    assert_write_error("plan", to_dev_full(&["plan", "--format", "table"]));
}

#[test]
fn audit_json_to_a_full_disk_or_a_closed_pipe_exits_two() {
    let scene = tiny_scene();
    let scene = scene.to_str().unwrap();
    let out = out_dir("audit");
    let args = [
        "audit",
        "--scene",
        scene,
        "--profile",
        "ci",
        "--json",
        "--quiet",
        "--out",
        &out,
    ];
    assert_write_error("audit", to_dev_full(&args));
    // The summary instead of the JSON goes through the same check.
    let summary: Vec<&str> = args.iter().copied().filter(|&a| a != "--json").collect();
    assert_write_error("audit", to_dev_full(&summary));
    assert_write_error("audit", to_closed_pipe(&args));
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_file(scene);
}

/// A closed pipe is a write error for `mfh plan` too; a run whose output arrives is a pass.
#[test]
fn plan_to_a_closed_pipe_exits_two_and_to_a_reader_passes() {
    assert_write_error("plan", to_closed_pipe(&["plan"]));
    let out = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .arg("plan")
        .stdin(Stdio::null())
        .output()
        .expect("mfh runs");
    assert_eq!(out.status.code(), Some(0));
    assert!(!out.stdout.is_empty());
}

/// `mfh selftest`, `mfh cost`, `mfh eval`, `mfh merge`, `--help` and `--version` with their output on
/// /dev/full exit 2 naming the lost output (selftest and cost exited 0, their summaries lost).
#[test]
fn every_command_to_a_full_disk_exits_two() {
    let out = out_dir("full");
    let selftest = [
        "selftest",
        "--calibrate",
        "1",
        "--profile",
        "ci",
        "--only",
        "ggx",
        "--quiet",
        "--out",
        &out,
    ];
    assert_write_error("selftest", to_dev_full(&selftest));
    let scene = tiny_scene();
    let scene = scene.to_str().unwrap();
    let cost = [
        "cost",
        "--quick",
        "--no-time",
        "--scene",
        scene,
        "--quiet",
        "--out",
        &out,
    ];
    assert_write_error("cost", to_dev_full(&cost));
    let mut json = cost.to_vec();
    json.push("--json");
    assert_write_error("cost", to_dev_full(&json));
    for flag in ["--help", "--version"] {
        assert_write_error("--help/--version", to_dev_full(&[flag]));
    }
    assert_write_error("--help/--version", to_dev_full(&["audit", "--help"]));
    let queries =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/queries.jsonl");
    let (code, err) = to_dev_full(&["eval", "--input", queries.to_str().unwrap()]);
    assert_eq!(code, Some(2), "eval: {err}");
    let shard = format!("{out}/shard");
    let args = [
        "audit",
        "--scene",
        scene,
        "--profile",
        "ci",
        "--shard",
        "1/1",
        "--quiet",
        "--out",
        &shard,
    ];
    let status = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    let merged = format!("{out}/merged");
    assert_write_error("merge", to_dev_full(&["merge", &shard, "--out", &merged]));
    let _ = std::fs::remove_dir_all(&out);
}

/// Runs `mfh args…` with standard output closed (`>&-` in a shell): (exit status, standard
/// error).
fn with_stdout_closed(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new("sh")
        .arg("-c")
        .arg("exec \"$0\" \"$@\" >&-")
        .arg(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .output()
        .expect("sh runs mfh");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Every command started with standard output closed exits 2 before it runs, naming the closed
/// output (they exited 0: Rust's runtime puts a read-write /dev/null in a closed descriptor's
/// place, where every write succeeds); `> /dev/null` (write-only) still runs and passes.
#[test]
fn every_command_with_stdout_closed_exits_two() {
    let scene = tiny_scene();
    let scene = scene.to_str().unwrap();
    let out = out_dir("closed");
    let queries =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/queries.jsonl");
    let runs: [&[&str]; 5] = [
        &["--version"],
        &["--help"],
        &[
            "audit",
            "--scene",
            scene,
            "--profile",
            "ci",
            "--quiet",
            "--out",
            &out,
        ],
        &["eval", "--input", queries.to_str().unwrap()],
        &[
            "selftest",
            "--calibrate",
            "1",
            "--profile",
            "ci",
            "--only",
            "ggx",
            "--quiet",
        ],
    ];
    for args in runs {
        let (code, err) = with_stdout_closed(args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(
            err.contains("standard output was closed"),
            "{args:?}: {err}"
        );
    }
    assert!(
        !std::path::Path::new(&out).exists(),
        "the audit ran with its output closed"
    );
    let status = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args([
            "audit",
            "--scene",
            scene,
            "--profile",
            "ci",
            "--quiet",
            "--out",
            &out,
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert_eq!(
        status.code(),
        Some(0),
        "> /dev/null is a choice, not a lost output"
    );
    let _ = std::fs::remove_dir_all(&out);
}
