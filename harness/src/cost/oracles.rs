//! The oracles' own knobs, measured like routes: what a tighter quadrature tolerance, a larger
//! Monte Carlo N or a larger chi-square sample count buys in accuracy (or detection power) and
//! costs in time.
//!
//! - Quadrature: Λ of STD γ = 3.5 by `oracle::quadrature::integrate_upper` of its definition
//!   (document 001 eq 5), asked for relative tolerances 1e-2 … 1e-12, against the certified
//!   double-double Λ: the achieved error next to the tolerance asked.
//! - Monte Carlo: ∫ D cos θ dω = 1 of GGX (α = 0.5) by `oracle::monte_carlo::estimate` with
//!   directions uniform on the hemisphere, N = 10³ … 10⁶, over 4 seeds: the largest |mean − 1|
//!   and the standard error.
//! - Chi-square: GGX (α = 0.3) sampled with a roughness distorted by a factor 1 + ε and tested
//!   against the undistorted pdf at the audit's level α = 1e-3 (`tolerance::STATISTICAL_ALPHA`,
//!   before its Šidák share); per sample count, the smallest ε caught (the "error" axis: the
//!   distortion that slips through is below it) and the time of one test.

use super::catalogue::THETAS;
use super::timing::Budget;
use super::{finish, measure, Candidate, CostOptions, Quantity, RouteCost, Sweep};
use crate::oracle::chi2::{chi2_test_in, Chi2Config};
use crate::oracle::precise::student_lambda_standardized;
use crate::oracle::quadrature::{integrate_upper, Accuracy};
use mfh_reference::ndf::ggx::Ggx;
use mfh_reference::ndf::student_lambda::p2_norm;
use mfh_reference::{Ndf, NormalSampler};
use std::time::Instant;

/// The tolerances asked of the quadrature oracle.
pub const QUADRATURE_TOLERANCES: [f64; 6] = [1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12];

/// Monte Carlo sample counts (the quick run stops at 10⁵).
pub const MC_SAMPLES: [u64; 4] = [1_000, 10_000, 100_000, 1_000_000];

/// Chi-square sample counts (the quick run stops at 10⁵).
pub const CHI2_SAMPLES: [u64; 3] = [10_000, 100_000, 1_000_000];

/// Roughness distortions injected into the chi-square sampler, largest first.
pub const DISTORTIONS: [f64; 6] = [0.3, 0.1, 0.03, 0.01, 0.003, 0.001];

/// A quantity to run.
pub type Run = Box<dyn FnOnce() -> Quantity>;

/// The number of quantities [`quantities`] returns.
pub fn planned(options: &CostOptions) -> usize {
    if options.selection.oracles {
        3
    } else {
        0
    }
}

/// The oracle quantities of a run.
pub fn quantities(options: &CostOptions, budget: Option<Budget>) -> Vec<Run> {
    if !options.selection.oracles {
        return vec![];
    }
    let (quick, seed) = (options.quick, options.seed);
    vec![
        Box::new(move || measure(quadrature(), budget)),
        Box::new(move || monte_carlo(quick, seed, budget)),
        Box::new(move || chi2_power(quick, seed, budget.is_some())),
    ]
}

/// The quadrature oracle of STD Λ (γ = 3.5, standardized) at each tolerance.
pub fn quadrature() -> Sweep<'static> {
    let c: f64 = 3.5;
    let s = super::catalogue::ALPHA * (c - 1.0).sqrt();
    let xs: Vec<f64> = THETAS[..THETAS.len() - 1]
        .iter()
        .map(|t| t.cos() / t.sin() / s)
        .collect();
    let refs: Vec<_> = xs
        .iter()
        .map(|&x| student_lambda_standardized(c, x).ok())
        .collect();
    let norm = p2_norm(c);
    let candidates = QUADRATURE_TOLERANCES
        .iter()
        .map(|&tol| {
            let xs = xs.clone();
            Candidate::total(format!("tolerance {tol:e}"), move |i| {
                let x = xs[i];
                let p2 = |q: f64| norm * (1.0 + q * q).powf(0.5 - c);
                integrate_upper(&|q| (q - x) * p2(q), x, 1.0, Accuracy::relative(tol)).value / x
            })
        })
        .collect();
    Sweep {
        name: "oracle: quadrature tolerance (STD Λ, γ = 3.5)".into(),
        reference: "oracle::precise (certified double-double Λ at the same x)".into(),
        error: "relative, max over θ (the achieved error against the tolerance asked)".into(),
        inputs_text: format!(
            "(1/x)∫_x^∞ (q − x) P2(q) dq, standardized P2 of seed 001 eq 15, x = cot θ/(α√(γ−1)), \
             α = {}, θ as the STD Λ sweep without π/2 − 1e-6",
            super::catalogue::ALPHA
        ),
        inputs: xs.len(),
        error_of: Box::new(move |i, v| refs[i].map(|r| r.relative_error_of(v))),
        candidates,
    }
}

/// Seeds of the Monte Carlo sweep: the run's seed and the next three.
const MC_SEEDS: u64 = 4;

/// 2π D(m) cos θ with m uniform on the hemisphere (cos θ = u₁, φ = 2π u₂): mean 1.
fn projected_area_integrand(ggx: &Ggx, u: [f64; 2]) -> f64 {
    let (z, phi) = (u[0], 2.0 * std::f64::consts::PI * u[1]);
    let r = (1.0 - z * z).max(0.0).sqrt();
    2.0 * std::f64::consts::PI * ggx.d([r * phi.cos(), r * phi.sin(), z]) * z
}

/// The Monte Carlo oracle at each N: max |mean − 1| over 4 seeds, and the standard error.
pub fn monte_carlo(quick: bool, seed: u64, budget: Option<Budget>) -> Quantity {
    let ggx = Ggx::new(0.5, 0.5).expect("valid GGX");
    let counts: Vec<u64> = MC_SAMPLES
        .iter()
        .copied()
        .filter(|&n| !quick || n <= 100_000)
        .collect();
    let candidates = counts
        .iter()
        .map(|&n| {
            let g = ggx.clone();
            Candidate::total(format!("N = {n}"), move |i| {
                crate::oracle::monte_carlo::estimate(
                    &|u| projected_area_integrand(&g, u),
                    n,
                    seed.wrapping_add(i as u64),
                )
                .mean
            })
        })
        .collect();
    let sweep = Sweep {
        name: "oracle: Monte Carlo N (∫ D cos θ dω of GGX α = 0.5)".into(),
        reference: "the exact value 1 (normalization of D, seed 001 eq 2)".into(),
        error: "absolute |mean − 1|, max over 4 seeds".into(),
        inputs_text: format!(
            "directions uniform on the hemisphere; seeds {seed} … {}",
            seed + MC_SEEDS - 1
        ),
        inputs: MC_SEEDS as usize,
        error_of: Box::new(|_, v| Some((v - 1.0).abs())),
        candidates,
    };
    let mut q = measure(sweep, budget);
    for (r, &n) in q.routes.iter_mut().zip(&counts) {
        let e =
            crate::oracle::monte_carlo::estimate(&|u| projected_area_integrand(&ggx, u), n, seed);
        r.note = Some(format!("standard error {:.3e}", e.standard_error));
    }
    q
}

/// Chi-square detection power: per sample count, the smallest roughness distortion caught.
pub fn chi2_power(quick: bool, seed: u64, timed: bool) -> Quantity {
    let alpha = 0.3;
    let level = crate::tolerance::STATISTICAL_ALPHA.value;
    let truth = Ggx::new(alpha, alpha).expect("valid GGX");
    let lobe = crate::oracle::lobe::measure(&|m| truth.d(m));
    let pdf = |m: [f64; 3]| truth.pdf_wm(m);
    let distortions: Vec<f64> = DISTORTIONS
        .iter()
        .copied()
        .filter(|&e| !quick || e >= 0.01)
        .collect();
    let mut routes = Vec::new();
    for n in CHI2_SAMPLES
        .iter()
        .copied()
        .filter(|&n| !quick || n <= 100_000)
    {
        let config = Chi2Config {
            resolution: 16,
            samples: n,
            seed,
            alpha: level,
        };
        let test = |eps: f64| {
            let a = alpha * (1.0 + eps);
            let sampler = Ggx::new(a, a).expect("valid GGX");
            let start = Instant::now();
            let r = chi2_test_in(
                &|u| sampler.sample_wm(u),
                &pdf,
                &config,
                crate::tolerance::CELL_RELATIVE_TOLERANCE,
                Some(&lobe),
            );
            (r, start.elapsed().as_secs_f64())
        };
        let (correct, t0) = test(0.0);
        let mut seconds = vec![t0];
        let mut caught = None;
        for &eps in &distortions {
            let (r, t) = test(eps);
            seconds.push(t);
            if r.verdict == crate::oracle::chi2::TestOutcome::Fail {
                caught = Some(eps);
            } else {
                break;
            }
        }
        seconds.sort_by(f64::total_cmp);
        let timing = super::timing::Timing {
            median: seconds[seconds.len() / 2],
            min: seconds[0],
            max: seconds[seconds.len() - 1],
            batches: seconds.len(),
            evaluations_per_batch: 1,
        };
        routes.push(RouteCost {
            route: format!("N = {n}"),
            status: "measured".into(),
            reason: None,
            max_error: caught,
            evaluated: seconds.len(),
            refused_inputs: 0,
            non_finite: 0,
            seconds_per_eval: timed.then_some(timing.median),
            timing: timed.then_some(timing),
            note: Some(format!(
                "{}; the undistorted sampler: p = {:.3} ({})",
                match caught {
                    Some(e) => format!("smallest distortion caught: ε = {e}"),
                    None => format!("no distortion down to ε = {} caught", distortions[0]),
                },
                correct.p_value,
                if correct.verdict == crate::oracle::chi2::TestOutcome::Pass {
                    "passes"
                } else {
                    "FAILS: a false alarm"
                }
            )),
        });
    }
    finish(Quantity {
        name: "oracle: chi-square sample count (detection power)".into(),
        reference: "GGX α = 0.3 pdf_wm; the sampler's α distorted to α(1 + ε)".into(),
        error: format!(
            "the smallest ε ∈ {{{}}} rejected at α = {level} (tests stop at the first ε that \
             passes; seconds = one test, median over the tests)",
            distortions
                .iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        inputs: format!("resolution 16 (16 × 32 cells), seed {seed}"),
        routes,
        frontier: vec![],
    })
}
