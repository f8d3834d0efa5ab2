//! The α sweep: correct samplers pass chi-square and KS, and D integrates to 1
//! within 1e-9, for α from 1e-4 to 2 (GGX, Beckmann, STD γ = 2.5), isotropic and at
//! anisotropy 1:100, with the oracles placing their cuts from the lobe measured from D alone
//! ([`lobe::measure`]); a sampler of α off by 5 % still fails. The CI subset is the extremes
//! (α = 1e-4 and 2 isotropic, and GGX 1e-4 : 1e-2); `MFH_EXTENSIVE=1` runs all 36.

use super::chi2::{chi2_test_in, Chi2Config, TestOutcome};
use super::ks::{ks_test_lobe, KsConfig, Marginal};
use super::lobe::{self, Lobe};
use super::quadrature::{integrate_hemisphere_lobe, Accuracy};
use crate::tolerance::CELL_RELATIVE_TOLERANCE;
use mfh_reference::{Model, ModelSpec};
use rayon::prelude::*;
use std::time::Instant;

/// Samples per chi-square and per KS test.
const SAMPLES: u64 = 200_000;
/// The per-test level: Šidák over the 36 × 3 tests of the full sweep at a family-wise 1e-3.
const LEVEL: f64 = 1e-5;
/// Normalization: |∫ D cos θ dω − 1| must be below this.
const NORMALIZATION: f64 = 1e-9;

fn model(json: &str) -> Box<dyn Model> {
    serde_json::from_str::<ModelSpec>(json)
        .unwrap()
        .build()
        .unwrap()
}

/// The extensive tier (`MFH_EXTENSIVE=1`, read by the build script: `mfh-test-tiers`).
fn extensive() -> bool {
    cfg!(mfh_extensive)
}

/// The roughness pairs: (a, a) and the 1:100 pair (a, 100a), or (a/100, a) where 100a > 2.
fn roughness(a: f64) -> [(f64, f64); 2] {
    [
        (a, a),
        if 100.0 * a <= 2.0 {
            (a, 100.0 * a)
        } else {
            (a / 100.0, a)
        },
    ]
}

struct Row {
    json: String,
    chi2_p: f64,
    chi2_pass: bool,
    ks_p: [f64; 2],
    ks_pass: [bool; 2],
    normalization_error: f64,
    normalization_bound: f64,
    seconds: f64,
    lobe: Lobe,
}

/// The three tests of one model, sampler against pdf (`sampler` may differ from `pdf_model`
/// for the negative test).
fn run(json: &str, sampler_json: &str, seed: u64) -> Row {
    let t = Instant::now();
    let m = model(json);
    let s_model = model(sampler_json);
    let pdf = m.as_sampler().unwrap();
    let sampler = s_model.as_sampler().unwrap();
    let lobe = lobe::measure(&|v| m.d(v));
    let chi2 = chi2_test_in(
        &|u| sampler.sample_wm(u),
        &|v| pdf.pdf_wm(v),
        &Chi2Config {
            resolution: 16,
            samples: SAMPLES,
            seed,
            alpha: LEVEL,
        },
        CELL_RELATIVE_TOLERANCE,
        Some(&lobe),
    );
    let ks = [Marginal::CosTheta, Marginal::Phi].map(|marginal| {
        ks_test_lobe(
            &|u| sampler.sample_wm(u),
            &|v| pdf.pdf_wm(v),
            marginal,
            &lobe,
            &[],
            &KsConfig {
                samples: SAMPLES,
                seed: seed + 1,
                alpha: LEVEL,
            },
        )
    });
    let t_ks = Instant::now();
    let norm =
        integrate_hemisphere_lobe(&|v| m.d(v) * v[2], &lobe, None, Accuracy::relative(1e-11));
    eprintln!(
        "{json}: χ² integration {:.2} s (p {:.3}), KS tables {:.2} + {:.2} s ({} + {} knots, \
         {} + {} evaluations), normalization {:.2} s ({} evaluations)",
        chi2.integration_seconds,
        chi2.p_value,
        ks[0].table_seconds,
        ks[1].table_seconds,
        ks[0].knots,
        ks[1].knots,
        ks[0].evaluations,
        ks[1].evaluations,
        t_ks.elapsed().as_secs_f64(),
        norm.evaluations
    );
    Row {
        json: json.to_string(),
        chi2_p: chi2.p_value,
        chi2_pass: chi2.verdict == TestOutcome::Pass,
        ks_p: [ks[0].p_value, ks[1].p_value],
        ks_pass: [
            ks[0].verdict == TestOutcome::Pass,
            ks[1].verdict == TestOutcome::Pass,
        ],
        normalization_error: (norm.value - 1.0).abs(),
        normalization_bound: norm.error_bound,
        seconds: t.elapsed().as_secs_f64(),
        lobe,
    }
}

fn print(rows: &[Row]) {
    eprintln!(
        "| model | χ² p | KS θ p | KS φ p | |∫D cos − 1| (bound) | lobe narrowest / widest | s |"
    );
    eprintln!("|---|---|---|---|---|---|---|");
    for r in rows {
        eprintln!(
            "| `{}` | {:.3} | {:.3} | {:.3} | {:.1e} ({:.1e}) | {:.2e} / {:.2e} | {:.1} |",
            r.json,
            r.chi2_p,
            r.ks_p[0],
            r.ks_p[1],
            r.normalization_error,
            r.normalization_bound,
            r.lobe.narrowest,
            r.lobe.widest,
            r.seconds
        );
    }
}

#[test]
fn sweep_correct_samplers_pass_from_alpha_1e_4_to_2() {
    let mut cases = Vec::new();
    for family in [
        r#""family":"ggx""#,
        r#""family":"beckmann""#,
        r#""family":"std","gamma":2.5"#,
    ] {
        for a in [1e-4, 1e-3, 1e-2, 0.3, 1.0, 2.0] {
            for (ax, ay) in roughness(a) {
                // CI: the extremes, isotropic for every family, and 1:100 for GGX α = 1e-4 (an
                // anisotropic case costs 70–270 s on the loaded shared 2-core machine, mostly
                // the 1e-9 normalization integral and the KS φ table).
                let ci = (ax == ay && (a == 1e-4 || a == 2.0))
                    || (ax != ay && a == 1e-4 && family.contains("ggx"));

                if !(ci || extensive()) {
                    continue;
                }
                cases.push(if ax == ay {
                    format!(r#"{{{family},"alpha":{ax}}}"#)
                } else {
                    format!(r#"{{{family},"alpha_x":{ax},"alpha_y":{ay}}}"#)
                });
            }
        }
    }
    let rows: Vec<Row> = cases
        .par_iter()
        .enumerate()
        .map(|(i, json)| run(json, json, 1000 + 2 * i as u64))
        .collect();
    print(&rows);
    for r in &rows {
        assert!(r.chi2_pass, "χ² of {}: p = {}", r.json, r.chi2_p);
        assert!(
            r.ks_pass[0] && r.ks_pass[1],
            "KS of {}: {:?}",
            r.json,
            r.ks_p
        );
        assert!(
            r.normalization_error < NORMALIZATION,
            "∫ D cos θ of {}: error {:e}",
            r.json,
            r.normalization_error
        );
    }
}

#[test]
fn sweep_narrow_sampler_off_by_five_percent_fails() {
    let cases = [
        (
            r#"{"family":"ggx","alpha":0.001}"#,
            r#"{"family":"ggx","alpha":0.00105}"#,
        ),
        (
            r#"{"family":"beckmann","alpha":0.0001}"#,
            r#"{"family":"beckmann","alpha":0.000105}"#,
        ),
        (
            r#"{"family":"std","gamma":2.5,"alpha_x":0.0001,"alpha_y":0.01}"#,
            r#"{"family":"std","gamma":2.5,"alpha_x":0.000105,"alpha_y":0.0105}"#,
        ),
    ];
    // The anisotropic case only with MFH_EXTENSIVE=1 (its quadrature is slow, above).
    let n = if extensive() { cases.len() } else { 2 };
    let rows: Vec<Row> = cases[..n]
        .par_iter()
        .map(|(pdf, sampler)| run(pdf, sampler, 77))
        .collect();
    print(&rows);
    for r in &rows {
        // The θ marginal sees a 5 % scale error at any width (D_N ≈ 0.05·max 2F(1 − F) ≈ 0.025,
        // λ ≈ 11 at N = 2·10⁵); the (φ, cos θ) grid of R = 16 cannot (all the mass is in its top
        // row), so only the KS verdict is asserted.
        assert!(!r.ks_pass[0], "{}: KS θ p = {}", r.json, r.ks_p[0]);
        assert!(r.ks_p[0] < 1e-12, "{}: KS θ p = {}", r.json, r.ks_p[0]);
    }
}
