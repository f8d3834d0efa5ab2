//! Limits: the Student-t family tends to Beckmann as γ → ∞ (document 001 §4), at the measured rate
//! O(1/γ), for D and Λ. Each record carries the fitted exponent (the verdict) and the constant
//! of the rate: max over γ of γ × (relative D error) or γ × (absolute Λ error).

use super::{applied, covers, Planned};
use crate::check::Check;
use crate::record::{relative_error, Measured, Verdict};
use crate::tolerance::LIMIT_RATE;
use mfh_reference::geometry::from_spherical;
use mfh_reference::ModelSpec;
use serde_json::json;

const GAMMAS: [f64; 4] = [1e2, 1e4, 1e6, 1e8];

/// Least-squares slope of ln e against ln γ.
fn fitted_exponent(gammas: &[f64], errors: &[f64]) -> f64 {
    let xs: Vec<f64> = gammas.iter().map(|g| g.ln()).collect();
    let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// Plans the γ → ∞ checks for an STD material of roughness `alpha`.
pub fn plan(alpha: f64, why: &str) -> Vec<Planned> {
    // The incidence where cot θ = α (a = 1, one slope standard deviation): the 1/γ term leads
    // there from γ = 100 on. Deep in the tail (a ≫ 1) the Student tail dominates until γ ≫ a⁴
    // (at θ = 0.5, α = 0.2, a = 9.2: STD's Λ at γ = 100 is 2.6e10 times Beckmann's), and the
    // fitted exponent measures the pre-asymptotic regime instead of the rate.
    ["d", "lambda"]
        .into_iter()
        .map(|quantity| {
            // D at tan θ_m = α, Λ at cot θ = α.
            let theta = if quantity == "d" {
                alpha.atan()
            } else {
                (1.0 / alpha).atan()
            };
            let case =
                json!({"quantity": quantity, "alpha": alpha, "theta": theta, "gammas": GAMMAS});
            Check::new(
                "limits.std_to_beckmann",
                json!({"family": "std", "gamma": "→∞", "alpha": alpha}),
                case,
                "seed 001 §4 (γ → ∞: STD → Beckmann), Table 1 (γ = ∞ row)",
            )
            .why(format!(
                "{why}: STD must reach Beckmann as γ → ∞ at rate 1/γ"
            ))
            .covers(vec![covers("std", quantity, "default")])
            .run(move |r, _| {
                let w = from_spherical(theta, 0.0);
                let eval = |spec: ModelSpec| -> Option<f64> {
                    let m = spec.build().ok()?;
                    Some(if quantity == "d" {
                        m.d(w)
                    } else {
                        m.as_smith()?.lambda(w)
                    })
                };
                let std = |g: f64| {
                    ModelSpec::Std(mfh_reference::ndf::student::StdSpec {
                        gamma: g,
                        alpha: Some(alpha),
                        alpha_x: None,
                        alpha_y: None,
                    })
                };
                let (Some(limit), Some(at_inf)) = (
                    eval(ModelSpec::Beckmann(
                        mfh_reference::ndf::beckmann::BeckmannSpec {
                            alpha: Some(alpha),
                            alpha_x: None,
                            alpha_y: None,
                        },
                    )),
                    eval(std(f64::INFINITY)),
                ) else {
                    r.verdict = Verdict::Error {
                        message: "cannot build the models".into(),
                    };
                    return Ok(());
                };
                let values: Vec<f64> = GAMMAS
                    .iter()
                    .map(|&g| eval(std(g)).unwrap_or(f64::NAN))
                    .collect();
                let errors: Vec<f64> = values.iter().map(|&v| relative_error(v, limit)).collect();
                // The constant of the O(1/γ) rate: relative for D, absolute for Λ (Λ → 0
                // at grazing-free incidences is not the concern; its size is O(1)).
                let scaled: Vec<f64> = GAMMAS
                    .iter()
                    .zip(&values)
                    .map(|(&g, &v)| {
                        g * if quantity == "d" {
                            relative_error(v, limit)
                        } else {
                            (v - limit).abs()
                        }
                    })
                    .collect();
                let constant = scaled.iter().copied().fold(f64::NAN, f64::max);
                let exponent = fitted_exponent(&GAMMAS, &errors);
                r.value = Some(exponent);
                r.measured = Some(Measured::Rate {
                    exponent,
                    expected: -1.0,
                });
                r.tolerance = Some(applied(&LIMIT_RATE));
                r.case = json!({"quantity": quantity, "alpha": alpha, "theta": theta,
                                        "gammas": GAMMAS, "relative_errors": errors,
                                        "rate_constant": constant,
                                        "rate_constant_kind": if quantity == "d" {
                                            "max γ·|D_γ/D_∞ − 1|"
                                        } else {
                                            "max γ·|Λ_γ − Λ_∞|"
                                        },
                                        "gamma_times_error": scaled,
                                        "gamma_inf_equals_beckmann": at_inf == limit});
                r.verdict = if (exponent + 1.0).abs() <= LIMIT_RATE.value && at_inf == limit {
                    Verdict::Pass
                } else {
                    Verdict::Fail
                };
                Ok(())
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_and_its_constants_are_recorded() {
        let ctx = super::super::RunContext { seed: 1 };
        for alpha in [0.2, 0.4] {
            for p in plan(alpha, "test") {
                let r = (p.run)(&ctx);
                let c = r.case["rate_constant"].as_f64().unwrap_or(f64::NAN);
                println!(
                    "α = {alpha} {}: exponent {:?}, constant {c:.4}, γ·error {}",
                    r.case["quantity"], r.value, r.case["gamma_times_error"]
                );
                assert!(matches!(r.verdict, Verdict::Pass), "{:?}", r.verdict);
                // O(1/γ): the constant is finite and of order one.
                assert!(c.is_finite() && c > 1e-3 && c < 1e2, "{c}");
            }
        }
    }
}
