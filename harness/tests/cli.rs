//! The `mfh` binary as a process: `mfh eval` over standard input, its exit status (0 when
//! every query is answered, 2 when some line failed), `--help`, and unknown subcommands.

use std::io::Write;
use std::process::{Command, Output, Stdio};

/// Runs the built `mfh` with `args`, feeding `stdin`.
fn mfh(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mfh starts");
    child
        .stdin
        .take()
        .expect("piped stdin")
        .write_all(stdin.as_bytes())
        .expect("mfh reads its input");
    child.wait_with_output().expect("mfh finishes")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).expect("UTF-8 output")
}

const GOOD: &str =
    r#"{"model":{"family":"std","gamma":2.5,"alpha":0.3},"quantity":"lambda","theta":1.2}"#;

#[test]
fn eval_from_stdin_exits_zero() {
    let out = mfh(&["eval"], &format!("{GOOD}\n{GOOD}\n"));
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    let v: serde_json::Value = serde_json::from_str(lines[0]).expect("JSON answer");
    let lambda = v["value"].as_f64().expect("a number");
    assert!(lambda > 0.0 && lambda < 1.0, "{lambda}");
    assert_eq!(lines[0], lines[1]);
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
}

#[test]
fn eval_with_a_bad_line_exits_two_and_answers_the_rest() {
    let out = mfh(&["eval"], &format!("{GOOD}\nnot json\n{GOOD}\n"));
    assert_eq!(out.status.code(), Some(2));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    assert!(lines[0].starts_with(r#"{"value":"#), "{}", lines[0]);
    assert!(lines[1].starts_with(r#"{"error":"#) && lines[1].contains(r#""kind":"parse""#));
    assert_eq!(lines[0], lines[2]);
    assert!(
        text(&out.stderr).contains("1 of 3 queries failed"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn help_works() {
    let out = mfh(&["--help"], "");
    assert_eq!(out.status.code(), Some(0));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("Usage") && stdout.contains("eval"),
        "{stdout}"
    );
    let out = mfh(&["eval", "--help"], "");
    assert_eq!(out.status.code(), Some(0));
    assert!(text(&out.stdout).contains("--input"));
}

#[test]
fn unknown_subcommand_exits_two_with_a_message() {
    let out = mfh(&["frobnicate"], "");
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let stderr = text(&out.stderr);
    assert!(stderr.contains("frobnicate"), "{stderr}");
    // No subcommand at all is bad input too.
    let out = mfh(&[], "");
    assert_eq!(out.status.code(), Some(2));
    assert!(!out.stderr.is_empty());
}
