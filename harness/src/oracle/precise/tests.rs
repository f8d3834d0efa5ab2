//! Tests of the precise path: N_C where Γ is elementary, Λ against a second substitution of its
//! defining integral and against GGX's elementary Λ in double-double, and the reference crate's
//! closed forms against the certified values (measured maxima printed with `--nocapture`).

use super::double_double::DoubleDouble as D;
use super::*;
use mfh_reference::geometry::from_spherical;

fn rel(a: D, b: D) -> f64 {
    ((a - b) / b).hi().abs()
}

#[test]
fn student_norm_matches_gamma_where_it_is_elementary() {
    let pi = D::PI;
    // N_C = Γ(C − ½)/(√π Γ(C − 1)).
    let cases = [
        (1.5, D::ONE / pi),
        (2.0, D::from(0.5)),
        (2.5, D::from(2.0) / pi),
        (3.0, D::from(0.75)),
        (4.0, D::from(15.0 / 16.0)),
        (5.5, D::from(24.0) / (pi * D::from(105.0 / 16.0))),
    ];
    for (c, exact) in cases {
        let n = student_norm(c).expect("certified");
        assert!(
            rel(n.value_dd, exact) < 1e-28,
            "C = {c}: {:e}",
            rel(n.value_dd, exact)
        );
        assert!(n.error_bound >= (n.value_dd - exact).hi().abs());
    }
}

/// (1/x) ∫_x^∞ (q − x) P(q) dq by the plain map q = x + L·v/(1 − v), v ∈ (0, 1), for a
/// standardized density P: a route that shares nothing with the moment-tail map but the rule.
fn plain_lambda(p: &dyn Fn(D) -> D, x: D, width: D) -> D {
    let integrand = |v: D, complement: D| {
        let offset = width * v / complement;
        let density = p(x + offset);
        if density.hi() == 0.0 {
            return D::ZERO;
        }
        offset * density * width / complement.square()
    };
    tanh_sinh::integrate_unit(&integrand, 1e-28, 1e-30).value / x
}

#[test]
fn lambda_matches_a_plain_substitution_of_its_integral() {
    let sqrt_pi = D::PI.sqrt();
    for a in [0.05, 0.4, 1.0, 2.5, 6.0] {
        let model = PreciseModel::new(Family::Beckmann, 1.0).expect("valid");
        let w = [1.0, 0.0, a];
        let certified = model.lambda(w).expect("certified");
        let x = D::from(a);
        let width = D::ONE / (x.ldexp(1) + D::ONE);
        let plain = plain_lambda(&|q: D| (-q.square()).exp() / sqrt_pi, x, width);
        assert!(rel(certified.value_dd, plain) < 1e-26, "a = {a}");
    }
    for (gamma, norm) in [(2.5, D::from(2.0) / D::PI), (4.0, D::from(15.0 / 16.0))] {
        for x in [0.05, 0.7, 3.0, 20.0] {
            let alpha = 1.0 / (gamma - 1.0f64).sqrt();
            let model = PreciseModel::new(Family::Std { gamma }, alpha).expect("valid");
            // s = α √(γ − 1) is 1 up to rounding: pass μ = x · s so that x is what we say.
            let s = D::from(alpha) * D::from(gamma - 1.0).sqrt();
            let mu = D::from(x) * s;
            let w = [1.0, 0.0, mu.hi()];
            let x_exact = D::from(mu.hi()) / s;
            let certified = model.lambda(w).expect("certified");
            let p = |q: D| norm * (q.square()).ln1p().mul_f64(0.5 - gamma).exp();
            let width = D::ONE + x_exact;
            let plain = plain_lambda(&p, x_exact, width);
            assert!(
                rel(certified.value_dd, plain) < 1e-26,
                "γ = {gamma}, x = {x}: {:e}",
                rel(certified.value_dd, plain)
            );
        }
    }
}

#[test]
fn ggx_lambda_matches_its_elementary_form_in_double_double() {
    let model = PreciseModel::new(Family::Ggx, 0.3).expect("valid");
    for theta in [1e-3, 0.2, 0.8, 1.3, 1.55, 1.5706] {
        let w = from_spherical(theta, 0.4);
        let certified = model.lambda(w).expect("certified");
        // Λ = 1/(2a² + 2a√(a² + 1)), a = μ/α.
        let [x, y, z] = w.map(D::from);
        let a = z / (x.square() + y.square()).sqrt() / D::from(0.3);
        let exact = D::ONE / (a.square().ldexp(1) + a.ldexp(1) * (a.square() + D::ONE).sqrt());
        assert!(rel(certified.value_dd, exact) < 1e-27, "θ = {theta}");
        assert!(certified.error_bound >= (certified.value_dd - exact).hi().abs());
        assert!(certified.relative_bound() <= CERTIFIED_RELATIVE);
    }
}

/// The reference model of a spec.
fn reference(spec: &str) -> Box<dyn mfh_reference::Model> {
    serde_json::from_str::<ModelSpec>(spec)
        .expect("spec")
        .build()
        .expect("model")
}

/// The measured agreement of one model's closed forms with the certified values.
#[derive(Debug, Default, Clone, Copy)]
struct Agreement {
    /// Largest relative error of Λ, of D.
    lambda: f64,
    d: f64,
    /// Largest relative error divided by what the conditioning allows, 1e-14 + 8 ε κ.
    lambda_ratio: f64,
    d_ratio: f64,
}

/// What an f64 evaluation may be off by at condition number κ: 1e-14 plus 8 ε κ.
fn allowed(condition: f64) -> f64 {
    1e-14 + 8.0 * f64::EPSILON * condition
}

/// The agreement of the reference's Λ and D with the certified values over a grid of θ.
fn agreement(spec: &str, thetas: &[f64]) -> Agreement {
    let model = reference(spec);
    let precise = PreciseModel::from_spec(&model.spec()).expect("covered");
    let smith = model.as_smith().expect("smith");
    let mut out = Agreement::default();
    // Values below 1e-290 (Beckmann and STD γ = 1000 where Λ or D underflows) are outside the
    // certified range and skipped.
    let error_of = |certified: Result<Certified, PreciseError>, value: f64| match certified {
        Err(PreciseError::Underflow { .. }) => None,
        Ok(c) => Some(c.relative_error_of(value)),
        Err(e) => panic!("{spec}: {e}"),
    };
    for &theta in thetas {
        let w = from_spherical(theta, 0.7);
        if let Some(e) = error_of(precise.lambda(w), smith.lambda(w)) {
            let kappa = precise.lambda_condition(w).expect("condition");
            out.lambda = out.lambda.max(e);
            out.lambda_ratio = out.lambda_ratio.max(e / allowed(kappa));
        }
        if let Some(e) = error_of(precise.d(w), model.d(w)) {
            out.d = out.d.max(e);
            out.d_ratio = out.d_ratio.max(e / allowed(precise.d_condition(w)));
        }
    }
    out
}

#[test]
fn closed_forms_agree_with_the_certified_values() {
    let thetas = [1e-3, 0.1, 0.4, 0.8, 1.1, 1.3, 1.45, 1.54, 1.565];
    let mut families: Vec<(&str, Vec<String>)> = vec![("beckmann", vec![]), ("ggx", vec![])];
    for gamma in [1.6, 2.0, 2.5, 3.7, 10.0, 1e3] {
        families.push(("std", vec![]));
        for alpha in [0.05, 0.3, 1.0] {
            families.last_mut().expect("pushed").1.push(format!(
                r#"{{"family":"std","gamma":{gamma},"alpha":{alpha}}}"#
            ));
        }
    }
    for alpha in [0.05, 0.3, 1.0] {
        families[0]
            .1
            .push(format!(r#"{{"family":"beckmann","alpha":{alpha}}}"#));
        families[1]
            .1
            .push(format!(r#"{{"family":"ggx","alpha":{alpha}}}"#));
    }
    for (family, specs) in &families {
        let mut worst = Agreement::default();
        for spec in specs {
            let a = agreement(spec, &thetas);
            assert!(
                a.lambda_ratio <= 1.0 && a.d_ratio <= 1.0,
                "{spec}: Λ off by {:e}, D by {:e} (beyond 1e-14 + 8 ε κ)",
                a.lambda,
                a.d
            );
            worst = Agreement {
                lambda: worst.lambda.max(a.lambda),
                d: worst.d.max(a.d),
                lambda_ratio: worst.lambda_ratio.max(a.lambda_ratio),
                d_ratio: worst.d_ratio.max(a.d_ratio),
            };
        }
        println!(
            "{family} {}: max relative error Λ {:.2e} (of allowed {:.2}), D {:.2e} (of allowed {:.2})",
            specs[0], worst.lambda, worst.lambda_ratio, worst.d, worst.d_ratio
        );
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    assert!(PreciseModel::new(Family::Beckmann, 0.0).is_err());
    assert!(PreciseModel::new(Family::Std { gamma: 1.0 }, 0.3).is_err());
    assert!(PreciseModel::new(Family::Ggx, f64::NAN).is_err());
    let model = PreciseModel::new(Family::Std { gamma: 1.4 }, 0.3).expect("valid D");
    assert!(model.lambda([0.6, 0.0, 0.8]).is_err());
    assert!(model.d([0.6, 0.0, 0.8]).is_ok());
    let ggx = PreciseModel::new(Family::Ggx, 0.3).expect("valid");
    assert!(ggx.lambda([1.0, 0.0, 0.0]).is_err());
    assert!(ggx.lambda([1.0, 0.0, f64::NAN]).is_err());
    assert_eq!(ggx.lambda([0.0, 0.0, 1.0]).expect("0").value, 0.0);
    assert_eq!(ggx.d([0.0, 0.6, -0.8]).expect("0").value, 0.0);
    assert!(ggx.d([0.0; 3]).is_err());
    let anisotropic: ModelSpec =
        serde_json::from_str(r#"{"family":"ggx","alpha_x":0.1,"alpha_y":0.2}"#).expect("spec");
    assert!(PreciseModel::from_spec(&anisotropic).is_err());
    assert!(student_norm(0.5).is_err());
}

#[test]
fn extreme_parameters_give_a_value_or_an_error() {
    let models = [
        PreciseModel::new(Family::Std { gamma: 1e8 }, 0.3),
        PreciseModel::new(Family::Std { gamma: 1.5 + 1e-9 }, 0.3),
        PreciseModel::new(Family::Std { gamma: 1.05 }, 0.3),
        PreciseModel::new(Family::Beckmann, 1e-4),
        PreciseModel::new(Family::Ggx, 1e4),
    ];
    for model in models {
        let model = model.expect("valid");
        for theta in [0.0, 1e-8, 0.5, 1.5, std::f64::consts::FRAC_PI_2 - 1e-9] {
            let w = from_spherical(theta, 0.3);
            let lambda = model.lambda(w);
            let d = model.d(w);
            println!(
                "{:?} θ = {theta}: Λ {lambda:?}\n    D {d:?}",
                model.family()
            );
            for c in [lambda, d].into_iter().flatten() {
                assert!(c.value.is_finite() && c.relative_bound() <= CERTIFIED_RELATIVE);
            }
        }
    }
}
