//! A renderer that gates its models with mfh gets the audit API and report.json without the
//! CLI's, the HTML report's or the Mitsuba reader's dependencies: this crate's build
//! (its dependencies and dev-dependencies, mfh-harness with `default-features = false`) holds
//! none of clap, indicatif, plotters or roxmltree.

use std::process::Command;

#[test]
fn the_gate_builds_without_the_cli_html_and_mitsuba_dependencies() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "tree",
            "-p",
            "mfh-outside-user",
            "-e",
            "normal,dev",
            "--prefix",
            "none",
            "--offline",
        ])
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    let crates: Vec<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(
        crates.contains(&"mfh-harness"),
        "mfh-harness is a dev-dependency:\n{tree}"
    );
    for heavy in ["clap", "indicatif", "plotters", "roxmltree"] {
        assert!(
            !crates.contains(&heavy),
            "{heavy} is in the outside user's build (mfh-harness's default features leaked):\n{tree}"
        );
    }
}
