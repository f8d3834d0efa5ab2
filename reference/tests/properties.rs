//! Property tests (proptest) of every registered family, over random directions, random
//! uniform pairs — with the edges of [0, 1)² drawn on purpose — and, for GGX, Beckmann and STD,
//! random parameters. Each property is a fact of microfacet theory that any correct model
//! satisfies, so no oracle is needed:
//!
//! - D(m) is finite and ≥ 0 on the upper hemisphere;
//! - Λ(w) is finite and ≥ 0 above the horizon, G1 ∈ (0, 1] toward the normal, and the
//!   height-correlated G2 = 1/(1 + Λo + Λi) is never below the uncorrelated G1·G1 (document 001,
//!   eq 22–23: (1 + a)(1 + b) ≥ 1 + a + b for a, b ≥ 0);
//! - Λ is non-decreasing in θ for the shape-invariant families (document 001, Λ a function of
//!   a = cot θ/α that decreases in a);
//! - `sample_wm(u)` is a finite unit vector in the upper hemisphere for every u ∈ [0, 1)², and
//!   `pdf_wm(m) = D(m) m_z` there (the density of normal sampling).
//!
//! Case counts: 256 per property for the closed-form families; the families whose Λ or sampler
//! is numerical (registry flags) get 24, to keep the test under a few seconds.

use mfh_reference::registry::FAMILIES;
use mfh_reference::{Masking, Model, ModelSpec, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::f64::consts::{FRAC_PI_2, TAU};

/// The largest f64 below 1: the top edge of [0, 1).
const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;

/// A uniform number in [0, 1), with the edges 0, 2⁻⁵³ and 1 − 2⁻⁵³ drawn one time in four.
fn unit() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => 0.0..1.0f64,
        1 => prop_oneof![Just(0.0), Just(f64::EPSILON / 2.0), Just(BELOW_ONE)],
    ]
}

/// θ in [0, π/2 − 1e-9] with normal incidence and near-grazing drawn on purpose.
fn theta() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => 0.0..(FRAC_PI_2 - 1e-9),
        1 => prop_oneof![Just(0.0), Just(1e-8), Just(FRAC_PI_2 - 1e-6), Just(FRAC_PI_2 - 1e-9)],
    ]
}

fn direction(theta: f64, phi: f64) -> Vec3 {
    let (s, c) = theta.sin_cos();
    [s * phi.cos(), s * phi.sin(), c]
}

/// Every registry example, built; with the number of cases its cost allows.
fn examples() -> Vec<(String, Box<dyn Model>, u32)> {
    let mut out = Vec::new();
    for info in FAMILIES {
        let cases = if info.lambda_numerical || info.slow_sampler {
            24
        } else {
            256
        };
        for text in info.examples {
            let spec: ModelSpec = serde_json::from_str(text).expect("registry example parses");
            let model = spec.build().expect("registry example builds");
            out.push((text.to_string(), model, cases));
        }
    }
    out
}

fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    })
}

#[test]
fn d_is_finite_and_non_negative_on_the_upper_hemisphere() {
    for (name, model, cases) in examples() {
        runner(cases)
            .run(&(theta(), 0.0..TAU), |(t, p)| {
                let d = model.d(direction(t, p));
                prop_assert!(
                    d.is_finite() && d >= 0.0,
                    "{name}: D = {d} at θ = {t}, φ = {p}"
                );
                Ok(())
            })
            .unwrap();
    }
}

#[test]
fn masking_is_finite_bounded_and_correlation_never_lowers_g2() {
    for (name, model, cases) in examples() {
        let Some(smith) = model.as_smith() else {
            continue;
        };
        runner(cases)
            .run(
                &(theta(), 0.0..TAU, theta(), 0.0..TAU),
                |(to, po, ti, pi)| {
                    let (wo, wi) = (direction(to, po), direction(ti, pi));
                    let lambda = smith.lambda(wo);
                    prop_assert!(
                        lambda.is_finite() && lambda >= 0.0,
                        "{name}: Λ = {lambda} at θ = {to}, φ = {po}"
                    );
                    let g1 = smith.g1(wo, [0.0, 0.0, 1.0]);
                    prop_assert!(g1 > 0.0 && g1 <= 1.0, "{name}: G1 = {g1} at θ = {to}");
                    let n = [0.0, 0.0, 1.0];
                    let correlated = smith.g2(wo, wi, n, Masking::HeightCorrelated);
                    let uncorrelated = smith.g2(wo, wi, n, Masking::Uncorrelated);
                    prop_assert!(
                        correlated >= uncorrelated * (1.0 - 1e-15),
                        "{name}: height-correlated G2 {correlated} < uncorrelated {uncorrelated} \
                         at θo = {to}, θi = {ti}"
                    );
                    Ok(())
                },
            )
            .unwrap();
    }
}

#[test]
fn sampled_normals_are_unit_upper_and_their_pdf_is_d_cos() {
    for (name, model, cases) in examples() {
        let Some(sampler) = model.as_sampler() else {
            continue;
        };
        runner(cases)
            .run(&(unit(), unit()), |(u1, u2)| {
                let m = sampler.sample_wm([u1, u2]);
                let norm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                prop_assert!(
                    m.iter().all(|c| c.is_finite()) && (norm - 1.0).abs() < 1e-12 && m[2] >= 0.0,
                    "{name}: sample_wm([{u1}, {u2}]) = {m:?}"
                );
                let pdf = sampler.pdf_wm(m);
                let want = model.d(m) * m[2];
                prop_assert!(
                    pdf.is_finite() && (pdf - want).abs() <= 1e-12 * want.abs().max(1e-300),
                    "{name}: pdf_wm = {pdf}, D·m_z = {want} at u = [{u1}, {u2}]"
                );
                Ok(())
            })
            .unwrap();
    }
}

/// GGX, Beckmann and STD over random roughness (and γ): Λ non-decreasing in θ.
#[test]
fn lambda_grows_toward_grazing_for_shape_invariant_families() {
    let spec = prop_oneof![
        (1e-3..3.0f64).prop_map(|a| format!(r#"{{"family":"ggx","alpha":{a}}}"#)),
        (1e-3..3.0f64).prop_map(|a| format!(r#"{{"family":"beckmann","alpha":{a}}}"#)),
        (1e-3..3.0f64, 1.6..1e4f64)
            .prop_map(|(a, g)| format!(r#"{{"family":"std","alpha":{a},"gamma":{g}}}"#)),
    ];
    runner(256)
        .run(
            &(spec, theta(), theta(), 0.0..TAU),
            |(text, t1, t2, phi)| {
                let spec: ModelSpec = serde_json::from_str(&text).unwrap();
                let model = spec.build().unwrap();
                let smith = model.as_smith().unwrap();
                let (lo, hi) = (t1.min(t2), t1.max(t2));
                let (a, b) = (
                    smith.lambda(direction(lo, phi)),
                    smith.lambda(direction(hi, phi)),
                );
                prop_assert!(
                    a <= b * (1.0 + 1e-12) + 1e-300,
                    "{text}: Λ({lo}) = {a} > Λ({hi}) = {b}"
                );
                Ok(())
            },
        )
        .unwrap();
}
