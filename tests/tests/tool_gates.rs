//! Every test that uses a tool beyond Rust carries that tool's gate, so that on a machine
//! without the tool the README's test command lists it as skipped instead of failing (a
//! newcomer's clean clone has no numpy, no g++ and no Chromium). The tools and their gates are
//! `mfh-test-tiers`'s (`tests/tiers/src/lib.rs`); `.ci/without-tools` then proves it on every
//! landing by hiding the tools and checking that nextest lists each gated test as skipped.
//!
//! The scan reads each `#[test]` function of the workspace's test files: its attributes must
//! hold `not(has_<tool>)` for every tool its body uses, by the markers below. The scanner is
//! tested on a gated and an ungated example, so that a pass means it looked.

use std::path::{Path, PathBuf};

/// A tool, its cfg flag, and the text in a test's body that means the test uses it.
const TOOLS: [(&str, &str, &[&str]); 4] = [
    (
        "numpy",
        "has_numpy",
        &["require_numpy()", "_numpy.py", "import numpy"],
    ),
    ("g++", "has_gxx", &["cpp_command(", "cpp_example("]),
    ("chromium", "has_chromium", &["chromium()"]),
    ("script", "has_script", &["Command::new(\"script\")"]),
];

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the workspace")
        .to_path_buf()
}

/// The integration-test files of the workspace (`<crate>/tests/*.rs`).
fn test_files(root: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for dir in [
        "harness/tests",
        "reference/tests",
        "tests/tests",
        "tests/outside-user/tests",
    ] {
        let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
            continue;
        };
        for e in entries {
            let path = e.expect("entry").path();
            // This file's own examples are deliberately ungated.
            if path.extension().is_some_and(|x| x == "rs") && !path.ends_with("tool_gates.rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// A test function as the scanner sees it: its name, its attributes, and its body (up to the
/// next `#[test]`).
struct TestFn<'a> {
    name: &'a str,
    attributes: &'a str,
    body: &'a str,
}

/// The `#[test]` functions of a source file.
fn tests_of(source: &str) -> Vec<TestFn<'_>> {
    let starts: Vec<usize> = source.match_indices("#[test]").map(|(i, _)| i).collect();
    let mut out = Vec::new();
    for (k, &start) in starts.iter().enumerate() {
        let end = starts.get(k + 1).copied().unwrap_or(source.len());
        let item = &source[start..end];
        let Some(fn_at) = item.find("fn ") else {
            continue;
        };
        let name_end = item[fn_at + 3..]
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .map_or(item.len(), |i| fn_at + 3 + i);
        out.push(TestFn {
            name: &item[fn_at + 3..name_end],
            attributes: &item[..fn_at],
            body: &item[fn_at..],
        });
    }
    out
}

/// The problems of one file: each test that uses a tool without its gate.
fn ungated(file: &str, source: &str) -> Vec<String> {
    let mut problems = Vec::new();
    for t in tests_of(source) {
        for (tool, cfg, markers) in TOOLS {
            let uses = markers.iter().any(|m| t.body.contains(m));
            let gated = t.attributes.contains(&format!("not({cfg})"));
            if uses && !gated {
                problems.push(format!(
                    "{file}: test `{}` uses {tool} but has no \
                     #[cfg_attr(not({cfg}), ignore = \"…\")]",
                    t.name
                ));
            }
        }
    }
    problems
}

#[test]
fn every_test_that_uses_a_tool_carries_its_gate() {
    let root = root();
    let mut problems = Vec::new();
    let mut gated = 0;
    for path in test_files(&root) {
        let source = std::fs::read_to_string(&path).expect("readable");
        let file = path.strip_prefix(&root).unwrap().display().to_string();
        problems.extend(ungated(&file, &source));
        gated += tests_of(&source)
            .iter()
            .filter(|t| t.attributes.contains("not(has_"))
            .count();
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // The scan saw the gated tests there are (numpy, g++, Chromium and `script` tests).
    assert!(
        gated >= 10,
        "only {gated} gated tests found: did the scan look?"
    );
}

#[test]
fn the_scanner_finds_an_ungated_test_and_accepts_a_gated_one() {
    let ungated_source = r#"
#[test]
fn runs_numpy() {
    require_numpy();
}
"#;
    let problems = ungated("x.rs", ungated_source);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].contains("runs_numpy") && problems[0].contains("has_numpy"));
    let gated_source = r#"
#[test]
#[cfg_attr(not(has_gxx), ignore = "g++ is not installed")]
fn builds_cpp() {
    let cmd = cpp_command("");
}
#[test]
fn plain() {}
"#;
    assert!(ungated("y.rs", gated_source).is_empty());
    assert_eq!(tests_of(gated_source).len(), 2);
    assert_eq!(tests_of(gated_source)[0].name, "builds_cpp");
}
