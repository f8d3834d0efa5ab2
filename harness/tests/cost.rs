//! `mfh cost`: the quick run writes cost.json (schema 1), a Pareto plot per quantity and
//! cost.html, and its errors say what the catalogue promises; an unwritable `--out` is exit 2
//! naming the path; the generated `reports/accuracy-versus-time.md` is current.

use mfh_harness::cost::{run, CostOptions, Selection};
use mfh_harness::report::cost::{errors_section, markdown_errors, MARKDOWN_FILE};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn mfh(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mfh"))
        .args(args)
        .output()
        .expect("mfh starts");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn route<'a>(cost: &'a Value, quantity: &str, route: &str) -> &'a Value {
    cost["quantities"]
        .as_array()
        .unwrap()
        .iter()
        .find(|q| q["name"] == quantity)
        .unwrap_or_else(|| panic!("no quantity {quantity}"))["routes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["route"] == route)
        .unwrap_or_else(|| panic!("no route {route} of {quantity}"))
}

#[test]
fn the_quick_run_writes_json_plots_and_html() {
    let out = folder("mfh-cost-quick");
    let (code, stdout, stderr) = mfh(&["cost", "--quick", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(stdout.contains("*frontier"), "{stdout}");
    let cost: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("cost.json")).unwrap()).unwrap();
    assert_eq!(cost["schema_version"], 1);
    assert_eq!(cost["quick"], true);
    let quantities = cost["quantities"].as_array().unwrap();
    assert!(quantities.len() >= 15, "{}", quantities.len());
    for q in quantities {
        assert!(!q["frontier"].as_array().unwrap().is_empty(), "{q}");
        let svg = out.join("cost").join(format!(
            "{}.svg",
            mfh_harness::report::cost::slug(q["name"].as_str().unwrap())
        ));
        let svg = std::fs::read_to_string(&svg).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains("Pareto frontier"),
            "{q}"
        );
    }
    // The stable STD route holds 1e-13 at every γ; routes outside their γ are refused, not
    // timed; the printed Table 1 row of γ = 7/2 is the erratum 001-1 (error ≫ 1).
    for g in ["1.6", "2", "3.5", "7", "20", "90", "1000"] {
        let stable = route(&cost, &format!("STD Λ, γ = {g}"), "stable");
        assert!(stable["max_error"].as_f64().unwrap() < 1e-13, "{stable}");
        assert!(
            stable["seconds_per_eval"].as_f64().unwrap() > 0.0,
            "{stable}"
        );
    }
    let refused = route(&cost, "STD Λ, γ = 1.6", "integer");
    assert_eq!(refused["status"], "refused");
    assert!(refused["seconds_per_eval"].is_null() && refused["reason"].is_string());
    let printed = route(&cost, "STD Λ, γ = 3.5", "table1_printed");
    assert!(printed["max_error"].as_f64().unwrap() > 1.0, "{printed}");
    // The trapezoid rule's error falls with the number of pieces.
    let trapezoid = |n: u32| {
        route(
            &cost,
            "piecewise-linear G1 (GGX α = 0.5 in n pieces)",
            &format!("trapezoid (eq 28), n = {n}"),
        )["max_error"]
            .as_f64()
            .unwrap()
    };
    assert!(trapezoid(64) < trapezoid(16) && trapezoid(16) < trapezoid(4));
    // A tighter quadrature tolerance never gives a worse achieved error than asked.
    let quadrature = route(
        &cost,
        "oracle: quadrature tolerance (STD Λ, γ = 3.5)",
        "tolerance 1e-12",
    );
    assert!(
        quadrature["max_error"].as_f64().unwrap() < 1e-11,
        "{quadrature}"
    );
    // Chi-square: 10⁵ samples catch a 10 % roughness error.
    let chi2 = route(
        &cost,
        "oracle: chi-square sample count (detection power)",
        "N = 100000",
    );
    assert!(chi2["max_error"].as_f64().unwrap() <= 0.1, "{chi2}");
    let html = std::fs::read_to_string(out.join("cost.html")).unwrap();
    assert!(html.contains("Accuracy versus time") && html.contains("STD Λ, γ = 1000"));
}

#[test]
fn an_unwritable_out_is_bad_input_naming_the_path() {
    let dir = folder("mfh-cost-unwritable");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "not a folder").unwrap();
    let out = file.join("sub");
    let (code, _, stderr) = mfh(&[
        "cost",
        "--quick",
        "--no-time",
        "--scene",
        "../examples/scenes/conductor.xml",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains(out.to_str().unwrap()), "{stderr}");
}

/// The error section of `reports/accuracy-versus-time.md` is what the code measures today
/// (regenerate: `mfh cost --markdown reports/`). Timings are not compared.
#[test]
fn cost_markdown_is_current() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../reports")
        .join(MARKDOWN_FILE);
    let committed = std::fs::read_to_string(&path).expect("reports/accuracy-versus-time.md");
    let report = run(
        &CostOptions {
            quick: false,
            timed: false,
            seed: mfh_harness::run::DEFAULT_SEED,
            selection: Selection::ALL,
        },
        &mut |_, _, _| {},
    );
    let now = markdown_errors(&report);
    let then = errors_section(&committed).expect("the error section's markers");
    assert!(
        now.trim_end() == then.trim_end(),
        "reports/{MARKDOWN_FILE} is stale: regenerate it with \
         `cargo run --release -p mfh-harness --bin mfh -- cost --markdown reports/`\n\
         --- now ---\n{now}"
    );
}
