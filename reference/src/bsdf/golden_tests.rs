//! The reference BSDFs against `reference/golden/bsdf.json`: an independent evaluation of
//! Walter 2007's formulas in mpmath at 50 digits (`reference/golden/tools/bsdf_golden.py`, whose
//! docstring gives every formula), 7 configurations (GGX and Beckmann, isotropic and
//! anisotropic; conductors, dielectrics at η = 1.5 and 1/1.5) × 24–77 (wi, wo) pairs including
//! grazing (cos θ = ±1e-3), near-critical and beyond-critical incidence and wo = −wi.

use super::{Bsdf, BsdfSpec};
use crate::geometry::Vec3;

/// The tolerance: relative, 1e-12 (the target). A golden 0 (a side condition fails)
/// must be an exact 0.
const TOL: f64 = 1e-12;

fn vec3(v: &serde_json::Value) -> Vec3 {
    let a = v.as_array().expect("a direction");
    [0, 1, 2].map(|k| a[k].as_f64().expect("a number"))
}

fn number(v: &serde_json::Value) -> f64 {
    v.as_str().expect("a string").parse().expect("a number")
}

fn build(config: &serde_json::Value, extra: &[(&str, &str)]) -> std::sync::Arc<dyn Bsdf> {
    let mut c = config.clone();
    for (k, v) in extra {
        c[*k] = serde_json::Value::String(v.to_string());
    }
    let spec: BsdfSpec = serde_json::from_value(c.clone()).unwrap_or_else(|e| panic!("{c}: {e}"));
    spec.build().unwrap_or_else(|e| panic!("{c}: {e}"))
}

/// |a − b|/|b|, or ∞ when b = 0 and a ≠ 0.
fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        if a == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    } else {
        ((a - b) / b).abs()
    }
}

#[test]
fn reference_bsdfs_match_the_mpmath_goldens() {
    let all: serde_json::Value =
        serde_json::from_str(include_str!("../../golden/bsdf.json")).expect("golden JSON");
    let mut worst: std::collections::BTreeMap<&str, (f64, String)> = Default::default();
    let mut count = 0;
    for table in all["tables"].as_array().expect("tables") {
        let config = &table["config"];
        let conductor = config["bsdf"] == "conductor";
        // (golden column, spec fields, eval (true) or pdf (false))
        let mut columns = vec![
            (
                "eval_uncorrelated",
                vec![("masking", "uncorrelated"), ("transport", "importance")],
                true,
            ),
            (
                "eval_height_correlated",
                vec![
                    ("masking", "height_correlated"),
                    ("transport", "importance"),
                ],
                true,
            ),
            (
                "eval_height_correlated_radiance",
                vec![("masking", "height_correlated"), ("transport", "radiance")],
                true,
            ),
            ("pdf_normals", vec![("sampling", "normals")], false),
            (
                "pdf_visible_normals",
                vec![("sampling", "visible_normals")],
                false,
            ),
        ];
        if conductor {
            // A conductor has no transport field.
            for c in columns.iter_mut() {
                c.1.retain(|(k, _)| *k != "transport");
            }
            columns.push((
                "eval_height_correlated_schlick",
                vec![("masking", "height_correlated"), ("fresnel", "schlick")],
                true,
            ));
        }
        for (column, fields, is_eval) in &columns {
            let b = build(config, fields);
            for row in table["rows"].as_array().expect("rows") {
                let (wi, wo) = (vec3(&row["wi"]), vec3(&row["wo"]));
                let want = number(&row[*column]);
                let got = if *is_eval {
                    b.eval(wi, wo)
                } else {
                    b.pdf(wi, wo)
                };
                let e = rel(got, want);
                count += 1;
                let w = worst.entry(column).or_insert((0.0, String::new()));
                if !(e <= w.0) {
                    *w = (
                        e,
                        format!("{config} wi {wi:?} wo {wo:?}: {got:e} vs {want:e}"),
                    );
                }
            }
        }
    }
    assert!(count > 1500, "{count} comparisons");
    // The file is the script's output: its provenance names the script and its precision.
    let script = include_str!("../../golden/tools/bsdf_golden.py");
    let prov = &all["provenance"];
    assert!(prov["command"].as_str().unwrap().contains("bsdf_golden.py"));
    assert!(
        script.contains("mp.mp.dps = 50") && prov["precision"].as_str().unwrap().contains("50")
    );
    let mut failed = Vec::new();
    for (column, (e, at)) in &worst {
        eprintln!("bsdf golden {column}: worst relative error {e:.2e} ({at})");
        if !(*e <= TOL) {
            failed.push(format!("{column}: {e:e} at {at}"));
        }
    }
    assert!(failed.is_empty(), "beyond {TOL:e}: {failed:#?}");
}
