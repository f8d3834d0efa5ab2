//! The `mfh` binary as a process: `mfh eval` over standard input, its exit status (0 when
//! every query is answered, 2 when some line failed), `--help`, and unknown subcommands.

use std::io::Write;
use std::process::{Command, Output, Stdio};

/// Runs the built `mfh` with `args`, feeding `stdin`.
fn mfh(args: &[&str], stdin: &str) -> Output {
    mfh_bytes(args, stdin.as_bytes())
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

/// Runs the built `mfh` with `args` and raw bytes on standard input.
fn mfh_bytes(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mfh starts");
    let mut input = child.stdin.take().expect("piped stdin");
    let bytes = stdin.to_vec();
    // Written from a thread: mfh may stop reading early, and its answers must be drained.
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&bytes);
    });
    let out = child.wait_with_output().expect("mfh finishes");
    let _ = writer.join();
    out
}

/// The error line of an answer.
fn error_of(line: &str) -> (String, String) {
    let v: serde_json::Value = serde_json::from_str(line).expect("JSON answer");
    (
        v["error"]["kind"].as_str().unwrap_or("").to_string(),
        v["error"]["message"].as_str().unwrap_or("").to_string(),
    )
}

#[test]
fn eval_invalid_utf8_on_one_line_answers_that_line_and_the_rest() {
    let mut input = Vec::new();
    input.extend_from_slice(GOOD.as_bytes());
    input.extend_from_slice(b"\n{\"x\": \"\xff\xfe\"}\n");
    input.extend_from_slice(GOOD.as_bytes());
    input.push(b'\n');
    let out = mfh_bytes(&["eval"], &input);
    assert_eq!(out.status.code(), Some(2));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    let (kind, message) = error_of(lines[1]);
    assert_eq!(kind, "parse");
    assert!(
        message.contains("line 2") && message.contains("UTF-8"),
        "{message}"
    );
    assert_eq!(lines[0], lines[2]);
}

#[test]
#[cfg_attr(not(unix), ignore = "needs /dev/zero")]
fn eval_dev_zero_ends_with_a_clear_error_in_bounded_memory() {
    let out = mfh(&["eval", "--input", "/dev/zero"], "");
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("line 1") && stderr.contains("1048576 bytes"),
        "{stderr}"
    );
    let stdout = text(&out.stdout);
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert_eq!(error_of(stdout.lines().next().unwrap()).0, "parse");
}

#[test]
fn eval_bad_queries_name_the_key_and_the_limit() {
    let cases = [
        // A misspelled optional key is rejected, naming it.
        (
            r#"{"model":{"family":"ggx","alpha":0.3},"quantity":"d","theta":0.5,"ph":1.5}"#,
            "argument",
            vec!["\"ph\"", "phi"],
        ),
        // A 300-digit number is written short.
        (
            r#"{"model":{"family":"ggx","alpha":0.3},"quantity":"d","theta":1e300}"#,
            "argument",
            vec!["1e300", "theta"],
        ),
        // No Rust type names.
        (
            r#"{"model":{"family":"std","gamma":[1],"alpha":0.3},"quantity":"d","theta":0}"#,
            "model",
            vec!["gamma"],
        ),
        // Λ of STD at γ = 3/2 says why.
        (
            r#"{"model":{"family":"std","gamma":1.5,"alpha":0.3},"quantity":"lambda","theta":1}"#,
            "unsupported",
            vec!["diverges", "3/2"],
        ),
        // GGX α = 1e308 is refused at construction with the range.
        (
            r#"{"model":{"family":"ggx","alpha":1e308},"quantity":"lambda","theta":1}"#,
            "model",
            vec!["alpha", "1e4", "1e308"],
        ),
        (
            r#"{"model":{"family":"ggx","alpha":1e308},"quantity":"sample_wm","u":[0.5,0.5]}"#,
            "model",
            vec!["alpha", "1e4"],
        ),
        // SG sharpness past the limit is a typed error, not NaN.
        (
            r#"{"quantity":"sg_inner","a":{"axis":[0,0,1],"sharpness":1e155},"b":{"axis":[0,0,1],"sharpness":1e155}}"#,
            "model",
            vec!["sharpness", "1e150"],
        ),
        // Unknown keys inside SG arguments and model specs.
        (
            r#"{"quantity":"sg_eval","a":{"axis":[0,0,1],"sharpness":1,"amp":2},"v":[0,0,1]}"#,
            "model",
            vec!["amp"],
        ),
        (
            r#"{"model":{"family":"ggx","alpha":0.3,"alpah":1},"quantity":"d","theta":0}"#,
            "model",
            vec!["alpah"],
        ),
    ];
    let input: String = cases.iter().map(|(q, _, _)| format!("{q}\n")).collect();
    let out = mfh(&["eval"], &input);
    assert_eq!(out.status.code(), Some(2));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), cases.len(), "{stdout}");
    for ((query, kind, names), line) in cases.iter().zip(&lines) {
        let (k, message) = error_of(line);
        assert_eq!(&k, kind, "{query}: {line}");
        for n in names {
            assert!(message.contains(n), "{query}: {message:?} lacks {n:?}");
        }
        assert!(message.len() < 400, "{message}");
        for rust in ["untagged enum", "NumberOrString", " f64", " u64"] {
            assert!(!message.contains(rust), "{message}");
        }
    }
    // At the sharpness limit sg_inner is finite (parallel axes: 4π e^0 (1 − e^{−4e150})/4e150).
    let out = mfh(
        &["eval"],
        r#"{"quantity":"sg_inner","a":{"axis":[0,0,1],"sharpness":1e150},"b":{"axis":[0,0,1],"sharpness":1e150}}"#,
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).unwrap();
    let x = v["value"].as_f64().expect("a finite number");
    let want = 4.0 * std::f64::consts::PI / 4e150;
    assert!((x / want - 1.0).abs() < 1e-12, "{x} vs {want}");
}

/// A scene file in the temp folder.
fn scene_file(name: &str, text: &str) -> std::path::PathBuf {
    let path = std::env::temp_dir().join(format!("mfh-cli-{name}-{}.json", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn plan_and_audit_refuse_bad_scenes_with_exit_two() {
    let many: Vec<String> = (0..10_000)
        .map(|i| format!(r#"{{"name": "m{i}", "model": {{"family": "ggx", "alpha": 0.3}}}}"#))
        .collect();
    let many = scene_file(
        "many",
        &format!(r#"{{"name": "many", "materials": [{}]}}"#, many.join(",")),
    );
    let std15 = scene_file(
        "std15",
        r#"{"name": "s", "materials": [{"name": "rough", "model": {"family": "std", "gamma": 1.5,
            "alpha": 0.3}, "masking": "height_correlated"}]}"#,
    );
    let mut cases = vec![
        (many.clone(), vec!["materials", "10000", "256"]),
        (std15.clone(), vec!["`rough`", "masking", "gamma", "3/2"]),
    ];
    if std::path::Path::new("/dev/zero").exists() {
        cases.push(("/dev/zero".into(), vec!["/dev/zero", "1048576 bytes"]));
    }
    for (scene, names) in &cases {
        for command in ["plan", "audit"] {
            let out_dir = std::env::temp_dir().join(format!("mfh-cli-out-{}", std::process::id()));
            let out = mfh(
                &[
                    command,
                    "--scene",
                    scene.to_str().unwrap(),
                    "--out",
                    out_dir.to_str().unwrap(),
                ][..if command == "plan" { 3 } else { 5 }],
                "",
            );
            assert_eq!(out.status.code(), Some(2), "{command} {scene:?}");
            assert!(out.stdout.is_empty());
            let stderr = text(&out.stderr);
            for n in names {
                assert!(
                    stderr.contains(n),
                    "{command} {scene:?}: {stderr:?} lacks {n:?}"
                );
            }
        }
    }
    let _ = std::fs::remove_file(many);
    let _ = std::fs::remove_file(std15);
}

#[test]
fn a_piped_audit_draws_no_progress_bar() {
    let scene = scene_file(
        "piped",
        r#"{"name": "p", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3}}]}"#,
    );
    let out_dir = std::env::temp_dir().join(format!("mfh-cli-piped-{}", std::process::id()));
    let out = mfh(
        &[
            "audit",
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ],
        "",
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    let stderr = text(&out.stderr);
    // indicatif draws with carriage returns and ANSI escapes; a pipe gets neither.
    assert!(
        !stderr.contains('\r') && !stderr.contains('\u{1b}') && !stderr.contains("checks,"),
        "{stderr:?}"
    );
    assert!(text(&out.stdout).contains("PASS"));
    let _ = std::fs::remove_file(scene);
    let _ = std::fs::remove_dir_all(out_dir);
}

/// On a terminal (a pty from util-linux `script`, where installed) a chi2 run longer than a
/// second draws its progress bar on standard error; `--quiet` draws none. The sampler is the
/// piecewise-linear one (a numerical inversion per sample, ~4e6 samples/s on 2 cores): 10⁷ of
/// its samples take seconds on any machine, where GGX's 5·10⁷ took 0.5 s once vectorized.
/// Ignored where `script` is absent, except under CI=true (the build script's `has_script`).
#[test]
#[cfg_attr(not(has_script), ignore = "util-linux `script` is not installed")]
fn a_long_chi2_on_a_terminal_shows_a_progress_bar() {
    assert!(
        Command::new("script")
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success()),
        "util-linux `script` is missing (CI=true, or it was removed since the build)"
    );
    let run = |quiet: bool| {
        let command = format!(
            "stty cols 120 rows 40; {} chi2 --model '{}' --samples 10000000 --resolution 8{}",
            env!("CARGO_BIN_EXE_mfh"),
            r#"{"family":"piecewise_linear","x":{"theta":[0,0.5,1.0,1.5707963267948966],"value":[1,0.6,0.1,0]}}"#,
            if quiet { " --quiet" } else { "" }
        );
        let out = Command::new("script")
            .args(["-qec", &command, "/dev/null"])
            .stdin(Stdio::null())
            .output()
            .expect("script runs");
        (out.status.code(), text(&out.stdout))
    };
    let (code, terminal) = run(false);
    assert_eq!(code, Some(0), "{terminal}");
    assert!(
        terminal.contains("samples") && terminal.contains("ETA") && terminal.contains('\r'),
        "{terminal:?}"
    );
    assert!(terminal.contains("verdict pass"), "{terminal}");
    let (code, terminal) = run(true);
    assert_eq!(code, Some(0), "{terminal}");
    assert!(!terminal.contains("ETA"), "{terminal:?}");
}

#[test]
fn eval_answers_bsdf_queries_and_exits_two_on_a_bad_spec() {
    let glass = r#"{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":0.3}}"#;
    let good = format!(
        r#"{{"bsdf":{glass},"quantity":"bsdf_sample","wi":[0.6,0,0.8],"u":[0.7,0.3,0.6]}}"#
    );
    let out = mfh(&["eval"], &format!("{good}\n"));
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text(&out.stdout).trim()).expect("JSON");
    assert!(v["value"]["pdf"].as_f64().is_some_and(|p| p > 0.0), "{v}");
    assert_eq!(v["value"]["wo"].as_array().map(Vec::len), Some(3), "{v}");
    let bad = r#"{"bsdf":{"bsdf":"dielectric","eta":0.01,"ndf":{"family":"ggx","alpha":0.3}},"quantity":"bsdf_eval","wi":[0,0,1],"wo":[0,0,1]}"#;
    let out = mfh(&["eval"], &format!("{good}\n{bad}\n"));
    assert_eq!(out.status.code(), Some(2));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert!(
        lines[1].contains(r#""kind":"model""#) && lines[1].contains("eta"),
        "{}",
        lines[1]
    );
}
